//! Built-in motors from the papers. Every value carries its provenance: taken from a
//! paper's table, assumed (the paper leaves it out; a physically reasonable value is
//! chosen and the reason given), or calibrated (chosen so the preset reproduces a result
//! the paper publishes; the test that checks it is named).

use crate::effects::Effects;
use crate::error::ParamError;
use crate::params::*;

/// A preset: the motor and the provenance of each value.
#[derive(Clone, Debug)]
pub struct Preset {
    /// Name used on the command line (`trum60a`).
    pub name: &'static str,
    /// One-line description.
    pub summary: &'static str,
    /// Sources.
    pub sources: &'static str,
    /// (dotted key, provenance) for every numeric value.
    pub notes: &'static [(&'static str, &'static str)],
    build: fn() -> Motor,
}

impl Preset {
    /// The motor.
    pub fn motor(&self) -> Motor {
        (self.build)()
    }
    /// Provenance of one value.
    pub fn note(&self, dotted: &str) -> Option<&'static str> {
        self.notes.iter().find(|(k, _)| *k == dotted).map(|(_, v)| *v)
    }
    /// The preset as a commented TOML motor file that reads back to the same motor.
    pub fn to_toml(&self) -> String {
        let header = format!(
            "trum motor file: preset '{}'\n{}\nSources: {}\nEvery value is SI; the comment gives its meaning, unit and provenance.\n",
            self.name, self.summary, self.sources
        );
        self.motor().to_toml_annotated(&header, &|k| self.note(k).map(str::to_string))
    }
}

const PAPER_000: &str = "seed 000 Table A1";
const _: &str = PAPER_000;

