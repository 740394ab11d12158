//! Errors the engine reports. Each names the problem and, where there is one, the fix.

/// A scene setting that an error names as its fix, in engine terms. The engine's messages show
/// it in words ("the cpu backend"); the script layer shows it as the script line that makes it
/// (`s.backend = "cpu"`), so neither layer's syntax leaks into the other.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Setting {
    /// Run on this backend ("cpu", "gpu", "auto").
    Backend(&'static str),
    /// Use this model ("micro", "rigid", "averaged").
    Model(&'static str),
    /// A fixed-step integrator (euler or rk4 with a step dt).
    FixedStep,
    /// The model's default integrator.
    DefaultIntegrator,
    /// A fixed step below ~2.8 over the scene's stiff rate.
    StableStep,
    /// Steric repulsion between swimmers switched on.
    Steric,
    /// Overlapping spheres of different swimmers allowed.
    AllowOverlaps,
    /// No far-field cutoff.
    NoCutoff,
    /// A swimmer added to the scene.
    AddSwimmer,
    /// Swimmers placed on a lattice instead of at random.
    Lattice,
    /// Use this mobility ("rpy", "oseen").
    Mobility(&'static str),
    /// Temperature 0: no thermal noise.
    NoNoise,
    /// A scheme for thermal noise: Euler-Maruyama or Platen's weak second-order scheme.
    NoiseIntegrator,
    /// Sum the box's mobility products by this Ewald method ("auto", "beenakker", "spectral").
    EwaldMethod(&'static str),
    /// A looser tolerance of the box's Ewald sums.
    LooserEwaldTol,
    /// No wall: open space.
    NoWall,
    /// No periodic box: open space.
    NoBox,
}

impl std::fmt::Display for Setting {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Setting::Backend(b) => write!(f, "the {b} backend"),
            Setting::Model(m) => write!(f, "the {m} model"),
            Setting::FixedStep => {
                f.write_str("a fixed-step integrator (euler or rk4 with a step dt)")
            }
            Setting::DefaultIntegrator => f.write_str("the model's default integrator"),
            Setting::StableStep => f.write_str("a step below ~2.8 / (the scene's stiff rate)"),
            Setting::Steric => f.write_str(
                "steric repulsion between swimmers (e.g. range 1e-7 m, stiffness 1e-3 N/m)",
            ),
            Setting::AllowOverlaps => f.write_str("overlapping spheres allowed"),
            Setting::NoCutoff => f.write_str("no cutoff (every pair)"),
            Setting::AddSwimmer => f.write_str("adding a swimmer"),
            Setting::Lattice => f.write_str("swimmers placed on a lattice"),
            Setting::Mobility(m) => write!(f, "the {m} mobility"),
            Setting::NoNoise => f.write_str("temperature 0 (no thermal noise)"),
            Setting::NoiseIntegrator => f.write_str(
                "a scheme for thermal noise: euler (Euler-Maruyama) or platen (weak order 2) with a step dt",
            ),
            Setting::EwaldMethod(m) => write!(f, "the {m} Ewald method"),
            Setting::LooserEwaldTol => f.write_str("a looser tolerance of the Ewald sums (e.g. 1e-6)"),
            Setting::NoWall => f.write_str("no wall"),
            Setting::NoBox => f.write_str("no periodic box"),
        }
    }
}

/// Everything that can go wrong in the engine. Its display speaks engine words; a front end
/// that has its own syntax for settings renders the same message with [`EngineError::message_with`].
#[derive(Debug, Clone, PartialEq)]
pub enum EngineError {
    /// A parameter or argument is out of its domain.
    Invalid(String),
    /// A name that is not one of a choice's values (see [`super::choice`]).
    UnknownChoice {
        /// What was chosen ("model").
        kind: &'static str,
        /// The name given.
        given: String,
        /// The closest valid name, if one is close ("did you mean").
        closest: Option<&'static str>,
        /// The valid names, each with a few words.
        valid: Vec<(&'static str, &'static str)>,
    },
    /// Something this scene's settings do not allow; any of `fixes` would.
    Unsupported {
        /// What cannot be done, and why.
        problem: String,
        /// Settings that would allow it.
        fixes: Vec<Setting>,
    },
    /// A step produced a bad state (NaN/inf or overlapping spheres); the scene kept the last good one.
    StepFailed {
        /// Time at which the bad state was produced.
        time: f64,
        /// Time of the state the scene kept.
        last_good: f64,
        /// Swimmer (0-based) where the problem was found, if one can be named.
        swimmer: Option<usize>,
        /// What went wrong.
        cause: String,
        /// What to change.
        hint: String,
        /// Settings that would avoid it.
        fixes: Vec<Setting>,
    },
    /// The run was interrupted from outside (Ctrl-C) at a clean step boundary.
    Interrupted {
        /// Time at which the run stopped.
        time: f64,
    },
}

impl EngineError {
    /// The message, with each fix shown by `show` (the display uses [`Setting`]'s words; the
    /// script layer shows the script line that makes the setting).
    pub fn message_with(&self, show: &dyn Fn(&Setting) -> String) -> String {
        compact_numbers(&self.message_in_full(show))
    }

    /// [`EngineError::message_with`] with its numbers as they were formatted.
    fn message_in_full(&self, show: &dyn Fn(&Setting) -> String) -> String {
        let fixes = |fixes: &[Setting]| fixes.iter().map(show).collect::<Vec<_>>().join(" or ");
        match self {
            EngineError::Invalid(msg) => msg.clone(),
            EngineError::UnknownChoice {
                kind,
                given,
                closest,
                valid,
            } => format!(
                "unknown {kind} \"{given}\";{} valid: {}",
                closest
                    .map(|c| format!(" did you mean \"{c}\"?"))
                    .unwrap_or_default(),
                valid
                    .iter()
                    .map(|(n, a)| format!("\"{n}\" ({a})"))
                    .collect::<Vec<_>>()
                    .join(", ")
            ),
            EngineError::Unsupported { problem, fixes: f } => {
                format!("{problem}; use {}", fixes(f))
            }
            EngineError::StepFailed {
                time,
                last_good,
                cause,
                hint,
                fixes: f,
                ..
            } => format!(
                "the run stopped at t = {time:.6e} s: {cause}; the scene keeps the last good state (t = {last_good:.6e} s). Likely fix: {hint}{}",
                if f.is_empty() {
                    String::new()
                } else {
                    format!("; or use {}", fixes(f))
                }
            ),
            EngineError::Interrupted { time } => format!(
                "run interrupted at t = {time:.6e} s; the scene keeps the state at that time"
            ),
        }
    }
}

impl std::fmt::Display for EngineError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.message_with(&Setting::to_string))
    }
}

