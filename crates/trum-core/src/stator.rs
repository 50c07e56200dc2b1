//! Stator modal dynamics: the traveling wave as two degenerate standing modes driven 90°
//! apart, with the contact's normal and tangential forces acting on them.
//!
//! Each mode obeys m·q̈ + c·q̇ + k_s·q = Θ·V_phase + (contact force on the mode)
//! (seed 001 eq. 6; seed 000 Appendix A, eq. A1-A4 with ε = 0). In steady state the
//! traveling wave q_A + i·q_B = W·e^{i(ωt−ψ)} gives one complex balance
//! Θ·V = [k_s + k_add − m·ω² + i·ω·(c + c_t)]·W·e^{−iψ}, where c_t is the equivalent
//! damping of the friction forces (power taken from the wave / (ω·W)²) and k_add any
//! stiffness the effects add (preload stiffening, Hertzian softening). This is seed 001
//! eq. 14 with the friction damping made explicit; see docs/MODEL.md for why the N22·F_N
//! term of eq. 14 is not in the baseline.

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

/// Crest tangential surface speed v0 = k·h0·ω·W [m/s] (seed 001 eq. 12, seed 000 eq. 1).
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

/// Feedback (isolated) electrode voltage amplitude V_f = K_WV·W [V] (seed 001 eq. 1;
/// the printed (√2/2) factor is a typo of the sum of two quadrature terms, and in any
/// case K_WV is identified from measured data, so it absorbs the constant).
#[inline]
pub fn feedback_voltage_v(gain_v_per_m: f64, amplitude_m: f64) -> f64 {
    gain_v_per_m * amplitude_m
}

#[cfg(test)]
mod tests {
    use super::*;
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
