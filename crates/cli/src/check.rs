//! `mbd check`: validate a model and describe it.

use crate::args::CheckArgs;
use crate::error::CliError;
use mbd_model::{BodyRef, System};
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
    let _ = writeln!(s, "gravity: [{}, {}] m/s^2", g[0], g[1]);
    let _ = writeln!(s, "bodies ({}):", sys.bodies().len());
    for b in sys.bodies() {
        let _ = writeln!(
            s,
            "  {:<16} mass {:<10} inertia {}",
            b.name, b.mass, b.inertia
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
            "redundant equations ({}; combinations of the others at the initial configuration, \
             carrying no multiplier; redundant_constraints = \"reject\" refuses them):",
            red.len()
        );
        for e in red {
            let _ = writeln!(s, "  {:<16} joints {}", e.equation, e.joints.join(", "));
        }
    }
    let _ = writeln!(s, "consistent initial state at t = 0:");
    let _ = writeln!(s, "  {:<24} {:>14} {:>14}", "coordinate", "q", "v");
    for (k, name) in sys.coordinate_names().iter().enumerate() {
        let _ = writeln!(s, "  {:<24} {:>14.9} {:>14.9}", name, c.q[k], c.v[k]);
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
        "energy H(0) = {:.9} J",
        sys.energy(c.q.as_slice(), c.v.as_slice())
    );
    s
}
