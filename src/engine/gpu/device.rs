//! Device acquisition: finding an adapter that can carry the engine's f64 arithmetic, once per
//! process. Nothing here runs GPU work; the kernels ([`super::kernels`]) take a [`GpuDevice`].
//!
//! The adapter must offer `SHADER_F64`: the net drift per period is ~1e-6 of the stroke, far
//! below f32's resolution of a position, so an adapter without f64 is refused with the reason,
//! never used at reduced accuracy. Adapters are ranked discrete > integrated > virtual > CPU
//! emulation (lavapipe/llvmpipe), so a real GPU wins over a software one when both exist.
//!
//! Environment: `WGPU_BACKEND` (e.g. `vulkan`) limits the backends searched, as in wgpu;
//! `SWIMLAB_NO_GPU=1` hides every adapter (to test the fallback); see also
//! [`quiet_device_selection`].

use crate::engine::error::{invalid, Result};
use std::sync::{Arc, Mutex, OnceLock};

/// Keep Mesa's device-selection layer (an implicit Vulkan layer) out of this process when
/// there is no session runtime folder (`XDG_RUNTIME_DIR` unset or not a folder: a server, a
/// container, CI), unless the user configured the layer (`NODEVICE_SELECT`,
/// `MESA_VK_DEVICE_SELECT`). The layer only orders the devices, which [`device`] ranks itself,
/// and to learn the desktop's default device it connects to the Wayland display, whose library
/// prints "XDG_RUNTIME_DIR is invalid or not set in the environment." on stderr for every
/// instance made without that folder. Nothing else is silenced: drivers' own errors still show.
///
/// It sets an environment variable, so it must run before any other thread starts: first thing
/// in `main`.
pub fn quiet_device_selection() {
    let configured = ["NODEVICE_SELECT", "MESA_VK_DEVICE_SELECT"]
        .iter()
        .any(|v| std::env::var_os(v).is_some());
    let runtime_dir =
        std::env::var_os("XDG_RUNTIME_DIR").is_some_and(|d| std::path::Path::new(&d).is_dir());
    if !configured && !runtime_dir {
        std::env::set_var("NODEVICE_SELECT", "1");
    }
}

/// Storage buffers each kernel binds (groups 0 and 1 of common.wgsl).
const STORAGE_BUFFERS: u32 = 10;

/// An acquired device with the limits the kernels need.
pub struct GpuDevice {
    /// The wgpu device (with `SHADER_F64`).
    pub device: wgpu::Device,
    /// Its queue.
    pub queue: wgpu::Queue,
    /// What the adapter says about itself.
    pub info: wgpu::AdapterInfo,
    /// Errors wgpu reported outside an error scope (validation, out of memory), newest last.
    /// The kernels check it after each submission and turn it into an engine error.
    pub(crate) errors: Arc<Mutex<Vec<String>>>,
}

impl std::fmt::Debug for GpuDevice {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "GpuDevice({})", self.describe())
    }
}

impl GpuDevice {
    /// "name (backend, device type)", e.g. "llvmpipe (LLVM 15.0.6, 256 bits) (vulkan, cpu emulation)".
    pub fn describe(&self) -> String {
        describe(&self.info)
    }

    /// Whether the adapter is a CPU emulation (lavapipe, WARP, SwiftShader) rather than a GPU.
    pub fn is_emulated(&self) -> bool {
        self.info.device_type == wgpu::DeviceType::Cpu
    }

    /// Take the errors wgpu reported since the last call.
    pub(crate) fn take_errors(&self) -> Vec<String> {
        match self.errors.lock() {
            Ok(mut e) => std::mem::take(&mut *e),
            Err(_) => vec!["the GPU error log was poisoned by a panic".into()],
        }
    }
}

fn describe(info: &wgpu::AdapterInfo) -> String {
    let kind = match info.device_type {
        wgpu::DeviceType::DiscreteGpu => "discrete GPU",
        wgpu::DeviceType::IntegratedGpu => "integrated GPU",
        wgpu::DeviceType::VirtualGpu => "virtual GPU",
        wgpu::DeviceType::Cpu => "CPU emulation",
        wgpu::DeviceType::Other => "other",
    };
    format!(
        "{} ({}, {kind})",
        info.name,
        format!("{:?}", info.backend).to_lowercase()
    )
}

