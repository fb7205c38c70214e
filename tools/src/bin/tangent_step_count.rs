//! Runs a fixed number of steps of tangent-space RK4 or plain RK4 (`Index1Rk`, RK4 tableau) on
//! the manipulator, from `t = 0`, inside one non-inlined function `run_steps`, for instruction
//! counts that do not depend on machine load:
//!
//! ```text
//! valgrind --tool=callgrind --toggle-collect='*run_steps*' \
//!     target/release/tangent_step_count tangent 0.01 1000
//! ```
//!
//! Arguments: `tangent` | `plain` (or `tangent-run` | `plain-run`: the same steps through
//! `mbd::solve::run`, which passes each step `h = t_next - t`), the step `h` (default 0.01), the number of steps (default
//! `10 / h`, the first 10 s of motion, as the benchmark cycles through), and the iteration
//! matrix `centre`, `interpolated` or `broyden` ([`IterationMatrix`], tangent only; default:
//! the solver's default). Prints the chord iterations and Broyden updates per step of the
//! tangent solver.
use mbd::model::{models, System};
use mbd::solve::{
    run, ButcherTableau, Index1Options, Index1Rk, Integrator, NoObserver, RunConfig, SolveError,
    State,
};
use mbd::tangent::{IterationMatrix, TangentOptions, TangentRk};

#[inline(never)]
fn run_steps<I: Integrator>(
    integ: &mut I,
    sys: &System,
    s: &mut State,
    h: f64,
    steps: usize,
    through_run: bool,
) -> Result<(), SolveError> {
    if through_run {
        // mbd::solve::run: times t0 + k h, each step passed h = t_next - t
        let cfg = RunConfig::new(s.t + steps as f64 * h, h);
        run(integ, sys, s, cfg, &mut NoObserver)?;
        return Ok(());
    }
    for _ in 0..steps {
        integ.step(sys, s, h)?;
    }
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut args = std::env::args().skip(1);
    let which = args.next().unwrap_or_else(|| "tangent".into());
    // `plain-run` / `tangent-run`: the same steps through `mbd::solve::run`
    let through_run = which.ends_with("-run");
    let which = which.trim_end_matches("-run").to_string();
    let h: f64 = match args.next() {
        Some(a) => a.parse()?,
        None => 0.01,
    };
    let steps: usize = match args.next() {
        Some(a) => a.parse()?,
        None => (10.0 / h).round() as usize,
    };
    let sys = models::manipulator()?;
    let mut s = State::consistent(&sys, 0.0)?;
    match which.as_str() {
        "plain" => {
            let mut p = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
            run_steps(&mut p, &sys, &mut s, h, steps, through_run)?;
            println!("plain RK4: {steps} steps of {h}, t = {}", s.t);
        }
        _ => {
            let opts = TangentOptions {
                iteration_matrix: match args.next().as_deref() {
                    Some("interpolated") => IterationMatrix::Interpolated,
                    Some("broyden") => IterationMatrix::Broyden,
                    Some("centre") => IterationMatrix::Centre,
                    _ => IterationMatrix::default(),
                },
                ..Default::default()
            };
            let mut t = TangentRk::new(&sys, ButcherTableau::rk4(), opts)?;
            run_steps(&mut t, &sys, &mut s, h, steps, through_run)?;
            let st = t.stats();
            let (upd, resets) = t.broyden_counts();
            println!(
                "tangent RK4: {steps} steps of {h}, t = {}, {:.2} chord iterations/step, \
                 {:.2} Broyden updates/step, {resets} resets, \
                 max map {}, max residual {:.2e}, halvings {}; final max |q| {:.0}, max |v| {:.0}",
                s.t,
                st.newton_iterations as f64 / st.steps as f64,
                upd as f64 / st.steps as f64,
                st.max_map_iterations,
                st.max_residual,
                st.halvings,
                s.q.amax(),
                s.v.amax()
            );
        }
    }
    Ok(())
}