impl std::error::Error for EngineError {}

/// An [`EngineError::Unsupported`].
pub fn unsupported(problem: impl Into<String>, fixes: &[Setting]) -> EngineError {
    EngineError::Unsupported {
        problem: problem.into(),
        fixes: fixes.to_vec(),
    }
}

/// Shorthand for engine results.
pub type Result<T> = std::result::Result<T, EngineError>;

/// Build an [`EngineError::Invalid`] from a format string.
macro_rules! invalid {
    ($($arg:tt)*) => { $crate::engine::error::EngineError::Invalid(format!($($arg)*)) };
}
pub(crate) use invalid;

/// Require that `value` is finite and strictly positive.
pub fn require_positive(name: &str, value: f64, unit: &str) -> Result<()> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(invalid!(
            "{name} must be a finite positive number ({unit}), got {value}"
        ))
    }
}

/// Require that `value` is finite.
pub fn require_finite(name: &str, value: f64) -> Result<()> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(invalid!("{name} must be a finite number, got {value}"))
    }
}

/// The most digits a number in a message is written with in full; a longer one (1e308 as a 1
/// and 308 zeros, 1e-320 as 320 zeros and a 1) is rewritten by [`compact_numbers`].
const MAX_DIGITS_IN_FULL: usize = 21;

/// `text` with every decimal number of more than [`MAX_DIGITS_IN_FULL`] digits (Rust's `{}` of
/// an extreme f64) in scientific form, to the last bit: "got 1e308", not a line of 309 digits.
/// Shorter numbers, and digits inside words or hex (a token, an address), are left as written.
pub fn compact_numbers(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut copied = 0;
    let mut i = 0;
    while i < bytes.len() {
        let starts = bytes[i].is_ascii_digit()
            && (i == 0
                || !(bytes[i - 1].is_ascii_alphanumeric() || matches!(bytes[i - 1], b'_' | b'.')));
        if !starts {
            i += 1;
            continue;
        }
        let mut end = i;
        let mut dot = false;
        while end < bytes.len() {
            match bytes[end] {
                b'0'..=b'9' => end += 1,
                b'.' if !dot && bytes.get(end + 1).is_some_and(u8::is_ascii_digit) => {
                    dot = true;
                    end += 1;
                }
                _ => break,
            }
        }
        let glued = bytes
            .get(end)
            .is_some_and(|b| b.is_ascii_alphanumeric() || *b == b'_');
        let digits = end - i - usize::from(dot);
        if !glued && digits > MAX_DIGITS_IN_FULL {
            if let Ok(x) = text[i..end].parse::<f64>() {
                out.push_str(&text[copied..i]);
                out.push_str(&format!("{x:e}"));
                copied = end;
            }
        }
        i = end.max(i + 1);
    }
    out.push_str(&text[copied..]);
    out
}

/// `x` to three significant digits, as a reader of a message takes it in: "75", "7.5e-7".
pub fn short(x: f64) -> String {
    let r: f64 = format!("{x:.2e}").parse().unwrap_or(x);
    if (1e-3..1e6).contains(&r.abs()) {
        format!("{r}")
    } else {
        format!("{r:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::compact_numbers;

    /// Only numbers of more than 21 digits change, to the last bit; digits in hex, in words and
    /// numbers of ordinary length stay as written.
    #[test]
    fn compact_numbers_rewrites_only_the_extreme() {
        let big = format!("got {}, {} and -{}", 1e308, 5e-324, 1.5e300);
        assert_eq!(compact_numbers(&big), "got 1e308, 5e-324 and -1.5e300");
        let plain = "t = 0.0125 s, 12345678901234567890 steps, seed 18446744073709551615";
        assert_eq!(compact_numbers(plain), plain);
        let token = format!(
            "http://127.0.0.1:8/{}a/ x{}",
            "1".repeat(31),
            "9".repeat(30)
        );
        assert_eq!(compact_numbers(&token), token);
    }
}
