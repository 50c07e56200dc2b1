//! Random stress of the steady-state solver: presets scaled as tests/invariants.rs draws
//! them (every continuous parameter × 0.7-1.4), random operating points; prints every
//! point that ends in `no_convergence` and the status counts (docs/RELIABILITY.md).
//!
//!     cargo run --release -p trum-core --example stress -- 300000 [effects]
//!
//! With `effects` (or only `sag`, only `thermal`), each case also switches on `voltage_sag` (10-1000 Ω) and
//! `thermal_drift` (0-5 × typical coefficients) at a random elapsed time (0-3600 s).
use trum_core::effects::Effect;
use trum_core::presets::preset;
use trum_core::*;
fn main() {
    let n: usize = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(100000);
    let with_sag = std::env::args().any(|a| a == "effects" || a == "sag");
    let with_thermal = std::env::args().any(|a| a == "effects" || a == "thermal");
    let with_effects = with_sag || with_thermal;
    let mut x: u64 = 0x9e3779b97f4a7c15;
    let mut rnd = || {
        x ^= x << 13;
        x ^= x >> 7;
        x ^= x << 17;
        (x >> 11) as f64 / (1u64 << 53) as f64
    };
    let keys = [
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
    let mut counts = std::collections::BTreeMap::new();
    for _ in 0..n {
        let i = (rnd() * 3.0) as usize;
        let mut m = preset(["trum60a", "trum60-qut", "generic60"][i.min(2)]).unwrap();
        for k in keys {
            let s = 0.7 + 0.7 * rnd();
            let s = if k.ends_with("resonance_frequency_hz") { 0.97 + (s - 0.7) * 0.06 / 0.7 } else { s };
            *m.param_mut(k).unwrap() *= s;
        }
        let mut op =
            OperatingPoint::new(5.0 + 595.0 * rnd(), 2.0 * rnd(), 30.0 + 270.0 * rnd(), 39000.0 + 7000.0 * rnd());
        if with_effects {
            let (z, k) = (10f64.powf(1.0 + 2.0 * rnd()), 5.0 * rnd());
            if with_sag {
                m.effects.set(Effect::VoltageSag, &[z]);
            }
            if with_thermal {
                m.effects.set(Effect::ThermalDrift, &[-4e-4 * k, -2e-3 * k, 2e-3 * k]);
            }
            op.elapsed_s = 3600.0 * rnd();
        }
        let s = solve(&m, &op);
        *counts.entry(s.status.as_str()).or_insert(0) += 1;
        // a valid state must be a fixed point: the rise its losses produce, the set
        // voltage its current drops to the electrode voltage (candidate forms)
        if s.status.is_valid() && with_thermal && op.elapsed_s > 0.0 {
            let hs = m.thermal.heat_transfer_coefficient_w_per_m2k * m.thermal.surface_area_m2;
            let want = s.temperature_rise_k * (1.0 - (-op.elapsed_s * hs / m.thermal.heat_capacity_j_per_k).exp());
            if (s.temperature_rise_at_elapsed_k - want).abs() > 1e-8 * want.max(1e-6) {
                *counts.entry("inconsistent_rise").or_insert(0) += 1;
            }
        }
        if s.status.is_valid() && with_sag {
            let z = m.effects.value(Effect::VoltageSag, 0);
            let v_set = (s.electrode_voltage_v + z * s.current_in_phase_a).hypot(z * s.current_quadrature_a);
            if (v_set - op.voltage_v).abs() > 1e-9 * op.voltage_v {
                *counts.entry("inconsistent_voltage").or_insert(0) += 1;
            }
        }
        if s.status == Status::NoConvergence {
            println!("{} {:?} iters {}", m.name, op, s.iterations);
            if let Ok(dir) = std::env::var("STRESS_DUMP") {
                let k = counts.get("no_convergence").copied().unwrap_or(0);
                let _ = std::fs::write(format!("{dir}/nc{k}.toml"), m.to_toml());
                let _ = std::fs::write(
                    format!("{dir}/nc{k}.op"),
                    format!("{} {} {} {} {}", op.preload_n, op.torque_nm, op.voltage_v, op.frequency_hz, op.elapsed_s),
                );
            }
        }
    }
    println!("{counts:?}");
}
