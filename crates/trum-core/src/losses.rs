//! Power losses: dielectric loss of the piezoceramic, structural damping of the stator,
//! friction in the contact interface (closed form and quadrature), rotor viscous loss.
//!
//! The baseline friction law is Coulomb: traction μ·p along the slip. The friction loss is
//! therefore ∫ μ·p·|v_s − v_r| dx over the contact of all N waves, which this module
//! evaluates both in closed form and by adaptive quadrature (a test checks they agree). The
//! papers' closed forms (Chen et al. 2020 eq. 9-10, Sun et al. 2021 eq. 22-26) integrate a
//! viscous-like ΔF·(v_s − v_r)² instead; `crate::papers` and docs/PAPERS.md compare them.

use crate::contact::{self, Contact};
use crate::quad;

/// Dielectric loss of both phases P = ω·C0·V²·tan δ [W] (Chen et al. 2020 eq. 7 with
/// ε_p·A/h_p = C0 and two phases of ½·ω·C0·V²·tan δ each). V is the zero-to-peak
/// amplitude per phase. Valid for any ω, C0, V ≥ 0.
#[inline]
pub fn dielectric_loss_w(omega_rad_s: f64, capacitance_f: f64, loss_tangent: f64, voltage_v: f64) -> f64 {
    omega_rad_s * capacitance_f * voltage_v * voltage_v * loss_tangent
}

/// Efficiency η = P_out / P_in [-] of the mechanical output over the electrical input,
/// clamped to [0, 1], and 0 where the input power is not positive. The solver's, the
/// averaged and linearised solutions' and the bench's efficiency readings all use it.
/// Valid for any finite powers.
#[inline]
pub fn efficiency(output_power_w: f64, input_power_w: f64) -> f64 {
    if input_power_w > 0.0 {
        (output_power_w / input_power_w).clamp(0.0, 1.0)
    } else {
        0.0
    }
}

/// Structural damping loss of the stator, two modes of amplitude W: P = 2·½·c·ω²·W² =
/// c·ω²·W² [W]. (Sun et al. 2021 eq. 17 gives the same loss per cycle from the composite
/// beam's bending energy; [`composite_modal_damping_ns_per_m`] converts one into the
/// other.)
#[inline]
pub fn stator_damping_loss_w(modal_damping_ns_per_m: f64, omega_rad_s: f64, amplitude_m: f64) -> f64 {
    modal_damping_ns_per_m * omega_rad_s * omega_rad_s * amplitude_m * amplitude_m
}

/// Coulomb friction loss of the contact interface in closed form [W]:
/// P = N·∫ μ·p(x)·|v0·cos(kx) − v_r| dx = (2Nμk_f W/k)·[v0·(2E(θs) − E(φ0)) − v_r·(2χ(θs) − χ(φ0))]
/// with χ, E from [`crate::contact`] and θs the stick half-angle (v0·cos θs = v_r, or
/// θs = min(φ0, π/2) with the rotor at rest). Valid for 0 ≤ θs ≤ φ0 ≤ π, v_r ≥ 0.
#[allow(clippy::too_many_arguments)]
pub fn friction_loss_coulomb_w(
    wave_number: f64,
    mu: f64,
    k_f_n_per_m2: f64,
    amplitude_m: f64,
    wavenumber_per_m: f64,
    crest_speed_m_s: f64,
    rotor_surface_speed_m_s: f64,
    stick_half_angle_rad: f64,
    contact: &Contact,
) -> f64 {
    let c = contact.offset;
    let pe = 2.0 * contact::e_int(stick_half_angle_rad, c) - contact::e_int(contact.half_angle_rad, c);
    let pc = contact::torque_factor(stick_half_angle_rad, contact);
    let scale = 2.0 * wave_number * mu * k_f_n_per_m2 * amplitude_m / wavenumber_per_m;
    (scale * (crest_speed_m_s * pe - rotor_surface_speed_m_s * pc)).max(0.0)
}

/// The same friction loss by adaptive quadrature of its defining integral
/// N·∫_{−x0}^{x0} μ·p(x)·|v0·cos(kx) − v_r| dx [W] (the kinks at ±θs are split off so the
/// integrand is smooth on each piece). Used to check the closed form.
#[allow(clippy::too_many_arguments)]
pub fn friction_loss_quadrature_w(
    wave_number: f64,
    mu: f64,
    k_f_n_per_m2: f64,
    amplitude_m: f64,
    wavenumber_per_m: f64,
    crest_speed_m_s: f64,
    rotor_surface_speed_m_s: f64,
    contact: &Contact,
) -> f64 {
    let x0 = contact.half_angle_rad / wavenumber_per_m;
    let f = |x: f64| {
        let th = wavenumber_per_m * x;
        mu * contact::pressure_n_per_m(th, k_f_n_per_m2, amplitude_m, contact)
            * (crest_speed_m_s * th.cos() - rotor_surface_speed_m_s).abs()
    };
    let ratio = rotor_surface_speed_m_s / crest_speed_m_s;
    let mut cuts = vec![0.0, x0];
    if ratio.abs() <= 1.0 {
        let xs = ratio.acos() / wavenumber_per_m;
        if xs < x0 {
            cuts.insert(1, xs);
        }
    }
    let mut total = 0.0;
    for w in cuts.windows(2) {
        total += quad::integrate(f, w[0], w[1], 1e-300, 1e-13).0;
    }
    2.0 * wave_number * total
}

