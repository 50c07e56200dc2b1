//! Harmonic-balance identification of β from a sampled isolated-electrode (feedback)
//! voltage (the Hertzian driving-circuit paper (2022) eq. 5-9).
//!
//! The feedback voltage is v(t) = g·w(t) (the Hertzian driving-circuit paper (2022) eq. 1, g = κ/C_0 in V/m). With the
//! complex Fourier coefficients a_n of w, b_n of w³ and c_n of the forcing, eq. 2 balances
//! harmonic by harmonic (eq. 8, with the linear stiffness the printed form omits):
//!
//! ```text
//! (k − n²ω²m + i·nωc)·a_n + β·b_n = c_n,   c_0 = N, c_{±1} = F/2, c_n = 0 otherwise.
//! ```
//!
//! β is the real weighted least-squares solution over n = 1..H (and n = 0 if the static
//! force is given): β = Σ w_n Re(b̄_n r_n) / Σ w_n |b_n|², r_n = c_n − D_n a_n,
//! D_n = k − n²ω²m + i nωc, w_n = (2 for n ≥ 1 — the ±n pair —, 1 for n = 0) / |D_n|².
//! The 1/|D_n|² weight measures every balance in displacement units (output error, the
//! maximum-likelihood weighting for white measurement noise); unweighted balances let the
//! noise of the stiffness-dominated higher harmonics (|D_3| ≈ 8k) swamp β. This replaces
//! the garbled eq. 9.
//! a_n come from a least-squares fit of the drive harmonics to the samples (any sample
//! spacing); b_n are the exact Fourier coefficients of the cube of the fitted series
//! (computed on a fine uniform grid), so additive measurement noise does not bias b_n.

use super::{check_finite, check_positive, not_ge, not_gt, HertzError, HertzResult};
use nalgebra::{DMatrix, DVector};
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// Input of [`identify_beta`].
#[derive(Debug, Clone, Copy)]
pub struct BetaIdentificationInput<'a> {
    /// Sample times, s, strictly increasing, spanning at least 4 drive periods.
    pub sample_times_s: &'a [f64],
    /// Feedback-electrode voltage samples, V (same length as `sample_times_s`).
    pub samples_v: &'a [f64],
    /// Drive frequency f (drive force F·cos 2πft with t on the same time base), Hz, > 0.
    pub drive_frequency_hz: f64,
    /// Feedback gain g of v = g·w, V/m, non-zero.
    pub feedback_gain_v_per_m: f64,
    /// Harmonic drive force amplitude F (A·V + k_c·N), N, finite.
    pub drive_force_amplitude_n: f64,
    /// Static force N (preload) if the DC balance should be used, N.
    pub static_force_n: Option<f64>,
    /// Modal mass m, kg, > 0.
    pub modal_mass_kg: f64,
    /// Modal damping c, N·s/m, >= 0.
    pub damping_ns_per_m: f64,
    /// Linear stiffness k, N/m, > 0 (see [`linear_stiffness_from_resonance_n_per_m`]).
    pub linear_stiffness_n_per_m: f64,
    /// Number of harmonics H in the Fourier fit, 1 ..= 16 (3 is typical).
    pub harmonics: usize,
}

/// Result of [`identify_beta`].
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct BetaIdentification {
    /// Identified cubic coefficient β, N/m³ (multi-harmonic least squares).
    pub beta_n_per_m3: f64,
    /// β from the fundamental balance alone (one-term harmonic balance about the measured
    /// mean w̄: w = w̄ + Re(A e^{iωt}), β = Re[(F − (k − mω² + icω)A)·Ā] / (|A|²(3w̄² + ¾|A|²))),
    /// N/m³.
    pub one_term_beta_n_per_m3: f64,
    /// Fraction of the sample variance explained by the fitted harmonic series (R²).
    pub harmonic_fit_r_squared: f64,
    /// RMS of the sample residual of the harmonic series, V.
    pub waveform_residual_rms_v: f64,
    /// RMS over the balanced harmonics of the residual e_n = (D_n a_n + β b_n − c_n)/D_n
    /// (displacement-equivalent harmonic-balance error), m.
    pub balance_residual_rms_m: f64,
    /// ‖e_n‖ / ‖a_n‖ over the balanced harmonics (0 is a perfect fit).
    pub balance_relative_residual: f64,
    /// Fundamental displacement amplitude |A|, m.
    pub displacement_amplitude_m: f64,
    /// Number of drive periods spanned by the record.
    pub periods_spanned: f64,
}

