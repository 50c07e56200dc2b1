//! KNOWN BUGS: inputs for which trum does not yet do what it should. Each test fails
//! until the bug is fixed; then delete the file's line in
//! tests/data/bad/motor/known_bugs.txt (so the normal corpus tests cover it) and the test
//! here (or keep it as a regression test). See docs/RELIABILITY.md, "Bugs found".

use std::path::Path;
use trum_core::Motor;

fn corpus_file(name: &str) -> (String, String) {
    let p = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/data/bad/motor").join(name);
    let text = std::fs::read_to_string(&p).expect("corpus file");
    let exp = std::fs::read_to_string(p.with_extension("expected")).expect("expected file");
    (text, exp.trim_end_matches('\n').replace("{source}", "bad.toml"))
}

fn check(name: &str) {
    let (text, expected) = corpus_file(name);
    let got = Motor::from_toml_str_with_sweep(&text, "bad.toml").err().map(|e| e.to_string()).unwrap_or_default();
    assert_eq!(got, expected, "{name}");
}

/// params.rs, `Motor::from_toml_str`: for an unknown section header `[statr]` the key is
/// qualified with the "section above it", which is the header's own `[` → key '.statr'.
#[test]
fn known_bug_unknown_section_key_has_a_leading_dot() {
    check("unknown_section.toml");
}

/// params.rs, `AxisSpec` (`#[serde(untagged)]`): a `[sweep]` axis that is neither a
/// number nor `[start, stop, n]` reports "data did not match any variant of untagged
/// enum AxisSpec": a Rust type name, and no key.
#[test]
fn known_bug_sweep_axis_of_the_wrong_shape_leaks_a_type_name() {
    check("sweep_axis_two_numbers.toml");
    check("sweep_axis_string.toml");
}
