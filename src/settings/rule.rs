//! A refused setting: its dotted key, why, and the fix; and the range rules most keys
//! follow. The scene's checks (`scene::check`) and each scene kind's own
//! (`scene::kinds`) refuse with these.

use crate::io::number::short;

/// A refused value: its dotted key and why, with the fix.
#[derive(Debug, Clone, PartialEq)]
pub struct Invalid {
    pub key: String,
    pub message: String,
    /// Other keys the refused value was weighed against: where the user set one of them
    /// (`--set test.speed=1e-300` against the scene's `test.max_strain`), the refusal is
    /// traced to it.
    pub also: Vec<String>,
}

pub fn invalid(key: &str, message: String) -> Invalid {
    Invalid { key: key.to_string(), message, also: Vec::new() }
}

pub fn positive(key: &str, v: f64) -> Result<f64, Invalid> {
    if v.is_finite() && v > 0.0 { Ok(v) } else { Err(invalid(key, format!("{key} must be a positive number, got {}", short(v)))) }
}

pub fn non_negative(key: &str, v: f64) -> Result<f64, Invalid> {
    if v.is_finite() && v >= 0.0 { Ok(v) } else { Err(invalid(key, format!("{key} must be zero or a positive number, got {}", short(v)))) }
}

/// Positive and at most `max` (`why` says what the bound is).
pub fn positive_at_most(key: &str, v: f64, max: f64, why: &str) -> Result<f64, Invalid> {
    positive(key, v)?;
    if v > max {
        return Err(invalid(key, format!("{key} = {} is more than {} ({why})", short(v), short(max))));
    }
    Ok(v)
}

