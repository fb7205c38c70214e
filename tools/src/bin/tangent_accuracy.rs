//! Global error of fixed-step tangent-space RK4 against a DOPRI5 reference (with projection,
//! `h / 10`), on the manipulator (to `t = 2 s`: its motion is chaotic, later differences of
//! round-off size grow to the size of the method's error), the four-bar and the slider-crank
//! (to `t = 10 s`) and a 30-link chain (to `t = 1 s`, the sparse chart), for a before/after check of changes that move the chart maps' results by
//! the chord tolerance (Newton starting points, stopping rules). Also prints how far the same
//! run moves when the initial coordinates are perturbed by one part in `1e15` (the trajectory's
//! own sensitivity to round-off).
//!
//! `cargo run --release -p mbd-tools --bin tangent_accuracy [h ...]` (default `1e-3 1e-2`)
use mbd::model::{models, System};
use mbd::solve::{reference_trajectory, ButcherTableau, Integrator, State};
use mbd::tangent::TangentRk;

/// The state after `steps` tangent RK4 steps of `h` from `s0`, and the chord iterations per
/// step.
fn run(
    sys: &System,
    s0: &State,
    h: f64,
    steps: usize,
) -> Result<(State, f64), Box<dyn std::error::Error>> {
    let mut rk = TangentRk::rk4(sys)?;
    let mut s = s0.clone();
    for _ in 0..steps {
        rk.step(sys, &mut s, h)?;
    }
    let it = rk.stats().newton_iterations as f64 / steps as f64;
    Ok((s, it))
}

/// Max-norm distance of two states' `q` and `v`.
fn dist(a: &State, b: &State) -> f64 {
    a.q.iter()
        .zip(b.q.iter())
        .chain(a.v.iter().zip(b.v.iter()))
        .fold(0.0f64, |d, (x, y)| d.max((x - y).abs()))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let hs: Vec<f64> = std::env::args()
        .skip(1)
        .filter_map(|a| a.parse().ok())
        .collect();
    let hs = if hs.is_empty() { vec![1e-3, 1e-2] } else { hs };
    let cases: [(&str, System, f64); 4] = [
        ("manipulator", models::manipulator()?, 2.0),
        ("four_bar", models::four_bar()?, 10.0),
        ("slider_crank", models::slider_crank()?, 10.0),
        ("chain30", models::n_link_chain(30)?, 1.0),
    ];
    println!("model         h       error vs reference   perturbed run moves   it/step");
    for (name, sys, t_end) in &cases {
        let s0 = State::consistent(sys, 0.0)?;
        let href = 1e-4;
        let r = reference_trajectory(
            sys,
            &s0,
            href,
            (t_end / href).round() as usize,
            10,
            ButcherTableau::dopri5(),
        )?;
        let (qref, vref) = (
            r.q.last().ok_or("empty reference")?,
            r.v.last().ok_or("empty reference")?,
        );
        for &h in &hs {
            let steps = (t_end / h).round() as usize;
            let (s, it) = run(sys, &s0, h, steps)?;
            let err =
                s.q.iter()
                    .zip(qref.iter())
                    .chain(s.v.iter().zip(vref.iter()))
                    .fold(0.0f64, |d, (x, y)| d.max((x - y).abs()));
            let mut sp = s0.clone();
            for v in sp.q.iter_mut() {
                *v *= 1.0 + 1e-15;
            }
            let (s2, _) = run(sys, &sp, h, steps)?;
            println!(
                "{name:<13} {h:<7} {err:<20.6e} {:<21.3e} {it:.3}",
                dist(&s, &s2)
            );
        }
    }
    Ok(())
}
