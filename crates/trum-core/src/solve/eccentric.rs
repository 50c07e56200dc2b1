//! `eccentricity`: the steady state averaged over one revolution of a rotor whose preload
//! varies with its angle.

use super::{map_solution, OperatingPoint, Prepared, Solution, Status, RAD_S_TO_RPM};
use crate::effects::Effect;
use crate::params::Motor;
use std::f64::consts::PI;

/// `eccentricity`: the preload varies once per revolution by ΔF = δ/(1/k_sp + 1/K_z)
/// (crate::contact::contact_normal_stiffness_n_per_m); every additive quantity is averaged
/// over the revolution with the time spent at each angle (∝ 1/Ω), so the energy balance
/// still holds, and the speed's time-weighted standard deviation is reported. The first
/// truth family adds a twice-per-revolution component of 30 % out of phase with the offset
/// (a rotor face tilted about an axis at 45° to the offset), the second clips the ripple
/// at half its peak (the shaft reaches its bearing's axial play, which then carries the
/// excess force, so the contact's mean preload over a revolution drops too). Neither is a
/// member of the harmonic family [`runout_shape`]: that one is even in φ with a zero mean.
/// `solve_at(op, guess)` is the steady-state solve at each preload (the nominal one first,
/// then the ripple samples in order): [`solve_effects`] in [`solve_prepared`];
/// crate::sensitivity records those solves, or passes linearised ones.
pub(crate) fn eccentric_average_with(
    p: &Prepared,
    motor: &Motor,
    op: &OperatingPoint,
    guess: Option<&Solution>,
    mut solve_at: impl FnMut(&OperatingPoint, Option<&Solution>) -> Solution,
) -> Solution {
    // The trapezoidal rule over a period is exact for trigonometric polynomials below the
    // sample count and the response to a smooth preload ripple is nearly one: 8 samples agree
    // with 16 to 1e-8 of the speed at the typical runout, 1e-6 at four times it.
    const SAMPLES: usize = 8;
    let nominal = solve_at(op, guess);
    if nominal.status != Status::Ok {
        return nominal;
    }
    let kz = crate::contact::contact_normal_stiffness_n_per_m(motor, nominal.contact_half_angle_rad);
    let ripple =
        (p.runout_m / (1.0 / motor.assembly.axial_spring_stiffness_n_per_m + 1.0 / kz)).min(0.9 * op.preload_n);
    let mut acc: Option<Solution> = None;
    let mut tsum = 0.0;
    // A ripple even in φ has sample j and SAMPLES − j at the same preload: solve j = 0 ..=
    // SAMPLES/2 and count the inner ones twice (5 solves instead of 8, 4 for the candidate
    // form). The first truth family's is not even: all 8.
    let even = !p.truth(Effect::Eccentricity) || p.truth_b(Effect::Eccentricity);
    let solved = if even { SAMPLES / 2 + 1 } else { SAMPLES };
    let mut speeds = [(0.0, 0.0); SAMPLES];
    let mut prev = nominal.clone();
    for (j, sp) in speeds.iter_mut().enumerate().take(solved) {
        let phi = 2.0 * PI * j as f64 / SAMPLES as f64;
        let shape = if p.truth_b(Effect::Eccentricity) {
            // the second truth family: the ripple clipped at half its peak
            phi.cos().min(0.5)
        } else if p.truth(Effect::Eccentricity) {
            (phi.cos() + 0.3 * (2.0 * phi).sin()) / 1.3
        } else if p.runout_harmonics != [0.0, 0.0] {
            runout_shape(phi, p.runout_harmonics)
        } else {
            phi.cos()
        };
        let count = if !even || j == 0 || j == SAMPLES / 2 { 1.0 } else { 2.0 };
        let mut o = *op;
        o.preload_n = op.preload_n + ripple * shape;
        // at a quarter turn the candidate's ripple is zero: the nominal solve is that sample
        let s = if !p.truth(Effect::Eccentricity) && p.runout_harmonics[0] == 0.0 && 4 * j == SAMPLES {
            nominal.clone()
        } else {
            solve_at(&o, Some(&prev))
        };
        if s.status != Status::Ok || s.speed_rad_s <= 0.0 {
            // the rotor sticks in this sector: it stops there
            let mut st = s;
            st.speed_std_rpm = 0.0;
            return st;
        }
        *sp = (s.speed_rad_s, count);
        let wt = count / s.speed_rad_s;
        tsum += wt;
        acc = Some(match acc {
            None => scale_solution(&s, wt),
            Some(a) => add_solution(&a, &scale_solution(&s, wt)),
        });
        prev = s;
    }
    let mut out = scale_solution(&acc.unwrap_or(nominal), 1.0 / tsum);
    let mean = out.speed_rad_s;
    let var: f64 = speeds.iter().filter(|s| s.1 > 0.0).map(|&(w, n)| n * (w - mean).powi(2) / w).sum::<f64>() / tsum;
    out.speed_std_rpm = var.sqrt() * RAD_S_TO_RPM;
    out.status = Status::Ok;
    out.efficiency = crate::losses::efficiency(out.output_power_w, out.input_power_w);
    out.torque_nm = op.torque_nm;
    out.iterations = prev.iterations;
    out
}

