//! The measurement reader on arbitrary bytes. Properties: no panic; an error names the
//! source first; accepted data re-reads identically from its own `to_csv_string()`; the
//! default plausible ranges accept a subset of what the layout alone accepts, with the
//! same values.
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::measurements::{parse_measurements, parse_measurements_with, PlausibleRanges};

fuzz_target!(|data: &[u8]| {
    let layout = parse_measurements_with(data, "fuzz.csv", &PlausibleRanges::unlimited());
    let plausible = parse_measurements(data, "fuzz.csv");
    if let Err(e) = &layout {
        assert!(e.to_string().starts_with("fuzz.csv"), "{e}");
        assert!(plausible.is_err());
    }
    if let Ok(p) = &plausible {
        assert_eq!(layout.as_ref().ok(), Some(p));
    }
    if let Ok(m) = layout {
        let written = m.to_csv_string();
        let back = parse_measurements_with(written.as_bytes(), "written.csv", &PlausibleRanges::unlimited())
            .unwrap_or_else(|e| panic!("written data do not read back: {e}\n{written}"));
        // the writer keeps neither extra columns nor warnings
        let mut m = m;
        m.extra_columns.clear();
        m.warnings.clear();
        let mut back = back;
        back.warnings.clear();
        assert_eq!(back.to_csv_string(), written);
        assert_eq!(back.len(), m.len());
    }
});
