//! A scene's device buffers and the encoding of whole runs: the host side of the GPU backend.

use super::common::WORKGROUP;
use super::device::GpuDevice;
use super::kernels::Kernels;
use super::rk_stages::{StageParams, Tableau};
use super::runs::{AdaptiveReport, AdaptiveSteps, GpuModel, RunOutcome, UniformSteps};
use crate::engine::error::{invalid, Result};
use crate::engine::mobility::Mobility;
use crate::engine::model::STATE_PER_SWIMMER;
use crate::engine::swimmer::Dumbbell;
use bytemuck::{Pod, Zeroable};
use nalgebra::Vector3;
use std::sync::Arc;
use std::time::Instant;

/// `struct Params` of common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Params {
    t0: f64,
    h: f64,
    oseen: f64,
    rpy: f64,
    rtol: f64,
    n: u32,
    nstate: u32,
    use_rpy: u32,
    project: u32,
    adaptive: u32,
    pad: u32,
}

/// `struct Control` of common.wgsl.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
struct Control {
    step: u32,
    failed: u32,
    rejected: u32,
    done: u32,
    accepted: u32,
    rejected_last: u32,
    rejects: u32,
    last: u32,
    guard: u32,
    pad0: u32,
    t: f64,
    t_end: f64,
    h: f64,
    h_try: f64,
    h_start: f64,
    fac_old: f64,
    err: f64,
}

impl Control {
    /// A fresh control block: no step taken, no failure; adaptive runs start at (t, h) towards
    /// t_end with the controller's initial previous error (the CPU's Dopri5 after a reset).
    fn start(t: f64, t_end: f64, h: f64) -> Self {
        Control {
            failed: NONE,
            guard: NONE,
            t,
            t_end,
            h,
            fac_old: 1e-4,
            ..Zeroable::zeroed()
        }
    }
}

const NONE: u32 = u32::MAX;
/// Shown a run between submissions: the scene time reached, the steps the run has taken and the
/// run, whose state [`GpuRun::peek_state`] reads back; it decides itself whether to (a live view).
pub type Peek<'a> = &'a mut dyn FnMut(f64, u64, &GpuRun);

/// Wall time one submission aims at: long enough to amortise submission, short enough for Ctrl-C.
const TARGET_SUBMISSION_SECONDS: f64 = 0.05;
/// At most this many steps per submission (bounds the command buffer's size).
const MAX_STEPS_PER_SUBMISSION: u64 = 4096;
/// Steps per run on the device before the step counter (u32) is restarted from a new t0.
const MAX_STEPS_PER_COUNTER: u64 = 1 << 30;

/// Device buffers for one scene size, model and method, reused by every run.
pub struct GpuRun {
    dev: Arc<GpuDevice>,
    kernels: Arc<Kernels>,
    model: GpuModel,
    n: usize,
    tableau: Tableau,
    params: wgpu::Buffer,
    y: wgpu::Buffer,
    control: wgpu::Buffer,
    swimmers: wgpu::Buffer,
    adapt: wgpu::Buffer,
    group0: wgpu::BindGroup,
    /// Bind groups of [`Tableau::stage_params`], in that order.
    stages: Vec<wgpu::BindGroup>,
    read_state: wgpu::Buffer,
    read_control: wgpu::Buffer,
    steps_per_submission: u64,
}

impl std::fmt::Debug for GpuRun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "GpuRun({} swimmers on {})", self.n, self.dev.describe())
    }
}

fn storage(dev: &GpuDevice, label: &str, bytes: usize) -> wgpu::Buffer {
    dev.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(32) as u64,
        usage: wgpu::BufferUsages::STORAGE
            | wgpu::BufferUsages::COPY_DST
            | wgpu::BufferUsages::COPY_SRC,
        mapped_at_creation: false,
    })
}

fn readback(dev: &GpuDevice, label: &str, bytes: usize) -> wgpu::Buffer {
    dev.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some(label),
        size: bytes.max(32) as u64,
        usage: wgpu::BufferUsages::MAP_READ | wgpu::BufferUsages::COPY_DST,
        mapped_at_creation: false,
    })
}