/// `eccentricity`'s harmonic family: the ripple's shape at rotor angle `phi` [rad],
/// (cos φ + h₂·cos 2φ + h₃·cos 3φ)/(1 + h₂ + h₃), its peak 1 at φ = 0 so that the runout
/// stays the ripple's peak. An offset rotor gives the once-per-revolution term (Chen et
/// al. 2020 §4.3); a rotor face tilted against the stator adds the twice-per-revolution
/// term and a three-lobed rotor or a three-point mount the three-times one. Even in φ, as
/// the sampling by halves assumes.
pub(crate) fn runout_shape(phi: f64, [h2, h3]: [f64; 2]) -> f64 {
    (phi.cos() + h2 * (2.0 * phi).cos() + h3 * (3.0 * phi).cos()) / (1.0 + h2 + h3)
}

fn scale_solution(a: &Solution, k: f64) -> Solution {
    map_solution(a, None, |x, _| x * k)
}

fn add_solution(a: &Solution, b: &Solution) -> Solution {
    map_solution(a, Some(b), |x, y| x + y)
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The harmonic ripple keeps the runout as its peak (at φ = 0), has a zero mean over a
    /// revolution (the mean preload stays) and its harmonics in the given proportions
    /// (Fourier coefficients by a 64-point rule, exact for these trigonometric polynomials).
    #[test]
    fn the_harmonic_ripple_peaks_at_the_runout_with_its_harmonics() {
        let h = [0.3, 0.7];
        assert!((runout_shape(0.0, h) - 1.0).abs() < 1e-15);
        let n = 64;
        let coef = |k: f64| {
            (0..n).map(|j| 2.0 * PI * j as f64 / n as f64).map(|p| runout_shape(p, h) * (k * p).cos()).sum::<f64>()
                * 2.0
                / n as f64
        };
        let mean = (0..n).map(|j| runout_shape(2.0 * PI * j as f64 / n as f64, h)).sum::<f64>() / n as f64;
        assert!(mean.abs() < 1e-15, "{mean}");
        let norm = 1.0 + h[0] + h[1];
        for (k, want) in [(1.0, 1.0 / norm), (2.0, h[0] / norm), (3.0, h[1] / norm), (4.0, 0.0)] {
            assert!((coef(k) - want).abs() < 1e-14, "harmonic {k}: {} vs {want}", coef(k));
        }
        // sampling by halves: even in φ
        for j in 1..8 {
            let p = 2.0 * PI * j as f64 / 8.0;
            assert!((runout_shape(p, h) - runout_shape(2.0 * PI - p, h)).abs() < 1e-14);
        }
    }
}
