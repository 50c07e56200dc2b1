//! The measured-input efficiency estimator of Sun et al. 2021: contact variables, losses
//! and efficiency from the *measured* preload and feedback-electrode voltage, on line,
//! instead of from a simulated amplitude.
//!
//! Per measurement row (preload F_N, drive voltage V and frequency f, load torque T,
//! feedback voltage V_f):
//! 1. the wave amplitude W = V_f / K_WV (Sun et al. 2021 eq. 1 with K_WV the motor's
//!    `electrical.feedback_gain_v_per_m`, trum's amplitude convention: the feedback voltage
//!    amplitude is K_WV·W, [`crate::stator::feedback_voltage_v`]);
//! 2. the contact zone from F_N at that amplitude (eq. 5, 9), the stick (driving) zone from
//!    the torque balance at T (eq. 10-11), the rotor speed from the stick point (eq. 12-13);
//! 3. every loss at that state: dielectric (eq. 15-16), stator damping (eq. 17 in trum's
//!    modal form c·ω²·W²), friction (eq. 22-26 in trum's Coulomb form), rotor viscous;
//! 4. output power T·Ω and the efficiency as the energy balance of eq. 27-30:
//!    η = P_out / (P_out + P_dielectric + P_damping + P_friction + P_rotor).
//!
//! No amplitude is solved: one contact and one stick-angle solve per row
//! ([`crate::solve::solve_at_amplitude`]), well under a microsecond (docs/PERFORMANCE.md).
//! The conventional model it is compared with is [`crate::solve`], whose amplitude is the
//! model's own (docs/ESTIMATE.md).

use crate::error::TrumError;
use crate::limits::{LimitWarnings, LimitedQuantities};
use crate::params::Motor;
use crate::solve::{solve_at_amplitude, OperatingPoint, Prepared, Status, RAD_S_TO_RPM};

/// One measurement row: the inputs of the estimator.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MeasuredPoint {
    /// Measured axial preload [N], > 0.
    pub preload_n: f64,
    /// Drive voltage amplitude per phase, zero-to-peak [V], > 0.
    pub voltage_v: f64,
    /// Drive frequency [Hz], > 0.
    pub frequency_hz: f64,
    /// Load torque [N·m], ≥ 0.
    pub torque_nm: f64,
    /// Feedback-electrode voltage amplitude [V], ≥ 0; `None` when not measured.
    pub feedback_v: Option<f64>,
    /// Measured rotor speed [rev/min], if any (only compared with the estimate).
    pub speed_rpm: Option<f64>,
}

/// Whether a row's reading admits a physical contact state.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EstimateStatus {
    /// A contact state with the rotor turning.
    Ok,
    /// The load torque is at or above the drive the measured amplitude gives: the rotor
    /// at rest (speed and output power zero, losses valid).
    Stall,
    /// The reading admits no contact state of a travelling wave: a zero feedback voltage
    /// (no wave) under a preload, or numbers that do not come out finite. Numbers withheld.
    NoContactState,
    /// The row has no feedback voltage: nothing to estimate from. Numbers withheld.
    NoFeedback,
    /// The row's operating point is invalid (non-finite, preload ≤ 0, ...).
    InvalidInput,
}

impl EstimateStatus {
    /// Every status, in code order (Python's `status_code` indexes [`Self::NAMES`]).
    pub const ALL: [EstimateStatus; 5] = [
        EstimateStatus::Ok,
        EstimateStatus::Stall,
        EstimateStatus::NoContactState,
        EstimateStatus::NoFeedback,
        EstimateStatus::InvalidInput,
    ];
    /// The status words in code order.
    pub const NAMES: [&'static str; 5] = ["ok", "stall", "no_contact_state", "no_feedback", "invalid_input"];

    /// The word written in status columns.
    pub fn as_str(self) -> &'static str {
        Self::NAMES[self.code() as usize]
    }

    /// The index in [`Self::ALL`].
    pub fn code(self) -> u8 {
        match self {
            EstimateStatus::Ok => 0,
            EstimateStatus::Stall => 1,
            EstimateStatus::NoContactState => 2,
            EstimateStatus::NoFeedback => 3,
            EstimateStatus::InvalidInput => 4,
        }
    }

    /// True when the numbers describe a contact state.
    pub fn is_valid(self) -> bool {
        matches!(self, EstimateStatus::Ok | EstimateStatus::Stall)
    }
}