/// All presets.
pub const PRESETS: &[Preset] = &[
    Preset {
        name: "trum60a",
        summary: "TRUM60A (Chunsheng, Nanjing), B09 mode, PTFE friction layer, as simulated by Chen, Zheng and Fan",
        sources: "seed 000 (Chen et al., Sensors 2020, 20, 2096), Table A1 and section 4",
        notes: &[
            ("geometry.wave_number", "seed 000 Table A1"),
            ("geometry.mean_radius_m", "seed 000 Table A1"),
            ("geometry.contact_width_m", "assumed: seed 001 Table 1 b_f of the same 60 mm motor family"),
            ("geometry.neutral_plane_distance_m", "assumed: 2 mm keeps the stator running up to the paper's 570 N preload at 200 V and gives about 100 rpm no-load at 260 N; not in the paper"),
            ("friction_layer.youngs_modulus_pa", "calibrated: contact angle 24.15 deg at 150 N and 28.94 deg at 200 N (seed 000 section 4.3); PTFE-like modulus"),
            ("friction_layer.thickness_m", "seed 000 Table A1 (h)"),
            ("friction_layer.friction_coefficient", "seed 000 Table A1"),
            ("stator.modal_mass_kg", "seed 000 Table A1 (m_o)"),
            ("stator.resonance_frequency_hz", "assumed: the printed k_o = 4.56e9 N/m with m_o gives 152 kHz, inconsistent with the 42-43 kHz drive; resonance placed 2.25 kHz below the 43 kHz drive, as usual for TRUMs"),
            ("stator.modal_damping_ns_per_m", "assumed: the printed d_o = 0.05 N s/m implies Q ~ 3e4; Q ~ 130 for a bronze stator with bonded PZT and teeth"),
            ("stator.force_factor_n_per_v", "seed 000 Table A1 (k_c)"),
            ("electrical.clamped_capacitance_f", "seed 000 Table A1 (C_p)"),
            ("electrical.dielectric_loss_tangent", "assumed: seed 001 Table 1 value of the same motor family"),
            ("electrical.feedback_gain_v_per_m", "assumed: mean conversion factor of seed 001 Table 2"),
            ("rotor.viscous_damping_nms", "seed 000 Table A1 (d_r)"),
            ("rotor.inertia_kg_m2", "seed 000 Table A1 (J_r, printed in kg/m^2)"),
            ("rotor.mass_kg", "seed 000 Table A1 (m_r)"),
            ("thermal.heat_transfer_coefficient_w_per_m2k", "seed 000 Table A1 (alpha)"),
            ("thermal.surface_area_m2", "seed 000 Table A1 (S)"),
            ("thermal.heat_capacity_j_per_k", "assumed: about 0.25 kg of motor at 600 J/(kg K); not in the paper"),
            ("thermal.ambient_c", "seed 000 section 4.2 (tests start at 28 degC)"),
            ("assembly.axial_spring_stiffness_n_per_m", "assumed: disc-spring stiffness of a 60 mm motor; not in the paper"),
        ],
        build: trum60a,
    },
    Preset {
        name: "trum60-qut",
        summary: "TRUM-60 as identified by Sun, Yin, Liu and Zhang (Qingdao University of Technology)",
        sources: "seed 001 (Sun et al., Actuators 2021, 10, 158), Tables 1 and 2",
        notes: &[
            ("geometry.wave_number", "assumed: B09 mode of the TRUM-60 family (seed 000)"),
            ("geometry.mean_radius_m", "seed 001 Table 1 (r)"),
            ("geometry.contact_width_m", "seed 001 Table 1 (b_f)"),
            ("geometry.neutral_plane_distance_m", "seed 001 Table 1 (h_0)"),
            ("friction_layer.youngs_modulus_pa", "seed 001 Table 1 (E_f)"),
            ("friction_layer.thickness_m", "assumed: h_f is not given; 0.5 mm as in seed 000 Table A1"),
            ("friction_layer.friction_coefficient", "seed 001 Table 1 (mu)"),
            ("stator.modal_mass_kg", "assumed: Table 1's m_s = 0.55 g and k_s = 345 N/m belong to a normalised model (their resonance would be 126 Hz); the TRUM60A modal mass of seed 000 is used"),
            ("stator.resonance_frequency_hz", "calibrated: no-load speeds of seed 001 Table 2 at 150 V, 42 kHz"),
            ("stator.modal_damping_ns_per_m", "calibrated with the resonance and force factor on seed 001 Table 2 (Q about 260)"),
            ("stator.force_factor_n_per_v", "calibrated: least squares on the no-load speeds and feedback voltages of seed 001 Table 2"),
            ("electrical.clamped_capacitance_f", "assumed: seed 000 Table A1 value of the same motor family"),
            ("electrical.dielectric_loss_tangent", "seed 001 Table 1 (tan delta)"),
            ("electrical.feedback_gain_v_per_m", "seed 001 Table 2: mean of the four conversion factors"),
            ("rotor.viscous_damping_nms", "assumed: seed 000 Table A1 value"),
            ("rotor.inertia_kg_m2", "assumed: seed 000 Table A1 value"),
            ("rotor.mass_kg", "assumed: seed 000 Table A1 value"),
            ("thermal.heat_transfer_coefficient_w_per_m2k", "assumed: seed 000 Table A1 value"),
            ("thermal.surface_area_m2", "assumed: seed 000 Table A1 value"),
            ("thermal.heat_capacity_j_per_k", "assumed: about 0.25 kg at 600 J/(kg K)"),
            ("thermal.ambient_c", "assumed: room temperature"),
            ("assembly.axial_spring_stiffness_n_per_m", "assumed: disc-spring stiffness of a 60 mm motor"),
        ],
        build: trum60_qut,
    },
    Preset {
        name: "generic60",
        summary: "A generic 60 mm, 9-wave traveling-wave motor with round-number parameters, for teaching and tests",
        sources: "typical values of the 60 mm motor class in seeds 000-002; every value assumed",
        notes: &[],
        build: generic60,
    },
];

/// Looks up a preset by name; the error lists the valid names.
pub fn find(name: &str) -> Result<&'static Preset, ParamError> {
    PRESETS.iter().find(|p| p.name == name).ok_or_else(|| ParamError {
        source_name: "presets".into(),
        line: None,
        key: "preset".into(),
        reason: format!(
            "unknown preset '{name}'; valid presets are: {}",
            PRESETS.iter().map(|p| p.name).collect::<Vec<_>>().join(", ")
        ),
    })
}

/// The motor of a preset by name.
pub fn preset(name: &str) -> Result<Motor, ParamError> {
    find(name).map(|p| p.motor())
}

