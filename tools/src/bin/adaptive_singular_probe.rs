//! The adaptive run loop through singular configurations: tangent DOPRI5 (and index-1 DOPRI5
//! with projection for comparison) on the free parallelogram four-bar, which passes its flat
//! configurations five times in 2 s, through `mbd::Simulation` at several tolerances; the
//! error at t = 2 against a symplectic (2,2) reference with fixed steps (h = 2 / N, N = 160000;
//! the first argument sets N). A DOPRI5 + projection reference is no reference here: refined
//! from 64000 to 1024000 steps it moves by 4e-2 (it changes branch at a flat passage).
//!
//! `cargo run --release -p mbd-tools --bin adaptive_singular_probe`
use mbd::model::models;
use mbd::solve::{AdaptiveConfig, RunConfig};
use mbd::Simulation;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let sys = models::parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, false)?;
    let n_ref: usize = std::env::args()
        .nth(1)
        .and_then(|a| a.parse().ok())
        .unwrap_or(160_000);
    let mut reference = Simulation::new(sys.clone(), "symplectic:2")?;
    reference.run(RunConfig::new(2.0, 2.0 / n_ref as f64))?;
    let r = reference.state();
    for solver in ["tangent:dopri5", "index1:dopri5"] {
        for tol in [1e-6, 1e-8, 1e-10] {
            let mut sim = Simulation::new(sys.clone(), solver)?;
            match sim.run(AdaptiveConfig::new(2.0, tol)) {
                Ok(st) => {
                    let s = sim.state();
                    let e =
                        s.q.iter()
                            .zip(r.q.iter())
                            .chain(s.v.iter().zip(r.v.iter()))
                            .map(|(a, b)| (a - b).abs())
                            .fold(0.0, f64::max);
                    println!(
                        "{solver} tol {tol:.0e}: error at t = 2: {e:.3e}; {} accepted, {} rejected, h in [{:.2e}, {:.2e}]",
                        st.steps, st.rejected_steps, st.min_step, st.max_step
                    );
                }
                Err(e) => println!("{solver} tol {tol:.0e}: {e}"),
            }
        }
    }
    Ok(())
}
