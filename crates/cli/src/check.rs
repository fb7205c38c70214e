//! `mbd check`: validate a model and describe it.

use crate::args::CheckArgs;
use crate::error::CliError;
use mbd_model::{format_number as num, BodyRef, SensorKind, System};
use std::fmt::Write;

/// Loads the model, projects its initial state onto the constraints and returns the report
/// printed by `mbd check`.
pub fn check(args: &CheckArgs) -> Result<String, CliError> {
    let sys = crate::model::load(&args.model)?;
    let c = mbd_solve::consistent_state(&sys, 0.0).map_err(|source| CliError::Initial {
        path: args.model.display().to_string(),
        source: Box::new(source),
    })?;
    Ok(report(&args.model.display().to_string(), &sys, &c))
}

fn body_name(sys: &System, r: BodyRef) -> String {
    match r.index() {
        Some(i) => sys.bodies()[i].name.clone(),
        None => "ground".into(),
    }
}

fn report(path: &str, sys: &System, c: &mbd_solve::ConsistentState) -> String {
    let mut s = String::new();
    let g = sys.gravity();
    // writing to a String cannot fail
    let _ = writeln!(s, "model {path}: valid");
    let _ = writeln!(s, "gravity: [{}, {}] m/s^2", num(g[0]), num(g[1]));
    let _ = writeln!(s, "bodies ({}):", sys.bodies().len());
    for b in sys.bodies() {
        let _ = writeln!(
            s,
            "  {:<16} mass {:<10} inertia {}",
            b.name,
            num(b.mass),
            num(b.inertia)
        );
    }
    let _ = writeln!(s, "joints ({}):", sys.joints().len());
    for j in sys.joints() {
        let (a, b) = j.bodies();
        let _ = writeln!(
            s,
            "  {:<16} {:<12} {} - {} ({} equation{})",
            j.name,
            j.kind_name(),
            body_name(sys, a),
            body_name(sys, b),
            j.n_equations(),
            if j.n_equations() == 1 { "" } else { "s" }
        );
    }
    if sys.has_spatial() {
        let g = sys.spatial_gravity();
        let _ = writeln!(
            s,
            "spatial gravity: [{}, {}, {}] m/s^2",
            num(g[0]),
            num(g[1]),
            num(g[2])
        );
        let _ = writeln!(s, "spatial bodies ({}):", sys.spatial_bodies().len());
        for b in sys.spatial_bodies() {
            let j = b.inertia.moments();
            let _ = writeln!(
                s,
                "  {:<16} mass {:<10} principal moments [{}, {}, {}]{}",
                b.name,
                num(b.inertia.mass()),
                num(j[0]),
                num(j[1]),
                num(j[2]),
                if b.inertia.has_singular_mass_matrix() {
                    " (singular mass matrix: a flat body)"
                } else {
                    ""
                }
            );
        }
        let points = sys.spatial_point_masses();
        if !points.is_empty() {
            let _ = writeln!(s, "spatial point masses ({}):", points.len());
            for p in points {
                let _ = writeln!(s, "  {:<16} mass {}", p.name, num(p.mass));
            }
        }
        let _ = writeln!(s, "spatial joints ({}):", sys.spatial_joints().len());
        let name = |r: mbd_model::spatial::SpatialBodyRef| match r {
            mbd_model::spatial::SpatialBodyRef::Body(h) => {
                sys.spatial_bodies()[h.index()].name.clone()
            }
            mbd_model::spatial::SpatialBodyRef::PointMass(h) => points[h.index()].name.clone(),
            mbd_model::spatial::SpatialBodyRef::Ground => "ground".to_string(),
        };
        for j in sys.spatial_joints() {
            let n = j.joint.n_equations();
            let _ = writeln!(
                s,
                "  {:<16} {:<12} {} - {} ({n} equation{})",
                j.name,
                j.joint.type_name(),
                name(j.a),
                name(j.b),
                if n == 1 { "" } else { "s" }
            );
        }
        if !sys.spatial_forces().is_empty() {
            let _ = writeln!(s, "spatial forces ({}):", sys.spatial_forces().len());
        }
        for f in sys.spatial_forces() {
            let _ = writeln!(
                s,
                "  {:<16} {:<14} {} - {}{}",
                f.name,
                f.kind_name(),
                name(f.a),
                name(f.b),
                if f.is_nonconservative() {
                    " (non-conservative)"
                } else {
                    ""
                }
            );
        }
    }
    let _ = writeln!(s, "forces ({}):", sys.forces().len());
    for f in sys.forces() {
        let (a, b) = f.bodies();
        let _ = writeln!(
            s,
            "  {:<16} {} - {}",
            f.name,
            body_name(sys, a),
            body_name(sys, b)
        );
    }
    let _ = writeln!(
        s,
        "coordinates: {}, constraint equations: {}, degrees of freedom: {}",
        sys.n_coords(),
        sys.n_constraints(),
        sys.dof()
    );
    let red = sys.redundant_equations();
    if !red.is_empty() {
        let _ = writeln!(
            s,
            "redundant equations ({}; combinations of the others at and near the initial \
             configuration, carrying no multiplier; redundant_constraints = \"reject\" refuses \
             them):",
            red.len()
        );
        for e in red {
            let _ = writeln!(s, "  {:<16} joints {}", e.equation, e.joints.join(", "));
        }
    }
    if let Some(note) = sys.singular_start_note() {
        let _ = writeln!(s, "{note}");
    }
    sensors(&mut s, sys);
    assembly(&mut s, sys);
    let _ = writeln!(s, "consistent initial state at t = 0:");
    let _ = writeln!(s, "  {:<24} {:>16} {:>16}", "coordinate", "q", "v");
    for (k, name) in sys.coordinate_names().iter().enumerate() {
        let _ = writeln!(
            s,
            "  {:<24} {:>16} {:>16}",
            name,
            value(c.q[k]),
            value(c.v[k])
        );
    }
    let _ = writeln!(
        s,
        "correction of the file's state: |q_consistent - q_file|_max = {:.3e}, \
         |v_consistent - v_file|_max = {:.3e} ({} Newton iteration(s))",
        c.position_correction, c.velocity_correction, c.iterations
    );
    let _ = writeln!(
        s,
        "residuals: |Phi|_max = {:.3e}, |Phi_q v + Phi_t|_max = {:.3e}",
        c.residual, c.velocity_residual
    );
    let _ = writeln!(
        s,
        "energy H(0) = {} J",
        value(sys.energy(c.q.as_slice(), c.v.as_slice()))
    );
    s
}

