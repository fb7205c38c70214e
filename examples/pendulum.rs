//! A single rod pendulum loaded from `examples/models/pendulum.toml`, integrated with RK4 and
//! post-step projection; prints the period estimate and energy/constraint errors.
//!
//! `cargo run --example pendulum`

use mbd::analysis::MeasureObserver;
use mbd::model::System;
use mbd::solve::{Flow, RunConfig, State};
use mbd::Simulation;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/models/pendulum.toml");
    let mut sim = Simulation::from_path(path, "rk4-projected")?;
    let mut measures = MeasureObserver::new(sim.system(), true);
    // detect upward zero crossings of the angular velocity to estimate the period
    let mut last_w = 0.0f64;
    let mut crossings: Vec<f64> = vec![];
    let mut obs = |s: &System, st: &State, k: usize| {
        measures.add(s, st)?;
        let w = st.v[2];
        if k > 0 && last_w < 0.0 && w >= 0.0 {
            crossings.push(st.t);
        }
        last_w = w;
        Ok(Flow::Continue)
    };
    sim.run_observed(RunConfig::new(10.0, 1e-3), &mut obs)?;
    let m = measures.measures();
    if crossings.len() >= 2 {
        let period = (crossings[crossings.len() - 1] - crossings[0]) / (crossings.len() - 1) as f64;
        println!(
            "period ~ {period:.5} s (small-amplitude: {:.5} s)",
            2.0 * std::f64::consts::PI / (1.5 * 9.81f64).sqrt()
        );
    }
    println!(
        "e(H) = {:.3e}, e(Phi) = {:.3e}, e(Phidot) = {:.3e}, e(Phiddot) = {:.3e}",
        m.e_h, m.e_phi, m.e_phidot, m.e_phiddot
    );
    Ok(())
}
