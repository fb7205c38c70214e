//! A crank-rocker four-bar linkage (closed loop), written out to JSON and read back, then
//! integrated with projected RK4; prints the rocker's angle range.
//!
//! `cargo run --release --example four_bar`

use mbd::model::{models, System};
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Flow, RunConfig, State};

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
    let mut state = State::consistent(&sys, 0.0)?;
    let mut rk4 = Rk4::new(&sys, Rk4Options::projected())?;
    let rocker = 3 * 2 + 2; // theta of body 3
    let (mut lo, mut hi) = (f64::INFINITY, f64::NEG_INFINITY);
    let mut obs = |_: &System, s: &State, _: usize| {
        lo = lo.min(s.q[rocker]);
        hi = hi.max(s.q[rocker]);
        Ok(Flow::Continue)
    };
    run(
        &mut rk4,
        &sys,
        &mut state,
        RunConfig::new(5.0, 1e-3),
        &mut obs,
    )?;
    println!("rocker angle range over 5 s: [{:.4}, {:.4}] rad", lo, hi);
    Ok(())
}
