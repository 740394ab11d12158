//! What every kernel shares on the host side, as `common.wgsl` is what every shader shares: the
//! workgroup size, and shader modules and compute pipelines built from WGSL source.

/// Threads per workgroup of every kernel (also the pair-sum tile size; `WG` in common.wgsl).
pub const WORKGROUP: u32 = 64;

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
