//! The measurements of `docs/tangent.md` sections 6 and 7 (robustness):
//!
//! ```text
//! cargo run --release -p mbd-tools --bin tangent_robust_probe -- adaptive
//! cargo run --release -p mbd-tools --bin tangent_robust_probe -- fourbar
//! ```
//!
//! `adaptive`: tangent DOPRI5 on the manipulator to t = 2 s at tolerances 1e-3 .. 1e-12 against a
//! DOPRI5 reference (32000 steps, projection): error (max-norm of q and v; of q alone), error /
//! tol, accepted, rejected and chart-rejected steps, first step. The environment variables
//! `PI_BETA`, `FAC_MAX`, `SAFETY` and `H0` override the controller's settings.
//!
//! `fourbar`: the parallelogram four-bar through its flat configurations (free and with the
//! crank driven), h = 1e-3 to t = 2 s: RK4 with projection, tangent RK4 and adaptive tangent
//! DOPRI5 (tol 1e-8).
use mbd::model::models;
use mbd::solve::{
    reference_trajectory, run, run_adaptive, AdaptiveConfig, ButcherTableau, Index1Options,
    Index1Rk, NoObserver, ProjectionSettings, RunConfig, State,
};
use mbd::tangent::TangentRk;

fn env_f64(name: &str) -> Result<Option<f64>, Box<dyn std::error::Error>> {
    match std::env::var(name) {
        Ok(v) => Ok(Some(v.parse()?)),
        Err(_) => Ok(None),
    }
}

fn max_diff(a: &[f64], b: &[f64]) -> f64 {
    mbd::solve::linalg::max_abs_diff(a, b)
}

fn adaptive() -> Result<(), Box<dyn std::error::Error>> {
    let sys = models::manipulator()?;
    let s0 = State::consistent(&sys, 0.0)?;
    let r = reference_trajectory(&sys, &s0, 2.0, 1, 32_000, ButcherTableau::dopri5())?;
    for k in 3..=12 {
        let tol = 10f64.powi(-k);
        let mut set = AdaptiveConfig::new(2.0, tol).without_drift_guard();
        if let Some(b) = env_f64("PI_BETA")? {
            set.pi_beta = Some(b);
        }
        if let Some(f) = env_f64("FAC_MAX")? {
            set.controller.fac_max = f;
        }
        if let Some(f) = env_f64("SAFETY")? {
            set.controller.safety = f;
        }
        set.h0 = env_f64("H0")?;
        let mut dp = TangentRk::dopri5(&sys)?;
        let mut s = s0.clone();
        match run_adaptive(&mut dp, &sys, &mut s, set, &mut NoObserver) {
            Ok(st) => {
                let chart = dp.stats().chart_failures;
                let eq = max_diff(s.q.as_slice(), &r.q[1]);
                let err = eq.max(max_diff(s.v.as_slice(), &r.v[1]));
                let attempts = st.steps + st.rejected_steps;
                println!(
                    "tol {tol:.0e}: error {err:.2e} (q {eq:.2e}), error/tol {:.1}, accepted {}, \
                     rejected {} (chart {chart}), rejection rate {:.3}, \
                     h in [{:.2e}, {:.2e}], exact maps {}, acceleration solves {}",
                    err / tol,
                    st.steps,
                    st.rejected_steps,
                    st.rejected_steps as f64 / attempts as f64,
                    st.min_step,
                    st.max_step,
                    dp.stats().exact_maps,
                    st.rhs_evals
                );
            }
            Err(e) => println!("tol {tol:.0e}: {e}"),
        }
    }
    Ok(())
}

fn four_bar() -> Result<(), Box<dyn std::error::Error>> {
    for driven in [false, true] {
        let sys = models::parallelogram_four_bar(0.4, 1.0, 1.0, 6.0, driven)?;
        let s0 = State::consistent(&sys, 0.0)?;
        let cfg = RunConfig::new(2.0, 1e-3);
        let opts = Index1Options {
            projection: Some(ProjectionSettings::default()),
            ..Default::default()
        };
        let mut p = Index1Rk::new(&sys, ButcherTableau::rk4(), opts)?;
        let mut sp = s0.clone();
        let rp = run(&mut p, &sys, &mut sp, cfg, &mut NoObserver);
        println!(
            "driven {driven}: RK4 + projection: {:?}, t = {}, coupler angle {:.1e}",
            rp.map(|_| ()),
            sp.t,
            sp.q[5]
        );
        let mut t = TangentRk::rk4(&sys)?;
        let mut s = s0.clone();
        let r = run(&mut t, &sys, &mut s, cfg, &mut NoObserver);
        println!(
            "  tangent RK4: {:?}, t = {}, coupler angle {:.1e}, to RK4 + projection {:.2e}; {:?}",
            r.map(|_| ()),
            s.t,
            s.q[5],
            max_diff(s.q.as_slice(), sp.q.as_slice())
                .max(max_diff(s.v.as_slice(), sp.v.as_slice())),
            t.stats()
        );
        let mut d = TangentRk::dopri5(&sys)?;
        let mut s = s0.clone();
        let r = run_adaptive(
            &mut d,
            &sys,
            &mut s,
            AdaptiveConfig::new(2.0, 1e-8),
            &mut NoObserver,
        );
        println!("  tangent DOPRI5 (tol 1e-8): {r:?}, t = {}", s.t);
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    match std::env::args().nth(1).as_deref() {
        Some("fourbar") => four_bar(),
        _ => adaptive(),
    }
}
