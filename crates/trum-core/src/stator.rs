//! Stator modal dynamics: the traveling wave as two degenerate standing modes driven 90°
//! apart, with the contact's normal and tangential forces acting on them.
//!
//! Each mode obeys m·q̈ + c·q̇ + k_s·q = Θ·V_phase + (contact force on the mode) (Sun et
//! al. 2021 eq. 6; Chen et al. 2020 Appendix A, eq. A1-A4 with ε = 0). In steady state the
//! traveling wave q_A + i·q_B = W·e^{i(ωt−ψ)} gives one complex balance Θ·V = [k_s + k_add
//! − m·ω² + i·ω·(c + c_t)]·W·e^{−iψ}, where c_t is the equivalent damping of the friction
//! forces (power taken from the wave / (ω·W)²) and k_add any stiffness the effects add
//! (preload stiffening, Hertzian softening). This is Sun et al. 2021 eq. 14 with the
//! friction damping made explicit; see docs/MODEL.md for why the N22·F_N term of eq. 14 is
//! not in the baseline.

use crate::contact::{self, Contact};
use crate::effects::Effect;
use crate::solve::bracket::SignBracket;
use crate::solve::trial::Drive;
use crate::solve::Prepared;

/// Angular frequency ω = 2π·f [rad/s].
#[inline]
pub fn angular_frequency(frequency_hz: f64) -> f64 {
    2.0 * std::f64::consts::PI * frequency_hz
}

/// Modal stiffness k_s = m·(2π·f_r)² [N/m] from the free resonance.
#[inline]
pub fn modal_stiffness_n_per_m(modal_mass_kg: f64, resonance_frequency_hz: f64) -> f64 {
    let w = angular_frequency(resonance_frequency_hz);
    modal_mass_kg * w * w
}

/// Crest tangential surface speed v0 = k·h0·ω·W [m/s] (Sun et al. 2021 eq. 12, Chen et al.
/// 2020 eq. 1).
#[inline]
pub fn crest_surface_speed_m_s(
    wavenumber_per_m: f64,
    neutral_plane_distance_m: f64,
    omega_rad_s: f64,
    amplitude_m: f64,
) -> f64 {
    wavenumber_per_m * neutral_plane_distance_m * omega_rad_s * amplitude_m
}

/// Complex modal impedance Z = (k_eff − m·ω²) + i·ω·c_total [N/m]; returns (re, im).
#[inline]
pub fn impedance(k_eff_n_per_m: f64, modal_mass_kg: f64, omega_rad_s: f64, damping_total_ns_per_m: f64) -> (f64, f64) {
    (k_eff_n_per_m - modal_mass_kg * omega_rad_s * omega_rad_s, omega_rad_s * damping_total_ns_per_m)
}

/// Phase current of one phase as (in-phase, quadrature) amplitudes [A]: dielectric
/// (ω·C0·V·tan δ), capacitive (ω·C0·V) and motional (i·ω·Θ·W·e^{−iψ}) parts.
pub fn phase_current_a(
    voltage_v: f64,
    omega_rad_s: f64,
    capacitance_f: f64,
    loss_tangent: f64,
    force_factor_n_per_v: f64,
    z: (f64, f64),
) -> (f64, f64) {
    let z2 = z.0 * z.0 + z.1 * z.1;
    let g = omega_rad_s * force_factor_n_per_v * force_factor_n_per_v * voltage_v / z2;
    (
        voltage_v * omega_rad_s * capacitance_f * loss_tangent + g * z.1,
        voltage_v * omega_rad_s * capacitance_f + g * z.0,
    )
}

/// Feedback (isolated) electrode voltage amplitude V_f = K_WV·W [V] (Sun et al. 2021 eq. 1;
/// the printed (√2/2) factor is a typo of the sum of two quadrature terms, and in any
/// case K_WV is identified from measured data, so it absorbs the constant).
#[inline]
pub fn feedback_voltage_v(gain_v_per_m: f64, amplitude_m: f64) -> f64 {
    gain_v_per_m * amplitude_m
}