/// A state value in a table column: nine decimals where that reads well, else scientific
/// notation with nine significant digits (never 30 digits for `1e20`).
fn value(x: f64) -> String {
    if x == 0.0 || !x.is_finite() || (1e-3..1e6).contains(&x.abs()) {
        format!("{x:.9}")
    } else {
        format!("{x:.8e}")
    }
}

/// The sensors and their output columns.
fn sensors(s: &mut String, sys: &System) {
    if sys.sensors().is_empty() {
        return;
    }
    let _ = writeln!(s, "sensors ({}):", sys.sensors().len());
    let joint = |j: mbd_model::JointHandle| {
        sys.joints()
            .get(j.index())
            .map_or_else(|| "?".to_string(), |j| j.name.clone())
    };
    for sensor in sys.sensors() {
        let what = match &sensor.kind {
            SensorKind::Point { body, point } => format!(
                "point [{}, {}] of {}",
                num(point[0]),
                num(point[1]),
                body_name(sys, *body)
            ),
            SensorKind::Joint { joint: j } => format!("coordinates of joint {}", joint(*j)),
            SensorKind::Reaction { joint: j } => format!("reaction of joint {}", joint(*j)),
            SensorKind::Energy { body: None } => "energy of the model".to_string(),
            SensorKind::Energy { body: Some(b) } => format!("energy of {}", body_name(sys, *b)),
            _ => "(a sensor kind this version does not describe)".to_string(),
        };
        let _ = writeln!(s, "  {:<16} {what}", sensor.name);
    }
}

/// The initial joint coordinates and the bodies they place.
fn assembly(s: &mut String, sys: &System) {
    let given: Vec<_> = sys.joint_initials().collect();
    if given.is_empty() {
        return;
    }
    let _ = writeln!(s, "assembly from joint coordinates ({}):", given.len());
    for (j, init) in &given {
        let name = sys.joints().get(j.index()).map_or("?", |j| j.name.as_str());
        let part = |label: &str, x: Option<f64>| {
            x.map_or_else(
                || format!("{label} from the bodies"),
                |x| format!("{label} {}", num(x)),
            )
        };
        let _ = writeln!(
            s,
            "  {:<16} {}, {}",
            name,
            part("coordinate", init.coordinate),
            part("rate", init.rate)
        );
    }
    let placed: Vec<&str> = sys
        .assembled_bodies()
        .iter()
        .zip(sys.bodies())
        .filter(|(placed, _)| **placed)
        .map(|(_, b)| b.name.as_str())
        .collect();
    let others = sys.bodies().len() - placed.len();
    let placed = if placed.is_empty() {
        "no body".to_string()
    } else {
        placed.join(", ")
    };
    let _ = match others {
        0 => writeln!(s, "  places {placed}"),
        _ => writeln!(
            s,
            "  places {placed} (the other {others} bod{} from their position and velocity, \
             then projected)",
            if others == 1 { "y" } else { "ies" }
        ),
    };
}
