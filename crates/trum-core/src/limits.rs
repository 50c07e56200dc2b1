//! Physical limits of a motor and the warnings of a solved point that exceeds them.
//!
//! The model solves any operating point it is given, including ones no real motor
//! survives (a steady temperature rise of thousands of kelvin, a drive far above the
//! depoling field of the piezoceramic). Every solved point therefore carries
//! [`LimitWarnings`]: the `[limits]` keys of the motor file it exceeds. The check is a few
//! comparisons per point; it never changes the solved numbers or the status.
//!
//! Default limits of the piezoceramic traveling-wave ring motor
//! ([`Limits::piezoceramic_ring`]; sources in docs/MOTOR_FILE.md):
//! - `max_voltage_v` = 300 V zero-to-peak: the highest drive the Hertzian driving-circuit
//!   paper (2022) applied to a 60 mm TRUM (600 Vpp), where its nonlinearity soars;
//! - `max_amplitude_m` = 5 µm: about three times the 1.2-1.4 µm that Sun et al. 2021
//!   Table 2 measured on the TRUM-60 (feedback voltage over conversion factor); assumed;
//! - `max_stator_temperature_c` = 150 °C: half the Curie temperature of PZT-8 (about
//!   300 °C), the usual limit for continuous operation without depoling;
//! - `max_input_power_w` = inf (no limit: set it to the driver's rating).

use crate::params::Limits;
use crate::solve::{OperatingPoint, Solution};

/// The limit keys in bit order of [`LimitWarnings`] (the order of the `[limits]` table).
pub const LIMIT_KEYS: [&str; 4] = ["max_voltage_v", "max_amplitude_m", "max_stator_temperature_c", "max_input_power_w"];

/// The set of limits one solved point exceeds (a bit per [`LIMIT_KEYS`] entry).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub struct LimitWarnings(u8);

impl LimitWarnings {
    /// No limit exceeded.
    pub const NONE: LimitWarnings = LimitWarnings(0);

    /// The bits (bit i: [`LIMIT_KEYS`]\[i\] exceeded); Python's `warning_code` arrays.
    pub fn bits(self) -> u8 {
        self.0
    }

    /// The set with these bits (bits beyond [`LIMIT_KEYS`] are dropped).
    pub fn from_bits(bits: u8) -> LimitWarnings {
        LimitWarnings(bits & ((1 << LIMIT_KEYS.len()) - 1))
    }

    /// True when no limit is exceeded.
    pub fn is_empty(self) -> bool {
        self.0 == 0
    }

    /// True when the limit `key` (one of [`LIMIT_KEYS`]) is exceeded.
    pub fn contains(self, key: &str) -> bool {
        LIMIT_KEYS.iter().position(|k| *k == key).is_some_and(|i| self.0 & (1 << i) != 0)
    }

    /// The union of two sets.
    pub fn union(self, other: LimitWarnings) -> LimitWarnings {
        LimitWarnings(self.0 | other.0)
    }

    /// The exceeded limit keys, in [`LIMIT_KEYS`] order.
    pub fn keys(self) -> impl Iterator<Item = &'static str> {
        LIMIT_KEYS.iter().enumerate().filter(move |(i, _)| self.0 & (1 << i) != 0).map(|(_, k)| *k)
    }

    fn with(self, i: usize, on: bool) -> LimitWarnings {
        if on {
            LimitWarnings(self.0 | (1 << i))
        } else {
            self
        }
    }
}

/// The keys joined by `;` (empty when none): the `warnings` CSV cell.
impl std::fmt::Display for LimitWarnings {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        for (j, k) in self.keys().enumerate() {
            if j > 0 {
                f.write_str(";")?;
            }
            f.write_str(k)?;
        }
        Ok(())
    }
}

/// The quantities a point is checked on, each against its `[limits]` key.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LimitedQuantities {
    /// Drive voltage amplitude per phase, zero-to-peak [V] (the set voltage).
    pub voltage_v: f64,
    /// Wave amplitude at the contact surface [m].
    pub amplitude_m: f64,
    /// Motor temperature [°C]: ambient plus the temperature rise the check is about.
    pub stator_temperature_c: f64,
    /// Electrical input power, both phases [W].
    pub input_power_w: f64,
}

impl LimitedQuantities {
    /// The quantities of a solved steady point: the set voltage, the amplitude, ambient
    /// plus the steady temperature rise (Chen et al. 2020 eq. 11 at t → ∞: a point run
    /// continuously reaches it) and the input power. For a point without a valid steady
    /// state only the voltage is known (the rest NaN, never exceeded).
    pub fn of_point(ambient_c: f64, op: &OperatingPoint, s: &Solution) -> LimitedQuantities {
        let valid = s.status.is_valid();
        let or_nan = |v: f64| if valid { v } else { f64::NAN };
        LimitedQuantities {
            voltage_v: op.voltage_v,
            amplitude_m: or_nan(s.amplitude_m),
            stator_temperature_c: or_nan(ambient_c + s.temperature_rise_k),
            input_power_w: or_nan(s.input_power_w),
        }
    }

