// Explicit Runge-Kutta stages on the device, one thread per swimmer (6 state components).

// y_stage = src + h Σ_{j<nk} a_j k_j.
@compute @workgroup_size(64)
fn stage_state(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if s >= params.n || stopped() {
        return;
    }
    for (var c = 0u; c < 6u; c++) {
        let i = 6u * s + c;
        var acc = 0.0lf;
        for (var j = 0u; j < stage.nk; j++) {
            acc += stage.a[j] * k[j * params.nstate + i];
        }
        var base = y[i];
        if stage.src == 1u {
            base = y_new[i];
        }
        y_stage[i] = base + params.h * acc;
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
        var acc = 0.0lf;
        for (var j = 0u; j < stage.nk; j++) {
            acc += stage.a[j] * k[j * params.nstate + i];
        }
        v[c] = y[i] + params.h * acc;
    }
    if params.project == 1u {
        let nv = vec3<f64>(v[3], v[4], v[5]);
        let u = nv / sqrt(dot(nv, nv));
        v[3] = u.x;
        v[4] = u.y;
        v[5] = u.z;
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
