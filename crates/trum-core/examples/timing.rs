use trum_core::*;
fn main() {
    for fx in [
        "none",
        "radial_friction=1",
        "tangential_compliance=1",
        "thermal_drift=-4e-4",
        "voltage_sag=150",
        "eccentricity=2e-5",
    ] {
        let mut m = presets::preset("trum60a").unwrap();
        m.effects.parse_assignment(fx).unwrap();
        let t0 = std::time::Instant::now();
        let mut it = 0u64;
        let mut n = 0;
        for i in 0..40 {
            for j in 0..25 {
                let mut op = OperatingPoint::new(100.0 + 7.0 * i as f64, 1.0 * j as f64 / 25.0, 200.0, 43000.0);
                op.elapsed_s = 60.0;
                let s = solve(&m, &op);
                it += s.iterations as u64;
                n += 1;
            }
        }
        let dt = t0.elapsed().as_secs_f64();
        println!("{fx:26} {:.2} us/solve, mean evals {:.1}", dt / n as f64 * 1e6, it as f64 / n as f64);
    }
}
