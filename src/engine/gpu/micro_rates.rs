//! Microscopic-model rates on the device (micro_rates.wgsl): sphere placement with the spring
//! forces, then the all-pairs mobility product tiled through workgroup memory.

use crate::engine::mobility::self_mobility;
use crate::engine::swimmer::Dumbbell;
use nalgebra::Vector3;

/// WGSL source of the microscopic kernels.
pub const SOURCE: &str = concat!(
    include_str!("common.wgsl"),
    include_str!("micro_rates.wgsl")
);

/// f64 per swimmer in the constants buffer (`STRIDE` in micro_rates.wgsl).
pub const STRIDE: usize = 16;

/// The microscopic pipelines.
pub struct Pipelines {
    pub(crate) place: wgpu::ComputePipeline,
    pub(crate) interact: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(crate) fn new(d: &wgpu::Device, layout: &wgpu::PipelineLayout) -> Self {
        let m = super::common::module(d, "micro_rates", SOURCE);
        Pipelines {
            place: super::common::pipeline(d, layout, &m, "place"),
            interact: super::common::pipeline(d, layout, &m, "interact"),
        }
    }
}

/// The per-swimmer constants in the layout micro_rates.wgsl reads, computed exactly as the CPU
/// model computes them.
pub fn pack(swimmers: &[Dumbbell], base: &[Vector3<f64>], mu: f64) -> Vec<f64> {
    let mut out = vec![0.0; STRIDE * swimmers.len()];
    for (s, d) in swimmers.iter().enumerate() {
        let v = &mut out[STRIDE * s..STRIDE * (s + 1)];
        v[..3].copy_from_slice(base[s].as_slice());
        v[3] = d.a1;
        v[4] = d.a2;
        v[5] = d.k0;
        v[6] = d.ell;
        v[7] = d.lambda;
        v[8] = d.omega;
        v[9] = d.phase;
        v[10] = d.w1();
        v[11] = d.w2();
        v[12] = self_mobility(mu, d.a1) + self_mobility(mu, d.a2);
    }
    out
}
