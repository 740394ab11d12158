//! Stroke-averaged rates on the device (averaged_rates.wgsl): the pairwise I, J, K, L sums of
//! [`crate::engine::averaged`], evaluated in 3D for every pair (the CPU's 1D shortcut gives the
//! same numbers for aligned scenes; the device needs no special case).

use crate::engine::averaged::pair_constants;
use crate::engine::model::Coefficients;
use crate::engine::swimmer::Dumbbell;
use nalgebra::Vector3;

/// WGSL source of the averaged kernel.
pub const SOURCE: &str = concat!(
    include_str!("common.wgsl"),
    include_str!("averaged_rates.wgsl")
);

/// f64 per swimmer in the constants buffer (`STRIDE` in averaged_rates.wgsl).
pub const STRIDE: usize = 12;

/// The averaged pipeline.
pub struct Pipelines {
    pub(crate) interact: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(crate) fn new(d: &wgpu::Device, layout: &wgpu::PipelineLayout) -> Self {
        let m = super::common::module(d, "averaged_rates", SOURCE);
        Pipelines {
            interact: super::common::pipeline(d, layout, &m, "interact"),
        }
    }
}

/// The per-swimmer constants in the layout averaged_rates.wgsl reads (the CPU model's own).
pub fn pack(swimmers: &[Dumbbell], base: &[Vector3<f64>], set: Coefficients) -> Vec<f64> {
    let mut out = vec![0.0; STRIDE * swimmers.len()];
    for (s, d) in swimmers.iter().enumerate() {
        let v = &mut out[STRIDE * s..STRIDE * (s + 1)];
        v[..3].copy_from_slice(base[s].as_slice());
        let c = pair_constants(d, set);
        v[3..11].copy_from_slice(&c);
    }
    out
}
