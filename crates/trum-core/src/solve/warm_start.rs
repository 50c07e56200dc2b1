//! The next point of a sweep, warm-started from the points solved before it.

use super::descent::{solve_drive_below, WarmTop};
use super::trial::Drive;
use super::{iterated, solve_prepared, OperatingPoint, Prepared, Solution, Status, Work};
use crate::params::Motor;
use std::f64::consts::PI;

/// The next point of a sweep after the points of `history` (same motor): [`solve_prepared`] warm-started
/// from the newest, with the amplitude descending from its when that is a proven upper bound
/// of this point's largest fixed point. That holds for the Coulomb interface when only the
/// load torque has risen: at fixed W the load moves only the stick angle θs ≤ π/2, up,
/// and with it the friction power factor 2E(θs) − E(φ0) (dE/dθ = cos θ·(cos θ − c) ≥ 0
/// there), so the friction damping grows, |Z| grows and the map G(W) = Θ·V/|Z| does not
/// rise; G(W) < W above the old largest fixed point then stays true. Effects that iterate
/// on the solution (thermal state, voltage sag) or average over a revolution
/// (eccentricity), and the generalised interface, take the usual descent from the bound.
/// So do preload stiffening and Hertz softening: G then need not rise with W, the previous
/// amplitude is no bound of the largest fixed point (the cold descent is capped for them,
/// docs/EFFECTS.md), and a sweep carrying the branch of its chunk's first point would
/// differ from the cold solve by whole branches and make maps depend on their chunking
/// (generic60 with a strong softening: 394 rpm in such a sweep, 70 rpm cold). A sweep
/// gives the cold answer.
///
/// `last` = the solution of the point solved just before (it warm-starts the inner angle
/// solves); `history` = the points solved before this one, oldest first, the newest being
/// `last`'s (a sweep keeps the last [`SWEEP_HISTORY`]). The newest is the warm start's
/// bound. Where earlier ones lie on this point's torque line too, the amplitude
/// extrapolated through them (Lagrange, up to quadratic) is tried first: within about 1e-6
/// of the root, where the bound is a whole torque step (1e-3) away. The first Newton step
/// from there takes the trial's exact slope of r (every warm trial has one: the baseline
/// Coulomb interface), and lands within the tolerance at 99 % of the running points of
/// trum60a's 100-torque rows (2.02 trials a point). The contact and stick angles are
/// extrapolated the same way for the first trial's angle solves. Where r ≥ 0 at the
/// prediction it is the top of the descent, else it and the bound bracket the root.
///
/// Bounded in work as [`solve_prepared`] is: the warm descent has the budget of a solve
/// of its own.
pub(crate) fn solve_in_sweep(
    p: &Prepared,
    motor: &Motor,
    op: &OperatingPoint,
    last: Option<&Solution>,
    history: &[SweepPoint],
) -> Solution {
    super::with_warnings(motor, op, warm_solve(p, motor, op, last, history))
}

/// [`solve_in_sweep`] without the limit check.
fn warm_solve(
    p: &Prepared,
    motor: &Motor,
    op: &OperatingPoint,
    last: Option<&Solution>,
    history: &[SweepPoint],
) -> Solution {
    let guess = last.filter(|g| g.status.is_valid());
    let on_line = |h: &SweepPoint| h.running && OperatingPoint { torque_nm: op.torque_nm, ..h.op } == *op;
    let top = history.last().filter(|h| {
        on_line(h)
            && h.op.torque_nm <= op.torque_nm
            && p.law.radial_ratio == 0.0
            && p.compliance == 0.0
            && p.stiffening == 0.0
            && p.beta == 0.0
            && p.runout_m == 0.0
            && iterated(p, op) == (false, false)
            && op.invalid_reason().is_none()
    });
    let Some(top) = top else {
        return solve_prepared(p, motor, op, guess);
    };
    // Torques and (amplitude, contact angle, stick angle) of the newest points on this
    // torque line, newest first, strictly falling in torque (fixed arrays: this runs once a
    // point)
    let (mut xs, mut ys, mut nw) = ([0.0; SWEEP_HISTORY], [[0.0; 3]; SWEEP_HISTORY], 0);
    for h in history.iter().rev() {
        if !(on_line(h) && (nw == 0 || h.op.torque_nm < xs[nw - 1])) {
            break;
        }
        xs[nw] = h.op.torque_nm;
        ys[nw] = [h.amplitude_m, h.contact_half_angle_rad, h.stick_half_angle_rad];
        nw += 1;
    }
    // In a stall G does not depend on the torque and the bound is the root itself: no
    // prediction (extrapolating across the onset of stall would land below it).
    let ahead = top.op.torque_nm < op.torque_nm && !top.stalled;
    let w = lagrange_weights(&xs[..nw], op.torque_nm);
    let at = |j: usize| ys[..nw].iter().zip(w).map(|(y, w)| w * y[j]).sum::<f64>();
    let predicted = (ahead && nw >= 2).then(|| at(0));
    // The contact and stick angles extrapolated the same way start the first trial's
    // angle solves (inside their ranges, φ0 < π and θs < min(φ0, π/2), else the newest
    // point's angles do).
    let contact_rad = predicted.map(|_| at(1)).filter(|&t| t > 0.0 && t < PI);
    let stick_rad = predicted.map(|_| at(2)).filter(|&t| t > 0.0 && t < top.contact_half_angle_rad.min(0.5 * PI));
    let warm = WarmTop { bound: top.amplitude_m, predicted, contact_rad, stick_rad };
    // (every solution of solve_drive_below comes through `finish`, which has checked it
    // for non-finite numbers; the descent has a budget of its own, as every solve)
    let work = Work::of(p);
    work.verdict(solve_drive_below(p, &Drive::at(p, op), op, guess, Some(warm), &work))
}

/// What a sweep keeps of a solved point for the warm start of the next ones.
#[derive(Clone, Copy, Debug)]
pub(crate) struct SweepPoint {
    op: OperatingPoint,
    amplitude_m: f64,
    stick_half_angle_rad: f64,
    contact_half_angle_rad: f64,
    /// Ok or Stall with a positive amplitude: a bound for the next point on its line.
    running: bool,
    stalled: bool,
}

impl SweepPoint {
    pub(crate) fn new(op: &OperatingPoint, s: &Solution) -> Self {
        let running = matches!(s.status, Status::Ok | Status::Stall) && s.amplitude_m > 0.0;
        SweepPoint {
            op: *op,
            amplitude_m: s.amplitude_m,
            stick_half_angle_rad: s.stick_half_angle_rad,
            contact_half_angle_rad: s.contact_half_angle_rad,
            running,
            stalled: s.status == Status::Stall,
        }
    }
}

/// Points a sweep keeps for [`solve_in_sweep`]'s extrapolation (quadratic through three).
pub(crate) const SWEEP_HISTORY: usize = 3;

/// Weights of the polynomial through nodes `xs` (distinct, at most [`SWEEP_HISTORY`])
/// at `x`: its value there is Σ wᵢ·yᵢ (Lagrange), whatever the values yᵢ.
fn lagrange_weights(xs: &[f64], x: f64) -> [f64; SWEEP_HISTORY] {
    let mut w = [0.0; SWEEP_HISTORY];
    for (i, &xi) in xs.iter().enumerate() {
        w[i] = xs.iter().enumerate().filter(|&(j, _)| j != i).map(|(_, &xj)| (x - xj) / (xi - xj)).product();
    }
    w
}