/// The pressed layer's pressure projected on the mode shape, per unit amplitude and per
/// N·k_f/k [-]: ∫ (cos θ − c)₊ cos θ dθ over one wavelength, = φ0 − sin φ0·c with
/// half-angle `phi0_rad` and rotor-plane offset `c` (= cos φ0 in partial contact, ≤ −1 in
/// full contact, where it is π). The stiffness the contact adds to the mode in the
/// radial-friction paper section 5.3 (the normal contact force on the generalised
/// coordinate, in phase with it); `preload_stiffening` with modal fraction 1. Equals Sun et
/// al. 2021 eq. 8's χ(φ0) = 2(sin φ0 − φ0·c) to leading order in φ0 (both 2φ0³/3) and half
/// of it at full contact.
#[inline]
pub fn modal_projection(phi0_rad: f64, c: f64) -> f64 {
    phi0_rad - phi0_rad.sin() * c
}

/// Relative spread of the wave amplitude across the contact width in the bench-truth form
/// of `preload_stiffening` [-]: the bending mode's amplitude grows across the tooth face
/// from the inner to the outer edge, a(ξ) = 1 + 0.3·ξ for ξ ∈ [−1, 1] (assumed: a 9-wave
/// ring mode grows steeply with radius; no paper gives the figure).
pub const TRUTH_WIDTH_SPREAD: f64 = 0.3;

/// Bench-truth form of `preload_stiffening` (docs/EFFECTS.md, candidate and truth forms):
/// the modal projection of [`modal_projection`] integrated over the contact width, where
/// the amplitude is a(ξ) = 1 + [`TRUTH_WIDTH_SPREAD`]·ξ and the rigid rotor's plane stays at
/// c·W. A strip touches over cos φ = c/a, presses with W·(a cos θ − c)₊ and projects on the
/// local mode shape a·cos θ, so it adds a²·modal_projection(φ, c/a). Five-point Gauss–
/// Legendre over ξ (the width mean); per unit amplitude and per N·k_f/k [-].
pub fn width_integrated_modal_projection(c: f64) -> f64 {
    // nodes and weights of the five-point Gauss–Legendre rule on [−1, 1], weights halved
    const NODES: [f64; 5] =
        [-0.906_179_845_938_664, -0.538_469_310_105_683, 0.0, 0.538_469_310_105_683, 0.906_179_845_938_664];
    const WEIGHTS: [f64; 5] = [
        0.118_463_442_528_094_5,
        0.239_314_335_249_683_2,
        0.284_444_444_444_444_4,
        0.239_314_335_249_683_2,
        0.118_463_442_528_094_5,
    ];
    NODES
        .iter()
        .zip(WEIGHTS)
        .map(|(&xi, w)| {
            let a = 1.0 + TRUTH_WIDTH_SPREAD * xi;
            let ci = c / a;
            let phi = ci.clamp(-1.0, 1.0).acos();
            w * a * a * modal_projection(phi, ci)
        })
        .sum()
}

// The W-dependent modal stiffness of the steady-state solve (crate::solve): preload
// stiffening and Hertz softening on the drive's stiffness, and where they cancel the detuning.

/// The Hertzian driving-circuit paper (2022): the softening cubic term by harmonic balance,
/// k − (3/4)·β·W²; this returns (3/4)·β·(its growth with the preload) [N/m³].
pub(crate) fn softening_per_w2(p: &Prepared, d: &Drive) -> f64 {
    let growth = if p.truth_b(Effect::HertzSoftening) {
        (0.8 * p.beta_gain * d.f_n).exp()
    } else if p.truth(Effect::HertzSoftening) {
        // the first truth family: a Hertzian contact F = c·δ^(3/2) expanded about its
        // static compression δ0 has a cubic term ∝ δ0^(−3/2) ∝ 1/F_N (Johnson 1985,
        // Contact Mechanics, the Hertz solution): the contact's share of the softening
        // falls as it is pressed towards the bulk's constant share, where the falling
        // members of (1 + g·F_N)^n, n < 0, fall towards zero
        1.0 + p.beta_gain * TRUTH_SOFTENING_REFERENCE_N.powi(2) / d.f_n.max(20.0)
    } else if p.beta_exponent != 1.0 {
        hertz_preload_growth(p.beta_gain, p.beta_exponent, d.f_n)
    } else {
        1.0 + p.beta_gain * d.f_n
    };
    0.75 * p.beta * growth
}