fn trum60a() -> Motor {
    Motor {
        name: "TRUM60A".into(),
        preset: Some("trum60a".into()),
        geometry: Geometry {
            wave_number: 9.0,
            mean_radius_m: 0.02625,
            contact_width_m: 3.2e-3,
            neutral_plane_distance_m: 2.0e-3,
        },
        friction_layer: FrictionLayer { youngs_modulus_pa: 1.305e8, thickness_m: 0.5e-3, friction_coefficient: 0.3 },
        stator: Stator {
            modal_mass_kg: 0.005,
            resonance_frequency_hz: 40_750.0,
            modal_damping_ns_per_m: 10.0,
            force_factor_n_per_v: 0.4147,
        },
        electrical: Electrical {
            clamped_capacitance_f: 5.41e-9,
            dielectric_loss_tangent: 3.5e-3,
            feedback_gain_v_per_m: 3.07e7,
        },
        rotor: Rotor { viscous_damping_nms: 5.0e-4, inertia_kg_m2: 7.2e-6, mass_kg: 0.03 },
        thermal: Thermal {
            heat_transfer_coefficient_w_per_m2k: 10.0,
            surface_area_m2: 0.02366,
            heat_capacity_j_per_k: 150.0,
            ambient_c: 28.0,
        },
        assembly: Assembly { axial_spring_stiffness_n_per_m: 2.0e5 },
        effects: Effects::none(),
    }
}

fn trum60_qut() -> Motor {
    Motor {
        name: "TRUM-60 (QUT)".into(),
        preset: Some("trum60-qut".into()),
        geometry: Geometry {
            wave_number: 9.0,
            mean_radius_m: 0.030,
            contact_width_m: 3.2e-3,
            neutral_plane_distance_m: 4.0e-3,
        },
        friction_layer: FrictionLayer { youngs_modulus_pa: 4.3e9, thickness_m: 0.5e-3, friction_coefficient: 0.24 },
        stator: Stator {
            modal_mass_kg: 0.005,
            resonance_frequency_hz: 41_300.0,
            modal_damping_ns_per_m: 5.0,
            force_factor_n_per_v: 0.1,
        },
        electrical: Electrical {
            clamped_capacitance_f: 5.41e-9,
            dielectric_loss_tangent: 3.5e-3,
            feedback_gain_v_per_m: 3.07e7,
        },
        rotor: Rotor { viscous_damping_nms: 5.0e-4, inertia_kg_m2: 7.2e-6, mass_kg: 0.03 },
        thermal: Thermal {
            heat_transfer_coefficient_w_per_m2k: 10.0,
            surface_area_m2: 0.02366,
            heat_capacity_j_per_k: 150.0,
            ambient_c: 25.0,
        },
        assembly: Assembly { axial_spring_stiffness_n_per_m: 2.0e5 },
        effects: Effects::none(),
    }
}

fn generic60() -> Motor {
    Motor {
        name: "generic 60 mm TRUM".into(),
        preset: Some("generic60".into()),
        geometry: Geometry {
            wave_number: 9.0,
            mean_radius_m: 0.027,
            contact_width_m: 3.0e-3,
            neutral_plane_distance_m: 3.0e-3,
        },
        friction_layer: FrictionLayer { youngs_modulus_pa: 1.0e9, thickness_m: 0.5e-3, friction_coefficient: 0.25 },
        stator: Stator {
            modal_mass_kg: 0.01,
            resonance_frequency_hz: 40_000.0,
            modal_damping_ns_per_m: 5.0,
            force_factor_n_per_v: 0.5,
        },
        electrical: Electrical {
            clamped_capacitance_f: 5.0e-9,
            dielectric_loss_tangent: 5.0e-3,
            feedback_gain_v_per_m: 3.0e7,
        },
        rotor: Rotor { viscous_damping_nms: 2.0e-4, inertia_kg_m2: 1.0e-5, mass_kg: 0.04 },
        thermal: Thermal {
            heat_transfer_coefficient_w_per_m2k: 10.0,
            surface_area_m2: 0.025,
            heat_capacity_j_per_k: 150.0,
            ambient_c: 25.0,
        },
        assembly: Assembly { axial_spring_stiffness_n_per_m: 2.0e5 },
        effects: Effects::none(),
    }
}
