//! Stator/rotor contact in the wave frame: contact zone from preload, pressure
//! distribution, axial force, driving (stick) points and the torque integral.
//!
//! Conventions (the papers are inconsistent, see docs/MODEL.md):
//! * θ is the wave phase measured from a wave crest; k = N/R0 is the wave number, so a
//!   circumferential length x corresponds to θ = k·x.
//! * φ0 is the contact **half-angle in wave phase**: contact where |θ| ≤ φ0, 0 < φ0 ≤ π.
//! * The contact angle Xc (Chen et al. 2020 eq. 1-2) is the **full** contact arc in
//!   mechanical degrees: Xc = 2·φ0/(2π)·(360°/N), which is 40·φ0/π for N = 9, so 0 ≤ Xc ≤
//!   40°.
//! * The friction layer is a Winkler bed (Chen et al. 2020 eq. 3, Sun et al. 2021 eq. 5):
//!   pressure per unit circumferential length p(θ) = k_f·W·(cos θ − c), k_f = E_f·b_f/h_f
//!   [N/m²]. In partial contact c = cos φ0; in full contact (the rotor touches the whole
//!   wave, φ0 = π) the rotor sits below the trough and c < −1.

use crate::params::Motor;
use std::f64::consts::PI;

/// χ(θ) = sin θ − θ·c, the integral ∫₀^θ (cos t − c) dt (Sun et al. 2021 eq. 10 with c =
/// cos φ0).
#[inline]
pub fn chi(theta_rad: f64, c: f64) -> f64 {
    theta_rad.sin() - theta_rad * c
}

/// E(θ) = ∫₀^θ (cos t − c)·cos t dt = θ/2 + sin 2θ/4 − c·sin θ: the power-weighted
/// pressure integral used by the friction-power closed forms.
#[inline]
pub fn e_int(theta_rad: f64, c: f64) -> f64 {
    let (s, co) = theta_rad.sin_cos();
    0.5 * theta_rad + 0.5 * s * co - c * s
}

/// Equivalent Winkler stiffness of the friction layer per unit circumferential length,
/// k_f = E_f·b_f/h_f [N/m²] (Sun et al. 2021 eq. 4).
pub fn layer_stiffness_n_per_m2(youngs_modulus_pa: f64, contact_width_m: f64, thickness_m: f64) -> f64 {
    youngs_modulus_pa * contact_width_m / thickness_m
}

/// Force scale A = 2·N·k_f·W/k [N]: the axial force is A·χ(φ0) (Sun et al. 2021 eq. 5,
/// Chen et al. 2020 eq. 6 with the width integral folded into k_f).
#[inline]
pub fn force_scale_n(wave_number: f64, k_f_n_per_m2: f64, amplitude_m: f64, wavenumber_per_m: f64) -> f64 {
    2.0 * wave_number * k_f_n_per_m2 * amplitude_m / wavenumber_per_m
}

/// Normal stiffness of the contact against rotor approach at fixed amplitude [N/m]:
/// K_z = dF/dz = 2·N·k_f·φ0/k (from F = A·χ(φ0) with z = W·cos φ0; π instead of φ0 in
/// full contact). Valid for a solved, vibrating steady state.
pub fn contact_normal_stiffness_n_per_m(motor: &Motor, half_angle_rad: f64) -> f64 {
    let g = &motor.geometry;
    let fl = &motor.friction_layer;
    let kf = layer_stiffness_n_per_m2(fl.youngs_modulus_pa, g.contact_width_m, fl.thickness_m);
    2.0 * g.wave_number * kf * half_angle_rad * g.mean_radius_m / g.wave_number
}

/// The contact zone at one preload and amplitude.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Contact {
    /// Contact half-angle φ0 in wave phase [rad], in (0, π].
    pub half_angle_rad: f64,
    /// Offset c of the pressure profile p = k_f·W·(cos θ − c): cos φ0, or < −1 in full contact.
    pub offset: f64,
    /// True when the rotor touches the whole wave.
    pub full: bool,
}

