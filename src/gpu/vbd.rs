//! Vertex block descent on the GPU (`shaders/vbd.wgsl`): the CPU's stencil (the particles
//! in colours, each one's springs seen from it) as one buffer of words, and one dispatch per
//! colour, so a sweep is the CPU's Gauss–Seidel sweep: particles that move at the same time
//! share no spring.

use crate::cloth::ClothModel;
use crate::sim::ForceSet;
use crate::sim::kernels::Stencil;

use super::error::GpuError;
use super::kernel::SubstepKernel;
use super::support::fits;
use super::xpbd::{Colours, colour_record};

/// The stencil of `model`'s springs in `forces` as the shader reads it: the words, where
/// the spans, links and memory start in them, and each colour's record.
pub(super) fn pack_stencil(
    model: &ClothModel,
    forces: &ForceSet,
) -> (Vec<u32>, [u32; 3], Vec<[u32; 4]>) {
    let n = model.particle_count();
    let stencil = Stencil::new(&forces.constraints(model), n);
    let links = stencil.other.len();
    let mut words = Vec::with_capacity(4 * n + 4 * links + 4 * n);
    words.extend(&stencil.order);
    let spans = words.len() as u32;
    for s in &stencil.spans {
        words.extend([s.first, s.count, s.stride]);
    }
    let at_links = words.len() as u32;
    for l in 0..links {
        let [rest, k, c] = [stencil.rest[l], stencil.k[l], stencil.c[l]].map(f32::to_bits);
        words.extend([stencil.other[l], rest, k, c]);
    }
    let memory = words.len() as u32;
    for &m in &model.mass {
        words.extend([0, 0, 0, m.to_bits()]);
    }
    let colours = (stencil.colours.iter())
        .filter(|c| !c.is_empty())
        .map(|c| colour_record(c.start, c.len(), false))
        .collect();
    (words, [spans, at_links, memory], colours)
}

/// The stencil on the device and its colours.
pub(super) struct VbdPass {
    /// Bound in the substep's group 0 (where XPBD binds its constraints).
    pub(super) stencil: wgpu::Buffer,
    /// Its colours, one dispatch each a sweep.
    pub(super) colours: Colours,
    /// Where the spans, links and memory start in the stencil's words.
    pub(super) starts: [u32; 3],
}

impl VbdPass {
    /// The pass for `model`'s springs in `forces`, or an empty one (`None`).
    ///
    /// # Errors
    /// [`GpuError::Unsupported`] with the sizes when the stencil exceeds one binding.
    pub(super) fn new(
        device: &wgpu::Device,
        queue: &wgpu::Queue,
        kernel: &SubstepKernel,
        springs: Option<(&ClothModel, &ForceSet)>,
    ) -> Result<Self, GpuError> {
        let (words, starts, colours) = match springs {
            Some((model, forces)) => pack_stencil(model, forces),
            None => Default::default(),
        };
        let bytes = words.len() as u64 * 4;
        let size = format!("{} words", words.len());
        fits(&device.limits(), &[(bytes, "VBD stencil")], &size)?;
        let stencil = device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("vbd stencil"),
            size: (words.len() as u64 * 4).max(32),
            // Read back by tests (what VBD remembers of a step).
            usage: wgpu::BufferUsages::STORAGE
                | wgpu::BufferUsages::COPY_DST
                | wgpu::BufferUsages::COPY_SRC,
            mapped_at_creation: false,
        });
        if !words.is_empty() {
            queue.write_buffer(&stencil, 0, bytemuck::cast_slice(&words));
        }
        Ok(Self {
            stencil,
            colours: Colours::new(device, queue, kernel, &colours),
            starts,
        })
    }
}
