//! The solver on a motor (a preset with up to four parameters overridden, effects on,
//! their parameters inside their ranges in seven inputs of eight) and an operating point
//! decoded from the bytes: values either raw f64 bits (NaN and infinities included) or a
//! nominal value times 10^(-8..8). Properties: no panic; an
//! invalid operating point gives `invalid_input`; for a motor that validates, a valid
//! status has every quantity finite and the efficiency in [0, 1]; a solve that spends its
//! work bound says so and is `no_convergence`. Each solve is bounded at
//! [`FUZZ_WORK_BOUND`], a five-hundredth of the default bound's units (at most about 0.2 s
//! of work), so that the inputs that reach the deepest routes (all seven effects,
//! parameters at their ends) do not take the run's time; every path below that bound is
//! the default solve's, bit for bit (docs/RELIABILITY.md, "The work bound of a solve").
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::effects::ALL as ALL_EFFECTS;
use trum_core::quantities::QUANTITIES;
use trum_core::solve::{solve_prepared, Prepared};
use trum_core::{presets, Motor, OperatingPoint, Status};

/// The work bound of each solve [interface-integrand evaluations; trum_core's
/// `solve::WORK_BOUND` is 10⁹].
const FUZZ_WORK_BOUND: u64 = 2_000_000;

struct Bytes<'a>(&'a [u8]);

impl Bytes<'_> {
    fn byte(&mut self) -> u8 {
        let (b, rest) = self.0.split_first().map_or((0, &[][..]), |(b, r)| (*b, r));
        self.0 = rest;
        b
    }
    /// Raw bits (odd tag) or `nominal` × 10^((b − 128)/16).
    fn value(&mut self, nominal: f64) -> f64 {
        let tag = self.byte();
        if tag & 1 == 1 && self.0.len() >= 8 {
            let mut a = [0u8; 8];
            a.copy_from_slice(&self.0[..8]);
            self.0 = &self.0[8..];
            f64::from_le_bytes(a)
        } else {
            nominal * 10f64.powf((f64::from(self.byte()) - 128.0) / 16.0)
        }
    }
}

fuzz_target!(|data: &[u8]| {
    let mut b = Bytes(data);
    let preset = &presets::PRESETS[usize::from(b.byte()) % presets::PRESETS.len()];
    let mut m: Motor = preset.motor();
    let keys: Vec<String> = Motor::all_keys().iter().map(|k| format!("{}.{}", k.section, k.key)).collect();
    for _ in 0..usize::from(b.byte() % 5) {
        let key = &keys[usize::from(b.byte()) % keys.len()];
        let nominal = m.param(key).unwrap_or(1.0);
        let v = b.value(nominal);
        if let Some(p) = m.param_mut(key) {
            *p = v;
        }
    }
    let fx = b.byte();
    // Seven inputs in eight keep every effect parameter inside its documented range (the
    // motors a reader accepts); the eighth scales the typical values by 10^±2, often
    // outside it. A motor that fails `validate` is solved too (no panic is its property),
    // but no front end solves one, and out-of-range parameters are where a single solve
    // takes seconds: without the bias most of the budget went to them.
    let in_range = b.byte() < 224;
    for (i, e) in ALL_EFFECTS.iter().enumerate() {
        if fx & (1 << i) != 0 {
            let values: Vec<f64> = e
                .info()
                .params
                .iter()
                .map(|p| {
                    let u = f64::from(b.byte()) / 255.0;
                    if !in_range {
                        p.typical * 10f64.powf((u - 0.5) * 4.0)
                    } else {
                        let hi = if p.max.is_finite() { p.max } else { p.typical.abs().max(1e-12) * 100.0 };
                        let lo = if p.min.is_finite() { p.min } else { -hi };
                        if lo > 0.0 && hi / lo > 100.0 {
                            lo * (hi / lo).powf(u)
                        } else {
                            lo + (hi - lo) * u
                        }
                    }
                })
                .collect();
            m.effects.set(*e, &values);
        }
    }
    let op = OperatingPoint {
        preload_n: b.value(250.0),
        torque_nm: b.value(0.1).abs() * if b.byte() < 16 { -1.0 } else { 1.0 },
        voltage_v: b.value(200.0),
        frequency_hz: b.value(43_000.0),
        elapsed_s: if b.byte() < 128 { 0.0 } else { b.value(60.0) },
    };
    let valid_motor = m.validate("fuzz", None).is_ok();
    let s = solve_prepared(&Prepared::new(&m).with_work_bound(FUZZ_WORK_BOUND), &m, &op, None);
    if s.work_bound_reached {
        assert_eq!(s.status, Status::NoConvergence, "{op:?}");
    }
    if op.invalid_reason().is_some() {
        assert_eq!(s.status, Status::InvalidInput, "{op:?}");
    }
    if valid_motor && s.status.is_valid() {
        for q in QUANTITIES.iter() {
            assert!((q.get)(&s).is_finite(), "{} = {} at {op:?}, {m:?}", q.name, (q.get)(&s));
        }
        assert!((0.0..=1.0).contains(&s.efficiency), "{}", s.efficiency);
    }
});
