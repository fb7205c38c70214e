//! Paper C's firefly search on Gauss's principle (FA-DAE) for the single rod pendulum. The
//! method is slow (a population search per step), so the run is short: 0.2 s at h = 0.01.
//! Writes the trajectory as CSV and prints the measures.
//!
//! `cargo run --release --example firefly_gauss [-- out.csv]`

use mbd::prelude::*;
use std::io::Write;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .map(std::path::PathBuf::from)
        .unwrap_or_else(|| std::env::temp_dir().join("mbd_firefly_gauss.csv"));
    let sys = models::pendulum(1.0, 1.0, 0.5, 9.81)?;
    let mut state = State::consistent(&sys, 0.0)?;
    // the polished variant (Gauss-Newton after the search), with a fixed seed: reproducible
    let mut fa = FireflyGauss::new(&sys, FaDaeOptions::polished().seed(7))?;
    let mut measures = MeasureObserver::new(&sys, true);
    let mut csv = CsvObserver::new(std::io::BufWriter::new(std::fs::File::create(&path)?));
    let mut both = |s: &System, st: &State, i: usize| {
        measures.add(s, st)?;
        csv.observe(s, st, i)
    };
    let stats = run(
        &mut fa,
        &sys,
        &mut state,
        RunConfig::new(0.2, 0.01),
        &mut both,
    )?;
    csv.into_inner().flush()?;
    let m = measures.measures();
    println!(
        "FA-DAE (polished), h = 0.01: {} steps, {} objective evaluations; e(H) = {:.3e}, \
         e(Phi) = {:.3e}, e(Phidot) = {:.3e}, e(Phiddot) = {:.3e}",
        stats.steps, stats.objective_evals, m.e_h, m.e_phi, m.e_phidot, m.e_phiddot
    );
    println!("trajectory: {}", path.display());
    Ok(())
}
