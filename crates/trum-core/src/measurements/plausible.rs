//! Plausible ranges of the measured columns: a second check after the layout's own ranges
//! (`> 0`, `>= 0`, a fraction), which every finite value of the right sign passes. A
//! speed of 10^5 rev/min, a preload of 1e308 N or 5e-324 N fits the layout but no bench of
//! a traveling-wave ultrasonic motor; fitted anyway, one such row dominates every sum of
//! squares and the diagnosis names an effect with confidence from nothing. The defaults
//! are [`super::ColumnSpec::plausible`]; each can be replaced or lifted.

use super::{Column, COLUMNS};

/// A plausible range, inclusive, per numeric column.
#[derive(Debug, Clone, PartialEq)]
pub struct PlausibleRanges {
    ranges: [(f64, f64); COLUMNS.len()],
}

impl Default for PlausibleRanges {
    fn default() -> Self {
        let mut ranges = [(f64::NEG_INFINITY, f64::INFINITY); COLUMNS.len()];
        for (r, c) in ranges.iter_mut().zip(COLUMNS.iter()) {
            *r = c.plausible;
        }
        PlausibleRanges { ranges }
    }
}

impl PlausibleRanges {
    /// No plausibility check at all (the layout's ranges still apply).
    pub fn unlimited() -> Self {
        PlausibleRanges { ranges: [(f64::NEG_INFINITY, f64::INFINITY); COLUMNS.len()] }
    }

    /// The range of `column`, in its unit.
    pub fn get(&self, column: Column) -> (f64, f64) {
        self.ranges[column as usize]
    }

    /// Replaces the range of `column` (either end may be infinite: no bound there).
    pub fn set(&mut self, column: Column, low: f64, high: f64) {
        self.ranges[column as usize] = (low, high);
    }

    /// Whether `value` of `column` is plausible.
    pub fn contains(&self, column: Column, value: f64) -> bool {
        let (lo, hi) = self.get(column);
        value >= lo && value <= hi
    }

    /// Applies `COLUMN=LOW:HIGH` (either end may be left empty: no bound there) or
    /// `COLUMN=any` (no bound at all). The error says what is wrong, naming the column.
    pub fn parse_assignment(&mut self, spec: &str) -> Result<(), String> {
        let (name, range) =
            spec.split_once('=').ok_or_else(|| "expected COLUMN=LOW:HIGH (or COLUMN=any)".to_string())?;
        let name = name.trim();
        let column = Column::from_name(name).filter(|c| c.is_numeric()).ok_or_else(|| {
            let names: Vec<&str> = COLUMNS.iter().filter(|c| c.column.is_numeric()).map(|c| c.name).collect();
            format!("'{name}' is not a numeric measurement column; valid columns are: {}", names.join(", "))
        })?;
        let range = range.trim();
        if range.eq_ignore_ascii_case("any") {
            self.set(column, f64::NEG_INFINITY, f64::INFINITY);
            return Ok(());
        }
        let (lo, hi) = range.split_once(':').ok_or_else(|| format!("{name}: expected LOW:HIGH, got '{range}'"))?;
        let bound = |t: &str, open: f64| -> Result<f64, String> {
            let t = t.trim();
            if t.is_empty() {
                return Ok(open);
            }
            match t.parse::<f64>() {
                Ok(v) if v.is_finite() => Ok(v),
                _ => Err(format!("{name}: '{t}' is not a finite number (leave an end empty for no bound)")),
            }
        };
        let (lo, hi) = (bound(lo, f64::NEG_INFINITY)?, bound(hi, f64::INFINITY)?);
        if lo > hi {
            return Err(format!("{name}: the low end {lo} is above the high end {hi}"));
        }
        self.set(column, lo, hi);
        Ok(())
    }
}

/// `0 to 10000 rev/min`, `at most 1000 N·m`, ...
pub(super) fn describe(column: Column, (lo, hi): (f64, f64)) -> String {
    let unit = column.spec().unit;
    let unit = if unit.is_empty() { String::new() } else { format!(" {unit}") };
    match (lo.is_finite(), hi.is_finite()) {
        (true, true) => format!("{lo} to {hi}{unit}"),
        (true, false) => format!("at least {lo}{unit}"),
        (false, true) => format!("at most {hi}{unit}"),
        (false, false) => "any value".into(),
    }
}

