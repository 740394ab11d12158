// Explicit Runge-Kutta stages on the device, one thread per swimmer (6 state components), and
// the adaptive Dormand-Prince 5(4) step: error norm, accept/reject and step size decided on the
// device, as the CPU's Dopri5 decides them (integrators/dopri5.rs).

// Σ_{j<nk} a_j k_j of state component i, with the stage's coefficients a.
fn combination(i: u32) -> f64 {
    var acc = 0.0lf;
    for (var j = 0u; j < stage.nk; j++) {
        acc += stage.a[j] * k[j * params.nstate + i];
    }
    return acc;
}

// A swimmer's state with its N (components 3-5, averaged model) made a unit vector again.
fn renormalised(v: array<f64, 6>) -> array<f64, 6> {
    var out = v;
    let nv = vec3<f64>(v[3], v[4], v[5]);
    let u = nv / sqrt(dot(nv, nv));
    out[3] = u.x;
    out[4] = u.y;
    out[5] = u.z;
    return out;
}

// y_stage = src + h Σ_{j<nk} a_j k_j.
@compute @workgroup_size(64)
fn stage_state(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if s >= params.n || stopped() {
        return;
    }
    for (var c = 0u; c < 6u; c++) {
        let i = 6u * s + c;
        let acc = combination(i);
        var base = y[i];
        if stage.src == 1u {
            base = y_new[i];
        }
        y_stage[i] = base + step_size() * acc;
    }
}

// y_new = y + h Σ_j b_j k_j (b in stage.a), renormalising N for the averaged model, with the
// finite-value guard.
@compute @workgroup_size(64)
fn combine(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if s >= params.n || stopped() {
        return;
    }
    var v: array<f64, 6>;
    for (var c = 0u; c < 6u; c++) {
        let i = 6u * s + c;
        let acc = combination(i);
        v[c] = y[i] + step_size() * acc;
    }
    if params.project == 1u {
        v = renormalised(v);
    }
    for (var c = 0u; c < 6u; c++) {
        // False for NaN as well as ±inf.
        if !(abs(v[c]) <= 1.7976931348623157e308lf) {
            fail(s, CODE_NOT_FINITE);
        }
        y_new[6u * s + c] = v[c];
    }
}

// Accept y_new unless a guard fired during this step.
@compute @workgroup_size(64)
fn commit(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if s >= params.n || stopped() {
        return;
    }
    for (var c = 0u; c < 6u; c++) {
        y[6u * s + c] = y_new[6u * s + c];
    }
    if s == 0u {
        control.step += 1u;
    }
}

// The CPU's adaptive controller with its PI rule (integrators/controller.rs, `StepRule::Pi`, as
// dopri5 runs it) and its MAX_REJECTS.
const SAFETY: f64 = 0.9lf;
const BETA: f64 = 0.04lf;
const FAC_MIN: f64 = 0.2lf;
const FAC_MAX: f64 = 10.0lf;
const MAX_REJECTS: u32 = 60u;

// One thread, before an attempt: its step, clipped to land on t_end.
@compute @workgroup_size(1)
fn begin_attempt() {
    if stopped() {
        return;
    }
    if control.rejects == 0u {
        control.h_start = control.h;
    }
    control.accepted = 0u;
    atomicStore(&control.guard, NONE);
    let span = control.t_end - control.t;
    if control.h >= span {
        control.h_try = span;
        control.last = 1u;
    } else {
        control.h_try = control.h;
        control.last = 0u;
    }
}

// Per swimmer, after the last stage (whose state, the fifth-order solution, is in y_stage and
// whose rates are k_6): the sum over its components of (h Σ_j e_j k_j / (rtol · scale))² with
// the error weights e in stage.a, and the solution, renormalised for the averaged model, in y_new.
@compute @workgroup_size(64)
fn error_part(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if s >= params.n || stopped() {
        return;
    }
    var sum = 0.0lf;
    var v: array<f64, 6>;
    for (var c = 0u; c < 6u; c++) {
        let i = 6u * s + c;
        let acc = combination(i);
        let r = control.h_try * acc / (params.rtol * adapt[i]);
        sum += r * r;
        v[c] = y_stage[i];
    }
    if params.project == 1u {
        v = renormalised(v);
    }
    for (var c = 0u; c < 6u; c++) {
        y_new[6u * s + c] = v[c];
    }
    adapt[params.nstate + s] = sum;
}

var<workgroup> partial: array<f64, WG>;
var<workgroup> quit: u32;

