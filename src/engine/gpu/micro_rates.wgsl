// Microscopic model on the device: spheres placed from the stage state, then the all-pairs
// mobility product u_α = Σ_{β≠α} H_αβ F_β tiled through workgroup memory, then the rates.
//
// swimmers[16 s + …]: 0-2 base of R_H, 3 a1, 4 a2, 5 k0, 6 ell, 7 lambda, 8 omega, 9 phase,
// 10 w1, 11 w2, 12 drag 1/γ1 + 1/γ2 (see micro_rates.rs).

const STRIDE: u32 = 16u;

fn sw(s: u32, i: u32) -> f64 {
    return swimmers[STRIDE * s + i];
}

// Sphere 2s (radius a1) at R_H − w2 b, sphere 2s+1 (a2) at R_H + w1 b; spring force
// f = k0 (|b| − L(t)) b̂ on sphere 2s and −f on sphere 2s+1.
@compute @workgroup_size(64)
fn place(@builtin(global_invocation_id) gid: vec3<u32>) {
    let s = gid.x;
    if s >= params.n || stopped() {
        return;
    }
    let base = vec3<f64>(sw(s, 0u), sw(s, 1u), sw(s, 2u));
    let rh = base + state3(s, 0u);
    let b = state3(s, 3u);
    let len = sqrt(dot(b, b));
    let rest = sw(s, 6u) + sw(s, 7u) * sin64(sw(s, 8u) * stage_time() + sw(s, 9u));
    let f = sw(s, 5u) * (len - rest) / len * b;
    if stage.check == 1u && abs(len - rest) > 0.5lf * sw(s, 6u) {
        fail(s, CODE_SPRING);
    }
    spheres[4u * s] = vec4<f64>(rh - sw(s, 11u) * b, sw(s, 3u));
    spheres[4u * s + 1u] = vec4<f64>(f, 0.0lf);
    spheres[4u * s + 2u] = vec4<f64>(rh + sw(s, 10u) * b, sw(s, 4u));
    spheres[4u * s + 3u] = vec4<f64>(-f, 0.0lf);
}

// The RPY tensor of overlapping spheres (Zuk et al. 2014) applied to f; 1/(6πμ) = (4/3)/(8πμ).
fn overlap_apply(r: vec3<f64>, r2: f64, ai: f64, aj: f64, f: vec3<f64>) -> vec3<f64> {
    let d = sqrt(r2);
    let stokes = 4.0lf / 3.0lf * params.oseen;
    if d <= abs(ai - aj) {
        return stokes / max(ai, aj) * f;
    }
    let dm = (ai - aj) * (ai - aj);
    let d3 = d * d * d;
    let scale = stokes / (32.0lf * d3 * ai * aj);
    let b = dm + 3.0lf * r2;
    let ci = (16.0lf * d3 * (ai + aj) - b * b) * scale;
    let crr = 3.0lf * (dm - r2) * (dm - r2) * scale;
    return ci * f + r * (crr * dot(r, f) / r2);
}

var<workgroup> tile_pos: array<vec4<f64>, WG>;
var<workgroup> tile_force: array<vec4<f64>, WG>;
var<workgroup> halt: u32;

// H_ij f for spheres at separation r = x_i − x_j with radii ai, aj (Mazur's RPY or Oseen; for
// overlapping spheres the RPY overlap forms, as Mobility::pair_coefficients on the CPU: a stage
// state of a rejected attempt may press a dumbbell's own spheres together).
fn pair_apply(r: vec3<f64>, ai: f64, aj: f64, f: vec3<f64>) -> vec3<f64> {
    let r2 = dot(r, r);
    if params.use_rpy == 1u && r2 <= (ai + aj) * (ai + aj) {
        return overlap_apply(r, r2, ai, aj, f);
    }
    let inv_r = 1.0lf / sqrt(r2);
    let rdf = dot(r, f) * inv_r * inv_r;
    var out = (params.oseen * inv_r) * (f + r * rdf);
    if params.use_rpy == 1u {
        let c3 = (ai * ai + aj * aj) * inv_r * inv_r * inv_r * params.rpy;
        out += c3 * (f - r * (3.0lf * rdf));
    }
    return out;
}

// One thread per swimmer (its two spheres); every thread takes part in loading each tile.
@compute @workgroup_size(64)
fn interact(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    if lid.x == 0u {
        halt = select(NONE, 0u, stopped());
    }
    if workgroupUniformLoad(&halt) != NONE {
        return;
    }
    let s = gid.x;
    let live = s < params.n;
    let count = 2u * params.n;
    let i0 = 2u * s;
    var p0 = vec4<f64>(0.0lf);
    var p1 = vec4<f64>(0.0lf);
    if live {
        p0 = spheres[2u * i0];
        p1 = spheres[2u * i0 + 2u];
    }
    var u0 = vec3<f64>(0.0lf);
    var u1 = vec3<f64>(0.0lf);
    for (var start = 0u; start < count; start += WG) {
        let load = start + lid.x;
        if load < count {
            tile_pos[lid.x] = spheres[2u * load];
            tile_force[lid.x] = spheres[2u * load + 1u];
        }
        workgroupBarrier();
        let m = min(WG, count - start);
        if live {
            for (var j = 0u; j < m; j++) {
                let jj = start + j;
                let q = tile_pos[j];
                let fj = tile_force[j].xyz;
                if jj != i0 {
                    let r = p0.xyz - q.xyz;
                    u0 += pair_apply(r, p0.w, q.w, fj);
                    if stage.check == 1u && dot(r, r) <= (p0.w + q.w) * (p0.w + q.w) {
                        fail(min(s, jj / 2u), CODE_CONTACT);
                    }
                }
                if jj != i0 + 1u {
                    let r = p1.xyz - q.xyz;
                    u1 += pair_apply(r, p1.w, q.w, fj);
                    if stage.check == 1u && dot(r, r) <= (p1.w + q.w) * (p1.w + q.w) {
                        fail(min(s, jj / 2u), CODE_CONTACT);
                    }
                }
            }
        }
        workgroupBarrier();
    }
    if live {
        let f = spheres[2u * i0 + 1u].xyz;
        let drh = sw(s, 10u) * u0 + sw(s, 11u) * u1;
        let db = -sw(s, 12u) * f + (u1 - u0);
        put_rates(s, drh, db);
    }
}
