//! Run-time choice of the vector unit: one `#[inline(always)]` body compiled for AVX-512, for
//! AVX2 and for the baseline, the widest the CPU has taken at each call. Fused multiply-adds are
//! enabled in both vector builds; they round the same in every width (and in software without
//! one), and Rust forms them only where `mul_add` is written.

/// `vector_dispatch! { /// docs
/// pub(crate) fn name(a: A, b: B) -> R = body; }` defines `name`, which calls `body` (an
/// `#[inline(always)]` function of the same signature) compiled for the widest unit present.
macro_rules! vector_dispatch {
    ($(#[$attr:meta])* $vis:vis fn $name:ident($($arg:ident: $ty:ty),* $(,)?) $(-> $ret:ty)? = $body:path;) => {
        $(#[$attr])*
        $vis fn $name($($arg: $ty),*) $(-> $ret)? {
            #[cfg(target_arch = "x86_64")]
            {
                #[target_feature(enable = "avx512f,fma")]
                unsafe fn wide($($arg: $ty),*) $(-> $ret)? {
                    $body($($arg),*)
                }
                #[target_feature(enable = "avx2,fma")]
                unsafe fn narrow($($arg: $ty),*) $(-> $ret)? {
                    $body($($arg),*)
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
            $body($($arg),*)
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
