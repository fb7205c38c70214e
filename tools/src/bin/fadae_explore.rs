//! Exploration: e(H), constraint errors, runtime and optimiser statistics on the manipulator.
//! `cargo run --release -p mbd-tools --bin fadae_explore -- T h [polish] [decay] [tol]`
use mbd::analysis::MeasureObserver;
use mbd::firefly_gauss::{FaDaeOptions, FireflyGauss};
use mbd::model::models;
use mbd::solve::{run, RunConfig, State};
use std::time::Instant;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().collect();
    let t_end: f64 = args.get(1).map_or(Ok(1.0), |s| s.parse())?;
    let h: f64 = args.get(2).map_or(Ok(0.01), |s| s.parse())?;
    let polish = args.get(3).is_some_and(|s| s == "1");
    let mut o = FaDaeOptions::default().polish(polish);
    if let Some(d) = args.get(4) {
        o.firefly.alpha_decay = d.parse()?;
    }
    if let Some(t) = args.get(5) {
        o.tolerance = t.parse()?;
    }
    let env = |k: &str| std::env::var(k).ok();
    if let Some(v) = env("SG") {
        o.stage_generations = v.parse()?;
    }
    if let Some(v) = env("STAG") {
        o.stagnation_generations = Some(v.parse()?);
    }
    if let Some(v) = env("KAPPA") {
        o.bounds.safety = v.parse()?;
    }
    if let Some(v) = env("ALPHA") {
        o.firefly.alpha = v.parse()?;
    }
    if let Some(v) = env("MINSH") {
        o.bounds.min_shrink = v.parse()?;
    }
    if let Some(v) = env("PLAIN") {
        if v == "1" {
            o.predictor = mbd::firefly_gauss::Predictor::Rk4;
        }
    }
    let sys = models::manipulator()?;
    let mut s = State::consistent(&sys, 0.0)?;
    let mut ff = FireflyGauss::new(&sys, o)?;
    let mut obs = MeasureObserver::new(&sys, true);
    let t = Instant::now();
    run(&mut ff, &sys, &mut s, RunConfig::new(t_end, h), &mut obs)?;
    let wall = t.elapsed().as_secs_f64();
    let m = obs.measures();
    let st = ff.stats();
    println!(
        "h={h} T={t_end} polish={polish}: e_H={:.3e} MRE={:.3e} e_phi={:.2e} e_phid={:.2e} e_phidd={:.2e} wall={wall:.2}s",
        m.e_h, m.mre_h, m.e_phi, m.e_phidot, m.e_phiddot
    );
    println!(
        "  steps={} gens/step={:.1} evals/step={:.0} expansions={} misses={} ratio gm={:.3e} min={:.3e} roundoff={} maxobj={:.2e} per-step={:.1}us us/gen={:.1}",
        st.steps,
        st.mean_generations(),
        st.evaluations as f64 / st.steps as f64,
        st.expansions,
        st.target_misses,
        st.mean_ratio(),
        st.min_ratio,
        st.roundoff_steps,
        st.max_objective,
        wall / st.steps as f64 * 1e6,
        wall / st.generations as f64 * 1e6
    );
    println!("  q_end = {:?}", s.q.as_slice());
    Ok(())
}
