//! The 3D view: the renderer's offscreen texture shown in the central panel, plus orbit /
//! zoom / pan input. What it shows is exactly what capture writes: the image is copied into
//! egui's pass texel for texel by a paint callback ([`ViewPaint`]).

use egui_wgpu::RenderState;

use crate::render::{
    Frame, OrbitCamera, RenderError, RenderOptions, RenderTarget, Renderer, RgbaImage, read_target,
};

/// Radians of orbit per point dragged.
const ORBIT_PER_POINT: f32 = 0.008;
/// Zoom factor per point scrolled: `exp(−delta · ZOOM_RATE)`.
const ZOOM_RATE: f32 = 0.0025;

pub struct Viewport {
    renderer: Renderer,
    target: RenderTarget,
}

impl Viewport {
    /// Creates the renderer and a first target with `samples` MSAA samples (one the adapter
    /// supports) on the GUI's device.
    ///
    /// # Errors
    /// [`RenderError::BadSize`] for an impossible size.
    pub fn new(
        rs: &RenderState,
        width: u32,
        height: u32,
        samples: u32,
    ) -> Result<Self, RenderError> {
        let target = RenderTarget::new(&rs.device, width.max(1), height.max(1), samples)?;
        let renderer = Renderer::new(&rs.device, samples);
        show_target(rs, &target);
        Ok(Self { renderer, target })
    }

    /// Resizes the target to `width × height` pixels if needed and draws the frame.
    ///
    /// # Errors
    /// [`RenderError::BadSize`].
    pub fn draw(
        &mut self,
        rs: &RenderState,
        width: u32,
        height: u32,
        frame: &Frame<'_>,
        camera: &OrbitCamera,
        options: &RenderOptions,
    ) -> Result<(), RenderError> {
        if self
            .target
            .resize(&rs.device, width.max(1), height.max(1))?
        {
            show_target(rs, &self.target);
        }
        self.renderer
            .render(&rs.device, &rs.queue, &self.target, camera, frame, options);
        Ok(())
    }

    /// MSAA samples per pixel.
    pub fn samples(&self) -> u32 {
        self.target.sample_count()
    }

    /// Puts the last drawn image into the window at `rect`'s top left corner, one texel per
    /// pixel (see [`ViewPaint`]).
    pub fn paint(&self, painter: &egui::Painter, rect: egui::Rect) {
        painter.add(egui_wgpu::Callback::new_paint_callback(rect, PaintView));
    }

    /// Stops showing this view's image (the window keeps only the pipeline).
    pub fn free(&self, rs: &RenderState) {
        if let Some(paint) = rs
            .renderer
            .write()
            .callback_resources
            .get_mut::<ViewPaint>()
        {
            paint.image = None;
        }
    }

    /// Reads the last drawn image back (what the window shows).
    ///
    /// # Errors
    /// [`RenderError::Readback`].
    pub fn read(&self, rs: &RenderState) -> Result<RgbaImage, RenderError> {
        read_target(&rs.device, &rs.queue, &self.target)
    }
}

/// Applies drag and scroll on `response` to `camera`; returns whether the user asked for
/// the view to be reset (double-click).
pub fn camera_input(ui: &egui::Ui, response: &egui::Response, camera: &mut OrbitCamera) -> bool {
    let height = response.rect.height().max(1.0);
    let shift = ui.input(|i| i.modifiers.shift);
    if response.dragged_by(egui::PointerButton::Middle)
        || (response.dragged_by(egui::PointerButton::Primary) && shift)
    {
        let d = response.drag_delta();
        camera.pan(-d.x / height, d.y / height);
    } else if response.dragged_by(egui::PointerButton::Primary)
        || response.dragged_by(egui::PointerButton::Secondary)
    {
        let d = response.drag_delta();
        camera.orbit(-d.x * ORBIT_PER_POINT, d.y * ORBIT_PER_POINT);
    }
    if response.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            camera.zoom((-scroll * ZOOM_RATE).exp());
        }
    }
    response.double_clicked()
}

/// What the window needs to put the view's image into egui's render pass: kept in egui's
/// callback resources, since a paint callback can only reach those. egui's own image shader
/// blends and dithers every pixel; on the software adapter that cost as much as drawing the
/// scene (42 ms of llvmpipe time a frame at 1280 × 720), where this opaque one-texel-per-pixel
/// copy costs next to nothing.
struct ViewPaint {
    pipeline: wgpu::RenderPipeline,
    layout: wgpu::BindGroupLayout,
    sampler: wgpu::Sampler,
    /// The target's image and its size in texels.
    image: Option<(wgpu::BindGroup, u32, u32)>,
}

