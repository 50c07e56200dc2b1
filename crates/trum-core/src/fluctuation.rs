//! Speed fluctuation from a once-per-revolution preload variation (eccentric assembly, Chen
//! et al. 2020 section 4.3). An axial runout δ of the rotor changes the compression of the
//! preload path — the disc spring k_sp in series with the contact's normal stiffness K_z —
//! by ΔF = δ/(1/k_sp + 1/K_z) once per revolution. The rotor period (~0.5 s) is far longer
//! than every mechanical time constant of the contact (~10 ms, the bar-type transient
//! paper), so the speed follows the preload quasi-statically: Ω(φ) = Ω_ss(F + ΔF·cos φ).

pub use crate::contact::contact_normal_stiffness_n_per_m;
use crate::error::TrumError;
use crate::params::Motor;
use crate::solve::{solve_prepared, OperatingPoint, Prepared, Solution, Status, RAD_S_TO_RPM};
use std::f64::consts::PI;

/// Speed statistics over one revolution.
#[derive(Clone, Debug, PartialEq)]
pub struct Fluctuation {
    /// Status of the worst sample (a stall anywhere stalls the rotor).
    pub status: Status,
    /// Preload ripple amplitude ΔF [N].
    pub preload_ripple_n: f64,
    /// Time-averaged speed over a revolution [rpm].
    pub mean_speed_rpm: f64,
    /// Time-weighted standard deviation of speed over a revolution [rpm].
    pub speed_std_rpm: f64,
    /// Smallest and largest contact angle over the revolution [deg] (Chen et al. 2020 Fig.
    /// 7).
    pub contact_angle_range_deg: (f64, f64),
}

/// Speed fluctuation at `op` for an axial runout `runout_m` [m], sampled at `samples`
/// rotor angles (≥ 4; 16 resolves the once-per-revolution harmonic to < 1e-6).
///
/// The mean is the time average 2π/T (the harmonic mean of the sampled speeds) and the
/// standard deviation is weighted by the time spent at each angle (∝ 1/Ω).
pub fn speed_fluctuation(
    motor: &Motor,
    op: &OperatingPoint,
    runout_m: f64,
    samples: usize,
) -> Result<Fluctuation, TrumError> {
    if !(runout_m.is_finite() && runout_m >= 0.0) {
        return Err(TrumError::input(format!("runout_m = {runout_m} must be a finite number >= 0")));
    }
    let p = Prepared::new(motor);
    let nominal = solve_prepared(&p, motor, op, None);
    Ok(fluctuation_about(motor, &p, op, &nominal, runout_m, samples.max(4)))
}

pub(crate) fn fluctuation_about(
    motor: &Motor,
    p: &Prepared,
    op: &OperatingPoint,
    nominal: &Solution,
    runout_m: f64,
    samples: usize,
) -> Fluctuation {
    if !nominal.status.is_valid() || nominal.status == Status::Clamped {
        return Fluctuation {
            status: nominal.status,
            preload_ripple_n: 0.0,
            mean_speed_rpm: nominal.speed_rpm,
            speed_std_rpm: 0.0,
            contact_angle_range_deg: (nominal.contact_angle_deg, nominal.contact_angle_deg),
        };
    }
    let kz = contact_normal_stiffness_n_per_m(motor, nominal.contact_half_angle_rad);
    let ksp = motor.assembly.axial_spring_stiffness_n_per_m;
    // never let the ripple unload the rotor completely
    let ripple = (runout_m / (1.0 / ksp + 1.0 / kz)).min(0.95 * op.preload_n);
    let mut speeds = Vec::with_capacity(samples);
    let mut xc = (f64::INFINITY, f64::NEG_INFINITY);
    let mut status = Status::Ok;
    let mut prev = Some(nominal.clone());
    for j in 0..samples {
        let phi = 2.0 * PI * j as f64 / samples as f64;
        let mut o = *op;
        o.preload_n = op.preload_n + ripple * phi.cos();
        let s = solve_prepared(p, motor, &o, prev.as_ref());
        // an invalid sample decides the status; a valid one with a warning only while none is set
        if !s.status.is_valid() || (s.status != Status::Ok && status == Status::Ok) {
            status = s.status;
        }
        xc = (xc.0.min(s.contact_angle_deg), xc.1.max(s.contact_angle_deg));
        speeds.push(s.speed_rad_s);
        prev = Some(s);
    }
    let (mean, std) = if speeds.iter().any(|&w| w <= 0.0) {
        (0.0, 0.0)
    } else {
        let tsum: f64 = speeds.iter().map(|w| 1.0 / w).sum();
        let mean = speeds.len() as f64 / tsum;
        let var: f64 = speeds.iter().map(|w| (w - mean).powi(2) / w).sum::<f64>() / tsum;
        (mean, var.sqrt())
    };
    Fluctuation {
        status,
        preload_ripple_n: ripple,
        mean_speed_rpm: mean * RAD_S_TO_RPM,
        speed_std_rpm: std * RAD_S_TO_RPM,
        contact_angle_range_deg: xc,
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::presets::frozen as preset;

    #[test]
    fn zero_runout_gives_no_fluctuation_and_small_runout_is_linear() {
        let m = preset("trum60a").expect("preset");
        let op = OperatingPoint::new(250.0, 0.2, 200.0, 43e3);
        let f0 = speed_fluctuation(&m, &op, 0.0, 16).expect("valid runout");
        // Zero up to rounding: the samples are warm-started from each other, and warm and
        // cold solves agree to the solver's tolerance, not to the last bit.
        assert!(f0.speed_std_rpm <= 1e-12 * f0.mean_speed_rpm, "{}", f0.speed_std_rpm);
        let s = crate::solve(&m, &op);
        assert!((f0.mean_speed_rpm - s.speed_rpm).abs() < 1e-9 * s.speed_rpm);
        // std ≈ |dΩ/dF|·ΔF/√2 for a small ripple (first-order perturbation)
        let f1 = speed_fluctuation(&m, &op, 1e-6, 32).expect("valid runout");
        let h = 0.5;
        let mut a = op;
        a.preload_n += h;
        let mut b = op;
        b.preload_n -= h;
        let slope = (crate::solve(&m, &a).speed_rpm - crate::solve(&m, &b).speed_rpm) / (2.0 * h);
        let expect = slope.abs() * f1.preload_ripple_n / 2f64.sqrt();
        assert!((f1.speed_std_rpm - expect).abs() < 0.02 * expect, "{} vs {expect}", f1.speed_std_rpm);
        assert!(speed_fluctuation(&m, &op, -1.0, 16).is_err());
    }
}