impl GpuRun {
    /// Buffers on `dev` for `n` swimmers of `model` stepped with `tableau`.
    pub fn new(dev: Arc<GpuDevice>, model: GpuModel, n: usize, tableau: Tableau) -> Result<Self> {
        let kernels = Kernels::on(&dev)?;
        let nstate = STATE_PER_SWIMMER * n;
        let f64s = |count: usize| count * std::mem::size_of::<f64>();
        let scope = dev.device.push_error_scope(wgpu::ErrorFilter::OutOfMemory);
        let params = storage(&dev, "params", std::mem::size_of::<Params>());
        let y = storage(&dev, "y", f64s(nstate));
        let y_new = storage(&dev, "y_new", f64s(nstate));
        let y_stage = storage(&dev, "y_stage", f64s(nstate));
        let k = storage(&dev, "k", f64s(nstate * tableau.stages()));
        let control = storage(&dev, "control", std::mem::size_of::<Control>());
        let stride = match model {
            GpuModel::Micro { .. } => super::micro_rates::STRIDE,
            GpuModel::Averaged { .. } => super::averaged_rates::STRIDE,
        };
        let swimmers = storage(&dev, "swimmers", f64s(stride * n));
        // Two vec4<f64> per sphere, two spheres per swimmer.
        let spheres = match model {
            GpuModel::Micro { .. } => storage(&dev, "spheres", f64s(16 * n)),
            GpuModel::Averaged { .. } => storage(&dev, "spheres (unused)", 32),
        };
        // Error scales and per-swimmer error sums of an adaptive method.
        let adapt = if tableau.is_adaptive() {
            storage(&dev, "adapt", f64s(nstate + n))
        } else {
            storage(&dev, "adapt (unused)", 32)
        };
        let buffers = [
            &params, &y, &y_new, &y_stage, &k, &control, &swimmers, &spheres, &adapt,
        ];
        let entries: Vec<_> = buffers
            .iter()
            .enumerate()
            .map(|(i, b)| wgpu::BindGroupEntry {
                binding: i as u32,
                resource: b.as_entire_binding(),
            })
            .collect();
        let group0 = dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
            label: Some("swimlab group 0"),
            layout: &kernels.group0,
            entries: &entries,
        });
        let stages = tableau
            .stage_params()
            .iter()
            .map(|p| {
                let buf = storage(&dev, "stage", std::mem::size_of::<StageParams>());
                dev.queue.write_buffer(&buf, 0, bytemuck::bytes_of(p));
                dev.device.create_bind_group(&wgpu::BindGroupDescriptor {
                    label: Some("stage"),
                    layout: &kernels.group1,
                    entries: &[wgpu::BindGroupEntry {
                        binding: 0,
                        resource: buf.as_entire_binding(),
                    }],
                })
            })
            .collect();
        let read_state = readback(&dev, "read state", f64s(nstate));
        let read_control = readback(&dev, "read control", std::mem::size_of::<Control>());
        if let Some(e) = pollster::block_on(scope.pop()) {
            return Err(invalid!(
                "the GPU has no room for {n} swimmers: {e}; use fewer swimmers or the CPU"
            ));
        }
        Ok(GpuRun {
            dev,
            kernels,
            model,
            n,
            tableau,
            params,
            y,
            control,
            swimmers,
            adapt,
            group0,
            stages,
            read_state,
            read_control,
            steps_per_submission: 8,
        })
    }

    /// Whether these buffers serve `n` swimmers of `model` with `tableau`.
    pub fn fits(&self, model: GpuModel, n: usize, tableau: &Tableau) -> bool {
        self.model == model && self.n == n && &self.tableau == tableau
    }

    /// Stages of the buffers' method.
    pub fn stages(&self) -> usize {
        self.tableau.stages()
    }

    /// The device these buffers live on.
    pub fn device(&self) -> &GpuDevice {
        &self.dev
    }

    /// Take `steps` uniform steps of size `h` from (t0, y): the state goes up, the steps run on the
    /// device in submissions of many steps, and `y` comes back once at the end (also after a guard
    /// fired or an interrupt, holding the last good state). `interrupted` is polled between
    /// submissions, and `peek` (a live view) is shown the run after each.
    pub fn run(
        &mut self,
        swimmers: &[Dumbbell],
        base: &[Vector3<f64>],
        y: &mut [f64],
        steps: UniformSteps,
        interrupted: &dyn Fn() -> bool,
        mut peek: Option<Peek<'_>>,
    ) -> Result<RunOutcome> {
        let UniformSteps {
            t0,
            h,
            count: steps,
        } = steps;
        self.upload(swimmers, base, y);
        let mut done = 0u64;
        let mut outcome = RunOutcome::Done;
        while done < steps {
            // A fresh step counter (u32) from a new t0 every 2^30 steps.
            let part = (steps - done).min(MAX_STEPS_PER_COUNTER);
            let t_part = t0 + done as f64 * h;
            let this_part = peek.as_mut().map(|p| &mut **p as Peek<'_>);
            match self.run_part(t_part, h, part, interrupted, this_part)? {
                RunOutcome::Done => done += part,
                RunOutcome::Failed { steps_done } => {
                    outcome = RunOutcome::Failed {
                        steps_done: done + steps_done,
                    };
                    break;
                }
                RunOutcome::Interrupted { steps_done } => {
                    outcome = RunOutcome::Interrupted {
                        steps_done: done + steps_done,
                    };
                    break;
                }
            }
        }
        self.read_state(y)?;
        Ok(outcome)
    }

    /// The swimmers' constants and the state go up.
    fn upload(&self, swimmers: &[Dumbbell], base: &[Vector3<f64>], y: &[f64]) {
        let constants = match self.model {
            GpuModel::Micro { mu, .. } => super::micro_rates::pack(swimmers, base, mu),
            GpuModel::Averaged { coefficients } => {
                super::averaged_rates::pack(swimmers, base, coefficients)
            }
        };
        self.dev
            .queue
            .write_buffer(&self.swimmers, 0, bytemuck::cast_slice(&constants));
        self.dev
            .queue
            .write_buffer(&self.y, 0, bytemuck::cast_slice(y));
    }

    /// The run's parameters: uniform steps of `h` from `t0`, or (`rtol` > 0) adaptive steps.
    fn params(&self, t0: f64, h: f64, rtol: f64) -> Params {
        let (oseen, rpy, use_rpy, project) = match self.model {
            GpuModel::Micro { mu, mobility } => (
                1.0 / (8.0 * std::f64::consts::PI * mu),
                1.0 / (24.0 * std::f64::consts::PI * mu),
                u32::from(mobility == Mobility::Rpy),
                0,
            ),
            GpuModel::Averaged { .. } => (0.0, 0.0, 0, 1),
        };
        Params {
            t0,
            h,
            oseen,
            rpy,
            rtol,
            n: self.n as u32,
            nstate: (STATE_PER_SWIMMER * self.n) as u32,
            use_rpy,
            project,
            adaptive: u32::from(rtol > 0.0),
            pad: 0,
        }
    }

    fn run_part(
        &mut self,
        t0: f64,
        h: f64,
        steps: u64,
        interrupted: &dyn Fn() -> bool,
        mut peek: Option<Peek<'_>>,
    ) -> Result<RunOutcome> {
        let params = self.params(t0, h, 0.0);
        let q = &self.dev.queue;
        q.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let control = Control::start(t0, t0, h);
        q.write_buffer(&self.control, 0, bytemuck::bytes_of(&control));
        let mut done = 0u64;
        let mut first = true;
        while done < steps {
            if interrupted() {
                return Ok(RunOutcome::Interrupted { steps_done: done });
            }
            let m = self.steps_per_submission.min(steps - done);
            let started = Instant::now();
            self.submit_steps(m, first);
            first = false;
            let c = self.read_control()?;
            let elapsed = started.elapsed().as_secs_f64().max(1e-6);
            if c.failed != NONE {
                return Ok(RunOutcome::Failed {
                    steps_done: u64::from(c.step),
                });
            }
            done += m;
            self.pace(m, elapsed);
            if let Some(p) = peek.as_deref_mut() {
                p(t0 + done as f64 * h, done, self);
            }
        }
        Ok(RunOutcome::Done)
    }

    /// Size the next submission from how long `m` steps took.
    fn pace(&mut self, m: u64, elapsed: f64) {
        let scale = (TARGET_SUBMISSION_SECONDS / elapsed).clamp(0.5, 4.0);
        self.steps_per_submission = ((m as f64 * scale) as u64).clamp(1, MAX_STEPS_PER_SUBMISSION);
    }

    /// Adaptive steps of the buffers' embedded tableau from (t0, y) to t_end, error-controlled
    /// against the per-component `scale` ([`crate::engine::integrators::OdeSystem::error_scale`]):
    /// the error norm is reduced, the step accepted or rejected and the next one chosen on the
    /// device, so a submission holds many attempts and only the control block comes back between
    /// them. `y` comes back at the end, after a guard fired (the last accepted state) or an
    /// interrupt. Fewer than 2^30 steps are taken per call; the caller goes on from the time
    /// reported. `peek` (a live view) is shown the run between submissions.
    pub fn run_adaptive(
        &mut self,
        swimmers: &[Dumbbell],
        base: &[Vector3<f64>],
        y: &mut [f64],
        steps: AdaptiveSteps,
        interrupted: &dyn Fn() -> bool,
        mut peek: Option<Peek<'_>>,
    ) -> Result<AdaptiveReport> {
        if !self.tableau.is_adaptive() {
            return Err(invalid!("these device buffers hold a fixed-step method"));
        }
        self.upload(swimmers, base, y);
        let q = &self.dev.queue;
        q.write_buffer(&self.adapt, 0, bytemuck::cast_slice(steps.scale));
        let params = self.params(steps.t0, 0.0, steps.rtol);
        q.write_buffer(&self.params, 0, bytemuck::bytes_of(&params));
        let control = Control::start(steps.t0, steps.t_end, steps.h);
        q.write_buffer(&self.control, 0, bytemuck::bytes_of(&control));
        let mut first = true;
        let (c, outcome) = loop {
            let m = self.steps_per_submission;
            let started = Instant::now();
            self.submit_attempts(m, first);
            first = false;
            let c = self.read_control()?;
            self.pace(m, started.elapsed().as_secs_f64().max(1e-6));
            let steps_done = u64::from(c.step);
            if c.failed != NONE {
                break (c, RunOutcome::Failed { steps_done });
            }
            if c.done != 0 || steps_done >= MAX_STEPS_PER_COUNTER {
                break (c, RunOutcome::Done);
            }
            if interrupted() {
                break (c, RunOutcome::Interrupted { steps_done });
            }
            if let Some(p) = peek.as_deref_mut() {
                p(c.t, steps_done, self);
            }
        };
        self.read_state(y)?;
        let failed = matches!(outcome, RunOutcome::Failed { .. });
        Ok(AdaptiveReport {
            outcome,
            t: c.t,
            h: if failed { c.h_start } else { c.h },
            steps: u64::from(c.step),
            rejected: u64::from(if failed {
                c.rejected - c.rejects
            } else {
                c.rejected
            }),
        })
    }

    /// Encode and submit `m` adaptive attempts (and, on a run's first submission, the rates at
    /// the start); attempts after the run's end or a failure return at once.
    fn submit_attempts(&self, m: u64, first: bool) {
        let s = self.tableau.stages();
        // Bind groups in the order of Tableau::stage_params: rows 1..S, error weights, start.
        let (error, start) = (s - 1, s);
        self.submit("attempts", first, start, |pass, groups| {
            let k = &self.kernels;
            for _ in 0..m {
                pass.set_pipeline(&k.stages.begin_attempt);
                pass.dispatch_workgroups(1, 1, 1);
                for stage in 0..s - 1 {
                    self.encode_rates(pass, stage, groups);
                }
                pass.set_bind_group(1, &self.stages[error], &[]);
                pass.set_pipeline(&k.stages.error_part);
                pass.dispatch_workgroups(groups, 1, 1);
                pass.set_pipeline(&k.stages.decide);
                pass.dispatch_workgroups(1, 1, 1);
                pass.set_pipeline(&k.stages.commit_attempt);
                pass.dispatch_workgroups(groups, 1, 1);
            }
        });
    }

    /// One submission: a compute pass with group 0 and the bind group `start` (stage 0) set, the
    /// rates at the start if `first`, then `body`; then the control block copied for read-back.
    fn submit(
        &self,
        label: &str,
        first: bool,
        start: usize,
        body: impl FnOnce(&mut wgpu::ComputePass<'_>, u32),
    ) {
        let groups = (self.n as u32).div_ceil(WORKGROUP);
        let mut enc = self
            .dev
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor { label: Some(label) });
        {
            let mut pass = enc.begin_compute_pass(&wgpu::ComputePassDescriptor {
                label: Some(label),
                timestamp_writes: None,
            });
            pass.set_bind_group(0, &self.group0, &[]);
            // Every pipeline's layout has group 1, also those that read no stage.
            pass.set_bind_group(1, &self.stages[start], &[]);
            if first {
                self.encode_rates(&mut pass, start, groups);
            }
            body(&mut pass, groups);
        }
        enc.copy_buffer_to_buffer(
            &self.control,
            0,
            &self.read_control,
            0,
            std::mem::size_of::<Control>() as u64,
        );
        self.dev.queue.submit([enc.finish()]);
    }

    /// The stage state of bind group `stage` and the model's rates there.
    fn encode_rates(&self, pass: &mut wgpu::ComputePass<'_>, stage: usize, groups: u32) {
        let k = &self.kernels;
        pass.set_bind_group(1, &self.stages[stage], &[]);
        pass.set_pipeline(&k.stages.stage_state);
        pass.dispatch_workgroups(groups, 1, 1);
        match self.model {
            GpuModel::Micro { .. } => {
                pass.set_pipeline(&k.micro.place);
                pass.dispatch_workgroups(groups, 1, 1);
                pass.set_pipeline(&k.micro.interact);
                pass.dispatch_workgroups(groups, 1, 1);
            }
            GpuModel::Averaged { .. } => {
                pass.set_pipeline(&k.averaged.interact);
                pass.dispatch_workgroups(groups, 1, 1);
            }
        }
    }

    /// Encode and submit `m` steps (and, on a run's first submission, the rates at the start).
    fn submit_steps(&self, m: u64, first: bool) {
        let s = self.tableau.stages();
        // Bind groups in the order of Tableau::stage_params.
        let (combine, check, start) = (s - 1, s, s + 1);
        self.submit("steps", first, start, |pass, groups| {
            let k = &self.kernels;
            for _ in 0..m {
                for stage in 0..s - 1 {
                    self.encode_rates(pass, stage, groups);
                }
                pass.set_bind_group(1, &self.stages[combine], &[]);
                pass.set_pipeline(&k.stages.combine);
                pass.dispatch_workgroups(groups, 1, 1);
                // The rates at y_new: the guards' contact test, and k_0 of the next step.
                self.encode_rates(pass, check, groups);
                pass.set_pipeline(&k.stages.commit);
                pass.dispatch_workgroups(groups, 1, 1);
            }
        });
    }

    fn read_control(&self) -> Result<Control> {
        let bytes = self.map_read(&self.read_control, std::mem::size_of::<Control>())?;
        Ok(bytemuck::pod_read_unaligned(&bytes))
    }

    /// The state on the device now, read back into `y` (between submissions: a live view's look).
    pub fn peek_state(&self, y: &mut [f64]) -> Result<()> {
        self.read_state(y)
    }

    fn read_state(&self, y: &mut [f64]) -> Result<()> {
        let size = std::mem::size_of_val(y);
        let mut enc = self
            .dev
            .device
            .create_command_encoder(&wgpu::CommandEncoderDescriptor {
                label: Some("read"),
            });
        enc.copy_buffer_to_buffer(&self.y, 0, &self.read_state, 0, size as u64);
        self.dev.queue.submit([enc.finish()]);
        let bytes = self.map_read(&self.read_state, size)?;
        for (v, b) in y.iter_mut().zip(bytes.chunks_exact(8)) {
            *v = bytemuck::pod_read_unaligned(b);
        }
        Ok(())
    }

    /// Wait for the queue, then copy the first `size` bytes of a readback buffer.
    fn map_read(&self, buf: &wgpu::Buffer, size: usize) -> Result<Vec<u8>> {
        let slice = buf.slice(..size as u64);
        let (tx, rx) = std::sync::mpsc::channel();
        slice.map_async(wgpu::MapMode::Read, move |r| {
            let _ = tx.send(r);
        });
        self.dev
            .device
            .poll(wgpu::PollType::wait_indefinitely())
            .map_err(|e| invalid!("the GPU stopped answering: {e}"))?;
        let errors = self.dev.take_errors();
        if !errors.is_empty() {
            return Err(invalid!("the GPU reported: {}", errors.join("; ")));
        }
        match rx.recv() {
            Ok(Ok(())) => {}
            Ok(Err(e)) => return Err(invalid!("reading back from the GPU failed: {e}")),
            Err(_) => return Err(invalid!("reading back from the GPU never completed")),
        }
        let out = slice
            .get_mapped_range()
            .map_err(|e| invalid!("reading back from the GPU failed: {e}"))?
            .to_vec();
        buf.unmap();
        Ok(out)
    }
}