impl Contact {
    /// χ(φ0) = sin φ0 − φ0·c: the axial force is A·χ(φ0).
    #[inline]
    pub fn chi0(&self) -> f64 {
        chi(self.half_angle_rad, self.offset)
    }
}

#[cfg(test)]
/// g(φ) = sin φ − φ·cos φ, strictly increasing on [0, π] from 0 to π (g' = φ·sin φ).
#[inline]
fn g(phi: f64) -> f64 {
    let (s, c) = phi.sin_cos();
    s - phi * c
}

/// Contact zone from the ratio y = F_N/A of preload to force scale (Sun et al. 2021 eq. 5
/// solved for x0; Chen et al. 2020 eq. 6). Valid for any y > 0: y ≥ π means full contact.
///
/// Inverts g(φ0) = y by safeguarded Newton iteration to 1e-14 in φ0, starting from the
/// small-angle (g ≈ φ³/3) or near-full (g ≈ π − π·ε²/2, ε = π − φ) asymptotes.
pub fn contact_from_ratio(y: f64) -> Contact {
    contact_from_ratio_near(y, None).0
}

/// Where an angle solve starts: an angle [rad] and, where the caller has them, its sine
/// and cosine (then the first Newton step costs no `sin_cos`).
pub type AngleStart = (f64, Option<(f64, f64)>);

/// sin and cos of x + δ from those of x by their Taylor series to δ³ (error below δ⁴/24:
/// 5e-18 at the |δ| ≤ 1e-4 the solver carries them over).
#[inline]
pub fn sin_cos_step((s, c): (f64, f64), d: f64) -> (f64, f64) {
    let (d2, d3) = (0.5 * d * d, d * d * d / 6.0);
    (s + d * c - d2 * s - d3 * c, c - d * s - d2 * c + d3 * s)
}

/// True where [`sin_cos_rotated`] carries the sine and cosine of an angle in (0, π) with
/// sine `sin_x` over the step `step` [rad]: sin x ≥ 1/4 and |δ| ≤ 0.1·sin x. Each
/// rotation rounds the sine by about one unit in its last place, as a fresh `sin_cos`
/// does, but the roundings of a chain of rotations add up, and the functions solved here
/// amplify them where the angle is small (g(φ) = sin φ − φ·cos φ is a difference of
/// nearly equal terms for a narrow contact: a root error of 1e-16/φ per rounding, 1e-14
/// at φ = 0.01). From a quarter up a few roundings stay below 1e-14 of the angle; the
/// bound on the step relative to the sine keeps the rotation's own error (about 1e-16·|δ|
/// absolute) below the sine's rounding where g' = φ·sin φ vanishes towards full contact.
#[inline]
pub fn rotation_carries(sin_x: f64, step: f64) -> bool {
    sin_x >= 0.25 && step.abs() <= 0.1 * sin_x
}

/// sin and cos of x + δ from those of x by the rotation through δ, with sin δ and
/// cos δ − 1 from their Taylor series to δ⁹ and δ¹⁰ (truncation below δ¹¹/11! = 2.5e-19
/// at |δ| ≤ 0.1; each rotation adds a rounding of a few units in the
/// last place). About 20 flops where `sin_cos` costs about 80 instructions: the angle
/// solves move their iterates by such steps.
#[inline]
pub fn sin_cos_rotated((s, c): (f64, f64), d: f64) -> (f64, f64) {
    let d2 = d * d;
    let sin_minus_d = -d * d2 * (1.0 / 6.0 - d2 * (1.0 / 120.0 - d2 * (1.0 / 5040.0 - d2 * (1.0 / 362_880.0))));
    let cos_minus_1 =
        -d2 * (0.5 - d2 * (1.0 / 24.0 - d2 * (1.0 / 720.0 - d2 * (1.0 / 40_320.0 - d2 * (1.0 / 3_628_800.0)))));
    let sd = d + sin_minus_d;
    (s + (c * sd + s * cos_minus_1), c + (c * cos_minus_1 - s * sd))
}

