//! Tick labels: numbers with as many digits as an axis's span needs.

/// A number for an axis whose visible range is `span` wide: enough significant digits that
/// neighbouring ticks (about a tenth of the span apart) differ, e.g. 5.0000100e-5 and
/// 5.0000200e-5 on a 1e-10 span, compact otherwise;
/// values within 1e-9 of the span from zero are zero (a tick at −1.7e-21 is a rounded 0).
pub fn format_number(v: f64, span: f64) -> String {
    if v == 0.0 || v.abs() < 1e-9 * span.abs() {
        return "0".into();
    }
    let digits = if span > 0.0 && span.is_finite() {
        // Axes carry about ten ticks: resolve a tenth of the span.
        ((v.abs() / (0.1 * span)).log10().ceil() as i64 + 1).clamp(1, 15) as usize
    } else {
        3
    };
    if (1e-3..1e4).contains(&v.abs()) && digits <= 6 {
        let decimals = (digits as i64 - 1 - v.abs().log10().floor() as i64).clamp(0, 15) as usize;
        let s = format!("{v:.decimals$}");
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        // Trailing zeros of the mantissa go as in the decimal form: 2e-5, not 2.0e-5.
        let d = digits.saturating_sub(1);
        let s = format!("{v:.d$e}");
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => {
                format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.'))
            }
            _ => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::format_number;

    #[test]
    fn tick_labels_drop_trailing_zeros_in_both_forms() {
        assert_eq!(format_number(2e-5, 1.1e-4), "2e-5");
        assert_eq!(format_number(1e-5, 1.1e-4), "1e-5");
        assert_eq!(format_number(2.5e-5, 1.1e-5), "2.5e-5");
        assert_eq!(format_number(0.5, 1.0), "0.5");
    }
}