fn rank(t: wgpu::DeviceType) -> u8 {
    match t {
        wgpu::DeviceType::DiscreteGpu => 4,
        wgpu::DeviceType::IntegratedGpu => 3,
        wgpu::DeviceType::VirtualGpu => 2,
        wgpu::DeviceType::Cpu => 1,
        wgpu::DeviceType::Other => 0,
    }
}

/// The process's GPU device, acquired on first use; `Err` says why there is none and what to do.
pub fn device() -> Result<Arc<GpuDevice>> {
    static DEVICE: OnceLock<Result<Arc<GpuDevice>>> = OnceLock::new();
    DEVICE.get_or_init(|| acquire().map(Arc::new)).clone()
}

/// Whether a usable (f64-capable) adapter exists, without failing.
pub fn available() -> bool {
    device().is_ok()
}

fn acquire() -> Result<GpuDevice> {
    if std::env::var_os("SWIMLAB_NO_GPU").is_some_and(|v| v != "0") {
        return Err(invalid!(
            "no GPU adapter: SWIMLAB_NO_GPU is set; unset it to use a GPU"
        ));
    }
    // Instance creation probes the drivers; a broken driver must not take the process down.
    let found = std::panic::catch_unwind(|| {
        let instance =
            wgpu::Instance::new(wgpu::InstanceDescriptor::new_without_display_handle_from_env());
        let backends = wgpu::Backends::from_env().unwrap_or(wgpu::Backends::PRIMARY);
        let adapters = pollster::block_on(instance.enumerate_adapters(backends));
        let seen: Vec<String> = adapters.iter().map(|a| describe(&a.get_info())).collect();
        let best = adapters
            .into_iter()
            .filter(|a| a.features().contains(wgpu::Features::SHADER_F64))
            .max_by_key(|a| rank(a.get_info().device_type));
        (best, seen)
    })
    .map_err(|_| invalid!("the GPU driver failed while listing adapters"))?;
    let adapter = match found {
        (Some(a), _) => a,
        (None, seen) if seen.is_empty() => {
            return Err(invalid!("no GPU adapter found (no Vulkan, Metal or DX12 driver answered); install a driver (on Debian: mesa-vulkan-drivers libvulkan1) or run on the CPU"))
        }
        (None, seen) => {
            return Err(invalid!(
                "no GPU adapter offers f64 in shaders (SHADER_F64), which swimlab needs: the drift per period is ~1e-6 of the stroke and f32 cannot carry it; adapters seen: {}",
                seen.join(", ")
            ))
        }
    };
    let info = adapter.get_info();
    let offered = adapter.limits();
    if offered.max_storage_buffers_per_shader_stage < STORAGE_BUFFERS {
        return Err(invalid!(
            "the GPU adapter {} allows {} storage buffers per kernel, swimlab's kernels bind {STORAGE_BUFFERS}",
            describe(&info),
            offered.max_storage_buffers_per_shader_stage
        ));
    }
    let limits = wgpu::Limits {
        max_storage_buffer_binding_size: offered.max_storage_buffer_binding_size,
        max_buffer_size: offered.max_buffer_size,
        max_storage_buffers_per_shader_stage: STORAGE_BUFFERS,
        ..wgpu::Limits::default()
    };
    let (device, queue) = pollster::block_on(adapter.request_device(&wgpu::DeviceDescriptor {
        label: Some("swimlab"),
        required_features: wgpu::Features::SHADER_F64,
        required_limits: limits,
        experimental_features: wgpu::ExperimentalFeatures::disabled(),
        memory_hints: wgpu::MemoryHints::Performance,
        trace: wgpu::Trace::Off,
    }))
    .map_err(|e| invalid!("the GPU adapter {} refused a device: {e}", describe(&info)))?;
    let errors = Arc::new(Mutex::new(Vec::new()));
    let sink = errors.clone();
    device.on_uncaptured_error(Arc::new(move |e: wgpu::Error| {
        if let Ok(mut v) = sink.lock() {
            v.push(e.to_string());
        }
    }));
    Ok(GpuDevice {
        device,
        queue,
        info,
        errors,
    })
}
