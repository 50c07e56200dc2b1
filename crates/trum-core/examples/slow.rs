use trum_core::*;
fn main() {
    let base = presets::preset(&std::env::args().nth(1).unwrap_or("trum60a".into())).unwrap();
    let mut worst = (0.0, String::new());
    for e in effects::ALL {
        for &s in &[0.0, 0.1, 0.5, 1.0, 3.0, 8.0] {
            let mut m = base.clone();
            let t = e.info().params[0].typical;
            m.effects.set_strength(e, (s * t).clamp(e.info().params[0].min, e.info().params[0].max));
            for &f in &[50.0, 100.0, 250.0, 400.0] {
                for &tq in &[0.0, 0.3, 0.8] {
                    for &hz in &[41000.0, 42000.0, 43000.0] {
                        let mut op = OperatingPoint::new(f, tq, 150.0, hz);
                        op.elapsed_s = 100.0;
                        let t0 = std::time::Instant::now();
                        let sol = solve(&m, &op);
                        let dt = t0.elapsed().as_secs_f64();
                        if dt > worst.0 {
                            worst = (
                                dt,
                                format!(
                                    "{} x{} F={f} T={tq} hz={hz} status={} it={}",
                                    e.name(),
                                    s,
                                    sol.status,
                                    sol.iterations
                                ),
                            );
                        }
                        if dt > 0.01 {
                            println!(
                                "{:.3}s {} x{} F={f} T={tq} hz={hz} status={} it={}",
                                dt,
                                e.name(),
                                s,
                                sol.status,
                                sol.iterations
                            );
                        }
                    }
                }
            }
        }
    }
    println!("worst {:.4}s {}", worst.0, worst.1);
}