/// The estimate of one row (SI, unit in each name). Numbers are NaN where the status is
/// not valid.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Estimate {
    /// Whether the reading admits a contact state.
    pub status: EstimateStatus,
    /// True when the rotor touches the whole wave at this amplitude and preload.
    pub full_contact: bool,
    /// Wave amplitude implied by the feedback voltage, W = V_f/K_WV [m].
    pub amplitude_m: f64,
    /// Contact half-angle φ0 in wave phase [rad].
    pub contact_half_angle_rad: f64,
    /// Contact angle, full arc in mechanical degrees.
    pub contact_angle_deg: f64,
    /// Contact length per wave 2·x0 [m].
    pub contact_length_m: f64,
    /// Stick (driving-zone) half-angle θs in wave phase [rad].
    pub stick_half_angle_rad: f64,
    /// Driving angle, full arc in mechanical degrees.
    pub driving_angle_deg: f64,
    /// Driving-zone length per wave 2·x_r [m].
    pub driving_length_m: f64,
    /// Proportion of the driving zone in the contact zone θs/φ0 [-].
    pub driving_ratio: f64,
    /// Rotor speed the contact state implies [rev/min].
    pub speed_rpm: f64,
    /// Measured minus estimated speed [rev/min] (NaN without a measured speed).
    pub speed_residual_rpm: f64,
    /// Stall torque at this amplitude and preload [N·m].
    pub stall_torque_nm: f64,
    /// Dielectric loss, both phases [W].
    pub dielectric_loss_w: f64,
    /// Stator damping loss [W].
    pub damping_loss_w: f64,
    /// Friction loss in the contact [W].
    pub friction_loss_w: f64,
    /// Of which radial slip (with `radial_friction`) [W].
    pub radial_friction_loss_w: f64,
    /// Rotor viscous loss [W].
    pub rotor_loss_w: f64,
    /// Output power T·Ω [W].
    pub output_power_w: f64,
    /// Input power as the energy balance: output plus every loss [W].
    pub input_power_w: f64,
    /// Output over input power [-].
    pub efficiency: f64,
    /// The motor's `[limits]` the state exceeds (voltage, amplitude, ambient plus the
    /// steady rise of these losses, input power).
    pub warnings: LimitWarnings,
}

/// The estimator of one motor: its constants, computed once.
#[derive(Clone, Debug)]
pub struct Estimator {
    motor: Motor,
    prepared: Prepared,
    gain_v_per_m: f64,
}

impl Estimator {
    /// The estimator of `motor`. Its feedback gain `electrical.feedback_gain_v_per_m` must
    /// be > 0 (the amplitude is read through it); the error names the key.
    pub fn new(motor: &Motor) -> Result<Estimator, TrumError> {
        let g = motor.electrical.feedback_gain_v_per_m;
        if !(g.is_finite() && g > 0.0) {
            return Err(TrumError::input(format!(
                "electrical.feedback_gain_v_per_m = {g}: the estimator reads the amplitude through the feedback gain, which must be > 0"
            )));
        }
        Ok(Estimator { motor: motor.clone(), prepared: Prepared::new(motor), gain_v_per_m: g })
    }

    /// The motor.
    pub fn motor(&self) -> &Motor {
        &self.motor
    }

    /// The estimate of one row (module docs). Never panics.
    pub fn estimate(&self, m: &MeasuredPoint) -> Estimate {
        let op = OperatingPoint::new(m.preload_n, m.torque_nm, m.voltage_v, m.frequency_hz);
        let measured_speed = m.speed_rpm.unwrap_or(f64::NAN);
        if op.invalid_reason().is_some() || m.feedback_v.is_some_and(|v| !(v.is_finite() && v >= 0.0)) {
            return withheld(EstimateStatus::InvalidInput);
        }
        let Some(vf) = m.feedback_v else { return withheld(EstimateStatus::NoFeedback) };
        let w = vf / self.gain_v_per_m;
        let s = solve_at_amplitude(&self.prepared, &op, w);
        let status = match s.status {
            Status::Ok => EstimateStatus::Ok,
            Status::Stall => EstimateStatus::Stall,
            Status::InvalidInput => EstimateStatus::InvalidInput,
            _ => EstimateStatus::NoContactState,
        };
        if !status.is_valid() {
            return Estimate { amplitude_m: w, ..withheld(status) };
        }
        let losses = s.dielectric_loss_w + s.damping_loss_w + s.friction_loss_w + s.rotor_loss_w;
        let input = s.output_power_w + losses;
        let efficiency = if input > 0.0 { s.output_power_w / input } else { 0.0 };
        let rise_k =
            losses / (self.motor.thermal.heat_transfer_coefficient_w_per_m2k * self.motor.thermal.surface_area_m2);
        let warnings = self.motor.limits.check(&LimitedQuantities {
            voltage_v: m.voltage_v,
            amplitude_m: w,
            stator_temperature_c: self.motor.thermal.ambient_c + rise_k,
            input_power_w: input,
        });
        Estimate {
            status,
            full_contact: s.full_contact,
            amplitude_m: w,
            contact_half_angle_rad: s.contact_half_angle_rad,
            contact_angle_deg: s.contact_angle_deg,
            contact_length_m: s.contact_length_m,
            stick_half_angle_rad: s.stick_half_angle_rad,
            driving_angle_deg: s.driving_angle_deg,
            driving_length_m: crate::contact::contact_length_m(s.stick_half_angle_rad, self.prepared.k),
            driving_ratio: s.driving_ratio,
            speed_rpm: s.speed_rad_s * RAD_S_TO_RPM,
            speed_residual_rpm: measured_speed - s.speed_rad_s * RAD_S_TO_RPM,
            stall_torque_nm: s.stall_torque_nm,
            dielectric_loss_w: s.dielectric_loss_w,
            damping_loss_w: s.damping_loss_w,
            friction_loss_w: s.friction_loss_w,
            radial_friction_loss_w: s.radial_friction_loss_w,
            rotor_loss_w: s.rotor_loss_w,
            output_power_w: s.output_power_w,
            input_power_w: input,
            efficiency,
            warnings,
        }
    }
}