impl ViewPaint {
    /// The pipeline for the window's format. It matches the pass eframe draws egui in: one
    /// sample and no depth buffer (`NativeOptions`' defaults, which the window keeps).
    fn new(device: &wgpu::Device, window_format: wgpu::TextureFormat) -> Self {
        let module = device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some("clothsim view paint"),
            source: wgpu::ShaderSource::Wgsl(include_str!("../../shaders/view.wgsl").into()),
        });
        let layout = device.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
            label: Some("clothsim view paint layout"),
            entries: &[
                wgpu::BindGroupLayoutEntry {
                    binding: 0,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Texture {
                        sample_type: wgpu::TextureSampleType::Float { filterable: true },
                        view_dimension: wgpu::TextureViewDimension::D2,
                        multisampled: false,
                    },
                    count: None,
                },
                wgpu::BindGroupLayoutEntry {
                    binding: 1,
                    visibility: wgpu::ShaderStages::FRAGMENT,
                    ty: wgpu::BindingType::Sampler(wgpu::SamplerBindingType::Filtering),
                    count: None,
                },
            ],
        });
        let pipeline_layout = device.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
            label: Some("clothsim view paint pipeline layout"),
            bind_group_layouts: &[Some(&layout)],
            immediate_size: 0,
        });
        let fragment = if window_format.is_srgb() {
            "fs_srgb_window"
        } else {
            "fs_main"
        };
        let pipeline = device.create_render_pipeline(&wgpu::RenderPipelineDescriptor {
            label: Some("clothsim view paint"),
            layout: Some(&pipeline_layout),
            vertex: wgpu::VertexState {
                module: &module,
                entry_point: Some("vs_main"),
                compilation_options: Default::default(),
                buffers: &[],
            },
            primitive: wgpu::PrimitiveState {
                topology: wgpu::PrimitiveTopology::TriangleStrip,
                ..Default::default()
            },
            depth_stencil: None,
            multisample: wgpu::MultisampleState::default(),
            fragment: Some(wgpu::FragmentState {
                module: &module,
                entry_point: Some(fragment),
                compilation_options: Default::default(),
                targets: &[Some(wgpu::ColorTargetState {
                    format: window_format,
                    blend: None,
                    write_mask: wgpu::ColorWrites::ALL,
                })],
            }),
            multiview_mask: None,
            cache: None,
        });
        // One texel per pixel: nearest shows the same image as linear and costs less.
        let sampler = device.create_sampler(&wgpu::SamplerDescriptor {
            label: Some("clothsim view paint sampler"),
            ..Default::default()
        });
        Self {
            pipeline,
            layout,
            sampler,
            image: None,
        }
    }

    /// Draws the image with its top left corner at pixel (`left`, `top`) of the pass's
    /// target, one texel per pixel; nothing before an image was set.
    fn draw(&self, pass: &mut wgpu::RenderPass<'_>, left: f32, top: f32) {
        let Some((group, width, height)) = &self.image else {
            return;
        };
        pass.set_viewport(left, top, *width as f32, *height as f32, 0.0, 1.0);
        pass.set_pipeline(&self.pipeline);
        pass.set_bind_group(0, group, &[]);
        pass.draw(0..4, 0..1);
    }

    /// Shows the `width × height` image `view` from now on.
    fn set_image(
        &mut self,
        device: &wgpu::Device,
        view: &wgpu::TextureView,
        (width, height): (u32, u32),
    ) {
        let group = device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("clothsim view image"),
            layout: &self.layout,
            entries: &[
                wgpu::BindGroupEntry {
                    binding: 0,
                    resource: wgpu::BindingResource::TextureView(view),
                },
                wgpu::BindGroupEntry {
                    binding: 1,
                    resource: wgpu::BindingResource::Sampler(&self.sampler),
                },
            ],
        });
        self.image = Some((group, width, height));
    }
}

/// Makes `target` the image the window shows (after a new target or a resize).
fn show_target(rs: &RenderState, target: &RenderTarget) {
    let mut renderer = rs.renderer.write();
    let resources = &mut renderer.callback_resources;
    if resources.get::<ViewPaint>().is_none() {
        resources.insert(ViewPaint::new(&rs.device, rs.target_format));
    }
    if let Some(paint) = resources.get_mut::<ViewPaint>() {
        paint.set_image(&rs.device, target.view(), target.size());
    }
}

/// The paint callback: draws the current image at the callback's top left corner, at the
/// image's own size (egui clips it to the panel).
struct PaintView;