/// Linear stiffness from a linear resonance, k = m(2πf)², N/m. m in kg (> 0), f in Hz
/// (> 0). the Hertzian driving-circuit paper (2022) eq. 2 with β = 0.
pub fn linear_stiffness_from_resonance_n_per_m(modal_mass_kg: f64, frequency_hz: f64) -> HertzResult<f64> {
    check_positive("modal_mass_kg", modal_mass_kg)?;
    check_positive("frequency_hz", frequency_hz)?;
    let w = 2.0 * PI * frequency_hz;
    Ok(modal_mass_kg * w * w)
}

/// Complex number as (re, im).
type C = (f64, f64);

struct HarmonicFit {
    /// Complex exponential coefficients a_0..a_H (a_n for e^{inωt}).
    coeffs: Vec<C>,
    r_squared: f64,
    residual_rms: f64,
}

/// Least-squares fit of v(t) ≈ α_0 + Σ (α_n cos nωt + γ_n sin nωt); returns a_n = (α_n − iγ_n)/2.
fn fit_harmonics(t: &[f64], v: &[f64], omega: f64, h: usize) -> HertzResult<HarmonicFit> {
    let ncol = 2 * h + 1;
    let mut ata = DMatrix::<f64>::zeros(ncol, ncol);
    let mut atb = DVector::<f64>::zeros(ncol);
    let mut row = vec![0.0; ncol];
    let t0 = t.first().copied().unwrap_or(0.0);
    let _ = t0;
    for (&ti, &vi) in t.iter().zip(v) {
        row[0] = 1.0;
        for n in 1..=h {
            let ph = omega * n as f64 * ti;
            row[2 * n - 1] = ph.cos();
            row[2 * n] = ph.sin();
        }
        for i in 0..ncol {
            atb[i] += row[i] * vi;
            for j in i..ncol {
                ata[(i, j)] += row[i] * row[j];
            }
        }
    }
    for i in 0..ncol {
        for j in 0..i {
            ata[(i, j)] = ata[(j, i)];
        }
    }
    let chol = ata.cholesky().ok_or(HertzError::Degenerate("harmonic least-squares matrix is singular"))?;
    let x = chol.solve(&atb);
    let mut coeffs = vec![(x[0], 0.0)];
    for n in 1..=h {
        coeffs.push((0.5 * x[2 * n - 1], -0.5 * x[2 * n]));
    }
    let mean = v.iter().sum::<f64>() / v.len() as f64;
    let (mut ss_res, mut ss_tot) = (0.0, 0.0);
    for (&ti, &vi) in t.iter().zip(v) {
        let mut fit = x[0];
        for n in 1..=h {
            let ph = omega * n as f64 * ti;
            fit += x[2 * n - 1] * ph.cos() + x[2 * n] * ph.sin();
        }
        ss_res += (vi - fit).powi(2);
        ss_tot += (vi - mean).powi(2);
    }
    let r_squared = if ss_tot > 0.0 { 1.0 - ss_res / ss_tot } else { 0.0 };
    Ok(HarmonicFit { coeffs, r_squared, residual_rms: (ss_res / v.len() as f64).sqrt() })
}

/// Fourier coefficients b_0..b_H of (Σ_{|n|≤H} a_n e^{inθ})³, exact for a grid of
/// M > 6H points (the cube is a trigonometric polynomial of degree 3H).
fn cube_coefficients(a: &[C], h: usize) -> Vec<C> {
    let m = 8 * (3 * h + 1);
    let mut b = vec![(0.0, 0.0); h + 1];
    for j in 0..m {
        let th = 2.0 * PI * j as f64 / m as f64;
        let mut w = a[0].0;
        for (n, an) in a.iter().enumerate().skip(1) {
            let (c, s) = ((n as f64 * th).cos(), (n as f64 * th).sin());
            // a_n e^{inθ} + conj = 2 Re(a_n e^{inθ})
            w += 2.0 * (an.0 * c - an.1 * s);
        }
        let w3 = w * w * w;
        for (n, bn) in b.iter_mut().enumerate() {
            let (c, s) = ((n as f64 * th).cos(), (n as f64 * th).sin());
            bn.0 += w3 * c / m as f64;
            bn.1 -= w3 * s / m as f64;
        }
    }
    b
}