fn withheld(status: EstimateStatus) -> Estimate {
    let n = f64::NAN;
    Estimate {
        status,
        full_contact: false,
        amplitude_m: n,
        contact_half_angle_rad: n,
        contact_angle_deg: n,
        contact_length_m: n,
        stick_half_angle_rad: n,
        driving_angle_deg: n,
        driving_length_m: n,
        driving_ratio: n,
        speed_rpm: n,
        speed_residual_rpm: n,
        stall_torque_nm: n,
        dielectric_loss_w: n,
        damping_loss_w: n,
        friction_loss_w: n,
        radial_friction_loss_w: n,
        rotor_loss_w: n,
        output_power_w: n,
        input_power_w: n,
        efficiency: n,
        warnings: LimitWarnings::NONE,
    }
}

/// One output column of the estimator: name with unit suffix, unit, meaning, accessor.
#[derive(Clone, Copy)]
pub struct EstimateColumn {
    /// Column name with unit suffix.
    pub name: &'static str,
    /// Unit as printed.
    pub unit: &'static str,
    /// Meaning.
    pub doc: &'static str,
    /// Accessor.
    pub get: fn(&Estimate) -> f64,
}

impl std::fmt::Debug for EstimateColumn {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "EstimateColumn({})", self.name)
    }
}

macro_rules! columns {
    ($(($field:ident, $unit:literal, $doc:literal)),* $(,)?) => {
        /// The numeric columns of an estimate, in the order `trum estimate` writes them.
        pub const ESTIMATE_COLUMNS: &[EstimateColumn] =
            &[$(EstimateColumn { name: stringify!($field), unit: $unit, doc: $doc, get: |e: &Estimate| e.$field }),*];
    };
}

columns! {
    (amplitude_m, "m", "wave amplitude implied by the feedback voltage"),
    (contact_half_angle_rad, "rad", "contact half-angle phi0 in wave phase"),
    (contact_angle_deg, "deg", "contact angle, full arc per wave"),
    (contact_length_m, "m", "contact length per wave"),
    (stick_half_angle_rad, "rad", "stick (driving-zone) half-angle theta_s in wave phase"),
    (driving_angle_deg, "deg", "driving angle, full arc per wave"),
    (driving_length_m, "m", "driving-zone length per wave"),
    (driving_ratio, "-", "proportion of the driving zone in the contact zone"),
    (speed_rpm, "rpm", "rotor speed the contact state implies"),
    (speed_residual_rpm, "rpm", "measured minus estimated speed"),
    (stall_torque_nm, "N m", "stall torque at this amplitude and preload"),
    (dielectric_loss_w, "W", "dielectric loss"),
    (damping_loss_w, "W", "stator damping loss"),
    (friction_loss_w, "W", "contact friction loss"),
    (radial_friction_loss_w, "W", "radial-slip part of the friction loss"),
    (rotor_loss_w, "W", "rotor viscous loss"),
    (output_power_w, "W", "output power T Omega"),
    (input_power_w, "W", "input power: output plus every loss"),
    (efficiency, "-", "output power / input power"),
}

#[cfg(test)]
#[allow(clippy::unwrap_used)]
mod tests {
    use super::*;
    use crate::solve::solve;

    fn row(op: &OperatingPoint, feedback_v: Option<f64>) -> MeasuredPoint {
        MeasuredPoint {
            preload_n: op.preload_n,
            voltage_v: op.voltage_v,
            frequency_hz: op.frequency_hz,
            torque_nm: op.torque_nm,
            feedback_v,
            speed_rpm: None,
        }
    }

