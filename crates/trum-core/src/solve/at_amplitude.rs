//! Every quantity of an operating point at a *given* wave amplitude instead of the solved
//! one: the measured-input model of Sun et al. 2021, where the amplitude comes from the
//! feedback-electrode voltage (eq. 1) rather than from the amplitude fixed point.

use super::finish::{clamped_trial, finish};
use super::trial::{trial, Drive};
use super::{OperatingPoint, Prepared, Solution, Status};

/// The operating point `op` with the wave amplitude held at `amplitude_m` [m] (≥ 0,
/// finite): contact zone from the preload at that amplitude, stick angle from the torque
/// balance, speed, stall torque and every loss, as the steady solver reports them for its
/// own amplitude (Sun et al. 2021 eq. 5-13 and 15-26 in trum's forms, docs/MODEL.md). The
/// drive is the set one (`voltage_sag` and `thermal_drift` do not act: the amplitude is
/// what they would change). `input_power_w`, `current_*` and `phase_lag_rad` are those of
/// the modal impedance at this amplitude, which balance the losses only at the solved
/// amplitude. Status: `Stall` when the load is at or above the drive at this amplitude,
/// `Clamped` for a zero amplitude, `InvalidInput` for an invalid point or amplitude, else
/// `Ok`. `iterations` is 1; `warnings` is left empty (the caller checks the limits that
/// apply to its use, as [`crate::estimate`] does).
pub fn solve_at_amplitude(p: &Prepared, op: &OperatingPoint, amplitude_m: f64) -> Solution {
    if op.invalid_reason().is_some() || !(amplitude_m.is_finite() && amplitude_m >= 0.0) {
        return Solution::invalid(Status::InvalidInput);
    }
    let d = Drive::at(p, op);
    if amplitude_m == 0.0 {
        return finish(p, &d, op, &clamped_trial(p, &d), Status::Clamped, 1);
    }
    let t = trial(p, &d, amplitude_m, None, None);
    finish(p, &d, op, &t, if t.stalled { Status::Stall } else { Status::Ok }, 1)
}
