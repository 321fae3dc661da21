//! Numbers as messages quote them: what the user wrote where that is short, otherwise four
//! significant figures, never the 301 digits `format!("{}", 1e300)` prints.

/// `v` for a message: its shortest exact form where that has at most a dozen characters
/// (`0.15`, `1e300`, `-0.3`), otherwise four significant figures (`1.235e-7`, `0.3`).
pub fn short(v: f64) -> String {
    if v.is_nan() {
        return "NaN".into();
    }
    if v.is_infinite() {
        return if v > 0.0 { "inf" } else { "-inf" }.into();
    }
    let exact = format!("{v:?}");
    if exact.len() <= 12 {
        // Debug writes whole numbers as `50.0`; a message reads `50`.
        return exact.strip_suffix(".0").map_or(exact.clone(), str::to_string);
    }
    let magnitude = v.abs();
    if (1e-3..1e6).contains(&magnitude) {
        let decimals = (3 - magnitude.log10().floor() as i32).max(0) as usize;
        let text = format!("{v:.decimals$}");
        if text.contains('.') { text.trim_end_matches('0').trim_end_matches('.').to_string() } else { text }
    } else {
        let text = format!("{v:.3e}");
        let (mantissa, exponent) = text.split_once('e').expect("exponent form");
        let mantissa = if mantissa.contains('.') { mantissa.trim_end_matches('0').trim_end_matches('.') } else { mantissa };
        format!("{mantissa}e{exponent}")
    }
}

#[cfg(test)]
mod tests {
    use super::short;

    #[test]
    fn short_numbers_keep_what_was_written_and_long_ones_are_cut_to_four_figures() {
        assert_eq!(short(0.15), "0.15");
        assert_eq!(short(1e300), "1e300");
        assert_eq!(short(-1e-300), "-1e-300");
        assert_eq!(short(16.8), "16.8");
        assert_eq!(short(50.0), "50");
        assert_eq!(short(-3.0), "-3");
        assert_eq!(short(0.1 + 0.2), "0.3");
        assert_eq!(short(1.0 / 3.0), "0.3333");
        assert_eq!(short(123456.789012345), "123457");
        assert_eq!(short(1.23456789e-7), "1.235e-7");
        assert_eq!(short(f64::MAX), "1.798e308");
        assert_eq!(short(f64::NAN), "NaN");
        assert_eq!(short(f64::NEG_INFINITY), "-inf");
        assert!(short(f64::MAX).len() <= 12, "{}", short(f64::MAX));
    }

}