/// [`contact_from_ratio`] started from `guess` (a nearby φ0, e.g. of the previous
/// amplitude iterate; the root is unique, so the start only changes the cost). Also
/// returns (sin φ0, cos φ0), which the solver would otherwise recompute.
pub fn contact_from_ratio_near(y: f64, guess: Option<AngleStart>) -> (Contact, f64, f64) {
    if y >= PI {
        // Full contact: p = k_f W (cos θ − c) over the whole wave, ∫ = −2π c / k  ⇒  c = −y/π.
        return (Contact { half_angle_rad: PI, offset: -y / PI, full: true }, PI.sin(), -1.0);
    }
    if y <= 0.0 {
        return (Contact { half_angle_rad: 0.0, offset: 1.0, full: false }, 0.0, 1.0);
    }
    let start = guess.filter(|g| g.0 > 0.0 && g.0 < PI).unwrap_or(if y < 1.5 {
        ((3.0 * y).cbrt().min(PI * 0.999), None)
    } else {
        (PI - (2.0 * (PI - y) / PI).sqrt(), None)
    });
    // g' = φ·sin φ, g'' = sin φ + φ·cos φ, g''' = 2·cos φ − φ·sin φ.
    let (phi, s, c) =
        newton_sin_cos(|p, s, c| [s - p * c - y, p * s, s + p * c, 2.0 * c - p * s], (0.0, -y), (PI, PI - y), start);
    (Contact { half_angle_rad: phi, offset: c, full: false }, s, c)
}

/// Root of an increasing f on the bracket [lo, hi] (f(lo) ≤ 0 ≤ f(hi), values given) by
/// safeguarded Halley iteration. `f(x, sin x, cos x)` returns [f, f′, f″, f‴]: every
/// function solved here is made of sin and cos of the unknown, so one sine and cosine per
/// iteration serves the value, the derivatives and the caller, who gets (x, sin x, cos x)
/// back; a start with its sine and cosine saves the first.
///
/// Halley's step is Newton's δ = f/f′ divided by 1 − δ·f″/(2f′), taken where that
/// correction is at most a half (Newton's step otherwise): its error is about
/// (c₂² − c₃)·δ³ with cₖ = f⁽ᵏ⁾/(k!·f′), against Newton's c₂·δ², so a start within 1e-2
/// of the root needs two evaluations, not three. A step that would leave the bracket is
/// replaced by regula falsi on the bracket (bisection if that stalls): near a root at the
/// bracket's edge, a step from the far side overshoots, and plain bisection then needed
/// ~30 iterations. Once the predicted error after a step is below 1e-16 relative the step
/// is taken without another evaluation, and sin/cos are carried over it by their Taylor
/// series (`sin_cos_step`, error δ⁴/24 < 1e-21). Between evaluations sin and cos are
/// rotated through the step where [`rotation_carries`] allows it ([`sin_cos_rotated`])
/// and recomputed after longer ones.
fn newton_sin_cos(
    f: impl Fn(f64, f64, f64) -> [f64; 4],
    (mut lo, mut flo): (f64, f64),
    (mut hi, mut fhi): (f64, f64),
    (start, start_sin_cos): AngleStart,
) -> (f64, f64, f64) {
    let inside = start > lo && start < hi;
    let mut x = if inside { start } else { 0.5 * (lo + hi) };
    let (mut s, mut c) = start_sin_cos.filter(|_| inside).unwrap_or_else(|| x.sin_cos());
    let mut stalled = 0;
    for _ in 0..100 {
        let [v, d, dd, ddd] = f(x, s, c);
        if v > 0.0 {
            (hi, fhi) = (x, v);
        } else {
            (lo, flo) = (x, v);
        }
        let newton = v / d;
        let (c2, c3) = (0.5 * dd / d, ddd / (6.0 * d));
        let halley = (newton * c2).abs() <= 0.5;
        let step = if halley { newton / (1.0 - newton * c2) } else { newton };
        let next = x - step;
        let from = x;
        if d > 0.0 && next > lo && next < hi {
            // Predicted error after the step; the step bound keeps the next term of the
            // series negligible where the leading one happens to vanish.
            let error = if halley { (c2 * c2 + c3.abs()) * step.abs().powi(3) } else { c2.abs() * step * step };
            if step.abs() <= if halley { 1e-5 } else { 1e-7 } * x.abs() && error <= 1e-16 * x.abs() {
                // Converged: carry sin and cos over the last (tiny) step.
                let (s1, c1) = sin_cos_step((s, c), -step);
                return (next, s1, c1);
            }
            x = next;
            stalled = 0;
        } else if d > 0.0 && next == x {
            // The step is below the rounding of x (v = 0 included): x is the root.
            // It is also an end of the bracket now, so the regula falsi below would take
            // the far end and bisect from there (5-10 % of the warm-started solves in a
            // diagnosis would spend 28-50 evaluations here).
            return (x, s, c);
        } else {
            // Regula falsi, with the Illinois halving when the same end keeps moving.
            let rf = lo - flo * (hi - lo) / (fhi - flo);
            stalled += 1;
            x = if stalled < 3 && rf > lo && rf < hi { rf } else { 0.5 * (lo + hi) };
            if stalled >= 3 {
                stalled = 0;
            }
        }
        // (sin and cos before the bracket test, so that they belong to the x returned)
        (s, c) = if rotation_carries(s, x - from) { sin_cos_rotated((s, c), x - from) } else { x.sin_cos() };
        if hi - lo <= 1e-15 * hi.abs().max(1e-300) {
            break;
        }
    }
    (x, s, c)
}

