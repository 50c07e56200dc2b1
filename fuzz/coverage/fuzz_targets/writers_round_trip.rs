//! Every writer's round trip on values and text decoded from the bytes: a motor with any
//! name and parameters (`to_toml` → `from_toml_str`, and the annotated form with any
//! header), and measurement rows with any values and run id (`to_csv_string` →
//! `parse_measurements_with`). Properties: what the builder or `validate` accepts reads
//! back identical; what they refuse is refused with an error, never written.
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::measurements::{parse_measurements_with, Column, Measurements, PlausibleRanges, Row};
use trum_core::{presets, Motor};

fuzz_target!(|data: &[u8]| {
    let split = data.first().map_or(0, |&b| usize::from(b)).min(data.len().saturating_sub(1));
    let (text_bytes, rest) = data.get(1..).unwrap_or(&[]).split_at(split.min(data.len().saturating_sub(1)));
    let text = String::from_utf8_lossy(text_bytes).into_owned();
    // a motor named by the text, with a header comment made of it too
    let mut m: Motor = presets::PRESETS[rest.len() % presets::PRESETS.len()].motor();
    m.name = text.clone();
    for (i, w) in rest.chunks(8).take(4).enumerate() {
        if w.len() == 8 {
            let keys = Motor::all_keys();
            let k = &keys[(i * 7 + usize::from(w[0])) % keys.len()];
            let key = format!("{}.{}", k.section, k.key);
            let v = f64::from_le_bytes(w.try_into().expect("8 bytes"));
            if let Some(p) = m.param_mut(&key) {
                *p = v;
            }
        }
    }
    if m.validate("fuzz", None).is_ok() {
        for written in [m.to_toml(), m.to_toml_annotated(&text, &|k| Some(text.clone() + k))] {
            let back = Motor::from_toml_str(&written, "written.toml")
                .unwrap_or_else(|e| panic!("a written motor file does not read back: {e}\n{written}"));
            assert_eq!(back, m, "{written}");
        }
    }
    // measurement rows: values from the bytes, the text as run id
    let mut b = Measurements::builder().column(Column::TemperatureC);
    for (i, w) in rest.chunks(8).enumerate().take(6) {
        let mut a = [0u8; 8];
        a[..w.len()].copy_from_slice(w);
        let v = f64::from_le_bytes(a);
        let row =
            Row::new(1.0 + i as f64, 150.0, 42_000.0, 0.0, v.abs()).with_temperature_c(v).with_run_id(text.clone());
        b = b.row(row);
    }
    if let Ok(meas) = b.build() {
        let written = meas.to_csv_string();
        let back = parse_measurements_with(written.as_bytes(), "written.csv", &PlausibleRanges::unlimited())
            .unwrap_or_else(|e| panic!("written data do not read back: {e}\n{written:?}"));
        assert_eq!(back, meas, "{written:?}");
    }
});
