//! Built-in motors from the papers. Each preset is an annotated TOML motor file in
//! `crates/trum-core/presets/` (embedded at build time), read by the motor-file reader:
//! every value sits beside its provenance comment (taken from a paper's table; assumed,
//! with the reason and the plausible range; or calibrated, with the figure it was fitted
//! to and the script that fits it), so a value and its note cannot drift apart. The
//! figures the presets are checked against are in `tests/data/papers/` and
//! `tests/papers.rs`; `crates/trum-core/examples/fit_presets.rs` recalibrates them.

use crate::dynamics::bar_type::BarMotor;
use crate::error::ParamError;
use crate::params::*;

/// A preset: its name, description and annotated motor file.
#[derive(Clone, Debug)]
pub struct Preset {
    /// Name used on the command line (`trum60a`).
    pub name: &'static str,
    /// One-line description.
    pub summary: &'static str,
    /// Sources.
    pub sources: &'static str,
    /// The annotated, complete motor file (`crates/trum-core/presets/NAME.toml`).
    pub toml: &'static str,
}

impl Preset {
    fn file_name(&self) -> String {
        format!("presets/{}.toml", self.name)
    }

    /// The motor. The embedded files are checked by the tests of this module, so they
    /// always parse.
    pub fn motor(&self) -> Motor {
        let mut m = Motor::from_toml_str(self.toml, &self.file_name())
            .unwrap_or_else(|e| panic!("built-in preset file is invalid: {e}"));
        m.preset = Some(self.name.to_string());
        m
    }

    /// The drive of the preset's source figures (`[drive]` of its file), if it has one.
    pub fn drive(&self) -> Option<Drive> {
        // `[drive]` of a complete file never looks up a preset, so this cannot recurse.
        Drive::from_toml_str(self.toml, &self.file_name()).ok().flatten()
    }

    /// Provenance of one value: the comment beside `key` in section `[section]` of the
    /// preset file (`dotted` = `section.key`; for effects `effects.NAME`).
    pub fn note(&self, dotted: &str) -> Option<&'static str> {
        let (section, key) = dotted.rsplit_once('.')?;
        let mut current = "";
        for line in self.toml.lines() {
            let t = line.trim();
            if let Some(h) = t.strip_prefix('[') {
                current = h.split(']').next().unwrap_or("").trim();
                continue;
            }
            if current != section {
                continue;
            }
            let Some((k, rest)) = t.split_once('=') else { continue };
            if k.trim() == key {
                return rest.split_once('#').map(|(_, c)| c.trim()).filter(|c| !c.is_empty());
            }
        }
        None
    }

    /// The text of one `[section]` of the preset file, comments included (empty if absent).
    fn section_text(&self, section: &str) -> String {
        let mut out = String::new();
        let mut inside = false;
        for line in self.toml.lines() {
            let t = line.trim();
            if t.starts_with('[') {
                inside = t.trim_start_matches('[').split(']').next().map(str::trim) == Some(section);
            }
            if inside {
                out.push_str(line);
                out.push('\n');
            }
        }
        out
    }

    /// The preset as a commented TOML motor file that reads back to the same motor: each
    /// value with its meaning, unit and provenance, the `[drive]` and `[effects]` tables
    /// with their notes.
    pub fn to_toml(&self) -> String {
        let header = format!(
            "trum motor file: preset '{}'\n{}\nSources: {}\nEvery value is SI; the comment gives its meaning, unit and provenance.\n",
            self.name, self.summary, self.sources
        );
        let motor = self.motor();
        let mut s = motor.to_toml_annotated(&header, &|k| self.note(k).map(str::to_string));
        // the generated effects table carries no notes: use the file's own
        let fx = self.section_text("effects");
        if !fx.is_empty() {
            if let Some(i) = s.find("\n[effects]") {
                s.truncate(i);
                s.truncate(s.trim_end().len());
                s.push_str("\n\n");
                s.push_str(fx.trim_end());
                s.push('\n');
            }
        }
        let drive = self.section_text("drive");
        if !drive.is_empty() {
            s.push('\n');
            s.push_str(drive.trim_end());
            s.push('\n');
        }
        s
    }
}

