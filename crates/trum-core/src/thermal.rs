//! Temperature rise of the motor from its losses (Chen et al. 2020 eq. 11): a single lumped
//! heat capacity C exchanging heat with ambient air through α·S, T(t) = T_air +
//! P_loss/(α·S)·(1 − exp(−α·S·t/C)). The paper's S is the motor's surface area, α the
//! convective coefficient; C is not given in the paper (the presets document the value
//! assumed).

/// Temperature rise over ambient after `elapsed_s` of constant loss [K] (Chen et al. 2020
/// eq. 11). Valid for loss ≥ 0, α·S > 0, C > 0, t ≥ 0; t → ∞ gives the steady rise P/(α·S).
pub fn temperature_rise_k(loss_w: f64, alpha_s_w_per_k: f64, heat_capacity_j_per_k: f64, elapsed_s: f64) -> f64 {
    loss_w / alpha_s_w_per_k * (1.0 - (-alpha_s_w_per_k * elapsed_s / heat_capacity_j_per_k).exp())
}

/// Thermal time constant C/(α·S) [s].
pub fn time_constant_s(alpha_s_w_per_k: f64, heat_capacity_j_per_k: f64) -> f64 {
    heat_capacity_j_per_k / alpha_s_w_per_k
}

/// Temperature rise over a run whose loss changes with time, by exact integration of
/// C·dT/dt = P(t) − α·S·T over piecewise-constant loss steps `(duration_s, loss_w)`.
/// Returns the rise at the end of every step [K].
pub fn temperature_rise_piecewise_k(
    steps: &[(f64, f64)],
    alpha_s_w_per_k: f64,
    heat_capacity_j_per_k: f64,
) -> Vec<f64> {
    let mut t = 0.0;
    steps
        .iter()
        .map(|&(dt, p)| {
            let target = p / alpha_s_w_per_k;
            let decay = (-alpha_s_w_per_k * dt / heat_capacity_j_per_k).exp();
            t = target + (t - target) * decay;
            t
        })
        .collect()
}

/// The rise a first-order temperature sensor of time constant `lag_s` [s] shows at
/// `elapsed_s` [s] of a warm-up whose stator rise is `rise_at_elapsed_k` there and tends to
/// `rise_ss_k` [K]. The stator follows the lumped model of Chen et al. 2020 (eq. 11),
/// rise_ss·(1 − e^(−t/τ)), whose τ the two rises give (τ = −t/ln(1 − rise_t/rise_ss)); the
/// sensor obeys τ_s·dT_s/dt = T − T_s from the ambient, so it reads
/// rise_ss·[1 − (τ·e^(−t/τ) − τ_s·e^(−t/τ_s))/(τ − τ_s)] (the limit (1 + t/τ)·e^(−t/τ) in
/// the bracket's second term where τ_s = τ). A thermocouple or resistance thermometer
/// bonded to a stator responds in seconds to tens of seconds through its sheath and the
/// bond. Without a lag, at the start, at steady state or where the rise is not a warming
/// (rise_t ≤ 0, rise_ss ≤ 0), the stator's rise itself. Valid for a run at one operating
/// point from the ambient; where the model's rise is not one exponential (`thermal_drift`
/// with a fast interface node) τ is the one that matches the rise at `elapsed_s`.
pub fn sensor_rise_k(rise_ss_k: f64, rise_at_elapsed_k: f64, elapsed_s: f64, lag_s: f64) -> f64 {
    let phi = rise_at_elapsed_k / rise_ss_k;
    if !(lag_s > 0.0 && elapsed_s > 0.0 && rise_ss_k > 0.0 && phi > 0.0 && phi < 1.0) {
        return rise_at_elapsed_k;
    }
    // a = t/τ, b = t/τ_s, r = τ_s/τ
    let a = -(-phi).ln_1p();
    let b = elapsed_s / lag_s;
    let r = a / b;
    let lagging =
        if (1.0 - r).abs() < 1e-6 { (1.0 + a) * (-a).exp() } else { ((-a).exp() - r * (-b).exp()) / (1.0 - r) };
    rise_ss_k * (1.0 - lagging)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn limits_and_ode_agree() {
        let (p, a, c) = (8.0, 0.2366, 60.0);
        assert_eq!(temperature_rise_k(p, a, c, 0.0), 0.0);
        assert!((temperature_rise_k(p, a, c, 1e9) - p / a).abs() < 1e-9);
        // one time constant: 1 − 1/e of the steady rise
        let tau = time_constant_s(a, c);
        assert!((temperature_rise_k(p, a, c, tau) - p / a * (1.0 - (-1.0f64).exp())).abs() < 1e-12);
        // many constant steps = the closed form
        let steps = vec![(1.0, p); 50];
        let pw = temperature_rise_piecewise_k(&steps, a, c);
        assert!((pw[49] - temperature_rise_k(p, a, c, 50.0)).abs() < 1e-12);
        // explicit Euler with a tiny step agrees to its truncation error
        let (mut t, dt) = (0.0f64, 1e-3);
        for _ in 0..50_000 {
            t += dt * (p - a * t) / c;
        }
        assert!((t - pw[49]).abs() < 1e-3 * pw[49]);
    }

    /// The lagged sensor against its own ODE integrated through the lumped warm-up (RK4,
    /// 1 ms steps), at lags below, at and above the stator's time constant; the limits
    /// (no lag, the start, steady state) are the stator's rise itself.
    #[test]
    fn a_lagged_sensor_follows_its_ode() {
        let (p, a, c) = (8.0, 0.2366, 60.0);
        let tau = time_constant_s(a, c);
        let rise = |t: f64| temperature_rise_k(p, a, c, t);
        let ss = p / a;
        for lag in [3.0, 30.0, tau, 400.0] {
            let (mut y, h) = (0.0f64, 1e-3);
            let f = |t: f64, y: f64| (rise(t) - y) / lag;
            let mut t = 0.0;
            for k in 1..=300_000 {
                let k1 = f(t, y);
                let k2 = f(t + 0.5 * h, y + 0.5 * h * k1);
                let k3 = f(t + 0.5 * h, y + 0.5 * h * k2);
                let k4 = f(t + h, y + h * k3);
                y += h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4);
                t = k as f64 * h;
                if k % 50_000 == 0 {
                    let s = sensor_rise_k(ss, rise(t), t, lag);
                    assert!((s - y).abs() < 1e-9 * ss, "lag {lag}, t {t}: {s} vs {y}");
                    assert!(s < rise(t), "a lagging sensor reads low while warming");
                }
            }
        }
        assert_eq!(sensor_rise_k(ss, rise(50.0), 50.0, 0.0), rise(50.0));
        assert_eq!(sensor_rise_k(ss, 0.0, 0.0, 30.0), 0.0);
        assert_eq!(sensor_rise_k(ss, ss, 1e9, 30.0), ss);
        assert_eq!(sensor_rise_k(0.0, 0.0, 50.0, 30.0), 0.0);
    }
}
