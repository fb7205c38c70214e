//! Branch keeping of tangent RK4 on the parallelogram four-bar through its flat
//! configurations, with direct `step` calls at a given step size:
//!
//! ```text
//! cargo run --release -p mbd-tools --bin tangent_branch_probe -- <driven|free> <h> [t_end]
//! ```
//!
//! Prints the steps at which the exact Newton fallback was used or the state left the
//! parallelogram branch (coupler angle, rocker - crank angle), and the end state.
use mbd::model::models;
use mbd::solve::{Integrator, State};
use mbd::tangent::TangentRk;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let driven = args.get(1).map(|s| s == "driven").unwrap_or(true);
    let h: f64 = args.get(2).map(|s| s.parse()).transpose()?.unwrap_or(1e-3);
    let t_end: f64 = args.get(3).map(|s| s.parse()).transpose()?.unwrap_or(2.0);
    // "run": the times of `mbd::solve::run` (t_k = k h set after each step, nominal h)
    let run_times = std::env::var("RUN_TIMES").is_ok();
    let sys = models::parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, driven)?;
    let mut s = State::consistent(&sys, 0.0)?;
    let mut rk = TangentRk::rk4(&sys)?;
    let n = (t_end / h).round() as usize;
    let mut exact = 0;
    let mut off_max = 0.0f64;
    for k in 0..n {
        let t0 = s.t;
        if let Err(e) = rk.step(&sys, &mut s, h) {
            println!("step {k} at t = {t0}: {e}");
            break;
        }
        if run_times {
            s.t = (k + 1) as f64 * h;
        }
        let off = s.q[5].abs().max((s.q[8] - s.q[2]).abs());
        let st = *rk.stats();
        if st.exact_maps != exact || (off > 1e-10 && off_max <= 1e-10) {
            println!(
                "step {k} t = {:.6} crank {:.6} off {off:.2e} exact maps {} (+{}) rcond {:.2e}",
                s.t,
                s.q[2],
                st.exact_maps,
                st.exact_maps - exact,
                rk.rcond()
            );
        }
        exact = st.exact_maps;
        off_max = off_max.max(off);
    }
    println!(
        "t = {} crank {} off max {off_max:.2e}; {:?}",
        s.t,
        s.q[2],
        rk.stats()
    );
    Ok(())
}
