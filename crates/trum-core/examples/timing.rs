use trum_core::*;
fn main() {
    let m = presets::preset("trum60a").unwrap();
    let t0 = std::time::Instant::now();
    let mut it = 0u64;
    let mut n = 0;
    for i in 0..200 {
        for j in 0..100 {
            let s = solve(&m, &OperatingPoint::new(100.0 + i as f64, 1.2 * j as f64 / 100.0, 200.0, 43000.0));
            it += s.iterations as u64;
            n += 1;
        }
    }
    let dt = t0.elapsed().as_secs_f64();
    println!("{n} solves in {dt:.3}s = {:.2} us/solve, mean evals {:.1}", dt / n as f64 * 1e6, it as f64 / n as f64);
}