/// Contact angle Xc [mechanical degrees, full arc] from the half-angle φ0 in wave phase
/// (Chen et al. 2020 eq. 2 convention: Xc = 40·φ0/π for N = 9).
#[inline]
pub fn contact_angle_deg(half_angle_rad: f64, wave_number: f64) -> f64 {
    half_angle_rad * 360.0 / (PI * wave_number)
}

/// Contact length 2·x0 = 2·φ0/k [m] along the circumference.
#[inline]
pub fn contact_length_m(half_angle_rad: f64, wavenumber_per_m: f64) -> f64 {
    2.0 * half_angle_rad / wavenumber_per_m
}

/// Pressure per unit circumferential length p(θ) = k_f·W·(cos θ − c) inside the contact,
/// 0 outside [N/m] (Chen et al. 2020 eq. 3, Sun et al. 2021 eq. 5).
pub fn pressure_n_per_m(theta_rad: f64, k_f_n_per_m2: f64, amplitude_m: f64, contact: &Contact) -> f64 {
    if theta_rad.abs() > contact.half_angle_rad {
        0.0
    } else {
        (k_f_n_per_m2 * amplitude_m * (theta_rad.cos() - contact.offset)).max(0.0)
    }
}

/// Torque shape factor 2·χ(θs) − χ(φ0) (Sun et al. 2021 eq. 11, Chen et al. 2020 eq. 4-5):
/// the drive torque is R0·μ·A·[2χ(θs) − χ(φ0)], where |θ| < θs is the driving zone.
#[inline]
pub fn torque_factor(stick_half_angle_rad: f64, contact: &Contact) -> f64 {
    2.0 * chi(stick_half_angle_rad, contact.offset) - contact.chi0()
}

/// Largest stick half-angle possible with the rotor at rest: the stator surface speed
/// v0·cos θ is positive only for |θ| < π/2.
#[inline]
pub fn stall_stick_half_angle_rad(contact: &Contact) -> f64 {
    contact.half_angle_rad.min(0.5 * PI)
}

