//! The native window: eframe's options and the app inside it.

use std::path::PathBuf;
use std::sync::Arc;

/// The device the window draws with, as eframe's default asks for it, plus what the GPU
/// backend's compute shader needs where the adapter has it: storage buffers in compute
/// shaders (the GL defaults allow none) as many and as large as the adapter offers.
pub fn device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
    let available = adapter.limits();
    let base = if adapter.get_info().backend == wgpu::Backend::Gl {
        wgpu::Limits::downlevel_webgl2_defaults()
    } else {
        wgpu::Limits::default()
    };
    let limits = wgpu::Limits {
        max_texture_dimension_2d: 8192.min(available.max_texture_dimension_2d),
        max_storage_buffers_per_shader_stage: available.max_storage_buffers_per_shader_stage,
        max_storage_buffer_binding_size: available.max_storage_buffer_binding_size,
        max_buffer_size: available.max_buffer_size,
        max_compute_workgroups_per_dimension: available.max_compute_workgroups_per_dimension,
        max_compute_invocations_per_workgroup: available.max_compute_invocations_per_workgroup,
        max_compute_workgroup_size_x: available.max_compute_workgroup_size_x,
        max_compute_workgroup_size_y: available.max_compute_workgroup_size_y,
        max_compute_workgroup_size_z: available.max_compute_workgroup_size_z,
        max_compute_workgroup_storage_size: available.max_compute_workgroup_storage_size,
        ..base
    };
    wgpu::DeviceDescriptor {
        label: Some("clothsim window device"),
        required_limits: limits,
        ..Default::default()
    }
}

/// `setup` with [`device_descriptor`] (when it creates its own device).
pub fn with_compute_limits(mut setup: egui_wgpu::WgpuSetup) -> egui_wgpu::WgpuSetup {
    if let egui_wgpu::WgpuSetup::CreateNew(new) = &mut setup {
        new.device_descriptor = Arc::new(device_descriptor);
    }
    setup
}

/// Opens the window and runs until it is closed.
///
/// # Errors
/// When no window or graphics context can be created.
pub fn run(obj: Option<PathBuf>) -> eframe::Result {
    let mut wgpu_options = egui_wgpu::WgpuConfiguration::default();
    wgpu_options.wgpu_setup = with_compute_limits(wgpu_options.wgpu_setup);
    let options = eframe::NativeOptions {
        viewport: egui::ViewportBuilder::default()
            .with_title("clothsim")
            .with_inner_size([1280.0, 800.0])
            .with_drag_and_drop(true),
        renderer: eframe::Renderer::Wgpu,
        // egui's pass keeps one sample and no depth buffer: the 3D view's image is put into
        // it by a pipeline made for exactly that (`viewport::ViewPaint`).
        multisampling: 0,
        depth_buffer: 0,
        wgpu_options,
        ..Default::default()
    };
    eframe::run_native(
        "clothsim",
        options,
        Box::new(move |cc| {
            let mut app = super::ClothApp::new(cc.wgpu_render_state.clone(), obj.as_deref());
            app.view.log_frame_times = std::env::var_os("CLOTHSIM_FRAME_TIMES").is_some();
            Ok(Box::new(app))
        }),
    )
}
