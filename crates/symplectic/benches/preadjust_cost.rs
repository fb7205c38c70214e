//! Cost of a preadjusted step against the plain step, measured in the same run: (1,1) plain,
//! (1,1) with the modified-Lagrangian preadjustment, (2,2) plain, (2,2) with paper A's `W_2`
//! (`gamma = 1`) and (2,2) with the modified Lagrangian's `h^4 e4`, on paper A's double pendulum (h = 0.04) and on a 10-link chain (h = 0.01).
//!
//! `cargo bench -p mbd-symplectic --bench preadjust_cost`; after the timings it prints the
//! ratios of the criterion means to the plain step of the same `s` and model, and the Newton
//! iterations per step of each mode.
//!
//! With `-- --count MODEL MODE STEPS` (MODEL `pendulum` or `chain10`, MODE one of `plain11`,
//! `modified11`, `plain22`, `paper22`, `modified22`) it only takes `STEPS` steps of that mode and prints the
//! Newton work: run it under `valgrind --tool=callgrind` for machine-independent instruction
//! counts (the difference of two step counts divided by their difference).
use criterion::Criterion;
use mbd_model::{models, System};
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, PreadjustMode, SymplecticOptions};
use std::hint::black_box;
use std::time::Duration;

const MODES: [&str; 5] = ["plain11", "modified11", "plain22", "paper22", "modified22"];

fn options(mode: &str) -> SymplecticOptions {
    match mode {
        "plain11" => SymplecticOptions::new(1),
        "modified11" => SymplecticOptions::new(1).with_preadjust(PreadjustMode::ModifiedLagrangian),
        "plain22" => SymplecticOptions::new(2),
        "modified22" => SymplecticOptions::new(2).with_preadjust(PreadjustMode::ModifiedLagrangian),
        _ => SymplecticOptions::new(2).with_gamma(1.0),
    }
}

fn model(name: &str) -> (System, f64, f64) {
    match name {
        "pendulum" => (
            models::paper_a_double_pendulum().expect("model"),
            0.04,
            20.0,
        ),
        _ => (models::n_link_chain(10).expect("model"), 0.01, 5.0),
    }
}

/// Steps of one mode from the consistent initial state, restarting after `t_end`; returns the
/// mean Newton iterations per step.
fn run(sys: &System, mode: &str, h: f64, t_end: f64, steps: usize) -> f64 {
    let s0 = State::consistent(sys, 0.0).expect("state");
    let mut g = Galerkin::new(sys, options(mode)).expect("scheme");
    let mut st = s0.clone();
    let mut it = 0usize;
    for _ in 0..steps {
        if st.t > t_end {
            st = s0.clone();
        }
        it += g.step(sys, &mut st, h).expect("step").newton_iterations;
    }
    it as f64 / steps.max(1) as f64
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    if let Some(i) = args.iter().position(|a| a == "--count") {
        let name = args.get(i + 1).map_or("pendulum", |s| s.as_str());
        let mode = args.get(i + 2).map_or("plain11", |s| s.as_str());
        let steps: usize = args.get(i + 3).and_then(|s| s.parse().ok()).unwrap_or(1000);
        let (sys, h, t_end) = model(name);
        let it = run(&sys, mode, h, t_end, steps);
        println!("{name} {mode}: {steps} steps, {it:.3} Newton iterations per step");
        return;
    }
    let mut c = Criterion::default()
        .warm_up_time(Duration::from_millis(500))
        .measurement_time(Duration::from_secs(3))
        .configure_from_args();
    let mut summary = Vec::new();
    for name in ["pendulum", "chain10"] {
        let (sys, h, t_end) = model(name);
        let s0 = State::consistent(&sys, 0.0).expect("state");
        let mut times = Vec::new();
        for mode in MODES {
            let mut g = Galerkin::new(&sys, options(mode)).expect("scheme");
            let mut st = s0.clone();
            let mut best = f64::INFINITY;
            c.bench_function(&format!("{name}_{mode}"), |b| {
                b.iter_custom(|iters| {
                    let t0 = std::time::Instant::now();
                    for _ in 0..iters {
                        if st.t > t_end {
                            st = s0.clone();
                        }
                        g.step(&sys, black_box(&mut st), h).expect("step");
                    }
                    let dt = t0.elapsed();
                    best = best.min(dt.as_secs_f64() / iters as f64);
                    dt
                })
            });
            let it = run(&sys, mode, h, t_end, 2000);
            times.push((mode, best, it));
        }
        summary.push((name, times));
    }
    println!("\nbest batch per step (ratio to the plain step of the same s), Newton iterations:");
    for (name, times) in &summary {
        for (mode, t, it) in times {
            let base = if mode.ends_with("11") {
                "plain11"
            } else {
                "plain22"
            };
            let plain = times.iter().find(|x| x.0 == base).map_or(f64::NAN, |x| x.1);
            println!(
                "  {name:9} {mode:11} {:8.3} us  x{:5.2}  {it:.2} it/step",
                t * 1e6,
                t / plain
            );
        }
    }
    c.final_summary();
}