/// The `[plausible]` table of a motor file: a plausible range per measured column, as
/// `speed_rpm = [0, 20000]` (inclusive; `inf` or `-inf` for no bound at that end) or
/// `speed_rpm = "any"` (no check). Unknown keys are refused by serde, naming the key and
/// the valid ones; the values are checked by [`PlausibleTable::apply`]. Every numeric
/// column of [`COLUMNS`] is a field (a test keeps the two in step).
#[derive(Debug, Default, serde::Deserialize)]
#[serde(deny_unknown_fields)]
pub(crate) struct PlausibleTable {
    preload_n: Option<toml::Value>,
    voltage_v: Option<toml::Value>,
    frequency_hz: Option<toml::Value>,
    torque_nm: Option<toml::Value>,
    speed_rpm: Option<toml::Value>,
    input_power_w: Option<toml::Value>,
    current_a: Option<toml::Value>,
    efficiency: Option<toml::Value>,
    feedback_v: Option<toml::Value>,
    temperature_c: Option<toml::Value>,
    ambient_c: Option<toml::Value>,
    elapsed_s: Option<toml::Value>,
    speed_std_rpm: Option<toml::Value>,
}

impl PlausibleTable {
    fn entries(&self) -> [(&'static str, &Option<toml::Value>); 13] {
        [
            ("preload_n", &self.preload_n),
            ("voltage_v", &self.voltage_v),
            ("frequency_hz", &self.frequency_hz),
            ("torque_nm", &self.torque_nm),
            ("speed_rpm", &self.speed_rpm),
            ("input_power_w", &self.input_power_w),
            ("current_a", &self.current_a),
            ("efficiency", &self.efficiency),
            ("feedback_v", &self.feedback_v),
            ("temperature_c", &self.temperature_c),
            ("ambient_c", &self.ambient_c),
            ("elapsed_s", &self.elapsed_s),
            ("speed_std_rpm", &self.speed_std_rpm),
        ]
    }

    /// Replaces the ranges of `ranges` the table sets. `err(key, reason)` builds the error
    /// for a bad value (the caller knows the file and finds the key's line).
    pub(crate) fn apply<E>(&self, ranges: &mut PlausibleRanges, err: impl Fn(&str, String) -> E) -> Result<(), E> {
        for (name, value) in self.entries() {
            let Some(value) = value else { continue };
            let column = Column::from_name(name).filter(|c| c.is_numeric()).ok_or_else(|| {
                err(name, "not a numeric measurement column (a bug: the table and the column list disagree)".into())
            })?;
            let (lo, hi) = range_of_value(value).map_err(|m| err(name, m))?;
            ranges.set(column, lo, hi);
        }
        Ok(())
    }
}

/// `[LOW, HIGH]` or `"any"` as a range; the message says what the key accepts.
fn range_of_value(value: &toml::Value) -> Result<(f64, f64), String> {
    const EXPECTED: &str = "expected [LOW, HIGH] (inclusive; inf or -inf for no bound at an end) or \"any\"";
    let number = |v: &toml::Value| match v {
        toml::Value::Integer(i) => Some(*i as f64),
        toml::Value::Float(x) => Some(*x),
        _ => None,
    };
    match value {
        toml::Value::String(s) if s.trim().eq_ignore_ascii_case("any") => Ok((f64::NEG_INFINITY, f64::INFINITY)),
        toml::Value::Array(a) if a.len() == 2 => {
            let (Some(lo), Some(hi)) = (number(&a[0]), number(&a[1])) else {
                return Err(format!("{EXPECTED}, got {value}"));
            };
            if lo.is_nan() || hi.is_nan() {
                return Err("nan is not a bound (inf or -inf for no bound at an end)".into());
            }
            if lo > hi {
                return Err(format!("the low end {lo} is above the high end {hi}"));
            }
            if lo == f64::INFINITY || hi == f64::NEG_INFINITY {
                return Err(format!("[{lo}, {hi}] holds no number"));
            }
            Ok((lo, hi))
        }
        _ => Err(format!("{EXPECTED}, got {value}")),
    }
}
