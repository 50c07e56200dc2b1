//! The writer: [`Measurements`] in the layout of docs/MEASUREMENTS.md, read back identically by
//! [`super::parse_measurements`].

use super::{Column, Measurements};

impl Measurements {
    /// The data in that layout: a header of the present columns in layout
    /// order, one line per row, `\n` line ends. Numbers are written in their shortest
    /// form that reads back to the same `f64`; empty optional cells stay empty; `run_id`
    /// is quoted when it holds a comma, a quote or surrounding whitespace. Extra columns
    /// are not written. Cells missing from a column shorter than `preload_n` are written
    /// empty.
    pub fn to_csv_string(&self) -> String {
        let cols = self.columns();
        let mut out = String::new();
        let names: Vec<&str> = cols.iter().map(|c| c.name()).collect();
        out.push_str(&names.join(","));
        out.push('\n');
        for row in 0..self.len() {
            for (i, &c) in cols.iter().enumerate() {
                if i > 0 {
                    out.push(',');
                }
                if c == Column::RunId {
                    if let Some(t) = self.run_id_at(row) {
                        out.push_str(&quote_text(t));
                    }
                } else if let Some(v) = self.value(c, row) {
                    out.push_str(&format_number(v));
                }
            }
            out.push('\n');
        }
        out
    }
}

/// Shortest text that reads back to the same `f64`: positional for ordinary magnitudes,
/// exponent form (`1.5e-7`) for very small or very large ones.
pub(super) fn format_number(v: f64) -> String {
    let a = v.abs();
    if a == 0.0 || (1e-4..1e15).contains(&a) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// A text cell, quoted (with doubled quotes) when it would not read back as written.
fn quote_text(t: &str) -> String {
    let needs = t.contains([',', '"', '\r', '\n']) || t.trim() != t || t.is_empty();
    if needs {
        format!("\"{}\"", t.replace('"', "\"\""))
    } else {
        t.to_string()
    }
}