/// The preload [N] at which the contact's share of the first truth family's softening is
/// g·F (as in the candidate); it falls as 1/F_N about it (floored at 20 N).
const TRUTH_SOFTENING_REFERENCE_N: f64 = 200.0;

/// `hertz_softening`'s preload family: the cubic coefficient's growth with the preload,
/// 2·((1 + g·F_N)/2)^n [-]: the candidate's 1 + g·F_N at n = 1, and every member meets it
/// where g·F_N = 1, so that the exponent changes how the softening varies with the preload
/// and not how strong it is there (a strength means the same in every form, and the
/// diagnosis' scan tries each form at the same strengths). The Hertzian driving-circuit
/// paper (2022, eq. 2-4) takes the contact's cubic term in proportion to its load (n = 1);
/// the stiffness of a Hertzian contact itself grows as F^(1/3) (point) to F^(1/2) and its
/// nonlinear terms faster (n up to 3). Expanded about its static compression δ0, a contact
/// F = c·δ^(3/2) has a cubic term ∝ δ0^(−3/2) ∝ 1/F_N (Johnson 1985, Contact Mechanics,
/// the Hertz solution): a softening that falls as the contact is pressed, n = −1 where
/// g·F_N ≫ 1. A bench may show any n in [−1, 3].
pub(crate) fn hertz_preload_growth(g: f64, n: f64, f_n: f64) -> f64 {
    2.0 * (0.5 * (1.0 + g * f_n)).max(0.0).powf(n)
}

/// The modal stiffness at amplitude `w` [m] with contact `ct` and force scale `a` [N]: the
/// drive's stiffness, plus preload stiffening, minus Hertz softening [N/m]. Both W-dependent
/// terms fall as W grows (the contact narrows; ¾·β·W² grows), for every valid strength.
pub(crate) fn modal_stiffness(p: &Prepared, d: &Drive, w: f64, ct: &Contact, a: f64) -> f64 {
    let mut k_eff = d.ks;
    if p.stiffening != 0.0 {
        let layer = p.n * p.kf / p.k;
        k_eff += p.stiffening
            * if p.truth_b(Effect::PreloadStiffening) {
                // the second truth family: the axial form of the contact stiffness with a
                // layer that stiffens as it is pressed
                a * ct.chi0() / w * (1.0 + d.f_n / 300.0)
            } else if p.truth(Effect::PreloadStiffening) {
                layer * width_integrated_modal_projection(ct.offset)
            } else {
                // Sun et al. 2021 eq. 8: k_s' = (2 n k_f / k)·[sin(kx0) − kx0·cos(kx0)] =
                // A·χ(φ0)/W
                let axial = a * ct.chi0() / w;
                if p.modal_fraction == 0.0 {
                    axial
                } else {
                    // (exact at both ends: λ = 1 is the radial-friction paper's projection
                    // bit for bit)
                    let modal = layer * modal_projection(ct.half_angle_rad, ct.offset);
                    (1.0 - p.modal_fraction) * axial + p.modal_fraction * modal
                }
            };
    }
    if p.beta != 0.0 {
        k_eff -= softening_per_w2(p, d) * w * w;
    }
    k_eff
}

