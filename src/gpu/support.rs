//! What the GPU backend runs, and whether a device can hold a cloth.

use crate::sim::{Effect, IntegratorKind, Precision, StepConfig};

use super::elements::PackedElements;
use super::error::GpuError;
use super::kernel::WORKGROUP;
use super::packing::{MAX_COLLIDERS, MAX_OBSTACLES, MAX_PARTICLES, Neighbour, Particle};

/// The integrator the GPU backend runs unless told otherwise.
pub const GPU_INTEGRATOR: IntegratorKind = IntegratorKind::SemiImplicitEuler;

/// The integrators the GPU backend runs.
pub const GPU_INTEGRATORS: [IntegratorKind; 4] = [
    IntegratorKind::SemiImplicitEuler,
    IntegratorKind::ImplicitEuler,
    IntegratorKind::Xpbd,
    IntegratorKind::Vbd,
];

/// What of `step`, `precision` and `effects` the GPU backend cannot run, if anything: it
/// runs semi-implicit Euler, implicit Euler (one linearised step), XPBD and VBD in `f32` with
/// gravity, springs (and bend springs), dihedral bending, wind, air damping, pins, handles,
/// up to four sphere and plane colliders, up to four mesh obstacles, still, keyframed or
/// OBJ sequences, and self-collision.
pub fn gpu_support(
    step: &StepConfig,
    precision: Precision,
    effects: &[Effect],
) -> Result<(), GpuError> {
    if precision != Precision::F32 {
        return Err(GpuError::Unsupported(format!(
            "computes in f32 only, not {precision} (f64 is slow or absent on most GPUs, and \
             WGSL has no f64); run {precision} on the CPU backend"
        )));
    }
    if !GPU_INTEGRATORS.contains(&step.integrator) {
        let runs: Vec<&str> = GPU_INTEGRATORS.iter().map(|k| k.label()).collect();
        return Err(GpuError::Unsupported(format!(
            "runs {} only, not {}",
            runs.join(", "),
            step.integrator.label()
        )));
    }
    for e in effects {
        if let Err(what) = e.on_gpu() {
            return Err(GpuError::Unsupported(format!(
                "has no {what}; run this scene on the CPU backend"
            )));
        }
    }
    let solids = (effects.iter()).filter(|e| matches!(e, Effect::Sphere(_) | Effect::Plane(_)));
    if solids.count() > MAX_COLLIDERS {
        return Err(GpuError::Unsupported(format!(
            "takes at most {MAX_COLLIDERS} colliders"
        )));
    }
    let obstacles = (effects.iter())
        .filter(|e| matches!(e, Effect::Obstacle(_)))
        .count();
    if obstacles > MAX_OBSTACLES {
        return Err(GpuError::Unsupported(format!(
            "takes at most {MAX_OBSTACLES} mesh obstacles"
        )));
    }
    Ok(())
}

/// Storage buffers the substep binds (the most any of the backend's kernels does): the
/// state it reads and the one it writes, the spring offsets and ends, the element forces
/// and each particle's slots among them, and XPBD's constraints.
pub(super) const STORAGE_BUFFERS: u32 = 7;

/// Whether a device with `limits` gives the shaders what they need for `count` particles:
/// [`STORAGE_BUFFERS`] storage buffers in a compute stage, and workgroups of [`WORKGROUP`]
/// enough of them.
pub(super) fn check_device(limits: &wgpu::Limits, count: u32) -> Result<(), GpuError> {
    offers_storage(limits, STORAGE_BUFFERS, "the substep")?;
    let groups = limits.max_compute_workgroups_per_dimension as u64 * WORKGROUP as u64;
    if limits.max_compute_workgroup_size_x < WORKGROUP
        || limits.max_compute_invocations_per_workgroup < WORKGROUP
        || (count as u64) > groups
    {
        return Err(GpuError::Unsupported(format!(
            "needs compute workgroups of {WORKGROUP} for {count} particles, which this \
         device does not offer"
        )));
    }
    Ok(())
}

/// Whether a device with `limits` offers `needed` storage buffers in a compute shader, for
/// `what` (the kernels that bind them).
pub(super) fn offers_storage(
    limits: &wgpu::Limits,
    needed: u32,
    what: &str,
) -> Result<(), GpuError> {
    let storage = limits.max_storage_buffers_per_shader_stage;
    if storage < needed {
        return Err(GpuError::Unsupported(format!(
            "{what} needs {needed} storage buffers in a compute shader; this device offers \
             {storage}"
        )));
    }
    Ok(())
}

