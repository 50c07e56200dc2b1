//! Step response of the rotor speed (transient model, the bar-type transient paper) and the timing figure.
//!
//! `cargo run --release -p trum-core --example step [preset] [voltage_v] [frequency_hz] [phase_deg] [ratio]`

use std::time::Instant;
use trum_core::dynamics::transient::{step_response, TransientConfig};
use trum_core::presets::preset;
use trum_core::solve::{solve, OperatingPoint};

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |i: usize, d: f64| args.get(i).and_then(|s| s.parse().ok()).unwrap_or(d);
    let name = args.get(1).cloned().unwrap_or_else(|| "trum60a".into());
    let motor = match preset(&name) {
        Ok(m) => m,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(2);
        }
    };
    let mut cfg = TransientConfig {
        voltage_v: arg(2, 200.0),
        frequency_hz: arg(3, 43e3),
        phase_difference_rad: arg(4, 90.0).to_radians(),
        tangential_stiffness_ratio: arg(5, TransientConfig::default().tangential_stiffness_ratio),
        snapshot_times_s: vec![0.02e-3, 0.1e-3, 3e-3],
        ..TransientConfig::default()
    };
    cfg.load_torque_nm = arg(6, 0.0);
    cfg.steps_per_period = arg(7, 64.0) as usize;
    cfg.duration_s = arg(8, 10e-3);
    cfg.nodes_per_wavelength = arg(9, 256.0) as usize;
    let t0 = Instant::now();
    let r = match step_response(&motor, &cfg) {
        Ok(r) => r,
        Err(e) => {
            eprintln!("{e}");
            std::process::exit(1);
        }
    };
    let el = t0.elapsed().as_secs_f64();
    println!(
        "{} steps, {} nodes/wavelength, {:.1} ms simulated in {:.3} s wall",
        r.steps,
        cfg.nodes_per_wavelength,
        cfg.duration_s * 1e3,
        el
    );
    let m = &r.metrics;
    println!("final speed {:.2} rpm, peak {:.2} rpm", m.final_speed_rpm, m.peak_speed_rpm);
    println!(
        "delay {:?} s, rise {:?} s, overshoot {:?}, settling {:?} s",
        m.delay_s, m.rise_time_s, m.overshoot, m.settling_time_s
    );
    let a = &r.averages;
    println!(
        "averages over {:.2} ms: speed {:.3} rpm, torque {:.5} N m, amplitude {:.4} um, axial {:.2} N, contact {:.3}, stick {:.3}",
        a.window_s * 1e3,
        a.speed_rpm,
        a.contact_torque_nm,
        a.amplitude_m * 1e6,
        a.axial_force_n,
        a.contact_fraction,
        a.stick_fraction
    );
    let s = solve(&motor, &OperatingPoint::new(cfg.preload_n, cfg.load_torque_nm, cfg.voltage_v, cfg.frequency_hz));
    println!(
        "steady solve: {} speed {:.3} rpm, amplitude {:.4} um, contact torque {:.5} N m, contact fraction {:.3}",
        s.status,
        s.speed_rpm,
        s.amplitude_m * 1e6,
        cfg.load_torque_nm + motor.rotor.viscous_damping_nms * s.speed_rad_s,
        s.contact_half_angle_rad / std::f64::consts::PI
    );
    for sn in &r.snapshots {
        let (nc, st, sl) = sn.counts();
        println!(
            "snapshot t = {:.3} ms: {:.2} rpm, no contact {nc}, stick {st}, slip {sl}",
            sn.time_s * 1e3,
            sn.speed_rpm
        );
    }
    let n = r.series.time_s.len();
    for i in (0..n).step_by((n / 40).max(1)) {
        println!(
            "  t {:7.3} ms  speed {:8.3} rpm  mean {:8.3}  W {:.4} um  z {:+.4} um  T {:+.5}",
            r.series.time_s[i] * 1e3,
            r.series.speed_rpm[i],
            r.series.speed_period_mean_rpm[i],
            r.series.amplitude_m[i] * 1e6,
            r.series.axial_position_m[i] * 1e6,
            r.series.torque_nm[i]
        );
    }
}
