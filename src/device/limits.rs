//! The limits clothsim asks a device for: storage buffers as large as the adapter has (the
//! GPU backend's large cloths), compute where the adapter offers it.

/// Storage buffers per shader stage asked for where the adapter has them: wgpu's default,
/// which every adapter with compute shaders but the most limited offers (OpenGL 4.3
/// guarantees 8 to compute shaders).
const STORAGE_BUFFERS: u32 = 8;

/// Limits for a headless device: the downlevel defaults at the adapter's resolution, with
/// up to eight storage buffers per stage, as large as the adapter allows.
pub fn compute_limits(adapter: &wgpu::Adapter) -> wgpu::Limits {
    let available = adapter.limits();
    let mut limits = wgpu::Limits::downlevel_defaults().using_resolution(available.clone());
    limits.max_storage_buffers_per_shader_stage = available
        .max_storage_buffers_per_shader_stage
        .min(STORAGE_BUFFERS);
    limits.max_storage_buffer_binding_size = available.max_storage_buffer_binding_size;
    limits.max_buffer_size = available.max_buffer_size;
    limits
}

/// The device the window draws with, as eframe's default asks for it, plus what the GPU
/// backend's compute shader needs where the adapter has it: storage buffers in compute
/// shaders (the GL defaults allow none) as many and as large as the adapter offers.
pub fn window_device_descriptor(adapter: &wgpu::Adapter) -> wgpu::DeviceDescriptor<'static> {
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
