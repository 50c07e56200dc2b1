//! The one table of output quantities shared by `trum point`, CSV maps and the Python
//! result object: column name (with unit suffix), unit, meaning, and accessor.

use crate::solution::Solution;

/// One output quantity.
#[derive(Clone, Copy)]
pub struct Quantity {
    /// Column name with unit suffix.
    pub name: &'static str,
    /// Unit as printed.
    pub unit: &'static str,
    /// Meaning.
    pub doc: &'static str,
    /// Accessor.
    pub get: fn(&Solution) -> f64,
}

impl std::fmt::Debug for Quantity {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "Quantity({})", self.name)
    }
}

/// The table and, from the same list, a reader of every value at once.
macro_rules! quantities {
    ($(($field:ident, $unit:literal, $doc:literal)),* $(,)?) => {
        /// Every numeric output quantity, in the order maps and `trum point` print them.
        pub const QUANTITIES: &[Quantity] =
            &[$(Quantity { name: stringify!($field), unit: $unit, doc: $doc, get: |s: &Solution| s.$field }),*];

        /// Every quantity of `s` in [`QUANTITIES`] order: the loops that write or check them
        /// all for every solved point read them here, without a call through `get` each.
        pub fn values(s: &Solution) -> [f64; QUANTITIES.len()] {
            [$(s.$field),*]
        }
    };
}

/// Index of `stall_torque_nm` in [`QUANTITIES`]: the one quantity a solve may leave
/// uncomputed (NaN), which the finiteness check of every solved point skips then.
pub(crate) const STALL_TORQUE_INDEX: usize = index_of("stall_torque_nm");

/// The index of the quantity `name` in [`QUANTITIES`], at compile time (a name that is not
/// there stops the build).
const fn index_of(name: &str) -> usize {
    let mut i = 0;
    while i < QUANTITIES.len() {
        let (a, b) = (QUANTITIES[i].name.as_bytes(), name.as_bytes());
        if a.len() == b.len() {
            let mut k = 0;
            while k < a.len() && a[k] == b[k] {
                k += 1;
            }
            if k == a.len() {
                return i;
            }
        }
        i += 1;
    }
    panic!("no such quantity")
}

quantities! {
    (speed_rpm, "rpm", "rotor speed"),
    (speed_rad_s, "rad/s", "rotor speed"),
    (efficiency, "-", "output power / electrical input power"),
    (output_power_w, "W", "mechanical output power"),
    (input_power_w, "W", "electrical input power, both phases"),
    (stall_torque_nm, "N·m", "stall (blocking) torque at this preload and drive"),
    (amplitude_m, "m", "wave amplitude at the contact surface"),
    (contact_angle_deg, "deg", "contact angle Xc, full arc per wave"),
    (driving_angle_deg, "deg", "driving angle Xs, full arc per wave"),
    (driving_ratio, "-", "proportion of the driving zone in the contact zone"),
    (contact_half_angle_rad, "rad", "contact half-angle phi0 in wave phase"),
    (stick_half_angle_rad, "rad", "stick half-angle theta_s in wave phase"),
    (contact_length_m, "m", "contact length per wave"),
    (crest_speed_m_s, "m/s", "peak tangential surface speed of the stator"),
    (axial_force_n, "N", "axial contact force"),
    (dielectric_loss_w, "W", "dielectric loss"),
    (damping_loss_w, "W", "stator damping loss"),
    (friction_loss_w, "W", "contact friction loss"),
    (radial_friction_loss_w, "W", "radial-slip part of the friction loss"),
    (rotor_loss_w, "W", "rotor viscous loss"),
    (current_a, "A", "drive current amplitude per phase"),
    (feedback_v, "V", "feedback electrode voltage amplitude"),
    (electrode_voltage_v, "V", "voltage at the electrodes (zero-to-peak)"),
    (phase_lag_rad, "rad", "phase lag of the wave behind the drive"),
    (modal_stiffness_n_per_m, "N/m", "effective modal stiffness"),
    (temperature_rise_k, "K", "steady-state temperature rise over ambient"),
    (temperature_rise_at_elapsed_k, "K", "temperature rise at the point's elapsed time"),
    (speed_std_rpm, "rpm", "speed standard deviation over a revolution"),
}

/// Looks up a quantity by column name; the error lists the valid names.
pub fn find(name: &str) -> Result<&'static Quantity, String> {
    QUANTITIES.iter().find(|q| q.name == name).ok_or_else(|| {
        format!(
            "unknown quantity '{name}'; valid quantities are: {}",
            QUANTITIES.iter().map(|q| q.name).collect::<Vec<_>>().join(", ")
        )
    })
}