/// Whether the stepper's largest storage buffers (the particles' state, and a record per
/// spring end) fit what one binding and one buffer of a device with `limits` may hold: a
/// cloth too big for the device is refused with the sizes, not left to a validation panic.
pub(super) fn fits_buffers(
    limits: &wgpu::Limits,
    particles: u64,
    spring_ends: u64,
) -> Result<(), GpuError> {
    if particles > MAX_PARTICLES {
        return Err(GpuError::Unsupported(format!(
            "takes at most {MAX_PARTICLES} particles, not {particles}"
        )));
    }
    let need = [
        (particles * size_of::<Particle>() as u64, "particles' state"),
        (spring_ends * size_of::<Neighbour>() as u64, "spring ends"),
    ];
    let cloth = format!("{particles} particles, {spring_ends} spring ends");
    fits(limits, &need, &cloth)
}

/// Whether the element pass's buffers for `packed` fit one binding of a device with
/// `limits` (see [`fits_buffers`]).
pub(super) fn fits_elements(
    limits: &wgpu::Limits,
    packed: &PackedElements,
) -> Result<(), GpuError> {
    let (triangles, hinges) = (packed.triangles as u64, packed.hinges as u64);
    let need = [
        ((triangles + 2 * hinges) * 16, "triangles and hinges"),
        ((1 + triangles + 4 * hinges) * 16, "element forces"),
        (packed.incidence.len() as u64 * 4, "element slots"),
    ];
    fits(
        limits,
        &need,
        &format!("{triangles} triangles, {hinges} hinges"),
    )
}

/// The first of `need` (bytes, what) that one storage binding of a device with `limits`
/// cannot hold, said with `cloth`'s sizes.
pub(super) fn fits(
    limits: &wgpu::Limits,
    need: &[(u64, &str)],
    cloth: &str,
) -> Result<(), GpuError> {
    let most = limits
        .max_storage_buffer_binding_size
        .min(limits.max_buffer_size);
    let mib = |bytes: u64| bytes as f64 / (1u64 << 20) as f64;
    match need.iter().find(|&&(bytes, _)| bytes > most) {
        Some(&(bytes, what)) => Err(GpuError::Unsupported(format!(
            "needs {:.1} MiB ({bytes} bytes) in one storage buffer for this cloth's {what} \
             ({cloth}); this device binds at most {:.1} MiB ({most} bytes)",
            mib(bytes),
            mib(most)
        ))),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// llvmpipe's 128 MiB binding holds a 1 000 × 1 000 bench cloth's spring ends (8 bytes
    /// each, 91.4 MiB); a 1 200 × 1 200 one's do not fit and are refused with both sizes;
    /// the most that fits does.
    #[test]
    fn a_cloth_bigger_than_the_devices_buffers_is_refused_with_the_sizes() {
        let limits = wgpu::Limits {
            max_storage_buffer_binding_size: 128 << 20,
            max_buffer_size: 256 << 20,
            ..wgpu::Limits::default()
        };
        assert!(fits_buffers(&limits, 1_000_000, 11_980_004).is_ok());
        let (particles, ends) = (1_440_000, 17_256_004);
        let err = fits_buffers(&limits, particles, ends).expect_err("too big");
        let text = err.to_string();
        assert!(
            text.contains("131.7 MiB") && text.contains("128.0 MiB") && text.contains("spring"),
            "{text}"
        );
        let most = (128u64 << 20) / size_of::<Neighbour>() as u64;
        assert!(fits_buffers(&limits, particles, most).is_ok());
        assert!(fits_buffers(&limits, particles, most + 1).is_err());
        // The smaller of the two limits counts.
        let small_buffers = wgpu::Limits {
            max_buffer_size: 64 << 20,
            ..limits
        };
        assert!(fits_buffers(&small_buffers, particles, most).is_err());
        assert!(fits_buffers(&small_buffers, 3 << 20, 0).is_err());
        // An index needs its 28 bits, whatever the buffers hold.
        let huge = wgpu::Limits {
            max_storage_buffer_binding_size: u64::MAX,
            max_buffer_size: u64::MAX,
            ..limits
        };
        assert!(fits_buffers(&huge, MAX_PARTICLES, 0).is_ok());
        let err = fits_buffers(&huge, MAX_PARTICLES + 1, 0).expect_err("too many");
        assert!(err.to_string().contains("268435456 particles"), "{err}");
        // The element pass's buffers: a triangle is one 16-byte row and one slot, a hinge
        // two rows and four slots.
        let elements = |triangles, hinges| PackedElements {
            triangles,
            hinges,
            ..PackedElements::default()
        };
        let rows = (128u32 << 20) / 16;
        assert!(fits_elements(&limits, &elements(rows - 1, 0)).is_ok());
        let err = fits_elements(&limits, &elements(0, rows / 2)).expect_err("too many slots");
        let text = err.to_string();
        assert!(
            text.contains("element forces") && text.contains("4194304 hinges"),
            "{text}"
        );
        assert!(fits_elements(&limits, &elements(0, rows / 4 - 1)).is_ok());
    }
}
