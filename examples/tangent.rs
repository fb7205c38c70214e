//! Paper B's tangent-space Runge-Kutta on the two-link manipulator: classical RK4 with fixed
//! steps through `run`, and DOPRI5 with adaptive steps through `run_adaptive`. Writes the
//! adaptive trajectory as CSV and prints the measures of both runs.
//!
//! `cargo run --release --example tangent [-- out.csv]`

use mbd::prelude::*;
use std::io::Write;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("mbd_tangent.csv"));
    let sys = models::manipulator()?;

    // fixed steps: tangent-space RK4
    let mut state = State::consistent(&sys, 0.0)?;
    let mut rk4 = TangentRk::new(&sys, ButcherTableau::rk4(), TangentOptions::default())?;
    let mut measures = MeasureObserver::new(&sys, true);
    let stats = run(
        &mut rk4,
        &sys,
        &mut state,
        RunConfig::new(5.0, 0.01),
        &mut measures,
    )?;
    let m = measures.measures();
    println!(
        "tangent RK4, h = 0.01: {} steps; e(H) = {:.3e}, e(Phi) = {:.3e}, e(Phidot) = {:.3e}, \
         e(Phiddot) = {:.3e}",
        stats.steps, m.e_h, m.e_phi, m.e_phidot, m.e_phiddot
    );

    // adaptive steps: tangent-space DOPRI5 through the shared run loop
    let mut state = State::consistent(&sys, 0.0)?;
    let mut dopri5 = TangentRk::new(&sys, ButcherTableau::dopri5(), TangentOptions::default())?;
    let mut measures = MeasureObserver::new(&sys, true);
    let mut csv = CsvObserver::new(std::io::BufWriter::new(std::fs::File::create(&path)?));
    let mut both = |s: &System, st: &State, i: usize| {
        measures.add(s, st)?;
        csv.observe(s, st, i)
    };
    let cfg = AdaptiveConfig::new(5.0, 1e-8);
    let stats = run_adaptive(&mut dopri5, &sys, &mut state, cfg, &mut both)?;
    csv.into_inner().flush()?;
    let m = measures.measures();
    println!(
        "tangent DOPRI5, tol 1e-8: {} accepted, {} rejected steps; e(H) = {:.3e}, \
         e(Phi) = {:.3e}, e(Phidot) = {:.3e}, e(Phiddot) = {:.3e}",
        stats.steps, stats.rejected_steps, m.e_h, m.e_phi, m.e_phidot, m.e_phiddot
    );
    println!("adaptive trajectory: {}", path.display());
    Ok(())
}