    fn values(&self) -> [f64; 4] {
        [self.voltage_v, self.amplitude_m, self.stator_temperature_c, self.input_power_w]
    }
}

impl Limits {
    /// Defaults of the piezoceramic traveling-wave ring motor class (module docs give the
    /// source of each): 300 V, 5 µm, 150 °C, no input-power limit.
    pub fn piezoceramic_ring() -> Limits {
        Limits {
            max_voltage_v: 300.0,
            max_amplitude_m: 5e-6,
            max_stator_temperature_c: 150.0,
            max_input_power_w: f64::INFINITY,
        }
    }

    fn maxima(&self) -> [f64; 4] {
        [self.max_voltage_v, self.max_amplitude_m, self.max_stator_temperature_c, self.max_input_power_w]
    }

    /// The limits `q` exceeds (strictly above the limit; NaN never exceeds).
    pub fn check(&self, q: &LimitedQuantities) -> LimitWarnings {
        q.values()
            .iter()
            .zip(self.maxima())
            .enumerate()
            .fold(LimitWarnings::NONE, |w, (i, (v, max))| w.with(i, *v > max))
    }

    /// The limits a solved steady point exceeds ([`LimitedQuantities::of_point`]).
    pub fn check_point(&self, ambient_c: f64, op: &OperatingPoint, s: &Solution) -> LimitWarnings {
        self.check(&LimitedQuantities::of_point(ambient_c, op, s))
    }

    /// One sentence per exceeded limit, with the value and the limit:
    /// `stator temperature 2530 °C exceeds limits.max_stator_temperature_c = 150 °C`.
    pub fn describe(&self, q: &LimitedQuantities, w: LimitWarnings) -> Vec<String> {
        const WHAT: [(&str, &str, f64); 4] = [
            ("drive voltage", "V", 1.0),
            ("amplitude", "µm", 1e6),
            ("steady stator temperature", "°C", 1.0),
            ("input power", "W", 1.0),
        ];
        let (vals, maxs) = (q.values(), self.maxima());
        (0..LIMIT_KEYS.len())
            .filter(|&i| w.bits() & (1 << i) != 0)
            .map(|i| {
                let (what, unit, scale) = WHAT[i];
                format!(
                    "{what} {} {unit} exceeds limits.{} = {} {unit}",
                    sig(vals[i] * scale),
                    LIMIT_KEYS[i],
                    sig(maxs[i] * scale)
                )
            })
            .collect()
    }
}

