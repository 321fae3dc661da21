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

/// `text` with every number of 16 digits or more written [`short`]: the last defence of a
/// message against the digits of a value the user (or serde, or `format!("{}")`) wrote out
/// in full. Shorter numbers (counts, line numbers, exact values) are left as they are.
pub fn shorten_in(text: &str) -> String {
    let bytes = text.as_bytes();
    let mut out = String::with_capacity(text.len());
    let mut i = 0;
    while i < bytes.len() {
        let starts_number = bytes[i].is_ascii_digit() && (i == 0 || !(bytes[i - 1].is_ascii_alphanumeric() || bytes[i - 1] == b'.'));
        if !starts_number {
            let c = text[i..].chars().next().expect("inside the text");
            out.push(c);
            i += c.len_utf8();
            continue;
        }
        // digits, an optional fraction, an optional exponent
        let mut end = i;
        let digits = |from: usize| from + bytes[from..].iter().take_while(|b| b.is_ascii_digit()).count();
        end = digits(end);
        if end < bytes.len() && bytes[end] == b'.' && end + 1 < bytes.len() && bytes[end + 1].is_ascii_digit() {
            end = digits(end + 1);
        }
        if end < bytes.len() && (bytes[end] == b'e' || bytes[end] == b'E') {
            let sign = usize::from(end + 1 < bytes.len() && (bytes[end + 1] == b'-' || bytes[end + 1] == b'+'));
            if end + 1 + sign < bytes.len() && bytes[end + 1 + sign].is_ascii_digit() {
                end = digits(end + 1 + sign);
            }
        }
        let token = &text[i..end];
        let count = token.bytes().filter(u8::is_ascii_digit).count();
        match token.parse::<f64>() {
            Ok(v) if count >= 16 => out.push_str(&short(v)),
            _ => out.push_str(token),
        }
        i = end;
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{short, shorten_in};

    #[test]
    fn long_numbers_in_a_message_are_cut_and_the_rest_left_alone() {
        let long = format!("{}", 1e300);
        assert_eq!(shorten_in(&format!("got -{long}, want 3; line 12")), "got -1e300, want 3; line 12");
        assert_eq!(shorten_in(&format!("[[{}, 5]]", 1e-300)), "[[1e-300, 5]]");
        assert_eq!(shorten_in("v2 0.30000000000000004 µN·m"), "v2 0.3 µN·m");
        assert_eq!(shorten_in("1234567890123 steps"), "1234567890123 steps");
    }

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
