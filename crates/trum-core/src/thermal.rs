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
}
