#![allow(clippy::unwrap_used)] // examples: developer tools, a panic is the error report
use trum_core::*;
fn main() {
    let args: Vec<String> = std::env::args().collect();
    let name = args.get(1).map(|s| s.as_str()).unwrap_or("trum60a");
    let v: f64 = args.get(2).and_then(|s| s.parse().ok()).unwrap_or(200.0);
    let f: f64 = args.get(3).and_then(|s| s.parse().ok()).unwrap_or(43000.0);
    let mut m = presets::preset(name).unwrap();
    for kv in args.iter().skip(4) {
        let (k, val) = kv.split_once('=').unwrap();
        *m.param_mut(k).unwrap() = val.parse().unwrap();
    }
    println!("F     T    status  W_um   Xc    Xs   rpm   Tst   Pin   Pout  Pd  Pdamp Pfric eff  I   Vf it");
    for &fz in &[50.0, 100.0, 150.0, 200.0, 260.0, 300.0, 400.0, 500.0] {
        for &t in &[0.0, 0.3, 0.6] {
            let s = solve(&m, &OperatingPoint::new(fz, t, v, f));
            let bal = s.input_power_w - s.output_power_w - s.total_loss_w();
            println!("{fz:5} {t:4} {:7} {:5.3} {:5.2} {:5.2} {:6.1} {:5.2} {:5.2} {:5.2} {:4.2} {:4.2} {:5.2} {:4.3} {:4.3} {:4.1} {} bal={:.1e}",
              s.status.as_str(), s.amplitude_m*1e6, s.contact_angle_deg, s.driving_angle_deg, s.speed_rpm, s.stall_torque_nm,
              s.input_power_w, s.output_power_w, s.dielectric_loss_w, s.damping_loss_w, s.friction_loss_w, s.efficiency, s.current_a, s.feedback_v, s.iterations, bal);
        }
    }
}
