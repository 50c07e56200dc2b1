//! Reading and writing numbers in TOML text, and finding the line of a key or offset for
//! error messages: shared by the motor file (`params`) and the effects' tables (`effects`).

use serde::de::{self, Deserializer, Visitor};
use serde::Deserialize;

/// A number that may be written as a TOML integer or float.
#[derive(Clone, Copy, Debug)]
pub(crate) struct Num(pub f64);

impl<'de> Deserialize<'de> for Num {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        struct V;
        impl Visitor<'_> for V {
            type Value = Num;
            fn expecting(&self, f: &mut std::fmt::Formatter) -> std::fmt::Result {
                f.write_str("a number")
            }
            fn visit_f64<E: de::Error>(self, v: f64) -> Result<Num, E> {
                Ok(Num(v))
            }
            fn visit_i64<E: de::Error>(self, v: i64) -> Result<Num, E> {
                Ok(Num(v as f64))
            }
            fn visit_u64<E: de::Error>(self, v: u64) -> Result<Num, E> {
                Ok(Num(v as f64))
            }
        }
        d.deserialize_any(V)
    }
}

/// 1-based line of `key` inside `[section]` (or a dotted/inline form) in TOML text.
/// Used only to point error messages at the right line; `None` when not found.
pub(crate) fn line_of_key(text: &str, section: &str, key: &str) -> Option<usize> {
    let mut current = String::new();
    for (i, raw) in text.lines().enumerate() {
        let line = raw.trim();
        if let Some(h) = line.strip_prefix('[') {
            current = h.trim_end_matches(']').trim().trim_end_matches(']').trim().to_string();
            if !section.is_empty() && current == format!("{section}.{key}") {
                return Some(i + 1);
            }
            continue;
        }
        // a quoted key (`"geometry.mean_radius_m" = ...`) names the same dotted path
        let lhs = line.split('=').next().unwrap_or("").trim().trim_matches(|c| c == '"' || c == '\'');
        let full = if current.is_empty() { lhs.to_string() } else { format!("{current}.{lhs}") };
        let want = if section.is_empty() { key.to_string() } else { format!("{section}.{key}") };
        if full == want || (current.is_empty() && lhs == want) {
            return Some(i + 1);
        }
    }
    None
}

/// 1-based line number of a byte offset.
pub(crate) fn line_of_offset(text: &str, offset: usize) -> usize {
    text.as_bytes()[..offset.min(text.len())].iter().filter(|&&b| b == b'\n').count() + 1
}

/// A TOML float or integer literal that reads back bit-identical.
pub(crate) fn fmt_toml_number(v: f64, integer: bool) -> String {
    if integer && v.fract() == 0.0 && v.abs() < 1e15 {
        return format!("{}", v as i64);
    }
    // `{:?}` gives the shortest representation that round-trips; make sure it reads as a float.
    let s = format!("{v:?}");
    if s.contains('.') || s.contains('e') || s.contains("inf") || s.contains("NaN") {
        s
    } else {
        format!("{s}.0")
    }
}
