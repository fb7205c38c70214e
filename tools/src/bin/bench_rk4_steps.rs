//! Runs many RK4 steps on the manipulator (for profilers such as callgrind), called directly or
//! through the public run loop (with or without its drift guard), to measure the loop's cost.
//!
//! `cargo run --release -p mbd-tools --bin bench_rk4_steps -- 100000 [direct|run|run-noguard]`
use mbd::model::models;
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{run, Integrator, NoObserver, RunConfig, State};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let n: usize = args.next().and_then(|s| s.parse().ok()).unwrap_or(100_000);
    let mode = args.next().unwrap_or_else(|| "direct".into());
    let sys = models::manipulator()?;
    let mut s = State::consistent(&sys, 0.0)?;
    let mut rk = Rk4::new(&sys, Rk4Options::plain())?;
    let t = std::time::Instant::now();
    match mode.as_str() {
        "direct" => {
            for _ in 0..n {
                rk.step(&sys, &mut s, 1e-3)?;
            }
        }
        "run" | "run-noguard" => {
            let mut cfg = RunConfig::new(n as f64 * 1e-3, 1e-3);
            if mode == "run-noguard" {
                cfg = cfg.without_drift_guard();
            }
            run(&mut rk, &sys, &mut s, cfg, &mut NoObserver)?;
        }
        other => return Err(format!("unknown mode '{other}': direct, run or run-noguard").into()),
    }
    let dt = t.elapsed().as_secs_f64();
    println!(
        "{n} steps ({mode}): {:.1} ns/step (q0 = {:.6})",
        dt / n as f64 * 1e9,
        s.q[0]
    );
    Ok(())
}