/// Solves the stick half-angle θs ∈ [0, θmax] of the torque balance R0·μ·A·[2χ(θs) − χ(φ0)]
/// = T_load + d_r·v0·cos(θs)/R0 (Chen et al. 2020 eq. 5 and Table A1's rotor damping; the
/// rotor surface speed is v_r = v0·cos θs, Sun et al. 2021 eq. 13).
///
/// `torque_scale_nm` = R0·μ·A, `viscous_nm_per_cos` = d_r·v0/R0. The left side increases
/// and the right side decreases with θs, so the root is unique when it exists; returns
/// `None` when T_load exceeds the stall torque (no root up to θmax).
pub fn stick_half_angle_rad(
    contact: &Contact,
    torque_scale_nm: f64,
    load_torque_nm: f64,
    viscous_nm_per_cos: f64,
    guess_rad: Option<f64>,
) -> Option<f64> {
    let (s0, c0) = contact.half_angle_rad.sin_cos();
    let guess = guess_rad.map(|g| (g, None));
    stick_half_angle_sin_cos(contact, (s0, c0), torque_scale_nm, load_torque_nm, viscous_nm_per_cos, guess).map(|r| r.0)
}

/// [`stick_half_angle_rad`] given (sin φ0, cos φ0) of the contact half-angle (cos φ0 = −1
/// in full contact); returns (θs, sin θs, cos θs).
pub fn stick_half_angle_sin_cos(
    contact: &Contact,
    (sin_phi0, cos_phi0): (f64, f64),
    torque_scale_nm: f64,
    load_torque_nm: f64,
    viscous_nm_per_cos: f64,
    guess: Option<AngleStart>,
) -> Option<(f64, f64, f64)> {
    let c = contact.offset;
    let chi0 = sin_phi0 - contact.half_angle_rad * c;
    let tmax = stall_stick_half_angle_rad(contact);
    // sin/cos of θmax: of φ0, or of π/2.
    let (smax, cmax) = if tmax < contact.half_angle_rad { (1.0, 0.0) } else { (sin_phi0, cos_phi0) };
    let f = |t: f64, s: f64, co: f64| {
        let val = torque_scale_nm * (2.0 * (s - t * c) - chi0) - load_torque_nm - viscous_nm_per_cos * co;
        let der = torque_scale_nm * 2.0 * (co - c) + viscous_nm_per_cos * s;
        let der2 = -torque_scale_nm * 2.0 * s + viscous_nm_per_cos * co;
        let der3 = -torque_scale_nm * 2.0 * co - viscous_nm_per_cos * s;
        [val, der, der2, der3]
    };
    let fmax = f(tmax, smax, cmax)[0];
    if fmax < 0.0 {
        return None;
    }
    let f0 = f(0.0, 0.0, 1.0)[0];
    // Starting point: warm start, else the middle of the range.
    let start = guess.filter(|g| g.0 > 0.0 && g.0 < tmax).unwrap_or((0.5 * tmax, None));
    Some(newton_sin_cos(f, (0.0, f0), (tmax, fmax), start))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::quad::integral;

    #[test]
    fn inverse_of_g_is_accurate_everywhere() {
        for i in 1..400 {
            let phi = PI * i as f64 / 400.0;
            let c = contact_from_ratio(g(phi));
            assert!((c.half_angle_rad - phi).abs() < 1e-9, "phi={phi} got {}", c.half_angle_rad);
        }
        // tiny contact: small-angle asymptote g ≈ φ³/3
        let c = contact_from_ratio(1e-9);
        assert!((c.half_angle_rad - (3e-9f64).cbrt()).abs() / (3e-9f64).cbrt() < 1e-5);
    }

    #[test]
    fn axial_force_closed_form_matches_quadrature() {
        // F = N ∫_{-x0}^{x0} p dx with p = k_f W (cos kx − c)  vs  A·χ(φ0)
        let (n, kf, w, k) = (9.0, 1.2e9, 1.5e-6, 9.0 / 0.02625);
        for &y in &[0.01, 0.5, 1.7, 3.0, 4.5] {
            let ct = contact_from_ratio(y);
            let a = force_scale_n(n, kf, w, k);
            let x0 = ct.half_angle_rad / k;
            let q = n * integral(|x| kf * w * ((k * x).cos() - ct.offset), -x0, x0);
            assert!((q - a * ct.chi0()).abs() < 1e-10 * q, "y={y}: {q} vs {}", a * ct.chi0());
            assert!((ct.chi0() - y).abs() < 1e-10 * y.max(1.0));
        }
    }

    #[test]
    fn torque_factor_matches_signed_quadrature() {
        // ∫ sgn(v0 cos θ − v_r)·(cos θ − c) dθ over the contact = 2·[2χ(θs) − χ(φ0)]
        let ct = contact_from_ratio(1.2);
        for &ts in &[0.1, 0.4, ct.half_angle_rad * 0.9] {
            let vr = ts.cos();
            let q =
                integral(|t| (t.cos() - vr).signum() * (t.cos() - ct.offset), -ct.half_angle_rad, ct.half_angle_rad);
            assert!((q - 2.0 * torque_factor(ts, &ct)).abs() < 1e-9, "{q}");
        }
    }

    #[test]
    fn stick_angle_solves_torque_balance_and_reports_stall() {
        let ct = contact_from_ratio(1.0);
        let scale = 2.0;
        let t = stick_half_angle_rad(&ct, scale, 0.3, 0.05, None).expect("a running stick angle");
        let resid = scale * torque_factor(t, &ct) - 0.3 - 0.05 * t.cos();
        assert!(resid.abs() < 1e-12);
        assert!(t > 0.0 && t <= ct.half_angle_rad);
        // stall torque with partial contact below π/2 is μ F R0 = scale·χ(φ0)
        let stall = scale * ct.chi0();
        assert!(stick_half_angle_rad(&ct, scale, stall * 1.001, 0.0, None).is_none());
        assert!(stick_half_angle_rad(&ct, scale, stall * 0.999, 0.0, None).is_some());
    }

    #[test]
    fn inner_solves_give_the_same_root_and_its_sine_and_cosine_from_any_start() {
        // Starts just beside the root (where plain Newton from the far side overshoots out
        // of the bracket), at the ends and far away: the root to 1e-14, sin/cos to 1e-15.
        // (y just below π: contact just short of full)
        for &y in &[1e-6, 0.3, 1.5, 2.9, PI - 1.6e-3] {
            let (cold, s, c) = contact_from_ratio_near(y, None);
            let phi = cold.half_angle_rad;
            assert!((s - phi.sin()).abs() < 1e-15 && (c - phi.cos()).abs() < 1e-15 && c == cold.offset);
            for g in [1e-12, phi * (1.0 - 1e-9), phi * (1.0 + 1e-9), PI - 1e-12, 1.0] {
                // (a start with its sine and cosine given, as the solver carries them)
                for start in [(g, None), (g, Some(g.sin_cos()))] {
                    let (w, s, c) = contact_from_ratio_near(y, Some(start));
                    assert!((w.half_angle_rad - phi).abs() < 1e-14 * (1.0 + phi), "y={y} start {start:?}");
                    assert!((s - w.half_angle_rad.sin()).abs() < 1e-15 && (c - w.half_angle_rad.cos()).abs() < 1e-15);
                }
            }
        }
        for &(y, load) in &[(0.5, 0.1), (2.5, 0.3), (2.5, 0.0), (4.0, 1.5)] {
            let ct = contact_from_ratio(y);
            let sc0 = if ct.full { (PI.sin(), -1.0) } else { ct.half_angle_rad.sin_cos() };
            let Some((t, _, _)) = stick_half_angle_sin_cos(&ct, sc0, 2.0, load, 0.05, None) else {
                panic!("y={y}: no stick angle")
            };
            let resid = 2.0 * torque_factor(t, &ct) - load - 0.05 * t.cos();
            assert!(resid.abs() < 1e-13, "y={y}: {resid}");
            let tmax = stall_stick_half_angle_rad(&ct);
            for g in [1e-12, t * (1.0 - 1e-9), t * (1.0 + 1e-9), tmax * (1.0 - 1e-12), 1.0] {
                for start in [(g, None), (g, Some(g.sin_cos()))] {
                    let (w, s, c) = stick_half_angle_sin_cos(&ct, sc0, 2.0, load, 0.05, Some(start)).expect("root");
                    assert!((w - t).abs() < 1e-14, "y={y} start {start:?}: {w} vs {t}");
                    assert!((s - w.sin()).abs() < 1e-15 && (c - w.cos()).abs() < 1e-15);
                }
            }
        }
    }

    /// The carry of sine and cosine over an angle step (the solver's, up to 1e-4 rad)
    /// against `sin_cos` of the moved angle: within rounding (a few units in the last place).
    #[test]
    fn sine_and_cosine_carried_over_a_step_are_those_of_the_moved_angle() {
        for i in 0..=64 {
            let x = PI * i as f64 / 64.0;
            for d in [1e-4, -1e-4, 3e-6, -2e-9, 0.0] {
                let (s, c) = sin_cos_step(x.sin_cos(), d);
                let (se, ce) = (x + d).sin_cos();
                assert!((s - se).abs() < 5e-16 && (c - ce).abs() < 5e-16, "x {x} step {d}: {s} {c} vs {se} {ce}");
            }
        }
        // a step ten times longer than the solver carries is visibly off (δ⁴/24 ≈ 4e-14)
        let (s, _) = sin_cos_step(1.0f64.sin_cos(), 1e-3);
        assert!((s - 1.001f64.sin()).abs() > 1e-14);
    }

    #[test]
    fn a_start_within_rounding_of_the_root_ends_at_once() {
        // A stick-angle solve of a 1000-row diagnosis (full contact, no load), started 2e-8
        // from its root: the second Newton step rounds to zero at an end of the bracket.
        // That used to fall through to bisection from the bracket's far end (28
        // evaluations); counted here through the closure.
        let (c, tscale, visc) = (-1.1014458264144047, 0.6867121650732799, 7.017890818196502e-3);
        let chi0 = PI.sin() - PI * c;
        let n = std::cell::Cell::new(0);
        let f = |t: f64, s: f64, co: f64| {
            n.set(n.get() + 1);
            let val = tscale * (2.0 * (s - t * c) - chi0) - visc * co;
            [val, tscale * 2.0 * (co - c) + visc * s, -tscale * 2.0 * s + visc * co, -tscale * 2.0 * co - visc * s]
        };
        let (lo, hi) = ((0.0, f(0.0, 0.0, 1.0)[0]), (0.5 * PI, f(0.5 * PI, 1.0, 0.0)[0]));
        for start in [0.8762107029595234, 0.8762107257814344, 0.5, 1.2] {
            n.set(0);
            let (t, s, co) = newton_sin_cos(f, lo, hi, (start, None));
            assert!((t - 0.8762107257814344).abs() < 1e-15, "start {start}: {t}");
            assert!((s - t.sin()).abs() < 1e-15 && (co - t.cos()).abs() < 1e-15);
            assert!(n.get() <= 6, "start {start}: {} evaluations", n.get());
        }
    }

    #[test]
    fn contact_angle_convention() {
        assert!((contact_angle_deg(PI, 9.0) - 40.0).abs() < 1e-12);
        assert!((contact_angle_deg(0.5 * PI, 9.0) - 20.0).abs() < 1e-12);
    }
}
