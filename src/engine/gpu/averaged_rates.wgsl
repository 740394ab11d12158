// Stroke-averaged model on the device: the pairwise I, J, K, L sums (see engine/averaged.rs for
// the equations), one thread per swimmer σ, the other swimmers ρ tiled through workgroup memory.
//
// swimmers[12 s + …]: 0-2 base of R_H, 3 A_R, 4 c_J, 5 A_N, 6 v0 = Λω(λ/ℓ)², 7 w0 = ω(λ/ℓ)²,
// 8 Λ/ℓ, 9 ell, 10 phase (see averaged_rates.rs).

const STRIDE: u32 = 12u;
// |sin Δφ| below this counts as zero, as on the CPU.
const SIN_ZERO: f64 = 1e-14lf;

fn sw(s: u32, i: u32) -> f64 {
    return swimmers[STRIDE * s + i];
}

var<workgroup> tile_center: array<vec4<f64>, WG>;
var<workgroup> tile_dir: array<vec4<f64>, WG>;
var<workgroup> halt: u32;

@compute @workgroup_size(64)
fn interact(@builtin(global_invocation_id) gid: vec3<u32>, @builtin(local_invocation_id) lid: vec3<u32>) {
    if lid.x == 0u {
        halt = select(NONE, 0u, stopped());
    }
    if workgroupUniformLoad(&halt) != NONE {
        return;
    }
    let s = gid.x;
    let n = params.n;
    let live = s < n;
    var cs = vec3<f64>(0.0lf);
    var ns = vec3<f64>(0.0lf);
    var phase_s = 0.0lf;
    var a_r = 0.0lf;
    var c_j = 0.0lf;
    var a_n = 0.0lf;
    var v0 = 0.0lf;
    var w0 = 0.0lf;
    var big_l = 0.0lf;
    var ell = 1.0lf;
    if live {
        cs = vec3<f64>(sw(s, 0u), sw(s, 1u), sw(s, 2u)) + state3(s, 0u);
        ns = state3(s, 3u);
        a_r = sw(s, 3u);
        c_j = sw(s, 4u);
        a_n = sw(s, 5u);
        v0 = sw(s, 6u);
        w0 = sw(s, 7u);
        big_l = sw(s, 8u);
        ell = sw(s, 9u);
        phase_s = sw(s, 10u);
    }
    var v = vec3<f64>(0.0lf);
    var torque = vec3<f64>(0.0lf);
    for (var start = 0u; start < n; start += WG) {
        let load = start + lid.x;
        if load < n {
            let base = vec3<f64>(sw(load, 0u), sw(load, 1u), sw(load, 2u));
            tile_center[lid.x] = vec4<f64>(base + state3(load, 0u), sw(load, 10u));
            tile_dir[lid.x] = vec4<f64>(state3(load, 3u), 0.0lf);
        }
        workgroupBarrier();
        let m = min(WG, n - start);
        if live {
            for (var j = 0u; j < m; j++) {
                let r = start + j;
                let sn = sin64(phase_s - tile_center[j].w);
                if r == s || abs(sn) <= SIN_ZERO {
                    continue;
                }
                let dvec = cs - tile_center[j].xyz;
                let dist = sqrt(dot(dvec, dvec));
                if stage.check == 1u && dist == 0.0lf {
                    fail(min(s, r), CODE_CONTACT);
                }
                let dh = dvec / dist;
                let nr = tile_dir[j].xyz;
                let ss = dot(dh, ns);
                let rr = dot(dh, nr);
                let q = dot(ns, nr);
                let xi = ell / dist;
                let xi3 = xi * xi * xi;
                let xi4 = xi3 * xi;
                let jk = 1.0lf + 2.0lf * q * q - 5.0lf * ss * ss - 5.0lf * rr * rr - 20.0lf * q * ss * rr
                    + 35.0lf * ss * ss * rr * rr;
                v += c_j * v0 * sn * (9.0lf / 64.0lf) * xi4
                    * (ns * (2.0lf * ss + 4.0lf * q * rr - 10.0lf * ss * rr * rr) + dh * jk);
                let l = w0 * sn * (15.0lf / 64.0lf) * big_l * xi4 * xi
                    * (3.0lf * ss + 6.0lf * rr * q + 6.0lf * ss * q * q - 7.0lf * ss * ss * ss
                        - 21.0lf * ss * rr * rr - 42.0lf * q * ss * ss * rr
                        + 63.0lf * ss * ss * ss * rr * rr);
                let i_br = 1.0lf - 3.0lf * rr * rr - 3.0lf * ss * ss - 6.0lf * q * ss * rr
                    + 15.0lf * ss * ss * rr * rr;
                v += ns * (a_r * v0 * sn * (9.0lf / 64.0lf) * big_l * xi3 * i_br);
                torque += dh * (l + a_n * w0 * sn * (9.0lf / 32.0lf) * big_l * xi4 * jk);
            }
        }
        workgroupBarrier();
    }
    if live {
        put_rates(s, v, -(torque - ns * dot(ns, torque)));
    }
}
