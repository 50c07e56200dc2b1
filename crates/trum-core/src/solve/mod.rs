//! The steady state of one operating point: stator amplitude, contact and stick angles,
//! torque, speed, every loss, efficiency, current and feedback voltage, solved together.
//!
//! Unknown: the wave amplitude W. For a trial W the contact zone follows from the
//! preload ([`crate::contact::contact_from_ratio`]), the stick angle from the torque
//! balance ([`crate::contact::stick_half_angle_rad`]), and then the friction forces'
//! equivalent damping gives a new amplitude W' = Θ·V/|Z(W)| ([`crate::stator`]). The
//! steady state is the fixed point W = W'. Because W' is bounded by Θ·V/(ω·c) and grows
//! with W, iterating from that bound descends monotonically onto the largest fixed point
//! (the running branch); secant/regula-falsi steps inside the bracket make it converge
//! in a handful of evaluations.
//!
//! Where the parts live:
//! - this file: the public types ([`OperatingPoint`], [`Status`], [`Solution`]) and the
//!   entry points [`solve`] and [`solve_prepared`];
//! - `prepared`: [`Prepared`], the motor constants computed once per motor;
//! - `trial`: one trial amplitude ([`trial::trial`]) under a drive (the set voltage and
//!   frequency after voltage sag and thermal drift act on them);
//! - `descent`: the amplitude descent onto the largest fixed point, with the window
//!   searches around a stiffness crossing;
//! - `bracket`: the scalar root brackets shared by the descent and the fixed points;
//! - `fixed_points`: the fixed points that `voltage_sag` and `thermal_drift` iterate
//!   around the amplitude solve;
//! - `eccentric`: the once-per-revolution average of `eccentricity`;
//! - `finish`: every reported quantity from a converged trial;
//! - `warm_start`: the next point of a sweep, started from the points before it;
//! - `branches`: every steady amplitude at a point and the jump frequencies.
//!
//! The contact interface laws live in [`crate::interface`], the W-dependent modal
//! stiffness in [`crate::stator`].

mod at_amplitude;
pub(crate) mod bracket;
mod branches;
mod descent;
mod eccentric;
mod finish;
mod fixed_points;
mod prepared;
pub(crate) mod trial;
mod warm_start;

pub use at_amplitude::solve_at_amplitude;
pub use branches::{amplitude_branches, jump_frequencies_hz, AmplitudeBranch};
pub(crate) use eccentric::eccentric_average_with;
pub(crate) use fixed_points::{iterated, solve_clamped, solve_effects, state_map};
pub use prepared::Prepared;
pub(crate) use trial::Trial;
pub(crate) use warm_start::{solve_in_sweep, SweepPoint, SWEEP_HISTORY};

use crate::limits::LimitWarnings;
use crate::params::Motor;
use std::f64::consts::PI;

/// Convert rad/s to rev/min.
pub const RAD_S_TO_RPM: f64 = 60.0 / (2.0 * PI);

/// One operating point. All fields SI.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct OperatingPoint {
    /// Axial preload pressing the rotor on the stator [N], > 0.
    pub preload_n: f64,
    /// Load torque on the rotor [N·m], ≥ 0.
    pub torque_nm: f64,
    /// Drive voltage amplitude per phase, zero-to-peak [V], > 0.
    pub voltage_v: f64,
    /// Drive frequency [Hz], > 0.
    pub frequency_hz: f64,
    /// Time since the drive was switched on [s], ≥ 0 (only `thermal_drift` uses it).
    pub elapsed_s: f64,
}

impl OperatingPoint {
    /// A steady operating point (elapsed time 0).
    pub fn new(preload_n: f64, torque_nm: f64, voltage_v: f64, frequency_hz: f64) -> Self {
        OperatingPoint { preload_n, torque_nm, voltage_v, frequency_hz, elapsed_s: 0.0 }
    }

    /// Why the point is invalid, if it is.
    pub fn invalid_reason(&self) -> Option<String> {
        let checks = [
            ("preload_n", self.preload_n, true),
            ("voltage_v", self.voltage_v, true),
            ("frequency_hz", self.frequency_hz, true),
            ("torque_nm", self.torque_nm, false),
            ("elapsed_s", self.elapsed_s, false),
        ];
        for (name, v, strict) in checks {
            if !v.is_finite() {
                return Some(format!("{name} = {v} is not a finite number"));
            }
            if strict && v <= 0.0 {
                return Some(format!("{name} = {v} must be > 0"));
            }
            if !strict && v < 0.0 {
                return Some(format!("{name} = {v} must be >= 0"));
            }
        }
        None
    }
}

