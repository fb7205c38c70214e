//! A single rod pendulum loaded from `examples/models/pendulum.toml`, integrated with RK4 and
//! post-step projection; prints the period estimate and energy/constraint errors.
//!
//! `cargo run --example pendulum`

use mbd::analysis::MeasureObserver;
use mbd::model::System;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Flow, RunConfig, State};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = concat!(env!("CARGO_MANIFEST_DIR"), "/examples/models/pendulum.toml");
    let sys = System::from_path(path)?;
    let mut state = State::consistent(&sys, 0.0)?;
    let mut rk4 = Rk4::new(&sys, Rk4Options::projected())?;
    let mut measures = MeasureObserver::new(&sys, true);
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
    run(
        &mut rk4,
        &sys,
        &mut state,
        RunConfig::new(10.0, 1e-3),
        &mut obs,
    )?;
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