/// All presets.
pub static PRESETS: &[Preset] = &[
    Preset {
        name: "trum60a",
        summary: "TRUM60A (Chunsheng, Nanjing), B09 mode, PTFE friction layer, as simulated by Chen, Zheng and Fan",
        sources: "Chen, Zheng, Fan 2020, Pre-pressure optimization for ultrasonic motors based on multi-sensor fusion (Sensors 20, 2096), Table A1 and sections 4-5",
        toml: include_str!("../presets/trum60a.toml"),
    },
    Preset {
        name: "trum60-qut",
        summary: "TRUM-60 as identified by Sun, Yin, Liu and Zhang (Qingdao University of Technology)",
        sources: "Sun, Yin, Liu, Zhang 2021, Efficiency model for traveling wave-type ultrasonic motors based on contact variables and preload (Actuators 10, 158), Tables 1 and 2, section 3",
        toml: include_str!("../presets/trum60-qut.toml"),
    },
    Preset {
        name: "generic60",
        summary: "A generic 60 mm, 9-wave traveling-wave motor with round-number parameters, for teaching and tests",
        sources: "typical values of the 60 mm motor class in Chen et al. 2020, Sun et al. 2021 and the radial-friction paper; every value assumed",
        toml: include_str!("../presets/generic60.toml"),
    },
];

/// A bar-type motor preset ([`crate::dynamics::bar_type`]): its name, description and
/// annotated bar-type motor file. Only the step response runs these motors.
#[derive(Clone, Debug)]
pub struct BarPreset {
    /// Name used on the command line (`bar36`).
    pub name: &'static str,
    /// One-line description.
    pub summary: &'static str,
    /// Sources.
    pub sources: &'static str,
    /// The annotated, complete bar-type motor file (`crates/trum-core/presets/NAME.toml`).
    pub toml: &'static str,
}

impl BarPreset {
    /// The motor. The embedded files are checked by the tests of this module.
    pub fn motor(&self) -> BarMotor {
        let mut m = BarMotor::from_toml_str(self.toml, &format!("presets/{}.toml", self.name))
            .unwrap_or_else(|e| panic!("built-in preset file is invalid: {e}"));
        m.preset = Some(self.name.to_string());
        m
    }

    /// Provenance of one value: the comment beside `section.key` in the preset file.
    pub fn note(&self, dotted: &str) -> Option<&'static str> {
        Preset { name: self.name, summary: self.summary, sources: self.sources, toml: self.toml }.note(dotted)
    }

    /// The preset as a commented bar-type motor file that reads back to the same motor.
    pub fn to_toml(&self) -> String {
        let header = format!(
            "trum bar-type motor file: preset '{}'\n{}\nSources: {}\nEvery value is SI; the comment gives its provenance.\n",
            self.name, self.summary, self.sources
        );
        self.motor().to_toml_annotated(&header, &|k| self.note(k).map(str::to_string))
    }
}

/// All bar-type presets.
pub static BAR_PRESETS: &[BarPreset] = &[BarPreset {
    name: "bar36",
    summary: "A bar-type motor (rigid-disc stator, 36.5 kHz, Q 200) at the conditions of the bar-type transient paper's simulation",
    sources: "Transient analysis of bar-type ultrasonic motors (section IV): natural frequency, Q, drive moment and frequency, 256 contact nodes; the rest assumed",
    toml: include_str!("../presets/bar36.toml"),
}];

/// Looks up a bar-type preset by name.
pub fn find_bar(name: &str) -> Option<&'static BarPreset> {
    BAR_PRESETS.iter().find(|p| p.name == name)
}

/// Looks up a preset by name; the error lists the valid names, and says so when the
/// name is a bar-type preset (which only the step response runs).
pub fn find(name: &str) -> Result<&'static Preset, ParamError> {
    PRESETS.iter().find(|p| p.name == name).ok_or_else(|| ParamError {
        source_name: "presets".into(),
        line: None,
        key: "preset".into(),
        reason: if find_bar(name).is_some() {
            format!("'{name}' is a bar-type motor: only the step response (`trum step`, Python `trum.step`) runs it; the ring-motor presets are: {}", PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", "))
        } else {
            format!(
                "unknown preset '{name}'; valid presets are: {}",
                PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
            )
        },
    })
}

/// The motors the model's own unit tests were written for: frozen baseline copies of the
/// paper presets (`tests/data/motors/`, no effects), so a recalibration of `trum60a` or
/// `trum60-qut` does not move the solver's regression points; other names are the presets.
#[cfg(test)]
pub(crate) fn frozen(name: &str) -> Result<Motor, ParamError> {
    match name {
        "trum60a" => Motor::from_toml_str(
            include_str!("../../../tests/data/motors/trum60a_baseline.toml"),
            "trum60a_baseline.toml",
        ),
        "trum60-qut" => Motor::from_toml_str(
            include_str!("../../../tests/data/motors/trum60-qut_baseline.toml"),
            "trum60-qut_baseline.toml",
        ),
        other => preset(other),
    }
}

