//! The compiled pipelines of every kernel with their bind group layouts, compiled once per
//! device and kept while the device lives.

use super::device::GpuDevice;
use super::{averaged_rates, micro_rates, rk_stages};
use crate::engine::error::{invalid, Result};
use std::sync::{Arc, Mutex, Weak};

/// The compiled pipelines of one device, shared by all scenes run there.
pub struct Kernels {
    pub(crate) group0: wgpu::BindGroupLayout,
    pub(crate) group1: wgpu::BindGroupLayout,
    pub(crate) stages: rk_stages::Pipelines,
    pub(crate) micro: micro_rates::Pipelines,
    pub(crate) averaged: averaged_rates::Pipelines,
}

impl Kernels {
    /// The kernels on `dev`, compiled on first use there (a failed compilation is kept too, so
    /// it is reported, not retried, by every run).
    pub fn on(dev: &Arc<GpuDevice>) -> Result<Arc<Kernels>> {
        type Compiled = (Weak<GpuDevice>, Result<Arc<Kernels>>);
        static COMPILED: Mutex<Vec<Compiled>> = Mutex::new(Vec::new());
        let mut compiled = COMPILED.lock().unwrap_or_else(|p| p.into_inner());
        compiled.retain(|(d, _)| d.strong_count() > 0);
        if let Some((_, k)) = compiled
            .iter()
            .find(|(d, _)| std::ptr::eq(d.as_ptr(), Arc::as_ptr(dev)))
        {
            return k.clone();
        }
        let k = compile(dev).map(Arc::new);
        compiled.push((Arc::downgrade(dev), k.clone()));
        k
    }
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

fn compile(dev: &GpuDevice) -> Result<Kernels> {
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
        Some(e) => Err(invalid!(
            "the GPU kernels did not compile on {}: {e}",
            dev.describe()
        )),
    }
}
