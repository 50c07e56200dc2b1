//! The random motors of the solver's property and stress tests: a preset with every
//! continuous parameter scaled by a factor in [0.7, 1.4] (the resonance frequency
//! mapped to ±3 % of nominal, so the drive frequencies stay near resonance).

use trum_core::presets::preset;
use trum_core::Motor;

/// The presets drawn from.
pub const PRESET_NAMES: [&str; 3] = ["trum60a", "trum60-qut", "generic60"];

/// The scaled parameters, in the order the factors are applied.
pub const SCALED_KEYS: [&str; 12] = [
    "geometry.neutral_plane_distance_m",
    "geometry.contact_width_m",
    "friction_layer.youngs_modulus_pa",
    "friction_layer.thickness_m",
    "friction_layer.friction_coefficient",
    "stator.modal_mass_kg",
    "stator.modal_damping_ns_per_m",
    "stator.force_factor_n_per_v",
    "electrical.clamped_capacitance_f",
    "electrical.dielectric_loss_tangent",
    "rotor.viscous_damping_nms",
    "stator.resonance_frequency_hz",
];

/// Preset `i` of [`PRESET_NAMES`] with factor `f[j]` (each in [0.7, 1.4]) applied to
/// `SCALED_KEYS[j]`.
pub fn scaled_preset(i: usize, f: &[f64]) -> Motor {
    let mut m = preset(PRESET_NAMES[i.min(2)]).expect("preset");
    for (k, &s) in SCALED_KEYS.iter().zip(f) {
        let s = if k.ends_with("resonance_frequency_hz") { 0.97 + (s - 0.7) * 0.06 / 0.7 } else { s };
        *m.param_mut(k).expect("key") *= s;
    }
    m
}