/// The motor of a preset by name.
pub fn preset(name: &str) -> Result<Motor, ParamError> {
    find(name).map(|p| p.motor())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every preset file parses, every motor key of every preset has a provenance comment
    /// of a known kind, and `to_toml` reads back to the same motor and drive.
    #[test]
    fn every_preset_file_is_complete_annotated_and_round_trips() {
        let kinds = ["Chen et al. 2020", "Sun et al. 2021", "assumed", "calibrated"];
        for p in PRESETS {
            let m = p.motor();
            assert_eq!(m.preset.as_deref(), Some(p.name));
            for info in Motor::all_keys() {
                let dotted = format!("{}.{}", info.section, info.key);
                let note = p.note(&dotted).unwrap_or_else(|| panic!("{}: {dotted} has no provenance", p.name));
                assert!(kinds.iter().any(|k| note.starts_with(k)), "{}: {dotted}: '{note}' names no source", p.name);
            }
            let text = p.to_toml();
            let back = Motor::from_toml_str(&text, "show").unwrap_or_else(|e| panic!("{}: {e}\n{text}", p.name));
            assert_eq!(back, m, "{}", p.name);
            assert_eq!(Drive::from_toml_str(&text, "show").expect("drive"), p.drive(), "{}", p.name);
            for e in m.effects.active() {
                let dotted = format!("effects.{}", e.name());
                assert!(p.note(&dotted).is_some_and(|n| n.len() > 20), "{}: {dotted} says not why", p.name);
            }
        }
    }

    /// Every bar-type preset file parses, every key has a provenance comment naming the
    /// paper or saying it is assumed, and `to_toml` reads back to the same motor; its
    /// name is refused by the ring-motor lookup with a message saying what runs it.
    #[test]
    fn bar_presets_are_annotated_round_trip_and_are_refused_by_ring_commands() {
        for p in BAR_PRESETS {
            let m = p.motor();
            for (sec, key, _, _) in crate::dynamics::bar_type::BAR_KEYS {
                let dotted = format!("{sec}.{key}");
                let note = p.note(&dotted).unwrap_or_else(|| panic!("{}: {dotted} has no provenance", p.name));
                assert!(note.starts_with("paper") || note.starts_with("assumed: "), "{}: {dotted}: {note}", p.name);
            }
            let back = BarMotor::from_toml_str(&p.to_toml(), "show").expect("reads back");
            assert_eq!(BarMotor { preset: m.preset.clone(), ..back }, m);
            let e = find(p.name).expect_err("not a ring preset");
            assert!(e.reason.contains("bar-type") && e.reason.contains("trum step"), "{e}");
            assert!(PRESETS.iter().all(|r| r.name != p.name));
        }
    }

    /// The presets from a paper carry that paper's drive; an override file inherits it,
    /// its own `[drive]` replaces it and a bad one is an error naming the key and line.
    #[test]
    fn drives_come_from_the_papers_and_files_override_them() {
        let d = find("trum60a").expect("preset").drive().expect("drive");
        assert_eq!((d.voltage_v, d.frequency_hz), (200.0, 42_000.0));
        let d = find("trum60-qut").expect("preset").drive().expect("drive");
        assert_eq!((d.voltage_v, d.frequency_hz), (150.0, 42_000.0));
        assert_eq!(find("generic60").expect("preset").drive(), None);
        let inherit = Drive::from_toml_str("preset = \"trum60a\"\n", "f.toml").expect("ok");
        assert_eq!(inherit.map(|d| d.frequency_hz), Some(42_000.0));
        let own =
            Drive::from_toml_str("preset = \"trum60a\"\n[drive]\nvoltage_v = 180\nfrequency_hz = 43000\n", "f.toml")
                .expect("ok")
                .expect("drive");
        assert_eq!((own.voltage_v, own.frequency_hz), (180.0, 43_000.0));
        let bad =
            Drive::from_toml_str("preset = \"trum60a\"\n[drive]\nvoltage_v = -1\nfrequency_hz = 43000\n", "f.toml")
                .expect_err("negative voltage");
        assert_eq!((bad.key.as_str(), bad.line), ("drive.voltage_v", Some(3)), "{bad}");
        let missing =
            Drive::from_toml_str("preset = \"trum60a\"\n[drive]\nvoltage_v = 100\n", "f.toml").expect_err("missing");
        assert_eq!(missing.key, "drive.frequency_hz", "{missing}");
        // the motor reader accepts the table too
        assert!(
            Motor::from_toml_str("preset = \"trum60a\"\n[drive]\nvoltage_v = 180\nfrequency_hz = 43000\n", "f").is_ok()
        );
    }
}
