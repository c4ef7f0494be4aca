//! Headless adapter and device selection.

use super::error::DeviceError;
use super::limits::compute_limits;

/// A wgpu instance, adapter, device and queue made without any window.
pub struct HeadlessDevice {
    pub instance: wgpu::Instance,
    pub adapter: wgpu::Adapter,
    pub device: wgpu::Device,
    pub queue: wgpu::Queue,
}

/// Which adapter to prefer.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum AdapterPreference {
    /// The software (CPU) adapter, for reproducible images in tests; any adapter if none.
    Software,
    /// Whatever the system offers first (a GPU when there is one).
    Any,
}

impl HeadlessDevice {
    /// Creates a device without a display handle. The backend can be pinned with the
    /// `WGPU_BACKEND` environment variable; unpinned, [`AdapterPreference::Software`] tries
    /// the GL backend first and takes it only if it is a software rasteriser (Mesa's
    /// llvmpipe), then every backend. A GPU's own GL through EGL is passed over: NVIDIA's
    /// lost the device on the first render target (seen on an H100).
    ///
    /// # Errors
    /// [`DeviceError::NoAdapter`] with what was tried, or [`DeviceError::Open`].
    pub fn open(preference: AdapterPreference) -> Result<HeadlessDevice, DeviceError> {
        let from_env = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
        let pinned = std::env::var_os("WGPU_BACKEND").is_some();
        // (instance, whether only a software adapter will do)
        let mut attempts = Vec::new();
        if preference == AdapterPreference::Software && !pinned {
            // Golden images depend on the rasteriser: prefer Mesa's llvmpipe through GL.
            let mut gl = wgpu::InstanceDescriptor::new_without_display_handle_from_env();
            gl.backends = wgpu::Backends::GL;
            attempts.push((gl, true));
        }
        attempts.push((from_env, false));
        let mut failures = Vec::new();
        for (desc, software_only) in attempts {
            let backends = desc.backends;
            let instance = wgpu::Instance::new(desc);
            match Self::pick(&instance, preference) {
                Ok(adapter)
                    if software_only && adapter.get_info().device_type != wgpu::DeviceType::Cpu =>
                {
                    failures.push(format!(
                        "{backends:?}: {} is not a software adapter",
                        describe_adapter(&adapter)
                    ));
                }
                Ok(adapter) => return Self::with_adapter(instance, adapter),
                Err(e) => failures.push(format!("{backends:?}: {e}")),
            }
        }
        Err(DeviceError::NoAdapter {
            detail: failures.join("; "),
        })
    }

    fn pick(
        instance: &wgpu::Instance,
        preference: AdapterPreference,
    ) -> Result<wgpu::Adapter, wgpu::RequestAdapterError> {
        let request = |force_fallback_adapter: bool| {
            pollster::block_on(instance.request_adapter(&wgpu::RequestAdapterOptions {
                power_preference: wgpu::PowerPreference::HighPerformance,
                force_fallback_adapter,
                ..Default::default()
            }))
        };
        match preference {
            AdapterPreference::Software => request(true).or_else(|_| request(false)),
            AdapterPreference::Any => request(false).or_else(|_| request(true)),
        }
    }

    fn with_adapter(
        instance: wgpu::Instance,
        adapter: wgpu::Adapter,
    ) -> Result<HeadlessDevice, DeviceError> {
        let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
            label: Some("clothsim device"),
            required_features: wgpu::Features::empty(),
            required_limits: compute_limits(&adapter),
            ..Default::default()
        }))
        .map_err(|e| DeviceError::Open(e.to_string()))?;
        Ok(HeadlessDevice {
            instance,
            adapter,
            device,
            queue,
        })
    }
}

/// "name (backend, device type)" of an adapter.
pub fn describe_adapter(adapter: &wgpu::Adapter) -> String {
    let info = adapter.get_info();
    format!("{} ({:?}, {:?})", info.name, info.backend, info.device_type)
}