/// Re Z without friction: the modal stiffness at `w` less m·ω² [N/m]; falls as W grows.
pub(crate) fn elastic_detuning(p: &Prepared, d: &Drive, w: f64) -> f64 {
    let a = contact::force_scale_n(p.n, p.kf, w, p.k);
    let (ct, _, _) = contact::contact_from_ratio_near(d.f_n / a, None);
    modal_stiffness(p, d, w, &ct, a) - p.m * d.omega * d.omega
}

/// The amplitude in (0, `w_top`) where the W-dependent stiffness cancels the detuning k −
/// m·ω² (Re Z = 0 without friction), where G(W) = Θ·V/|Z(W)| peaks; `None` where the
/// elastic detuning keeps one sign below `w_top`. Closed forms for one candidate effect —
/// softening k − ¾βW² (the Hertzian driving-circuit paper (2022)), stiffening k + s·F/W
/// (A·χ(φ0) = F, Sun et al. 2021 eq. 8) — else Illinois regula falsi on ln W, the detuning
/// falling monotonically in W.
pub(crate) fn stiffness_crossing(p: &Prepared, d: &Drive, w_top: f64) -> Option<f64> {
    let detuning = d.ks - p.m * d.omega * d.omega;
    let w = match (p.stiffening != 0.0, p.beta != 0.0) {
        (false, false) => return None,
        // the truth form's softening is also ∝ W² (its preload growth differs)
        (false, true) => (detuning > 0.0).then(|| (detuning / softening_per_w2(p, d)).sqrt())?,
        // (Sun et al. 2021 eq. 8 alone: A·χ(φ0)/W = F/W)
        (true, false) if !p.truth(Effect::PreloadStiffening) && p.modal_fraction == 0.0 => {
            (detuning < 0.0).then(|| p.stiffening * d.f_n / -detuning)?
        }
        _ => {
            let f = |u: f64| elastic_detuning(p, d, u.exp());
            let (mut lo, mut hi) = ((1e-9 * w_top).ln(), w_top.ln());
            let (f_lo, f_hi) = (f(lo), f(hi));
            if !(f_lo > 0.0 && f_hi < 0.0) {
                return None;
            }
            // Bisection while the bracket is wider than 1 % in W: over nine decades Re Z
            // spans many orders of magnitude (the stiffening grows like 1/W), and regula
            // falsi from there had not converged after 100 steps (1e-6 off at generic60,
            // truth-form stiffening 3.3: a test below); then Illinois regula falsi.
            let mut b = SignBracket { neg: Some((hi, f_hi)), pos: Some((lo, f_lo)), last_side: 0 };
            for _ in 0..200 {
                let u = if hi - lo > 1e-2 { 0.5 * (lo + hi) } else { b.regula_falsi()? };
                let fu = f(u);
                if fu > 0.0 {
                    lo = u;
                } else {
                    hi = u;
                }
                // (Re Z is a difference of stiffnesses ~1e8-1e9 N/m: its rounding, through the
                // contact angle, is ~10 N/m, 1e-8 of them; 1e-7 in W is far inside the spike)
                if fu.abs() <= 1e-8 * p.m * d.omega * d.omega {
                    (lo, hi) = (u, u);
                }
                if hi - lo < 1e-7 {
                    break;
                }
                b.record(u, fu, true);
            }
            (0.5 * (lo + hi)).exp()
        }
    };
    (w.is_finite() && w > 0.0 && w < w_top).then_some(w)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quad::integral;
    use std::f64::consts::PI;

    /// The pressure over one wavelength projected on the mode shape, by quadrature.
    fn projected_pressure(c: f64) -> f64 {
        integral(|t| (t.cos() - c).max(0.0) * t.cos(), -PI, PI)
    }

    /// Closed form against its defining integral, partial and full contact (to 1e-11).
    #[test]
    fn the_modal_projection_is_the_projected_pressure() {
        for c in [0.999, 0.9, 0.5, 0.0, -0.5, -0.9, -0.999] {
            let phi: f64 = f64::acos(c);
            // the kinks at ±φ end the panels
            let q = integral(|t| (t.cos() - c) * t.cos(), -phi, phi);
            assert!((modal_projection(phi, c) - q).abs() < 1e-11 * q.max(1e-3), "c = {c}");
        }
        for c in [-1.0, -1.3, -2.0] {
            assert!((modal_projection(PI, c) - projected_pressure(c)).abs() < 1e-11, "full contact, c = {c}");
        }
        // leading order: both forms 2φ³/3 at a narrow contact; half of Sun et al. 2021's at
        // full contact
        let phi: f64 = 1e-2;
        let chi = 2.0 * (phi.sin() - phi * phi.cos());
        assert!((modal_projection(phi, phi.cos()) / chi - 1.0).abs() < 1e-4);
        assert!((modal_projection(PI, -1.0) / (2.0 * PI) - 0.5).abs() < 1e-15);
    }

    /// The truth form's five-point rule against the two-dimensional integral it stands for
    /// (adaptive over the width of the angle integral): within 5e-4 over wide contacts (c ≤
    /// 0.5, φ0 ≥ 60°, where the bench campaigns of trum60a run; 1.0e-4 at most today, at
    /// −0.8 and −1.1, where the outer strips reach full contact), and it differs in form
    /// from every blend of Sun et al. 2021 eq. 8 and the modal projection (the strips reach
    /// full contact one by one): by 3.5 % at best today, at λ = 1.
    #[test]
    fn the_width_integrated_projection_is_its_two_dimensional_integral() {
        let exact = |c: f64| {
            0.5 * integral(
                |xi| {
                    let a = 1.0 + TRUTH_WIDTH_SPREAD * xi;
                    let ci = c / a;
                    if ci >= 1.0 {
                        return 0.0;
                    }
                    let phi = ci.max(-1.0).acos();
                    a * a * integral(|t| (t.cos() - ci) * t.cos(), -phi, phi)
                },
                -1.0,
                1.0,
            )
        };
        for c in [0.5, 0.2, 0.0, -0.4, -0.8, -1.1, -1.5] {
            let (g, e) = (width_integrated_modal_projection(c), exact(c));
            assert!((g / e - 1.0).abs() < 5e-4, "c = {c}: rule {g}, integral {e}");
        }
        // no blend s·[(1 − λ)·χ + λ·M] follows it from a wide partial to a full contact: for
        // each λ the scale s that minimises the largest relative miss over the points (the
        // ratios' midrange) still misses by 3.5 % (at λ = 1)
        let m = |c: f64| if c <= -1.0 { PI } else { modal_projection(c.acos(), c) };
        let chi = |c: f64| if c <= -1.0 { -2.0 * PI * c } else { 2.0 * (c.acos().sin() - c.acos() * c) };
        let t = width_integrated_modal_projection;
        let best = (0..=100)
            .map(|i| {
                let lam = i as f64 / 100.0;
                let ratios =
                    [0.5, 0.3, 0.0, -0.5, -0.95, -1.2, -1.5].map(|c| ((1.0 - lam) * chi(c) + lam * m(c)) / t(c));
                let (lo, hi) = ratios.iter().fold((f64::INFINITY, 0.0_f64), |(l, h), &r| (l.min(r), h.max(r)));
                (hi - lo) / (hi + lo)
            })
            .fold(f64::INFINITY, f64::min);
        assert!(best > 0.03, "a blend follows the truth form within {best}");
    }

    #[test]
    fn electrical_power_equals_mechanical_power_of_the_drive() {
        // Re-part of the motional current times V must equal ω·c·W² with W = ΘV/|Z|.
        let (v, w, theta) = (150.0, angular_frequency(42e3), 0.4);
        let z = impedance(3.3e8, 5e-3, w, 40.0);
        let (ire, _) = phase_current_a(v, w, 0.0, 0.0, theta, z);
        let amp = theta * v / (z.0 * z.0 + z.1 * z.1).sqrt();
        assert!((v * ire - w * w * 40.0 * amp * amp).abs() < 1e-12 * v * ire);
    }
}