/// Whether the model has a physical solution at the point.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Status {
    /// Converged, rotor turning.
    Ok,
    /// The load torque is at or above the stall (blocking) torque: the rotor is at rest.
    /// All quantities are valid (speed and output power are zero).
    Stall,
    /// The friction forces clamp the stator: no vibrating steady state exists at this
    /// drive (amplitude zero), or, with `voltage_sag`, the moving stator would sag its
    /// drive below clamping and the clamped one's recovered voltage cannot start it. Valid,
    /// with zero amplitude, speed and output.
    Clamped,
    /// No steady state was found: the iteration did not converge, or, with `voltage_sag`
    /// or `thermal_drift`, the state jumps between a moving and a clamped (or stalled) one
    /// at every pass (the motor hunts, docs/EFFECTS.md). Numbers are the last iterate and
    /// must not be used.
    NoConvergence,
    /// The operating point itself is invalid (non-finite, non-positive preload, ...).
    InvalidInput,
}

impl Status {
    /// The word written in status columns.
    pub fn as_str(self) -> &'static str {
        match self {
            Status::Ok => "ok",
            Status::Stall => "stall",
            Status::Clamped => "clamped",
            Status::NoConvergence => "no_convergence",
            Status::InvalidInput => "invalid_input",
        }
    }
    /// True when the numbers describe a physical steady state.
    pub fn is_valid(self) -> bool {
        matches!(self, Status::Ok | Status::Stall | Status::Clamped)
    }
}

impl std::fmt::Display for Status {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.as_str())
    }
}

/// Every quantity of one steady operating point (SI, unit in each name).
#[derive(Clone, Debug, PartialEq)]
pub struct Solution {
    /// Whether the numbers are a physical steady state.
    pub status: Status,
    /// True when the rotor touches the whole wave.
    pub full_contact: bool,
    /// Amplitude evaluations the solver used.
    pub iterations: u32,
    /// Wave amplitude W at the contact surface [m].
    pub amplitude_m: f64,
    /// Contact half-angle φ0 in wave phase [rad].
    pub contact_half_angle_rad: f64,
    /// Contact angle Xc, full arc in mechanical degrees (0-40° for N = 9).
    pub contact_angle_deg: f64,
    /// Contact length 2·x0 per wave [m].
    pub contact_length_m: f64,
    /// Stick (equal-speed) half-angle θs in wave phase [rad].
    pub stick_half_angle_rad: f64,
    /// Driving angle Xs, full arc in mechanical degrees.
    pub driving_angle_deg: f64,
    /// Proportion of the driving zone in the contact zone, θs/φ0 [-].
    pub driving_ratio: f64,
    /// Rotor speed [rad/s].
    pub speed_rad_s: f64,
    /// Rotor speed [rev/min].
    pub speed_rpm: f64,
    /// Peak tangential speed of the stator surface at the crest [m/s].
    pub crest_speed_m_s: f64,
    /// Load torque [N·m].
    pub torque_nm: f64,
    /// Stall (blocking) torque at this preload and drive [N·m].
    pub stall_torque_nm: f64,
    /// Axial contact force [N] (equals the preload at equilibrium).
    pub axial_force_n: f64,
    /// Electrical input power, both phases [W].
    pub input_power_w: f64,
    /// Mechanical output power T_load·Ω [W].
    pub output_power_w: f64,
    /// Dielectric loss of the piezoceramic, both phases [W].
    pub dielectric_loss_w: f64,
    /// Structural damping loss of the stator [W].
    pub damping_loss_w: f64,
    /// Friction loss in the contact interface [W].
    pub friction_loss_w: f64,
    /// Of which radial slip (nonzero only with `radial_friction`) [W].
    pub radial_friction_loss_w: f64,
    /// Rotor viscous loss d_r·Ω² [W].
    pub rotor_loss_w: f64,
    /// Output power / input power, in [0, 1].
    pub efficiency: f64,
    /// Feedback-electrode voltage amplitude [V].
    pub feedback_v: f64,
    /// Drive current amplitude per phase [A].
    pub current_a: f64,
    /// Part of the phase current in phase with the electrode voltage [A].
    pub current_in_phase_a: f64,
    /// Part of the phase current in quadrature (leading) [A].
    pub current_quadrature_a: f64,
    /// Voltage at the electrodes, zero-to-peak [V] (below the set voltage with `voltage_sag`).
    pub electrode_voltage_v: f64,
    /// Phase lag ψ of the wave behind the drive [rad].
    pub phase_lag_rad: f64,
    /// Effective modal stiffness including effects [N/m].
    pub modal_stiffness_n_per_m: f64,
    /// Steady-state temperature rise of the motor over ambient [K] (Chen et al. 2020 eq.
    /// 11, t → ∞).
    pub temperature_rise_k: f64,
    /// Temperature rise at the point's elapsed time [K] (Chen et al. 2020 eq. 11).
    pub temperature_rise_at_elapsed_k: f64,
    /// Standard deviation of speed over a revolution [rev/min] (nonzero with `eccentricity`).
    pub speed_std_rpm: f64,
    /// The motor's `[limits]` this point exceeds ([`crate::limits`]); empty when it is
    /// inside all of them. Never changes the status or the numbers.
    pub warnings: LimitWarnings,
}

