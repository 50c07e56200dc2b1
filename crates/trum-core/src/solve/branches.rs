//! Every steady amplitude at an operating point, and the frequency band where two stable
//! ones coexist (the jumps of a softening stator).

use super::trial::{trial, Drive};
use super::{OperatingPoint, Prepared};
use crate::params::Motor;
use crate::stator::stiffness_crossing;

/// One steady amplitude of the stator at an operating point: a fixed point of the
/// harmonic-balance amplitude map W ↦ Θ·V/|Z(W)| (Sun et al. 2021 eq. 14; with
/// `hertz_softening` the modal stiffness is k − ¾·β·W², the Hertzian driving-circuit paper
/// (2022) eq. 10-12).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AmplitudeBranch {
    /// Transverse amplitude W [m].
    pub amplitude_m: f64,
    /// Stable under slow amplitude changes: the residual W − Θ·V/|Z(W)| rises through
    /// zero (above the root the drive cannot hold the amplitude, below it it grows).
    pub stable: bool,
}

/// Every steady amplitude at `op`, smallest first: the multi-valued region of a softening
/// stator (`hertz_softening`) has three (the middle one unstable), elsewhere there is one.
/// [`super::solve`] reports the largest stable one (the amplitude reached from above, i.e. when
/// the frequency is swept down onto the resonance). Effects that iterate on the solution
/// (thermal state, voltage sag) are not applied here: the drive is the set voltage.
/// Found by a scan of 400 logarithmically spaced amplitudes from 10⁻⁶ of the bound
/// Θ·V/(ω·c) to the bound, plus 9000 linearly spaced ones from 0.8 to 1.3 of the
/// amplitude where a W-dependent stiffness cancels the detuning (narrow folds), each sign
/// change refined by bisection to 1e-12 relative.
pub fn amplitude_branches(motor: &Motor, op: &OperatingPoint) -> Vec<AmplitudeBranch> {
    if op.invalid_reason().is_some() {
        return Vec::new();
    }
    let p = Prepared::new(motor);
    let d = Drive::at(&p, op);
    let r = |w: f64| {
        let t = trial(&p, &d, w, None, None);
        t.w - t.w_next
    };
    let mut w_hi = p.theta * d.v / (d.omega * d.c);
    // softening can lift the response above the linear bound: grow until r > 0
    for _ in 0..60 {
        if r(w_hi) > 0.0 {
            break;
        }
        w_hi *= 1.5;
    }
    const N: usize = 400;
    let mut ws: Vec<f64> = (0..=N).map(|i| w_hi * 1e-6f64.powf(1.0 - i as f64 / N as f64)).collect();
    // Near the crossing a window of r < 0 can be far narrower than the log grid's 3.5 %
    // steps: below it near a fold (0.3 % at trum60-qut, β = 1.089e18), above it where
    // friction damping keeps |Z| falling (0.65 % at trum60a with both effects, 1.2 % above
    // the crossing): scan 20 % below the crossing to 30 % above it in steps of 0.0055 %.
    if let Some(c) = stiffness_crossing(&p, &d, w_hi) {
        ws.extend((0..=9000).map(|i| c * (0.8 + 0.5 * i as f64 / 9000.0)).filter(|&w| w < w_hi));
        ws.sort_by(f64::total_cmp);
    }
    let rs: Vec<f64> = ws.iter().map(|&w| r(w)).collect();
    let mut out = Vec::new();
    for i in 0..ws.len() - 1 {
        let (r0, r1) = (rs[i], rs[i + 1]);
        if !(r0.is_finite() && r1.is_finite()) || (r0 < 0.0) == (r1 < 0.0) {
            continue;
        }
        let (mut a, mut b, ra) = (ws[i], ws[i + 1], r0);
        while b - a > 1e-12 * b {
            let m = 0.5 * (a + b);
            if (r(m) < 0.0) == (ra < 0.0) {
                a = m;
            } else {
                b = m;
            }
        }
        out.push(AmplitudeBranch { amplitude_m: 0.5 * (a + b), stable: r1 > r0 });
    }
    out
}

/// The multi-valued frequency band of the steady response at `op`'s preload, torque and
/// voltage, where two stable amplitudes coexist: (jump-down, jump-up) frequencies [Hz]. A
/// sweep down in frequency follows the upper branch and drops at the lower edge; a sweep up
/// follows the lower branch and jumps up at the upper edge (softening, the Hertzian
/// driving-circuit paper (2022) section 3). `None` when no frequency of `f_lo_hz..f_hi_hz`
/// (scanned in `steps`, edges refined by bisection to 0.01 Hz) has two stable amplitudes;
/// an edge beyond the scan is reported as the scan's end. With the cubic softening term the
/// lower edge often lies far below the resonance (the upper branch lives as long as ¾·β·W²
/// can cancel k − m·ω², beyond the validity of a small nonlinearity): the jump-up edge is
/// the meaningful one there.
pub fn jump_frequencies_hz(
    motor: &Motor,
    op: &OperatingPoint,
    f_lo_hz: f64,
    f_hi_hz: f64,
    steps: usize,
) -> Option<(f64, f64)> {
    let multi = |f: f64| {
        let o = OperatingPoint { frequency_hz: f, ..*op };
        amplitude_branches(motor, &o).iter().filter(|b| b.stable).count() >= 2
    };
    let steps = steps.max(2);
    let fs: Vec<f64> = (0..=steps).map(|i| f_lo_hz + (f_hi_hz - f_lo_hz) * i as f64 / steps as f64).collect();
    let inside: Vec<usize> = (0..=steps).filter(|&i| multi(fs[i])).collect();
    let (&first, &last) = (inside.first()?, inside.last()?);
    // edge between a frequency outside (`out`) and one inside (`ins`)
    let edge = |mut out: f64, mut ins: f64| {
        while (ins - out).abs() > 0.01 {
            let m = 0.5 * (out + ins);
            if multi(m) {
                ins = m;
            } else {
                out = m;
            }
        }
        0.5 * (out + ins)
    };
    let down = if first == 0 { fs[0] } else { edge(fs[first - 1], fs[first]) };
    let up = if last == steps { fs[steps] } else { edge(fs[last + 1], fs[last]) };
    Some((down, up))
}
