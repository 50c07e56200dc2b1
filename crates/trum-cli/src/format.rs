//! Numbers and units as the commands print them.

/// The unit of an input column or output quantity, if known.
pub fn unit_of(name: &str) -> Option<&'static str> {
    match name {
        "preload_n" => Some("N"),
        "torque_nm" => Some("N·m"),
        "voltage_v" => Some("V"),
        "frequency_hz" => Some("Hz"),
        "elapsed_s" | "time_s" => Some("s"),
        "position_m" => Some("m"),
        "tangential_force_n_per_m" => Some("N/m"),
        "score" => Some("-"),
        "max_efficiency" => Some("-"),
        "torque_at_max_efficiency_nm" => Some("N·m"),
        "no_load_speed_rpm" => Some("rpm"),
        _ => trum_core::quantities::QUANTITIES.iter().find(|q| q.name == name).map(|q| q.unit),
    }
}

/// A CSV/JSON-friendly number: Rust's shortest round-trip digits, empty when not finite;
/// plain decimals for magnitudes in [1e-5, 1e16) (and zero), exponent form outside it
/// (`1e23`, `1.5e-9`), so that no cell is a run of zeros.
pub fn csv_number(v: f64) -> String {
    if !v.is_finite() {
        String::new()
    } else if v == 0.0 || (PLAIN_MIN..PLAIN_MAX).contains(&v.abs()) {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Magnitudes written in plain decimals by [`csv_number`]: at most 5 leading zeros after
/// the point, at most 16 digits before it.
pub const PLAIN_MIN: f64 = 1e-5;
/// See [`PLAIN_MIN`].
pub const PLAIN_MAX: f64 = 1e16;

/// Rounds to `sig` significant digits.
pub fn round_sig(v: f64, sig: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let p = 10f64.powi(sig - 1 - v.abs().log10().floor() as i32);
    (v * p).round() / p
}

/// A readable number with `sig` significant digits (fixed notation for magnitudes in
/// [1e-3, 1e6), exponent form otherwise); `-` when not finite.
pub fn fmt_sig(v: f64, sig: usize) -> String {
    if !v.is_finite() {
        return "-".into();
    }
    if v == 0.0 {
        return "0".into();
    }
    let mag = v.abs().log10().floor() as i32;
    if (-3..6).contains(&mag) {
        let decimals = (sig as i32 - 1 - mag).max(0) as usize;
        let s = format!("{v:.decimals$}");
        // rounding can carry into a new digit (999.9995 → 1000.000); that is harmless here
        if s.contains('.') {
            s.trim_end_matches('0').trim_end_matches('.').to_string()
        } else {
            s
        }
    } else {
        let s = format!("{v:.prec$e}", prec = sig.saturating_sub(1));
        // trim trailing zeros of the mantissa: 1.50000e-9 → 1.5e-9
        match s.split_once('e') {
            Some((m, e)) if m.contains('.') => format!("{}e{e}", m.trim_end_matches('0').trim_end_matches('.')),
            _ => s,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn significant_digits() {
        assert_eq!(fmt_sig(95.123456, 6), "95.1235");
        assert_eq!(fmt_sig(43000.0, 6), "43000");
        assert_eq!(fmt_sig(5.41e-9, 6), "5.41e-9");
        assert_eq!(fmt_sig(-0.25, 6), "-0.25");
        assert_eq!(fmt_sig(f64::NAN, 6), "-");
        assert_eq!(csv_number(f64::NAN), "");
        assert_eq!(csv_number(0.1), "0.1");
        assert_eq!(csv_number(1e23), "1e23");
        assert_eq!(csv_number(-2.5e-9), "-2.5e-9");
        assert_eq!(csv_number(43000.0), "43000");
        assert_eq!(csv_number(0.0), "0");
        assert_eq!(round_sig(0.7345, 2), 0.73);
    }
}
