//! The offscreen render target every frame is drawn into.

use super::error::RenderError;

/// Format of the resolved colour texture: what the GUI shows and capture reads. Shaders
/// write sRGB-encoded values into it, so its bytes are directly the PNG's bytes.
pub const COLOR_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Rgba8Unorm;
pub const DEPTH_FORMAT: wgpu::TextureFormat = wgpu::TextureFormat::Depth32Float;

/// Colour + depth, multisampled where the adapter can (4×, else 1×), resolved into an
/// [`COLOR_FORMAT`] texture.
pub struct RenderTarget {
    width: u32,
    height: u32,
    sample_count: u32,
    /// Multisampled colour (only when `sample_count > 1`).
    msaa: Option<wgpu::TextureView>,
    depth: wgpu::TextureView,
    resolved: wgpu::Texture,
    resolved_view: wgpu::TextureView,
}

/// The largest MSAA count ≤ 4 that both target formats support on this adapter.
pub fn supported_sample_count(adapter: &wgpu::Adapter) -> u32 {
    supported_sample_counts(adapter)
        .last()
        .copied()
        .unwrap_or(1)
}

/// The MSAA counts (1, 2, 4) that both target formats support on this adapter, ascending.
pub fn supported_sample_counts(adapter: &wgpu::Adapter) -> Vec<u32> {
    let color = adapter.get_texture_format_features(COLOR_FORMAT).flags;
    let depth = adapter.get_texture_format_features(DEPTH_FORMAT).flags;
    [1, 2, 4]
        .into_iter()
        .filter(|&n| n == 1 || color.sample_count_supported(n) && depth.sample_count_supported(n))
        .collect()
}

impl RenderTarget {
    /// A target of `width × height` pixels with `sample_count` samples (see
    /// [`supported_sample_count`]).
    ///
    /// # Errors
    /// [`RenderError::BadSize`] for a zero or over-limit size.
    pub fn new(
        device: &wgpu::Device,
        width: u32,
        height: u32,
        sample_count: u32,
    ) -> Result<Self, RenderError> {
        let max = device.limits().max_texture_dimension_2d;
        if width == 0 || height == 0 || width > max || height > max {
            return Err(RenderError::BadSize {
                width,
                height,
                why: format!("each side must be in 1..={max}"),
            });
        }
        let size = wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |label, format, samples, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: Some(label),
                size,
                mip_level_count: 1,
                sample_count: samples,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let resolved = texture(
            "clothsim resolved colour",
            COLOR_FORMAT,
            1,
            wgpu::TextureUsages::RENDER_ATTACHMENT
                | wgpu::TextureUsages::TEXTURE_BINDING
                | wgpu::TextureUsages::COPY_SRC,
        );
        let msaa = (sample_count > 1).then(|| {
            texture(
                "clothsim msaa colour",
                COLOR_FORMAT,
                sample_count,
                wgpu::TextureUsages::RENDER_ATTACHMENT,
            )
            .create_view(&Default::default())
        });
        let depth = texture(
            "clothsim depth",
            DEPTH_FORMAT,
            sample_count,
            wgpu::TextureUsages::RENDER_ATTACHMENT,
        )
        .create_view(&Default::default());
        let resolved_view = resolved.create_view(&Default::default());
        Ok(Self {
            width,
            height,
            sample_count,
            msaa,
            depth,
            resolved,
            resolved_view,
        })
    }

    /// Recreates the textures if the size changed; returns whether it did.
    ///
    /// # Errors
    /// As [`RenderTarget::new`].
    pub fn resize(
        &mut self,
        device: &wgpu::Device,
        width: u32,
        height: u32,
    ) -> Result<bool, RenderError> {
        if (width, height) == (self.width, self.height) {
            return Ok(false);
        }
        *self = Self::new(device, width, height, self.sample_count)?;
        Ok(true)
    }

    pub fn size(&self) -> (u32, u32) {
        (self.width, self.height)
    }

    pub fn sample_count(&self) -> u32 {
        self.sample_count
    }

    /// The resolved colour texture (single-sampled, [`COLOR_FORMAT`]).
    pub fn texture(&self) -> &wgpu::Texture {
        &self.resolved
    }

    /// View of the resolved colour texture, for display.
    pub fn view(&self) -> &wgpu::TextureView {
        &self.resolved_view
    }

    /// Colour attachment: the MSAA texture resolving into the output, or the output itself.
    pub(crate) fn color_attachment(
        &self,
        clear: wgpu::Color,
    ) -> wgpu::RenderPassColorAttachment<'_> {
        let (view, resolve_target) = match &self.msaa {
            Some(msaa) => (msaa, Some(&self.resolved_view)),
            None => (&self.resolved_view, None),
        };
        wgpu::RenderPassColorAttachment {
            view,
            depth_slice: None,
            resolve_target,
            ops: wgpu::Operations {
                load: wgpu::LoadOp::Clear(clear),
                // The MSAA samples are only needed until resolved.
                store: if self.msaa.is_some() {
                    wgpu::StoreOp::Discard
                } else {
                    wgpu::StoreOp::Store
                },
            },
        }
    }

    pub(crate) fn depth_attachment(&self) -> wgpu::RenderPassDepthStencilAttachment<'_> {
        wgpu::RenderPassDepthStencilAttachment {
            view: &self.depth,
            depth_ops: Some(wgpu::Operations {
                load: wgpu::LoadOp::Clear(1.0),
                store: wgpu::StoreOp::Discard,
            }),
            stencil_ops: None,
        }
    }
}
