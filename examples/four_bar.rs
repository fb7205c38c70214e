//! A crank-rocker four-bar linkage (closed loop), written out to JSON and read back, then
//! integrated with projected RK4; prints the rocker's angle range.
//!
//! `cargo run --release --example four_bar`

use mbd::model::{models, System};
use mbd::solve::{observe, RunConfig};
use mbd::Simulation;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let built = models::four_bar()?;
    let json = built.to_model_file().to_json()?;
    let sys = System::from_json(&json)?; // the same model, through a model file
    println!(
        "four-bar: {} coordinates, {} constraints, {} dof",
        sys.n_coords(),
        sys.n_constraints(),
        sys.dof()
    );
    let mut sim = Simulation::new(sys, "rk4-projected")?;
    let rocker = 3 * 2 + 2; // theta of body 3
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    sim.run_observed(
        RunConfig::new(5.0, 1e-3),
        &mut observe(|s| {
            lo = lo.min(s.q[rocker]);
            hi = hi.max(s.q[rocker]);
        }),
    )?;
    println!("rocker angle range over 5 s: [{:.4}, {:.4}] rad", lo, hi);
    Ok(())
}
