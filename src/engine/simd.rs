//! Run-time choice of the vector unit: one `#[inline(always)]` body compiled for AVX-512, for
//! AVX2 and for the baseline, the widest the CPU has taken at each call. Fused multiply-adds are
//! enabled in both vector builds; they round the same in every width (and in software without
//! one), and Rust forms them only where `mul_add` is written. A kernel may also take 1/√x the
//! way each build does it best ([`InvSqrt`]): AVX-512's estimate and one correction, or a square
//! root and a division.

/// `vector_dispatch! { /// docs
/// pub(crate) fn name(a: A, b: B) -> R = body; }` defines `name`, which calls `body` (an
/// `#[inline(always)]` function of the same signature) compiled for the widest unit present.
/// `= body::<InvSqrt>;` instead calls `body::<Avx512InvSqrt>` in the AVX-512 build and
/// `body::<ExactInvSqrt>` in the others (see [`InvSqrt`]).
macro_rules! vector_dispatch {
    ($(#[$attr:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? = $body:ident::<InvSqrt>;) => {
        $crate::engine::simd::vector_dispatch! {
            @emit $(#[$attr])* $vis fn $name($($arg: $ty),*) $(-> $ret)?;
            $body::<$crate::engine::simd::Avx512InvSqrt>,
            $body::<$crate::engine::simd::ExactInvSqrt>
        }
    };
    ($(#[$attr:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? = $body:path;) => {
        $crate::engine::simd::vector_dispatch! {
            @emit $(#[$attr])* $vis fn $name($($arg: $ty),*) $(-> $ret)?; $body, $body
        }
    };
    (@emit $(#[$attr:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),*) $(-> $ret:ty)?; $wide:expr, $other:expr) => {
        $(#[$attr])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f,fma")]
                unsafe fn wide($($arg: $ty),*) $(-> $ret)? {
                    ($wide)($($arg),*)
                }
                #[target_feature(enable = "avx2,fma")]
                unsafe fn narrow($($arg: $ty),*) $(-> $ret)? {
                    ($other)($($arg),*)
                }
                if std::is_x86_feature_detected!("fma") {
                    if std::is_x86_feature_detected!("avx512f") {
                        // SAFETY: the CPU has AVX-512F and FMA (checked just above).
                        return unsafe { wide($($arg),*) };
                    }
                    if std::is_x86_feature_detected!("avx2") {
                        // SAFETY: the CPU has AVX2 and FMA (checked just above).
                        return unsafe { narrow($($arg),*) };
                    }
                }
            }
            ($other)($($arg),*)
        }
    };
}
pub(crate) use vector_dispatch;

/// The widest vector unit this CPU has (of those [`vector_dispatch`] uses), for reports.
pub fn vector_unit() -> &'static str {
    #[cfg(target_arch = "x86_64")]
    {
        if std::is_x86_feature_detected!("fma") {
            if std::is_x86_feature_detected!("avx512f") {
                return "avx512f";
            }
            if std::is_x86_feature_detected!("avx2") {
                return "avx2";
            }
        }
    }
    "baseline"
}

/// Independent accumulators of the vector kernels (one AVX-512 register, two AVX2 registers),
/// and the lanes of an [`InvSqrt`] block.
pub const LANES: usize = 8;

/// The block `v[start..start + LANES]` as an array: the kernels' loops over its lanes then need
/// no bounds checks (the slice's one check is here; a block past `v`'s end panics).
#[inline(always)]
pub(crate) fn block(v: &[f64], start: usize) -> [f64; LANES] {
    v[start..start + LANES].try_into().unwrap_or([0.0; LANES])
}

/// Sum of the lanes in a fixed pairwise order.
#[inline(always)]
pub(crate) fn lane_sum(a: &[f64; LANES]) -> f64 {
    ((a[0] + a[4]) + (a[1] + a[5])) + ((a[2] + a[6]) + (a[3] + a[7]))
}

/// 1/√x for a block of lanes, the way one vector build computes it.
///
/// # Safety
/// An implementation may use instructions of one vector unit; [`vector_dispatch!`] calls it only
/// in the build for that unit.
pub(crate) trait InvSqrt {
    /// 1/√x per lane (x > 0 and finite; other lanes are the caller's to mask).
    ///
    /// # Safety
    /// The CPU has the vector unit the implementation names.
    unsafe fn inv_sqrt(x: [f64; LANES]) -> [f64; LANES];
}

/// 1/√x as a square root and a division (within 1 ulp; the same bits in every vector width).
pub(crate) struct ExactInvSqrt;

impl InvSqrt for ExactInvSqrt {
    #[inline(always)]
    unsafe fn inv_sqrt(x: [f64; LANES]) -> [f64; LANES] {
        x.map(|v| 1.0 / v.sqrt())
    }
}

/// 1/√x from AVX-512's 14-bit estimate and one third-order correction (within 2 ulp): seven
/// vector operations where a square root and a division keep the divider busy for about twice
/// as long. Its last bit may differ from [`ExactInvSqrt`]'s.
pub(crate) struct Avx512InvSqrt;

impl InvSqrt for Avx512InvSqrt {
    #[inline(always)]
    unsafe fn inv_sqrt(x: [f64; LANES]) -> [f64; LANES] {
        #[cfg(target_arch = "x86_64")]
        {
            // SAFETY: the caller's contract: the CPU has AVX-512F (and FMA).
            unsafe { avx512_inv_sqrt(x) }
        }
        #[cfg(not(target_arch = "x86_64"))]
        {
            // SAFETY: no instructions of any unit.
            unsafe { ExactInvSqrt::inv_sqrt(x) }
        }
    }
}

/// y₀ = the 14-bit estimate (relative error e₀ < 2⁻¹⁴), e = 1 − x y₀² (≈ 2e₀), and
/// y = y₀ (1 + e/2 + 3e²/8 + 5e³/16): the binomial series of (1 − e)^(−1/2) to e³, whose first
/// term left out, 35e⁴/128, is below 2⁻⁵⁴.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx512f,fma")]
#[inline]
unsafe fn avx512_inv_sqrt(x: [f64; LANES]) -> [f64; LANES] {
    use std::arch::x86_64::*;
    // SAFETY: both pointers cover 8 f64 (the array's length); unaligned loads and stores.
    unsafe {
        let x = _mm512_loadu_pd(x.as_ptr());
        let y0 = _mm512_rsqrt14_pd(x);
        let e = _mm512_fnmadd_pd(_mm512_mul_pd(x, y0), y0, _mm512_set1_pd(1.0));
        let p = _mm512_fmadd_pd(_mm512_set1_pd(5.0 / 16.0), e, _mm512_set1_pd(3.0 / 8.0));
        let p = _mm512_fmadd_pd(p, e, _mm512_set1_pd(0.5));
        let y = _mm512_fmadd_pd(_mm512_mul_pd(y0, e), p, y0);
        let mut out = [0.0; LANES];
        _mm512_storeu_pd(out.as_mut_ptr(), y);
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The AVX-512 estimate against a square root and a division, over 600 decades and every
    /// mantissa pattern class: within 2 ulp (the series' truncation is below half an ulp, and
    /// the products and sums round a few times).
    #[test]
    fn avx512_inverse_square_root_is_within_two_ulp() {
        #[cfg(target_arch = "x86_64")]
        {
            if !(std::is_x86_feature_detected!("avx512f") && std::is_x86_feature_detected!("fma")) {
                return;
            }
            let mut worst = 0.0f64;
            let mut rng = crate::engine::rng::Rng::new(0x9e37_79b9_7f4a_7c15);
            for _ in 0..20_000 {
                let x: [f64; LANES] = std::array::from_fn(|_| {
                    let state = rng.next_u64();
                    let mantissa = 1.0 + (state >> 11) as f64 / (1u64 << 53) as f64;
                    mantissa * 10f64.powi((state % 600) as i32 - 300)
                });
                // SAFETY: AVX-512F and FMA checked above.
                let (fast, exact) =
                    unsafe { (Avx512InvSqrt::inv_sqrt(x), ExactInvSqrt::inv_sqrt(x)) };
                for (f, e) in fast.iter().zip(exact) {
                    worst = worst.max((f - e).abs() / (e * f64::EPSILON));
                }
            }
            assert!(worst <= 2.0, "{worst} ulp");
        }
    }
}