/// Identifies β by harmonic balance from a sampled feedback-electrode voltage
/// (the Hertzian driving-circuit paper (2022) eq. 5-9, corrected; see module docs).
///
/// Errors: [`HertzError::TooShort`] (fewer than 4 drive periods, fewer than
/// 4(2H+1) samples or fewer than 2H+2 samples per period on average),
/// [`HertzError::NonFinite`], [`HertzError::LengthMismatch`],
/// [`HertzError::NonMonotonicTime`], [`HertzError::NonPeriodic`] (harmonic series explains
/// < 90 % of the variance, or the fundamental differs by > 5 % between the two halves of
/// the record), [`HertzError::InvalidParameter`], [`HertzError::Degenerate`]
/// (zero amplitude). Never panics.
pub fn identify_beta(input: &BetaIdentificationInput<'_>) -> HertzResult<BetaIdentification> {
    let t = input.sample_times_s;
    let v = input.samples_v;
    if t.len() != v.len() {
        return Err(HertzError::LengthMismatch { left: t.len(), right: v.len() });
    }
    let f = check_positive("drive_frequency_hz", input.drive_frequency_hz)?;
    let g = check_finite("feedback_gain_v_per_m", input.feedback_gain_v_per_m)?;
    if g == 0.0 {
        return Err(HertzError::InvalidParameter {
            name: "feedback_gain_v_per_m",
            value: g,
            reason: "must be non-zero",
        });
    }
    let force = check_finite("drive_force_amplitude_n", input.drive_force_amplitude_n)?;
    let m = check_positive("modal_mass_kg", input.modal_mass_kg)?;
    let c = super::check_non_negative("damping_ns_per_m", input.damping_ns_per_m)?;
    let k = check_positive("linear_stiffness_n_per_m", input.linear_stiffness_n_per_m)?;
    if let Some(n0) = input.static_force_n {
        check_finite("static_force_n", n0)?;
    }
    let h = input.harmonics;
    if !(1..=16).contains(&h) {
        return Err(HertzError::InvalidParameter { name: "harmonics", value: h as f64, reason: "must be in 1 ..= 16" });
    }
    if let Some(i) = t.iter().position(|x| !x.is_finite()) {
        return Err(HertzError::NonFinite { name: "sample_times_s", index: i });
    }
    if let Some(i) = v.iter().position(|x| !x.is_finite()) {
        return Err(HertzError::NonFinite { name: "samples_v", index: i });
    }
    let min_samples = 4 * (2 * h + 1);
    if t.len() < min_samples {
        return Err(HertzError::TooShort { reason: format!("{} samples, need at least {min_samples}", t.len()) });
    }
    if let Some(i) = t.windows(2).position(|w| w[1] <= w[0]) {
        return Err(HertzError::NonMonotonicTime { index: i + 1 });
    }
    let span = t[t.len() - 1] - t[0];
    let periods = span * f;
    if not_ge(periods, 4.0) {
        return Err(HertzError::TooShort { reason: format!("record spans {periods:.3} drive periods, need >= 4") });
    }
    let per_period = t.len() as f64 / periods;
    if per_period < (2 * h + 2) as f64 {
        return Err(HertzError::TooShort {
            reason: format!("{per_period:.2} samples per period, need >= {} for {h} harmonics", 2 * h + 2),
        });
    }
    let omega = 2.0 * PI * f;
    let fit = fit_harmonics(t, v, omega, h)?;
    if not_ge(fit.r_squared, 0.9) {
        return Err(HertzError::NonPeriodic {
            reason: format!("harmonic series explains R² = {:.4} < 0.9 of the variance", fit.r_squared),
        });
    }
    // Periodicity: the fundamental must agree between the two halves of the record.
    let mid = t.partition_point(|&x| x < t[0] + 0.5 * span);
    if mid >= min_samples / 2 && t.len() - mid >= min_samples / 2 {
        let f1 = fit_harmonics(&t[..mid], &v[..mid], omega, h)?;
        let f2 = fit_harmonics(&t[mid..], &v[mid..], omega, h)?;
        let (p, q) = (f1.coeffs[1], f2.coeffs[1]);
        let diff = (p.0 - q.0).hypot(p.1 - q.1);
        let scale = fit.coeffs[1].0.hypot(fit.coeffs[1].1);
        if not_gt(scale, 0.0) || diff > 0.05 * scale {
            return Err(HertzError::NonPeriodic {
                reason: format!(
                    "fundamental differs by {:.2} % between record halves",
                    100.0 * diff / scale.max(1e-300)
                ),
            });
        }
    }
    // Displacement coefficients.
    let a: Vec<C> = fit.coeffs.iter().map(|&(re, im)| (re / g, im / g)).collect();
    let amp = 2.0 * a[1].0.hypot(a[1].1);
    if not_gt(amp, 0.0) {
        return Err(HertzError::Degenerate("zero fundamental amplitude"));
    }
    let b = cube_coefficients(&a, h);
    // Residuals r_n = c_n − D_n a_n, D_n = k − n²ω²m + i nωc. Output-error weighting:
    // each balance divided by D_n (displacement units), i.e. weights mult_n / |D_n|².
    let start = if input.static_force_n.is_some() { 0 } else { 1 };
    let forcing = |n: usize| match n {
        0 => input.static_force_n.unwrap_or(0.0),
        1 => 0.5 * force,
        _ => 0.0,
    };
    let mut rs: Vec<(f64, C, C, C)> = Vec::new(); // (weight, r_n, b_n, D_n)
    for n in start..=h {
        let nf = n as f64;
        let d = (k - nf * nf * omega * omega * m, nf * omega * c);
        let d2 = d.0 * d.0 + d.1 * d.1;
        if not_gt(d2, 0.0) {
            return Err(HertzError::Degenerate("a harmonic coincides with the undamped linear resonance"));
        }
        let da = (d.0 * a[n].0 - d.1 * a[n].1, d.0 * a[n].1 + d.1 * a[n].0);
        let mult = if n == 0 { 1.0 } else { 2.0 };
        rs.push((mult / d2, (forcing(n) - da.0, -da.1), b[n], d));
    }
    let (mut num, mut den) = (0.0, 0.0);
    for &(wgt, r, bn, _) in &rs {
        num += wgt * (bn.0 * r.0 + bn.1 * r.1);
        den += wgt * (bn.0 * bn.0 + bn.1 * bn.1);
    }
    if not_gt(den, 0.0) {
        return Err(HertzError::Degenerate("cubic term has no harmonic content"));
    }
    let beta = num / den;
    let (mut res2, mut amp2, mut cnt) = (0.0, 0.0, 0.0);
    for (i, &(wgt, r, bn, d)) in rs.iter().enumerate() {
        let e = (r.0 - beta * bn.0, r.1 - beta * bn.1);
        let mult = wgt * (d.0 * d.0 + d.1 * d.1);
        res2 += wgt * (e.0 * e.0 + e.1 * e.1);
        let an = a[start + i];
        amp2 += mult * (an.0 * an.0 + an.1 * an.1);
        cnt += mult;
    }
    // One-term harmonic balance with A = 2a_1.
    let big_a = (2.0 * a[1].0, 2.0 * a[1].1);
    let d1 = (k - omega * omega * m, omega * c);
    let r1 = (force - (d1.0 * big_a.0 - d1.1 * big_a.1), -(d1.0 * big_a.1 + d1.1 * big_a.0));
    let a2 = big_a.0 * big_a.0 + big_a.1 * big_a.1;
    let mean = a[0].0;
    let one_term = (r1.0 * big_a.0 + r1.1 * big_a.1) / (a2 * (3.0 * mean * mean + 0.75 * a2));
    Ok(BetaIdentification {
        beta_n_per_m3: beta,
        one_term_beta_n_per_m3: one_term,
        harmonic_fit_r_squared: fit.r_squared,
        waveform_residual_rms_v: fit.residual_rms,
        balance_residual_rms_m: (res2 / cnt.max(1.0)).sqrt(),
        balance_relative_residual: if amp2 > 0.0 { (res2 / amp2).sqrt() } else { f64::INFINITY },
        displacement_amplitude_m: amp,
        periods_spanned: periods,
    })
}