impl egui_wgpu::CallbackTrait for PaintView {
    fn paint(
        &self,
        info: egui::PaintCallbackInfo,
        pass: &mut wgpu::RenderPass<'static>,
        resources: &egui_wgpu::CallbackResources,
    ) {
        if let Some(paint) = resources.get::<ViewPaint>() {
            let at = info.viewport_in_pixels();
            paint.draw(pass, at.left_px as f32, at.top_px as f32);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::device::{AdapterPreference, HeadlessDevice};
    use crate::render::{RgbaImage, read_texture};

    /// An image whose neighbouring texels all differ, running through every byte value.
    fn pattern(width: u32, height: u32) -> RgbaImage {
        RgbaImage::from_fn(width, height, |x, y| {
            let i = y * width + x;
            image::Rgba([
                (i % 256) as u8,
                (x * 7 + y * 3) as u8,
                (255 - i % 256) as u8,
                255,
            ])
        })
    }

    /// `source` painted with its corner at `at` into a `canvas`-sized target of `format`
    /// cleared to black, read back.
    fn painted(
        format: wgpu::TextureFormat,
        source: &RgbaImage,
        canvas: (u32, u32),
        at: (f32, f32),
    ) -> RgbaImage {
        let gpu = HeadlessDevice::open(AdapterPreference::Software).expect("software adapter");
        let (device, queue) = (&gpu.device, &gpu.queue);
        let extent = |(width, height)| wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        };
        let texture = |size, format, usage| {
            device.create_texture(&wgpu::TextureDescriptor {
                label: None,
                size: extent(size),
                mip_level_count: 1,
                sample_count: 1,
                dimension: wgpu::TextureDimension::D2,
                format,
                usage,
                view_formats: &[],
            })
        };
        let image = texture(
            source.dimensions(),
            wgpu::TextureFormat::Rgba8Unorm,
            wgpu::TextureUsages::TEXTURE_BINDING | wgpu::TextureUsages::COPY_DST,
        );
        queue.write_texture(
            image.as_image_copy(),
            source.as_raw(),
            wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(4 * source.width()),
                rows_per_image: None,
            },
            extent(source.dimensions()),
        );
        let window = texture(
            canvas,
            format,
            wgpu::TextureUsages::RENDER_ATTACHMENT | wgpu::TextureUsages::COPY_SRC,
        );
        let mut paint = ViewPaint::new(device, format);
        paint.set_image(
            device,
            &image.create_view(&Default::default()),
            source.dimensions(),
        );
        let mut encoder = device.create_command_encoder(&Default::default());
        {
            let target = window.create_view(&Default::default());
            let mut pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: None,
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: &target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations {
                        load: wgpu::LoadOp::Clear(wgpu::Color::BLACK),
                        store: wgpu::StoreOp::Store,
                    },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            paint.draw(&mut pass, at.0, at.1);
        }
        queue.submit([encoder.finish()]);
        read_texture(device, queue, &window).expect("read back")
    }

    /// Every pixel of `out`: `source`'s texel within `tolerance` per channel where the image
    /// was put (corner `at`), the clear colour (black) elsewhere.
    fn assert_shows(out: &RgbaImage, source: &RgbaImage, at: (u32, u32), tolerance: u8) {
        let (w, h) = source.dimensions();
        for (x, y, pixel) in out.enumerate_pixels() {
            let inside = (at.0..at.0 + w).contains(&x) && (at.1..at.1 + h).contains(&y);
            let want = if inside {
                *source.get_pixel(x - at.0, y - at.1)
            } else {
                image::Rgba([0, 0, 0, 255])
            };
            let close = (pixel.0.iter().zip(want.0)).all(|(p, w)| p.abs_diff(w) <= tolerance);
            assert!(close, "pixel ({x}, {y}): {pixel:?}, want {want:?}");
        }
    }

    #[test]
    fn the_view_is_put_into_the_window_texel_for_texel_at_its_corner() {
        let source = pattern(37, 23);
        let out = painted(
            wgpu::TextureFormat::Rgba8Unorm,
            &source,
            (50, 31),
            (5.0, 4.0),
        );
        assert_shows(&out, &source, (5, 4), 0);
    }

    #[test]
    fn an_srgb_window_shows_the_same_colours() {
        // The image holds sRGB-encoded bytes; a window that encodes itself must be handed
        // linear values, or every mid-tone comes out brighter.
        let source = pattern(64, 8);
        let out = painted(
            wgpu::TextureFormat::Rgba8UnormSrgb,
            &source,
            (64, 8),
            (0.0, 0.0),
        );
        assert_shows(&out, &source, (0, 0), 1);
    }
}
