use trum_core::*;
fn main() {
    let m = presets::preset("trum60a").unwrap();
    let r = criterion::evaluate(&m, &criterion::CriterionConfig::seed000(), &mut |_, _| {}).unwrap();
    for row in &r.rows {
        println!(
            "{:5.0} {:?} Tst={:.2} eta={:.3} dT={:.2} std={:.3} v0={:.1} score={:.3} {}",
            row.preload_n,
            row.status,
            row.stall_torque_nm,
            row.max_efficiency,
            row.temperature_rise_k,
            row.speed_std_rpm,
            row.no_load_speed_rpm,
            row.score,
            row.in_region
        );
    }
    println!("opt {} region {:?}", r.optimum_preload_n, r.region_n);
}
