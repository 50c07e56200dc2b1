//! The power budget behind the maximum efficiency against preload: for each preload, at
//! the load torque of the maximum efficiency (the quantity of Chen et al. 2020 Fig. 8c and
//! of `trum optimize`), the output, every loss and the input, and the no-load amplitude.
//!
//! ```sh
//! cargo run --release -p trum-core --example efficiency_budget -- trum60a 200 42000
//! cargo run --release -p trum-core --example efficiency_budget -- trum60a 200 42000 electrical.dielectric_loss_tangent=0.02
//! cargo run --release -p trum-core --example efficiency_budget -- my-motor.toml 200 42000
//! ```

use trum_core::criterion::{evaluate, CriterionConfig};
use trum_core::solve::{solve, OperatingPoint};
use trum_core::sweep::Axis;

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map_or("trum60a", String::as_str);
    let v: f64 = args.get(2).map_or(200.0, |s| s.parse().expect("voltage"));
    let hz: f64 = args.get(3).map_or(42_000.0, |s| s.parse().expect("frequency"));
    // a preset name, or a motor file (`preset = "trum60a"` with the values to try)
    let mut m = if std::path::Path::new(name).is_file() {
        let text = std::fs::read_to_string(name).expect("motor file");
        trum_core::params::Motor::from_toml_str(&text, name).unwrap_or_else(|e| panic!("{e}"))
    } else {
        trum_core::presets::preset(name).expect("preset")
    };
    // KEY=VALUE: try a value without editing the preset file
    for kv in args.iter().skip(4) {
        let (k, x) = kv.split_once('=').expect("KEY=VALUE");
        *m.param_mut(k).expect("key") = x.parse().expect("number");
    }
    let cfg = CriterionConfig {
        preload_n: Axis::linspace(100.0, 450.0, 15),
        voltage_v: v,
        frequency_hz: hz,
        ..CriterionConfig::seed000()
    };
    let r = evaluate(&m, &cfg, &mut |_, _| {}).expect("criterion");
    println!(
        "{:>6} {:>7} {:>7} {:>7} {:>6} {:>7} | {:>7} {:>7} {:>7} {:>7} {:>7} {:>7} {:>7}",
        "F_N", "W0_um", "stall", "T_eta", "eta", "rpm", "P_out", "diel", "damp", "fric", "radial", "rotor", "P_in"
    );
    let r0 = m.geometry.mean_radius_m;
    // (preload, output, input) at each maximum-efficiency point, for the fixed-loss scan
    let mut budget: Vec<(f64, f64, f64)> = Vec::new();
    let mut visc_scale = f64::NAN;
    for row in &r.rows {
        let w0 = solve(&m, &OperatingPoint::new(row.preload_n, 0.0, v, hz)).amplitude_m * 1e6;
        let s = solve(&m, &OperatingPoint::new(row.preload_n, row.torque_at_max_efficiency_nm, v, hz));
        // the shape of Chen et al. 2020 eq. 9 (corrected): ξ·J(b)·(v_sm, v_r), b = π/2 − φ0,
        // scaled to trum's interface loss at the first preload
        let q3 = trum_core::papers::chen2020::friction_loss_w(
            1.0,
            2.0 * std::f64::consts::PI,
            s.amplitude_m,
            1.0,
            1.0,
            s.crest_speed_m_s,
            s.speed_rad_s * r0,
            std::f64::consts::FRAC_PI_2 - s.contact_half_angle_rad.min(std::f64::consts::FRAC_PI_2),
        );
        if visc_scale.is_nan() {
            visc_scale = s.friction_loss_w / q3;
        }
        let q3 = q3 * visc_scale;
        let eta_visc = s.output_power_w / (s.input_power_w - s.friction_loss_w + q3);
        budget.push((row.preload_n, s.output_power_w, s.input_power_w));
        println!(
            "{:>6.0} {:>7.3} {:>7.3} {:>7.3} {:>6.3} {:>7.1} | {:>7.3} {:>7.3} {:>7.3} {:>7.3} {:>7.3} {:>7.3} {:>7.3} | {:>7.3} {:>6.3}",
            row.preload_n,
            w0,
            row.stall_torque_nm,
            row.torque_at_max_efficiency_nm,
            row.max_efficiency,
            s.speed_rpm,
            s.output_power_w,
            s.dielectric_loss_w,
            s.damping_loss_w,
            s.friction_loss_w,
            s.radial_friction_loss_w,
            s.rotor_loss_w,
            s.input_power_w,
            q3,
            eta_visc
        );
    }
    // a preload-independent loss P0 added to every input: where the efficiency then peaks
    // (at the maximum-efficiency points above; the load torque of the maximum moves a
    // little with P0, which this ignores)
    println!("\nextra preload-independent loss [W] -> preload of the largest P_out/(P_in + P0) [N]");
    for p0 in [0.0, 1.0, 2.0, 5.0, 10.0, 20.0, 30.0, 50.0] {
        let best = budget.iter().fold((f64::NAN, -1.0), |b, &(f, po, pi)| {
            let e = po / (pi + p0);
            if e > b.1 {
                (f, e)
            } else {
                b
            }
        });
        println!("{p0:>6.1} -> {:>5.0} N (efficiency {:.3})", best.0, best.1);
    }
}
