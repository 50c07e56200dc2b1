//! The steady state of one operating point: stator amplitude, contact and stick angles,
//! torque, speed, every loss, efficiency, current and feedback voltage, solved together.
//!
//! Unknown: the wave amplitude W. For a trial W the contact zone follows from the
//! preload ([`crate::contact::contact_from_ratio`]), the stick angle from the torque
//! balance ([`crate::contact::stick_half_angle_rad`]), and then the friction forces'
//! equivalent damping gives a new amplitude W' = Θ·V/|Z(W)| ([`crate::stator`]). The
//! steady state is the fixed point W = W'. Because W' is bounded by Θ·V/(ω·c) and grows
//! with W, iterating from that bound descends monotonically onto the largest fixed point
//! (the running branch); Newton steps on W·|Z(W)| − Θ·V where the trial has an exact
//! slope, secants elsewhere, and regula falsi inside a bracket make it converge in a
//! handful of evaluations.
//!
//! Where the parts live:
//! - this file: the entry points [`solve`] and [`solve_prepared`] (the public types
//!   [`OperatingPoint`], [`Status`] and [`Solution`] are in modules of their own, re-exported
//!   here);
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
//! - `branches`: every steady amplitude at a point and the jump frequencies;
//! - `work`: the work bound of one solve, shared by every route it nests.
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
mod work;

pub use at_amplitude::solve_at_amplitude;
pub use branches::{amplitude_branches, jump_frequencies_hz, AmplitudeBranch};
pub(crate) use eccentric::eccentric_average_with;
pub(crate) use fixed_points::{iterated, solve_clamped, solve_effects, state_map};
pub use prepared::Prepared;
pub(crate) use trial::Trial;
pub(crate) use warm_start::{solve_in_sweep, SweepPoint, SWEEP_HISTORY};
pub(crate) use work::Work;
pub use work::WORK_BOUND;

pub use crate::operating_point::OperatingPoint;
use crate::params::Motor;
pub use crate::solution::{Solution, Status};
use std::f64::consts::PI;

/// Convert rad/s to rev/min.
pub const RAD_S_TO_RPM: f64 = 60.0 / (2.0 * PI);

/// Solves one operating point from scratch. Never panics; an invalid or unsolvable point
/// is reported in [`Solution::status`].
pub fn solve(motor: &Motor, op: &OperatingPoint) -> Solution {
    solve_prepared(&Prepared::new(motor), motor, op, None)
}

/// Solves one operating point, optionally warm-started from a neighbouring solution
/// (sweeps use this; the result does not depend on the guess beyond the tolerance). The
/// solve is bounded in work ([`Prepared::with_work_bound`], default [`WORK_BOUND`]): one
/// that spends its bound is `no_convergence` with [`Solution::work_bound_reached`].
pub fn solve_prepared(p: &Prepared, motor: &Motor, op: &OperatingPoint, guess: Option<&Solution>) -> Solution {
    solve_prepared_counted(p, motor, op, guess).0
}

/// [`solve_prepared`] and the work it spent [units of [`WORK_BOUND`]].
pub(crate) fn solve_prepared_counted(
    p: &Prepared,
    motor: &Motor,
    op: &OperatingPoint,
    guess: Option<&Solution>,
) -> (Solution, u64) {
    let work = Work::of(p);
    let s = solve_prepared_with(p, motor, op, guess, &work, |o, g| solve_effects(p, o, g, &work));
    (s, work.spent())
}

/// [`solve_prepared`] with `solve_at(op, guess)` in place of each steady-state solve it
/// makes (one, or the nominal one and the ripple samples of an eccentric motor), each
/// charging `work`, the budget they share: crate::sensitivity keeps them.
pub(crate) fn solve_prepared_with(
    p: &Prepared,
    motor: &Motor,
    op: &OperatingPoint,
    guess: Option<&Solution>,
    work: &Work,
    mut solve_at: impl FnMut(&OperatingPoint, Option<&Solution>) -> Solution,
) -> Solution {
    if op.invalid_reason().is_some() {
        return Solution::invalid(Status::InvalidInput);
    }
    let s = if p.runout_m > 0.0 { eccentric_average_with(p, motor, op, guess, solve_at) } else { solve_at(op, guess) };
    with_warnings(motor, op, work.verdict(finite_or_unconverged(p, s)))
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
        capacitive_current_a,
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
