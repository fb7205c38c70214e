//! SI units of the columns that [`CsvObserver`](crate::CsvObserver) writes (and `mbd run`
//! with it), for axis labels: the one place that knows them.
//!
//! The unit follows from the column's name alone: `t` (s); a coordinate `body.x`, `body.y`,
//! `body.z` (m), `body.theta` (rad); a velocity `d_body.x` (m/s), `d_body.theta` (rad/s); the
//! energy `H` and
//! the energy balance `W_external`, `E_dissipated`, `energy_balance` (J); a joint reaction
//! `joint.fx`, `joint.fy`, a spatial joint's `.fz` (N), `joint.mz`, `.mx`, `.my` (N m) and a
//! reaction sensor's `.fx_body`,
//! `.fy_body` (N); a point sensor's `.vx`, `.vy`, `.vz` (m/s), `.ax`, `.ay`, `.az` (m/s^2); an
//! angular velocity sensor's `.wx`, `.wy`, `.wz`, `.wx_body`, `.wy_body`, `.wz_body` (rad/s);
//! a joint sensor's
//! `.angle` (rad), `.rate` (rad/s), `.s` (m), `.ds` (m/s); an energy sensor's `.kinetic`,
//! `.potential`, `.total` (J).
//! The constraint residuals `max_abs_phi`, `max_abs_phidot` have none (their equations mix
//! lengths and angles), nor has any other name. A point sensor whose own name starts with `d_`
//! has its `.x`, `.y` read as a velocity: the names carry no more than that.
//!
//! ```
//! use mbd_analysis::units::{axis_label, unit_of};
//! assert_eq!(unit_of("crank.theta"), Some("rad"));
//! assert_eq!(unit_of("d_slider.x"), Some("m/s"));
//! assert_eq!(unit_of("max_abs_phi"), None);
//! assert_eq!(axis_label("H"), "H [J]");
//! assert_eq!(axis_label("max_abs_phi"), "max_abs_phi");
//! ```

/// The unit of a result column by its name (see the module documentation), `None` for a
/// dimensionless or unknown column.
pub fn unit_of(column: &str) -> Option<&'static str> {
    match column {
        "t" => return Some("s"),
        "H" | "W_external" | "E_dissipated" | "energy_balance" => return Some("J"),
        _ => {}
    }
    let (owner, part) = column.rsplit_once('.')?;
    if owner.is_empty() {
        return None;
    }
    let rate = owner.starts_with("d_") && owner.len() > 2;
    Some(match (part, rate) {
        ("x" | "y" | "z", false) | ("s", _) => "m",
        ("x" | "y" | "z", true) | ("vx" | "vy" | "vz" | "ds", _) => "m/s",
        ("theta", false) | ("angle", _) => "rad",
        ("theta", true) | ("rate", _) => "rad/s",
        ("wx" | "wy" | "wz" | "wx_body" | "wy_body" | "wz_body", _) => "rad/s",
        ("ax" | "ay" | "az", _) => "m/s^2",
        ("fx" | "fy" | "fz" | "fx_body" | "fy_body", _) => "N",
        ("mx" | "my", _) => "N m",
        ("kinetic" | "potential" | "total", _) => "J",
        ("mz", _) => "N m",
        _ => return None,
    })
}

/// `column [unit]`, or the bare column name when it has no unit.
pub fn axis_label(column: &str) -> String {
    match unit_of(column) {
        Some(u) => format!("{column} [{u}]"),
        None => column.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::unit_of;

    #[test]
    fn time_and_energies() {
        assert_eq!(unit_of("t"), Some("s"));
        for c in ["H", "W_external", "E_dissipated", "energy_balance"] {
            assert_eq!(unit_of(c), Some("J"), "{c}");
        }
    }

    #[test]
    fn coordinates_and_velocities() {
        assert_eq!(unit_of("crank.x"), Some("m"));
        assert_eq!(unit_of("crank.y"), Some("m"));
        assert_eq!(unit_of("crank.theta"), Some("rad"));
        assert_eq!(unit_of("d_crank.x"), Some("m/s"));
        assert_eq!(unit_of("d_crank.y"), Some("m/s"));
        assert_eq!(unit_of("d_crank.theta"), Some("rad/s"));
        // a body whose name holds a dot
        assert_eq!(unit_of("arm.link1.theta"), Some("rad"));
    }

    #[test]
    fn reaction_and_energy_sensors() {
        assert_eq!(unit_of("pin.fx_body"), Some("N"));
        assert_eq!(unit_of("tip.az"), Some("m/s^2"));
        assert_eq!(unit_of("top.wz_body"), Some("rad/s"));
        assert_eq!(unit_of("d_top.z"), Some("m/s"));
        assert_eq!(unit_of("pin.fy_body"), Some("N"));
        for c in ["e.kinetic", "e.potential", "e.total"] {
            assert_eq!(unit_of(c), Some("J"), "{c}");
        }
    }

    #[test]
    fn reactions() {
        assert_eq!(unit_of("crank_pin.fx"), Some("N"));
        assert_eq!(unit_of("crank_pin.fy"), Some("N"));
        assert_eq!(unit_of("crank_pin.mz"), Some("N m"));
        // a spatial joint's
        assert_eq!(unit_of("tip.fz"), Some("N"));
        assert_eq!(unit_of("tip.mx"), Some("N m"));
        assert_eq!(unit_of("tip.my"), Some("N m"));
    }

    #[test]
    fn sensors() {
        assert_eq!(unit_of("tip.x"), Some("m"));
        assert_eq!(unit_of("tip.vx"), Some("m/s"));
        assert_eq!(unit_of("tip.vy"), Some("m/s"));
        assert_eq!(unit_of("tip.ax"), Some("m/s^2"));
        assert_eq!(unit_of("tip.ay"), Some("m/s^2"));
        assert_eq!(unit_of("elbow.angle"), Some("rad"));
        assert_eq!(unit_of("elbow.rate"), Some("rad/s"));
        assert_eq!(unit_of("guide.s"), Some("m"));
        assert_eq!(unit_of("guide.ds"), Some("m/s"));
    }

    #[test]
    fn residuals_and_unknown_columns_have_none() {
        for c in [
            "max_abs_phi",
            "max_abs_phidot",
            "temperature",
            "crank.colour",
            ".x",
            "",
        ] {
            assert_eq!(unit_of(c), None, "{c}");
        }
    }
}
