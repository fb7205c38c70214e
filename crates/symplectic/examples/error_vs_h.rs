//! Error at t = 2 s on the manipulator against a tight reference, as h halves from 0.01 (the
//! table of `docs/symplectic.md` section 7), with the Newton work per step.
//!
//! `cargo run --release -p mbd-symplectic --example error_vs_h -- s [halvings] [predictor_order]`
//!
//! h runs from 0.01 through `halvings` halvings (default 8), `2/h` steps of exactly `h`. The
//! reference is DOPRI5 + projection with 2^16 steps (`mbd_solve::reference_trajectory`); its
//! difference to 2^15 steps is printed. With `REFCHECK=1` set, also the differences to 2^17
//! steps and to the (4,4) and (3,3) schemes at h = 2/1024 .. 2/8192, and theirs to each other
//! (together they bound what the reference resolves: about 2e-13).
use mbd_model::models;
use mbd_model::System;
use mbd_solve::linalg::max_abs_diff;
use mbd_solve::{reference_trajectory, ButcherTableau, Integrator, State};
use mbd_symplectic::{Galerkin, SymplecticOptions};

const T_END: f64 = 2.0;

/// `n` steps of `T_END / n`; returns the final positions, Newton iterations and Jacobians per
/// step.
fn run(
    sys: &System,
    s0: &State,
    opts: SymplecticOptions,
    n: usize,
) -> Result<(Vec<f64>, f64, f64), Box<dyn std::error::Error>> {
    let h = T_END / n as f64;
    let mut g = Galerkin::new(sys, opts)?;
    let mut st = s0.clone();
    let mut it = 0usize;
    for k in 1..=n {
        it += g.step(sys, &mut st, h)?.newton_iterations;
        st.t = k as f64 * h;
    }
    Ok((
        st.q.as_slice().to_vec(),
        it as f64 / n as f64,
        g.jacobian_count() as f64 / n as f64,
    ))
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let s: usize = args.next().and_then(|a| a.parse().ok()).unwrap_or(2);
    let halvings: u32 = args.next().and_then(|a| a.parse().ok()).unwrap_or(8);
    let p: Option<usize> = args.next().and_then(|a| a.parse().ok());
    let sys = models::manipulator()?;
    let s0 = State::consistent(&sys, 0.0)?;
    let r1 = reference_trajectory(&sys, &s0, T_END, 1, 1 << 15, ButcherTableau::dopri5())?;
    let r2 = reference_trajectory(&sys, &s0, T_END, 1, 1 << 16, ButcherTableau::dopri5())?;
    let reference = r2.q[1].clone();
    println!(
        "reference DOPRI5 + projection, h = 2/2^16; |difference to h = 2/2^15| = {:.2e}",
        max_abs_diff(&r1.q[1], &reference)
    );
    if std::env::var("REFCHECK").is_ok() {
        let r3 = reference_trajectory(&sys, &s0, T_END, 1, 1 << 17, ButcherTableau::dopri5())?;
        println!(
            "dopri 2^17 vs 2^16: {:.2e}",
            max_abs_diff(&r3.q[1], &reference)
        );
        let mut qs = Vec::new();
        for (s, n) in [
            (4usize, 1024usize),
            (4, 2048),
            (4, 4096),
            (4, 8192),
            (3, 4096),
            (3, 8192),
        ] {
            let (q, ..) = run(&sys, &s0, SymplecticOptions::new(s), n)?;
            println!(
                "({s},{s}) n = {n}: vs dopri 2^16 {:.2e}, vs 2^17 {:.2e}",
                max_abs_diff(&q, &reference),
                max_abs_diff(&q, &r3.q[1])
            );
            qs.push(((s, n), q));
        }
        for i in 0..qs.len() {
            for j in i + 1..qs.len() {
                println!(
                    "{:?} vs {:?}: {:.2e}",
                    qs[i].0,
                    qs[j].0,
                    max_abs_diff(&qs[i].1, &qs[j].1)
                );
            }
        }
    }
    let mut opts = SymplecticOptions::new(s);
    if let Some(p) = p {
        opts.predictor_order = p;
    }
    println!(
        "({s},{s}) predictor_order = {}: h, max error at t = 2 s, Newton iterations / step, Jacobians / step",
        opts.predictor_order
    );
    for k in 0..=halvings {
        let n = 200usize << k;
        let (q, it, jac) = run(&sys, &s0, opts, n)?;
        println!(
            "{:.4e}  {:.2e}  {:.2}  {:.2}",
            T_END / n as f64,
            max_abs_diff(&q, &reference),
            it,
            jac
        );
    }
    Ok(())
}