impl Solution {
    /// Sum of all losses [W].
    pub fn total_loss_w(&self) -> f64 {
        self.dielectric_loss_w + self.damping_loss_w + self.friction_loss_w + self.rotor_loss_w
    }

    pub(crate) fn invalid(status: Status) -> Solution {
        let n = f64::NAN;
        Solution {
            status,
            full_contact: false,
            iterations: 0,
            amplitude_m: n,
            contact_half_angle_rad: n,
            contact_angle_deg: n,
            contact_length_m: n,
            stick_half_angle_rad: n,
            driving_angle_deg: n,
            driving_ratio: n,
            speed_rad_s: n,
            speed_rpm: n,
            crest_speed_m_s: n,
            torque_nm: n,
            stall_torque_nm: n,
            axial_force_n: n,
            input_power_w: n,
            output_power_w: n,
            dielectric_loss_w: n,
            damping_loss_w: n,
            friction_loss_w: n,
            radial_friction_loss_w: n,
            rotor_loss_w: n,
            efficiency: n,
            feedback_v: n,
            current_a: n,
            current_in_phase_a: n,
            current_quadrature_a: n,
            electrode_voltage_v: n,
            phase_lag_rad: n,
            modal_stiffness_n_per_m: n,
            temperature_rise_k: n,
            temperature_rise_at_elapsed_k: n,
            speed_std_rpm: n,
            warnings: LimitWarnings::NONE,
        }
    }
}

/// Solves one operating point from scratch. Never panics; an invalid or unsolvable point
/// is reported in [`Solution::status`].
pub fn solve(motor: &Motor, op: &OperatingPoint) -> Solution {
    solve_prepared(&Prepared::new(motor), motor, op, None)
}

/// Solves one operating point, optionally warm-started from a neighbouring solution
/// (sweeps use this; the result does not depend on the guess beyond the tolerance).
pub fn solve_prepared(p: &Prepared, motor: &Motor, op: &OperatingPoint, guess: Option<&Solution>) -> Solution {
    solve_prepared_with(p, motor, op, guess, |o, g| solve_effects(p, o, g))
}

/// [`solve_prepared`] with `solve_at(op, guess)` in place of each steady-state solve it
/// makes (one, or the nominal one and the ripple samples of an eccentric motor):
/// crate::sensitivity keeps them.
pub(crate) fn solve_prepared_with(
    p: &Prepared,
    motor: &Motor,
    op: &OperatingPoint,
    guess: Option<&Solution>,
    mut solve_at: impl FnMut(&OperatingPoint, Option<&Solution>) -> Solution,
) -> Solution {
    if op.invalid_reason().is_some() {
        return Solution::invalid(Status::InvalidInput);
    }
    let s = if p.runout_m > 0.0 { eccentric_average_with(p, motor, op, guess, solve_at) } else { solve_at(op, guess) };
    with_warnings(motor, op, finite_or_unconverged(p, s))
}

/// `s` with the warnings of the motor's `[limits]` it exceeds (every public solve path
/// ends here).
pub(crate) fn with_warnings(motor: &Motor, op: &OperatingPoint, mut s: Solution) -> Solution {
    s.warnings = motor.limits.check_point(motor.thermal.ambient_c, op, &s);
    s
}

/// Every path (averaged and linearised ones too): non-finite numbers never carry a valid
/// status.
pub(crate) fn finite_or_unconverged(p: &Prepared, mut s: Solution) -> Solution {
    if s.status.is_valid() && !p.all_finite(&s) {
        s.status = Status::NoConvergence;
    }
    s
}

pub(crate) fn map_solution(a: &Solution, b: Option<&Solution>, f: impl Fn(f64, f64) -> f64) -> Solution {
    let mut o = a.clone();
    let bb = b.unwrap_or(a);
    macro_rules! each {
        ($($x:ident),*) => { $( o.$x = f(a.$x, bb.$x); )* };
    }
    each!(
        amplitude_m,
        contact_half_angle_rad,
        contact_angle_deg,
        contact_length_m,
        stick_half_angle_rad,
        driving_angle_deg,
        driving_ratio,
        speed_rad_s,
        speed_rpm,
        crest_speed_m_s,
        stall_torque_nm,
        axial_force_n,
        input_power_w,
        output_power_w,
        dielectric_loss_w,
        damping_loss_w,
        friction_loss_w,
        radial_friction_loss_w,
        rotor_loss_w,
        feedback_v,
        current_a,
        current_in_phase_a,
        current_quadrature_a,
        electrode_voltage_v,
        phase_lag_rad,
        modal_stiffness_n_per_m,
        temperature_rise_k,
        temperature_rise_at_elapsed_k
    );
    o
}

#[cfg(test)]
mod tests;