/// Modal damping c [N·s/m] equivalent to the composite stator's material damping (Sun et
/// al. 2021 eq. 17-21). A traveling wave u = W·cos(kx − ωt) is two standing modes, each
/// with peak strain energy ½·EI·k⁴·W²·π·R0; hysteretic damping η loses 2π·η of that per
/// cycle and mode, a viscous modal damper π·c·ω·W². Equating gives c =
/// π·R0·k⁴·(E_eq·I_e·η_e + E_p·I_p·η_p)/ω.
///
/// `ei_eta_nm2` = E_eq·I_e·η_e + E_p·I_p·η_p [N·m²], the loss-weighted bending stiffness;
/// [`composite_section`] gives I_e, I_p and the neutral-layer depth D (eq. 18-21).
pub fn composite_modal_damping_ns_per_m(
    ei_eta_nm2: f64,
    wavenumber_per_m: f64,
    mean_radius_m: f64,
    omega_rad_s: f64,
) -> f64 {
    let k4 = wavenumber_per_m.powi(4);
    ei_eta_nm2 * k4 * std::f64::consts::PI * mean_radius_m / omega_rad_s
}

/// Composite stator section (Sun et al. 2021 eq. 18-21): returns (D, I_e, I_p) for ring width
/// b_e, ring+teeth height h_e, piezo width b_p and thickness h_p, moduli E_eq and E_p.
/// D is the depth of the neutral layer below the ring's upper surface [m]; I_e, I_p the
/// cross-section moments about it [m⁴]. Eq. 19 is printed with a 1/12 factor where the
/// parallel-axis integral gives 1/3, and with (h−D)³ + (h_e−D)³ where the bounds of the
/// piezo layer give (h−D)³ − (h_e−D)³; both corrected here (docs/PAPERS.md).
pub fn composite_section(b_e: f64, h_e: f64, b_p: f64, h_p: f64, e_eq: f64, e_p: f64) -> (f64, f64, f64) {
    let d = (e_eq * h_e * h_e * b_e + 2.0 * e_p * h_p * h_e * b_p + e_p * h_p * h_p * b_p)
        / (2.0 * (e_eq * h_e * b_e + e_p * h_p * b_p));
    let h = h_e + h_p;
    let i_e = b_e * (d.powi(3) + (h_e - d).powi(3)) / 3.0;
    let i_p = b_p * ((h - d).powi(3) - (h_e - d).powi(3)) / 3.0;
    (d, i_e, i_p)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::contact::contact_from_ratio;

    #[test]
    fn friction_closed_form_matches_quadrature() {
        let (n, mu, kf, w, k) = (9.0, 0.3, 1.2e9, 1.5e-6, 9.0 / 0.02625);
        for &y in &[0.05, 0.8, 2.0, 3.1, 5.0] {
            let ct = contact_from_ratio(y);
            let v0 = 0.4;
            for &frac in &[0.0, 0.3, 0.7, 0.99] {
                let ts = contact::stall_stick_half_angle_rad(&ct) * frac + (1.0 - frac) * 1e-3;
                let vr = v0 * ts.cos();
                let closed = friction_loss_coulomb_w(n, mu, kf, w, k, v0, vr, ts, &ct);
                let q = friction_loss_quadrature_w(n, mu, kf, w, k, v0, vr, &ct);
                assert!((closed - q).abs() <= 1e-9 * q.max(1e-12), "y={y} frac={frac}: {closed} vs {q}");
            }
            // rotor at rest: θs = min(φ0, π/2)
            let ts = contact::stall_stick_half_angle_rad(&ct);
            let closed = friction_loss_coulomb_w(n, mu, kf, w, k, v0, 0.0, ts, &ct);
            let q = friction_loss_quadrature_w(n, mu, kf, w, k, v0, 0.0, &ct);
            assert!((closed - q).abs() <= 1e-9 * q, "stall y={y}: {closed} vs {q}");
        }
    }

    #[test]
    fn composite_neutral_axis_is_the_modulus_weighted_centroid() {
        let (be, he, bp, hp, ee, ep) = (5e-3, 4e-3, 4.5e-3, 0.5e-3, 110e9, 70e9);
        let (d, ie, ip) = composite_section(be, he, bp, hp, ee, ep);
        // first moment of modulus-weighted area about the neutral layer vanishes
        let first =
            ee * be * (d * d - (he - d).powi(2)) / 2.0 - ep * bp * ((he + hp - d).powi(2) - (he - d).powi(2)) / 2.0;
        assert!(first.abs() < 1e-9 * ee * be * he * he, "{first}");
        // moments by quadrature of y² over each layer
        let qe = crate::quad::integral(|y| be * (y - d) * (y - d), 0.0, he);
        let qp = crate::quad::integral(|y| bp * (y - d) * (y - d), he, he + hp);
        assert!((ie - qe).abs() < 1e-12 * qe && (ip - qp).abs() < 1e-12 * qp);
    }
}
