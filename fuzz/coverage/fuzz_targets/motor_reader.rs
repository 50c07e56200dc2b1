//! The motor-file reader on arbitrary bytes. Properties: no panic; an error names the
//! source first; an accepted motor validates, and its own `to_toml()` reads back to the
//! identical motor (so every motor file trum writes reads back).
#![no_main]
use libfuzzer_sys::fuzz_target;
use trum_core::Motor;

fuzz_target!(|data: &[u8]| {
    let text = String::from_utf8_lossy(data);
    match Motor::from_toml_str_with_sweep(&text, "fuzz.toml") {
        Err(e) => assert!(e.to_string().starts_with("fuzz.toml"), "{e}"),
        Ok((m, _)) => {
            assert!(m.validate("fuzz.toml", None).is_ok());
            let written = m.to_toml();
            let back = Motor::from_toml_str(&written, "written.toml")
                .unwrap_or_else(|e| panic!("a written motor file does not read back: {e}\n{written}"));
            assert_eq!(back, m, "{written}");
        }
    }
});