    /// Fed the feedback voltage of the steady solution, the estimator is that solution:
    /// the same contact and stick angles, speed and losses, and an input power (the energy
    /// balance) equal to the electrical input power of the solved point. Independent
    /// routes: the amplitude fixed point versus one evaluation at the measured amplitude.
    #[test]
    fn at_the_solved_feedback_voltage_the_estimate_is_the_steady_state() {
        for (name, v, hz) in [("generic60", 200.0, 43_000.0), ("trum60-qut", 150.0, 42_000.0)] {
            let m = crate::presets::frozen(name).unwrap();
            let e = Estimator::new(&m).unwrap();
            for (f, t) in [(150.0, 0.0), (250.0, 0.05), (350.0, 0.1)] {
                let op = OperatingPoint::new(f, t, v, hz);
                let s = solve(&m, &op);
                assert_eq!(s.status, Status::Ok, "{name} {f} N {t} N m");
                let est = e.estimate(&row(&op, Some(s.feedback_v)));
                assert_eq!(est.status, EstimateStatus::Ok);
                let close = |a: f64, b: f64, what: &str| {
                    assert!((a - b).abs() <= 1e-6 * b.abs().max(1e-12), "{name} {f} N {t}: {what} {a} vs {b}")
                };
                close(est.amplitude_m, s.amplitude_m, "amplitude");
                close(est.contact_angle_deg, s.contact_angle_deg, "contact angle");
                close(est.driving_angle_deg, s.driving_angle_deg, "driving angle");
                close(est.speed_rpm, s.speed_rpm, "speed");
                close(est.friction_loss_w, s.friction_loss_w, "friction loss");
                close(est.damping_loss_w, s.damping_loss_w, "damping loss");
                close(est.dielectric_loss_w, s.dielectric_loss_w, "dielectric loss");
                // the solver's input power is V·I from the modal impedance: at the fixed
                // point it balances output and losses (to the solver's tolerance)
                assert!((est.input_power_w - s.input_power_w).abs() < 1e-5 * s.input_power_w, "{name} {f} {t}");
                close(est.efficiency, s.efficiency, "efficiency");
                assert!(est.driving_length_m <= est.contact_length_m);
            }
        }
    }

    /// Contact and loss trends with the measured amplitude at a fixed preload: a larger
    /// amplitude presses a shorter contact arc and loses more to damping; a torque beyond
    /// the drive stalls; no feedback or a zero one is said so.
    #[test]
    fn amplitude_trends_and_statuses() {
        let m = crate::presets::frozen("generic60").unwrap();
        let e = Estimator::new(&m).unwrap();
        let op = OperatingPoint::new(250.0, 0.1, 200.0, 43_000.0);
        let g = m.electrical.feedback_gain_v_per_m;
        let at = |w: f64| e.estimate(&row(&op, Some(w * g)));
        let (a, b) = (at(1.0e-6), at(2.0e-6));
        assert!(b.contact_angle_deg < a.contact_angle_deg, "{a:?} {b:?}");
        assert!((b.damping_loss_w / a.damping_loss_w - 4.0).abs() < 1e-9, "damping grows as W²");
        assert!(b.speed_rpm > a.speed_rpm);
        let stalled = e.estimate(&row(&OperatingPoint { torque_nm: 50.0, ..op }, Some(1e-6 * g)));
        assert_eq!(stalled.status, EstimateStatus::Stall);
        assert_eq!((stalled.speed_rpm, stalled.output_power_w, stalled.efficiency), (0.0, 0.0, 0.0));
        let zero = e.estimate(&row(&op, Some(0.0)));
        assert_eq!(zero.status, EstimateStatus::NoContactState);
        assert!(zero.efficiency.is_nan() && zero.amplitude_m == 0.0);
        assert_eq!(e.estimate(&row(&op, None)).status, EstimateStatus::NoFeedback);
        assert_eq!(
            e.estimate(&row(&OperatingPoint { preload_n: -1.0, ..op }, Some(1.0))).status,
            EstimateStatus::InvalidInput
        );
        assert_eq!(e.estimate(&row(&op, Some(f64::NAN))).status, EstimateStatus::InvalidInput);
        // beyond a limit: the amplitude
        let big = at(2.0 * m.limits.max_amplitude_m);
        assert!(big.warnings.contains("max_amplitude_m"), "{big:?}");
        assert!(at(1e-6).warnings.is_empty());
        let mut no_gain = m.clone();
        no_gain.electrical.feedback_gain_v_per_m = 0.0;
        assert!(Estimator::new(&no_gain).unwrap_err().to_string().contains("electrical.feedback_gain_v_per_m"));
        for (i, s) in EstimateStatus::ALL.iter().enumerate() {
            assert_eq!(usize::from(s.code()), i);
            assert_eq!(s.as_str(), EstimateStatus::NAMES[i]);
        }
    }
}