/// Four significant digits, no exponent for the magnitudes of the limits.
fn sig(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return format!("{v}");
    }
    let digits = (3 - v.abs().log10().floor() as i32).max(0) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::solve::Status;

    fn q(voltage_v: f64, amplitude_m: f64, stator_temperature_c: f64, input_power_w: f64) -> LimitedQuantities {
        LimitedQuantities { voltage_v, amplitude_m, stator_temperature_c, input_power_w }
    }

    #[test]
    fn each_limit_warns_only_beyond_itself() {
        let l = Limits { max_input_power_w: 50.0, ..Limits::piezoceramic_ring() };
        let inside = q(299.0, 4.9e-6, 149.0, 49.0);
        assert!(l.check(&inside).is_empty());
        // exactly at a limit is inside
        assert!(l.check(&q(300.0, 5e-6, 150.0, 50.0)).is_empty());
        let beyond =
            [q(301.0, 0.0, 0.0, 0.0), q(0.0, 5.1e-6, 0.0, 0.0), q(0.0, 0.0, 151.0, 0.0), q(0.0, 0.0, 0.0, 51.0)];
        for (i, b) in beyond.iter().enumerate() {
            let w = l.check(b);
            assert_eq!(w.keys().collect::<Vec<_>>(), vec![LIMIT_KEYS[i]], "{b:?}");
            assert!(w.contains(LIMIT_KEYS[i]));
            let text = l.describe(b, w);
            assert_eq!(text.len(), 1);
            assert!(text[0].contains(&format!("limits.{}", LIMIT_KEYS[i])), "{}", text[0]);
        }
        let all = l.check(&q(400.0, 1e-5, 2530.0, 600.0));
        assert_eq!(all.to_string(), LIMIT_KEYS.join(";"));
        assert_eq!(LimitWarnings::from_bits(all.bits()), all);
        assert_eq!(LimitWarnings::from_bits(0xff), all);
        // NaN (a point without valid numbers) never exceeds; inf switches a limit off
        assert!(l.check(&q(f64::NAN, f64::NAN, f64::NAN, f64::NAN)).is_empty());
        assert!(Limits::piezoceramic_ring().check(&q(0.0, 0.0, 0.0, 1e9)).is_empty());
        assert_eq!(
            l.describe(&q(0.0, 0.0, 2530.0, 0.0), LimitWarnings::from_bits(4)),
            vec!["steady stator temperature 2530 °C exceeds limits.max_stator_temperature_c = 150 °C".to_string()]
        );
        assert_eq!(
            l.describe(&q(0.0, 6.4817e-6, 0.0, 0.0), LimitWarnings::from_bits(2)),
            vec!["amplitude 6.482 µm exceeds limits.max_amplitude_m = 5 µm".to_string()]
        );
    }

    #[test]
    fn a_point_is_checked_on_its_steady_temperature_and_an_invalid_one_on_its_voltage_only() {
        let op = OperatingPoint::new(250.0, 0.0, 350.0, 42e3);
        let mut s = Solution::invalid(Status::NoConvergence);
        s.temperature_rise_k = 1e4;
        let l = Limits::piezoceramic_ring();
        assert_eq!(l.check_point(28.0, &op, &s).to_string(), "max_voltage_v");
        s.status = Status::Ok;
        s.amplitude_m = 1e-6;
        s.input_power_w = 10.0;
        s.temperature_rise_k = 121.0;
        assert_eq!(l.check_point(28.0, &op, &s).to_string(), "max_voltage_v");
        s.temperature_rise_k = 123.0;
        assert_eq!(l.check_point(28.0, &op, &s).to_string(), "max_voltage_v;max_stator_temperature_c");
    }

    #[test]
    fn the_limits_table_parses_defaults_and_names_a_bad_key_or_value() {
        use crate::params::Motor;
        let m = Motor::from_toml_str(
            "preset = \"generic60\"\n[limits]\nmax_voltage_v = 250\nmax_input_power_w = 40\n",
            "m.toml",
        )
        .expect("valid limits");
        assert_eq!(m.limits.max_voltage_v, 250.0);
        assert_eq!(m.limits.max_input_power_w, 40.0);
        // keys not given keep the preset's
        assert_eq!(m.limits.max_stator_temperature_c, 150.0);
        let e = Motor::from_toml_str("preset = \"generic60\"\n[limits]\nmax_voltage = 250\n", "m.toml")
            .expect_err("unknown key");
        assert_eq!((e.key.as_str(), e.line), ("limits.max_voltage", Some(3)), "{e}");
        let e = Motor::from_toml_str("preset = \"generic60\"\n[limits]\nmax_amplitude_m = -1e-6\n", "m.toml")
            .expect_err("negative limit");
        assert_eq!((e.key.as_str(), e.line), ("limits.max_amplitude_m", Some(3)), "{e}");
        assert!(e.reason.contains("> 0"), "{e}");
        // inf switches a limit off, and the motor file writer reads back
        let m = Motor::from_toml_str("preset = \"generic60\"\n[limits]\nmax_voltage_v = inf\n", "m.toml").expect("inf");
        assert!(m.limits.max_voltage_v.is_infinite());
        assert_eq!(Motor::from_toml_str(&m.to_toml(), "back").expect("round trip"), m);
        // a complete file without [limits] takes the class defaults
        let frozen = crate::presets::frozen("trum60a").expect("frozen motor");
        assert_eq!(frozen.limits, Limits::piezoceramic_ring());
        // a point beyond each limit warns, one inside does not
        let solve = |m: &Motor, v: f64, f: f64| crate::solve(m, &OperatingPoint::new(250.0, 0.0, v, f));
        let g = crate::presets::preset("generic60").expect("preset");
        let inside = solve(&g, 200.0, 43e3);
        assert_eq!(inside.status, crate::Status::Ok);
        assert!(inside.warnings.is_empty(), "{}", inside.warnings);
        let hot = solve(&g, 200.0, 40e3);
        assert!(hot.temperature_rise_k + 25.0 > 150.0 && hot.amplitude_m > 5e-6);
        assert_eq!(hot.warnings.to_string(), "max_amplitude_m;max_stator_temperature_c");
        let high = solve(&g, 350.0, 43e3);
        assert!(high.warnings.contains("max_voltage_v"), "{}", high.warnings);
        let mut capped = g.clone();
        capped.limits.max_input_power_w = 0.5 * inside.input_power_w;
        assert_eq!(solve(&capped, 200.0, 43e3).warnings.to_string(), "max_input_power_w");
        // the warnings do not touch the numbers
        assert_eq!(Solution { warnings: LimitWarnings::NONE, ..solve(&capped, 200.0, 43e3) }, inside);
    }
}
