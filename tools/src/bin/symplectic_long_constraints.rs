//! Constraint residuals of the (1,1) and (2,2) schemes over `10^5` steps of the manipulator at
//! `h = 0.01` (the target: `<= 1e-12` at every step), with the Newton work per step.
//!
//! `cargo run --release -p mbd-tools --bin symplectic_long_constraints [steps]`
use mbd::model::models;
use mbd::solve::{Integrator, State};
use mbd::symplectic::{Galerkin, SymplecticOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let steps: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(100_000);
    let sys = models::manipulator()?;
    let s0 = State::consistent(&sys, 0.0)?;
    let m = sys.n_constraints();
    let (mut phi, mut phid) = (vec![0.0; m], vec![0.0; m]);
    for s in [1, 2] {
        let mut g = Galerkin::new(&sys, SymplecticOptions::new(s))?;
        let mut st = s0.clone();
        let (mut e_phi, mut e_phid, mut qmax, mut it) = (0.0f64, 0.0f64, 0.0f64, 0usize);
        for _ in 0..steps {
            it += g.step(&sys, &mut st, 0.01)?.newton_iterations;
            sys.phi_and_phi_dot(st.q.as_slice(), st.v.as_slice(), st.t, &mut phi, &mut phid);
            e_phi = phi.iter().fold(e_phi, |a, x| a.max(x.abs()));
            e_phid = phid.iter().fold(e_phid, |a, x| a.max(x.abs()));
            qmax = st.q.iter().fold(qmax, |a, x| a.max(x.abs()));
        }
        println!(
            "({s},{s}): max|Phi| {e_phi:.2e}, max|Phidot| {e_phid:.2e}, max|q| {qmax:.1}, {:.2} iterations per step",
            it as f64 / steps as f64
        );
    }
    Ok(())
}