// e^z in f64 for |z| ≲ 700 (WGSL has exp in f32 only): z = k ln2 + r with a two-part ln2
// (Cody-Waite), |r| ≤ ln2/2, e^r by its Taylor series to r^14/14! (< 1e-17), times 2^k built
// by exact doublings.
fn exp64(z: f64) -> f64 {
    let kf = round(z * 1.44269504088896338700e+00lf);
    let r = (z - kf * 6.93147180369123816490e-01lf) - kf * 1.90821492927058770002e-10lf;
    var term = 1.0lf;
    var sum = 1.0lf;
    for (var j = 1; j <= 14; j++) {
        term *= r / f64(j);
        sum += term;
    }
    var k = i32(kf);
    var two = 2.0lf;
    if k < 0 {
        two = 0.5lf;
        k = -k;
    }
    for (var j = 0; j < k; j++) {
        sum *= two;
    }
    return sum;
}

// ln x in f64 for x > 0: the f32 logarithm refined by two Newton steps on e^y = x
// (y ← y − 1 + x e^−y), each squaring its relative error: 1e-7 → 1e-14 → round-off.
fn ln64(x: f64) -> f64 {
    var y = f64(log(f32(x)));
    for (var j = 0; j < 2; j++) {
        y = y - 1.0lf + x * exp64(-y);
    }
    return y;
}

// x^p for x in [1e-30, 1e30] (clamped): within a few ulps of the CPU's powf, so both
// backends choose the same steps.
fn pow64(x: f64, p: f64) -> f64 {
    return exp64(p * ln64(clamp(x, 1e-30lf, 1e30lf)));
}

// One workgroup: the RMS error norm (the swimmers' sums reduced in a fixed order), then, in one
// thread, accept or reject and the next step, as the CPU's Dopri5 (its powers in f64 by
// pow64: at a tolerance where dopri5 runs at its stability limit, step sizes ~1e-7 apart,
// as f32 powers give, end 1e-5 apart in the state).
@compute @workgroup_size(64)
fn decide(@builtin(local_invocation_index) li: u32) {
    if li == 0u {
        quit = select(0u, 1u, stopped());
    }
    if workgroupUniformLoad(&quit) == 1u {
        return;
    }
    var sum = 0.0lf;
    for (var s = li; s < params.n; s += WG) {
        sum += adapt[params.nstate + s];
    }
    partial[li] = sum;
    workgroupBarrier();
    for (var w = WG / 2u; w > 0u; w >>= 1u) {
        if li < w {
            partial[li] += partial[li + w];
        }
        workgroupBarrier();
    }
    if li != 0u {
        return;
    }
    let err = sqrt(partial[0] / f64(params.nstate));
    control.err = err;
    // False for NaN as well as +inf.
    let finite = err <= 1.7976931348623157e308lf;
    // Clamped to [1e-30, 1e30] (pow64): beyond, the factors below are clamped anyway.
    let fac11 = pow64(err, 0.2lf - BETA * 0.75lf);
    let h_try = control.h_try;
    if finite && err <= 1.0lf && atomicLoad(&control.guard) != NONE {
        // Accepted but its state fails a guard: the CPU replays the step from its start.
        atomicMin(&control.failed, atomicLoad(&control.guard));
    } else if finite && err <= 1.0lf {
        let fac = clamp(fac11 / pow64(control.fac_old, BETA) / SAFETY, 1.0lf / FAC_MAX, 1.0lf / FAC_MIN);
        var h_next = h_try / fac;
        if control.rejected_last == 1u {
            h_next = min(h_next, h_try);
        }
        control.fac_old = max(err, 1e-4lf);
        // A step clipped to land on t_end says nothing about the natural step size.
        if control.last == 1u && h_try < control.h {
            control.h = max(control.h, h_next);
        } else {
            control.h = h_next;
        }
        if control.last == 1u {
            control.t = control.t_end;
            control.done = 1u;
        } else {
            control.t = control.t + h_try;
        }
        control.step += 1u;
        control.accepted = 1u;
        control.rejected_last = 0u;
        control.rejects = 0u;
    } else {
        control.rejected += 1u;
        control.rejects += 1u;
        if control.rejects >= MAX_REJECTS {
            fail(0u, CODE_TOLERANCE);
        }
        var shrink = 1.0lf / FAC_MIN;
        if finite {
            shrink = min(fac11 / SAFETY, 1.0lf / FAC_MIN);
        }
        control.h = h_try / shrink;
        control.rejected_last = 1u;
    }
}

// Per swimmer, after `decide`: an accepted attempt's solution becomes y, and the rates there
// (k_6) the first stage of the next step (first same as last).
@compute @workgroup_size(64)
fn commit_attempt(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if s >= params.n || atomicLoad(&control.failed) != NONE || control.accepted == 0u {
        return;
    }
    for (var c = 0u; c < 6u; c++) {
        let i = 6u * s + c;
        y[i] = y_new[i];
        k[i] = k[6u * params.nstate + i];
    }
}
