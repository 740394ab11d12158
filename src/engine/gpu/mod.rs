//! The GPU backend: both models stepped on a wgpu device (Vulkan, Metal, DX12) in f64.
//!
//! Layout: [`device`] finds and opens an adapter (nothing else touches adapters); each kernel is a
//! pair of files, `name.rs` (host side: pipelines, data layout) and `name.wgsl` (the shader), all
//! sharing `common.wgsl`; [`runner`] owns a scene's device buffers and encodes whole runs of steps.
//!
//! Design, for real GPUs as much as for the CPU emulation CI has:
//! - the state lives on the device; a run of many steps is encoded into one submission and the
//!   state is read back only at the end of a run segment (a recorder's row or the run's end);
//! - the O(N²) pair sums tile the sources through workgroup memory (64 per tile), so each
//!   source sphere is read from global memory once per workgroup instead of once per thread;
//! - buffers and bind groups are made once per scene size and reused by every step and run;
//! - stage coefficients are tiny per-stage buffers chosen by bind group, so a step costs
//!   dispatches only, no uploads;
//! - the guards (finite state, runaway spring, contact) run on the device into one atomic flag;
//!   once it is set every kernel returns at once, the last good state stays in place, and the host
//!   replays the failing step on the CPU, which reports it exactly as the CPU backend would.

pub mod averaged_rates;
pub mod device;
pub mod micro_rates;
pub mod rk_stages;
pub mod runner;
pub mod support;

pub use device::{available, device, quiet_device_selection, GpuDevice};
pub use runner::{AdaptiveReport, AdaptiveSteps, GpuModel, GpuRun, RunOutcome, UniformSteps};

use std::sync::{Arc, OnceLock};

/// Threads per workgroup of every kernel (also the pair-sum tile size; `WG` in common.wgsl).
pub const WORKGROUP: u32 = 64;

/// The compiled pipelines, shared by all scenes of the process.
pub struct Kernels {
    pub(crate) group0: wgpu::BindGroupLayout,
    pub(crate) group1: wgpu::BindGroupLayout,
    pub(crate) stages: rk_stages::Pipelines,
    pub(crate) micro: micro_rates::Pipelines,
    pub(crate) averaged: averaged_rates::Pipelines,
}

/// The process's kernels on the process's device, compiled on first use.
pub fn kernels() -> Result<(Arc<GpuDevice>, Arc<Kernels>), String> {
    static KERNELS: OnceLock<Result<Arc<Kernels>, String>> = OnceLock::new();
    let dev = device()?;
    let k = KERNELS
        .get_or_init(|| compile(&dev).map(Arc::new))
        .clone()?;
    Ok((dev, k))
}

fn storage_entry(binding: u32, read_only: bool) -> wgpu::BindGroupLayoutEntry {
    wgpu::BindGroupLayoutEntry {
        binding,
        visibility: wgpu::ShaderStages::COMPUTE,
        ty: wgpu::BindingType::Buffer {
            ty: wgpu::BufferBindingType::Storage { read_only },
            has_dynamic_offset: false,
            min_binding_size: None,
        },
        count: None,
    }
}

fn compile(dev: &GpuDevice) -> Result<Kernels, String> {
    let d = &dev.device;
    let scope = d.push_error_scope(wgpu::ErrorFilter::Validation);
    // Group 0 as declared in common.wgsl: params, y, y_new, y_stage, k, control, swimmers, spheres,
    // adapt.
    let read_only = [true, false, false, false, false, false, true, false, false];
    let entries: Vec<_> = read_only
        .iter()
        .enumerate()
        .map(|(i, &ro)| storage_entry(i as u32, ro))
        .collect();
    let group0 = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("swimlab group 0"),
        entries: &entries,
    });
    let group1 = d.create_bind_group_layout(&wgpu::BindGroupLayoutDescriptor {
        label: Some("swimlab stage"),
        entries: &[storage_entry(0, true)],
    });
    let layout = d.create_pipeline_layout(&wgpu::PipelineLayoutDescriptor {
        label: Some("swimlab"),
        bind_group_layouts: &[Some(&group0), Some(&group1)],
        immediate_size: 0,
    });
    let kernels = Kernels {
        stages: rk_stages::Pipelines::new(d, &layout),
        micro: micro_rates::Pipelines::new(d, &layout),
        averaged: averaged_rates::Pipelines::new(d, &layout),
        group0,
        group1,
    };
    match pollster::block_on(scope.pop()) {
        None => Ok(kernels),
        Some(e) => Err(format!(
            "the GPU kernels did not compile on {}: {e}",
            dev.describe()
        )),
    }
}

/// A compute pipeline from a kernel's source (common.wgsl already prepended) and entry point.
pub(crate) fn pipeline(
    d: &wgpu::Device,
    layout: &wgpu::PipelineLayout,
    module: &wgpu::ShaderModule,
    entry: &str,
) -> wgpu::ComputePipeline {
    d.create_compute_pipeline(&wgpu::ComputePipelineDescriptor {
        label: Some(entry),
        layout: Some(layout),
        module,
        entry_point: Some(entry),
        compilation_options: Default::default(),
        cache: None,
    })
}

/// A shader module from WGSL source.
pub(crate) fn module(d: &wgpu::Device, label: &str, source: &str) -> wgpu::ShaderModule {
    d.create_shader_module(wgpu::ShaderModuleDescriptor {
        label: Some(label),
        source: wgpu::ShaderSource::Wgsl(source.into()),
    })
}
