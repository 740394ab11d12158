// Declarations shared by every swimlab kernel (prepended to each kernel's own source).
//
// State: 6 f64 per swimmer (ΔR_H, then b = X2 − X1 for the microscopic model or the unit N for the
// averaged one), as in the CPU engine. Every kernel binds the same group 0; group 1 holds the
// coefficients of one Runge-Kutta stage (one small buffer per stage, bound per dispatch).

struct Params {
    // Start of the run (s) and the uniform step (s): stage time = t0 + (step + c) h (uniform runs).
    t0: f64,
    h: f64,
    // 1/(8πμ) and 1/(24πμ): the Oseen and finite-size prefactors of the RPY tensor.
    oseen: f64,
    rpy: f64,
    // Adaptive runs: the relative tolerance of the error norm.
    rtol: f64,
    // Number of swimmers, state length (6 n), 1 for RPY (0: Oseen), 1 to renormalise N after a step.
    n: u32,
    nstate: u32,
    use_rpy: u32,
    project: u32,
    // 1: adaptive steps, their time and size in `control`; 0: uniform steps.
    adaptive: u32,
    pad: u32,
}

struct Control {
    // Steps committed since the start of the run.
    step: u32,
    // NONE, or 4 × swimmer + code of the first problem found (CODE_*); every kernel stops once set.
    failed: atomic<u32>,
    // Adaptive runs (rk_stages.wgsl): attempts rejected since the start; 1 once t reached t_end
    // (every kernel stops); 1 if the last attempt was accepted; whether the attempt before this
    // one (of the same step) was rejected; consecutive rejections of this step; 1 if this
    // attempt is clipped to land on t_end.
    rejected: u32,
    done: u32,
    accepted: u32,
    rejected_last: u32,
    rejects: u32,
    last: u32,
    // Adaptive runs: the first problem the guards found at this attempt's solution (as
    // `failed`); it fails the run only if the attempt is accepted, as the CPU checks accepted
    // steps only.
    guard: atomic<u32>,
    pad0: u32,
    // Time of y (s), end of the run (s), the step to try next (s), this attempt's step (s), the
    // step proposed when this step began (a failing step is replayed on the CPU from it), the
    // PI controller's previous error, and the last error norm.
    t: f64,
    t_end: f64,
    h: f64,
    h_try: f64,
    h_start: f64,
    fac_old: f64,
    err: f64,
}

// One Runge-Kutta stage: y_stage = src + h Σ_{j<nk} a_j k_j at time t0 + (step + c) h, its rates
// written to k slot `out`; `check` asks the rates kernels to test the state (guards).
struct Stage {
    a: array<f64, 8>,
    c: f64,
    src: u32,
    out: u32,
    nk: u32,
    check: u32,
}

const NONE: u32 = 0xffffffffu;
const CODE_NOT_FINITE: u32 = 1u;
const CODE_SPRING: u32 = 2u;
const CODE_CONTACT: u32 = 3u;
// An adaptive step rejected MAX_REJECTS times in a row (rk_stages.wgsl).
const CODE_TOLERANCE: u32 = 0u;
const WG: u32 = 64u;

@group(0) @binding(0) var<storage, read> params: Params;
@group(0) @binding(1) var<storage, read_write> y: array<f64>;
@group(0) @binding(2) var<storage, read_write> y_new: array<f64>;
@group(0) @binding(3) var<storage, read_write> y_stage: array<f64>;
@group(0) @binding(4) var<storage, read_write> k: array<f64>;
@group(0) @binding(5) var<storage, read_write> control: Control;
// Per-swimmer constants, laid out by the model's kernel (see its .rs file).
@group(0) @binding(6) var<storage, read> swimmers: array<f64>;
// Per sphere: (x, y, z, radius), (force, 0). Microscopic model only.
@group(0) @binding(7) var<storage, read_write> spheres: array<vec4<f64>>;
// Adaptive runs: the error scale of each state component (nstate), then each swimmer's sum of
// squared scaled errors (n).
@group(0) @binding(8) var<storage, read_write> adapt: array<f64>;
@group(1) @binding(0) var<storage, read> stage: Stage;

fn fail(swimmer: u32, code: u32) {
    if params.adaptive == 1u && stage.check == 1u {
        atomicMin(&control.guard, swimmer * 4u + code);
    } else {
        atomicMin(&control.failed, swimmer * 4u + code);
    }
}

// A guard fired, or an adaptive run reached its end.
fn stopped() -> bool {
    return atomicLoad(&control.failed) != NONE || control.done != 0u;
}

fn stage_time() -> f64 {
    if params.adaptive == 1u {
        return control.t + stage.c * control.h_try;
    }
    return params.t0 + (f64(control.step) + stage.c) * params.h;
}

// The step of the stage being taken.
fn step_size() -> f64 {
    if params.adaptive == 1u {
        return control.h_try;
    }
    return params.h;
}

fn state3(s: u32, offset: u32) -> vec3<f64> {
    let i = 6u * s + offset;
    return vec3<f64>(y_stage[i], y_stage[i + 1u], y_stage[i + 2u]);
}

fn put_rates(s: u32, drh: vec3<f64>, db: vec3<f64>) {
    let i = stage.out * params.nstate + 6u * s;
    k[i] = drh.x;
    k[i + 1u] = drh.y;
    k[i + 2u] = drh.z;
    k[i + 3u] = db.x;
    k[i + 4u] = db.y;
    k[i + 5u] = db.z;
}

// sin(x) in f64 (WGSL and SPIR-V offer sin only in f32): Cody-Waite reduction by π/2 with a 3-part
// constant (exact products for |x| < 2^20 π/2) and fdlibm's minimax kernels on [−π/4, π/4];
// within ~1 ulp of libm, so both backends see the same rest length L(t).
fn sin64(x: f64) -> f64 {
    let kq = round(x * 6.36619772367581382433e-01lf);
    let r = ((x - kq * 1.57079632673412561417e+00lf) - kq * 6.07710050630396597660e-11lf)
        - kq * 2.02226624871116645580e-21lf;
    let z = r * r;
    let s = r + r * z * (-1.66666666666666324348e-01lf + z * (8.33333333332248946124e-03lf
        + z * (-1.98412698298579493134e-04lf + z * (2.75573137070700676789e-06lf
        + z * (-2.50507602534068634195e-08lf + z * 1.58969099521155010221e-10lf)))));
    let c = 1.0lf - 0.5lf * z + z * z * (4.16666666666666019037e-02lf
        + z * (-1.38888888888741095749e-03lf + z * (2.48015872894767294178e-05lf
        + z * (-2.75573143513906633035e-07lf + z * (2.08757232129817482790e-09lf
        + z * -1.13596475577881948265e-11lf)))));
    let q = i32(kq - 4.0lf * floor(kq * 0.25lf));
    switch q {
        case 0: { return s; }
        case 1: { return c; }
        case 2: { return -s; }
        default: { return -c; }
    }
}
