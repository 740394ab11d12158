//! Explicit Runge-Kutta stages on the device (rk_stages.wgsl): the stage states, the combination
//! of a step, and the commit that accepts it unless a guard fired; for an embedded pair
//! (Dormand-Prince 5(4)) the error norm, accept/reject and the next step size. The tableaux are
//! those of the CPU steppers, so both backends take the same steps.

use bytemuck::{Pod, Zeroable};

/// WGSL source of the stage kernels.
pub const SOURCE: &str = concat!(include_str!("common.wgsl"), include_str!("rk_stages.wgsl"));

/// The stage pipelines.
pub struct Pipelines {
    pub(crate) stage_state: wgpu::ComputePipeline,
    pub(crate) combine: wgpu::ComputePipeline,
    pub(crate) commit: wgpu::ComputePipeline,
    pub(crate) begin_attempt: wgpu::ComputePipeline,
    pub(crate) error_part: wgpu::ComputePipeline,
    pub(crate) decide: wgpu::ComputePipeline,
    pub(crate) commit_attempt: wgpu::ComputePipeline,
}

impl Pipelines {
    pub(crate) fn new(d: &wgpu::Device, layout: &wgpu::PipelineLayout) -> Self {
        let m = super::common::module(d, "rk_stages", SOURCE);
        Pipelines {
            stage_state: super::common::pipeline(d, layout, &m, "stage_state"),
            combine: super::common::pipeline(d, layout, &m, "combine"),
            commit: super::common::pipeline(d, layout, &m, "commit"),
            begin_attempt: super::common::pipeline(d, layout, &m, "begin_attempt"),
            error_part: super::common::pipeline(d, layout, &m, "error_part"),
            decide: super::common::pipeline(d, layout, &m, "decide"),
            commit_attempt: super::common::pipeline(d, layout, &m, "commit_attempt"),
        }
    }
}

/// `struct Stage` of common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct StageParams {
    /// Stage coefficients a_j (or the weights b_j of the combination).
    pub a: [f64; 8],
    /// Stage time as a fraction of the step.
    pub c: f64,
    /// 0: start from y; 1: from y_new.
    pub src: u32,
    /// k slot the rates go to.
    pub out: u32,
    /// How many k slots the combination reads.
    pub nk: u32,
    /// 1: the rates kernels apply the guards to this state.
    pub check: u32,
}

/// An explicit Runge-Kutta method: stage times `c`, stage matrix rows `a`, weights `b`, and for
/// an embedded pair the error weights `e`.
#[derive(Debug, Clone, PartialEq)]
pub struct Tableau {
    /// c_s, s = 0..S (c_0 = 0).
    pub c: Vec<f64>,
    /// a_sj for j < s.
    pub a: Vec<Vec<f64>>,
    /// b_j.
    pub b: Vec<f64>,
    /// Empty for a fixed-step method. For an embedded pair whose last stage is taken at the
    /// solution (a_Sj = b_j: first same as last): the solution minus the embedded one, e_j, over
    /// all S stages. Such a method runs adaptively.
    pub e: Vec<f64>,
}

impl Tableau {
    /// Forward Euler.
    pub fn euler() -> Self {
        Tableau {
            c: vec![0.0],
            a: vec![vec![]],
            b: vec![1.0],
            e: Vec::new(),
        }
    }

    /// Classic RK4.
    pub fn rk4() -> Self {
        Tableau {
            c: vec![0.0, 0.5, 0.5, 1.0],
            a: vec![vec![], vec![0.5], vec![0.0, 0.5], vec![0.0, 0.0, 1.0]],
            b: vec![1.0 / 6.0, 1.0 / 3.0, 1.0 / 3.0, 1.0 / 6.0],
            e: Vec::new(),
        }
    }

    /// Number of stages.
    pub fn stages(&self) -> usize {
        self.b.len()
    }

    /// Whether the method runs adaptively (an embedded pair).
    pub fn is_adaptive(&self) -> bool {
        !self.e.is_empty()
    }

    fn coefficients(v: &[f64]) -> [f64; 8] {
        let mut a = [0.0; 8];
        a[..v.len()].copy_from_slice(v);
        a
    }

    /// The stage parameters. Fixed steps: stages 1..S, then the combination, then the check pass
    /// at y_new (whose rates are k_0 of the next step), then stage 0 at y (to start a run).
    /// Adaptive: stages 1..S (the last, at the solution, checked by the guards), then the error
    /// weights, then stage 0 at y.
    pub(crate) fn stage_params(&self) -> Vec<StageParams> {
        let s = self.stages();
        let adaptive = self.is_adaptive();
        // Stages 1..S; adaptive: the last one is taken at the solution and checked by the guards.
        let mut out: Vec<StageParams> = (1..s)
            .map(|i| StageParams {
                a: Self::coefficients(&self.a[i]),
                c: self.c[i],
                src: 0,
                out: i as u32,
                nk: i as u32,
                check: u32::from(adaptive && i == s - 1),
            })
            .collect();
        // The weights b of the combination, or the error weights e.
        out.push(StageParams {
            a: Self::coefficients(if adaptive { &self.e } else { &self.b }),
            c: 1.0,
            src: 0,
            out: 0,
            nk: s as u32,
            check: 0,
        });
        if !adaptive {
            out.push(StageParams {
                a: [0.0; 8],
                c: 1.0,
                src: 1,
                out: 0,
                nk: 0,
                check: 1,
            });
        }
        // Stage 0 at y: the rates that start a run.
        out.push(StageParams {
            a: [0.0; 8],
            c: 0.0,
            src: 0,
            out: 0,
            nk: 0,
            check: 0,
        });
        out
    }
}
