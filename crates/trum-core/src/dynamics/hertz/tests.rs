use super::*;

#[test]
fn explore() {
    let o = HertzOscillator::default();
    for v in [100.0, 200.0, 300.0] {
        let op = OperatingPoint { voltage_v: v, preload_n: 400.0 };
        let e = o.effective(&op).unwrap();
        let j = o.jump_frequencies(&op, ResponseMethod::MultipleScales).unwrap();
        let jc = o.jump_frequencies_closed_form(&op).unwrap();
        let jh = o.jump_frequencies(&op, ResponseMethod::HarmonicBalance).unwrap();
        println!("V={v} eff={e:?}\n f0={} MS={j:?}\n CF={jc:?}\n HB={jh:?}", e.linear_resonance_hz());
    }
}
