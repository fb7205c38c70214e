//! Steps one registry solver through the N-four-bar's flat configurations and prints the
//! steps near rank loss (condition estimate, constraint residual, coupler angle):
//!
//! ```text
//! cargo run --release -p mbd-tools --bin singular_probe -- <spec> <N> <driven|free> <h> [t_end]
//! ```
//!
//! `WATCH=c` prints the steps whose condition estimate exceeds `c` (default 1e3), `EVERY=k`
//! also every `k`-th step (the tracked crank's error against the exact motion over time).
use mbd::model::models::ClosedLoop;
use mbd::solve::State;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let a: Vec<String> = std::env::args().collect();
    let spec = a.get(1).cloned().unwrap_or_else(|| "rk4".into());
    let n: usize = a.get(2).map(|s| s.parse()).transpose()?.unwrap_or(2);
    let driven = a.get(3).is_some_and(|s| s == "driven");
    let h: f64 = a.get(4).map(|s| s.parse()).transpose()?.unwrap_or(1e-2);
    let t_end: f64 = a.get(5).map(|s| s.parse()).transpose()?.unwrap_or(10.0);
    let watch: f64 = std::env::var("WATCH")
        .ok()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(1e3);
    let cl = ClosedLoop::n_four_bar(n, 0.4, 1.0)?;
    let sys = cl.system(1.0, 6.0, driven)?;
    let exact = if driven {
        mbd::model::models::CrankMotion::driven(1.0, 6.0)
    } else {
        cl.motion(1.0, 6.0)
    }?;
    let parsed = mbd::registry().parse(&spec)?;
    let mut integ = parsed.build(&sys)?;
    let mut s = State::consistent(&sys, 0.0)?;
    let body = sys
        .body_handle(&cl.tracked_body())
        .ok_or("no body")?
        .index();
    let c1 = sys.body_handle("coupler1").ok_or("no coupler")?.index();
    let every: usize = std::env::var("EVERY")
        .ok()
        .map(|s| s.parse())
        .transpose()?
        .unwrap_or(0);
    let steps = (t_end / h).round() as usize;
    let mut phi = vec![0.0; sys.n_constraints()];
    for k in 0..steps {
        let st = match integ.step(&sys, &mut s, h) {
            Ok(st) => st,
            Err(e) => {
                println!("step {k} t = {:.6}: {e}", s.t);
                break;
            }
        };
        s.t = (k + 1) as f64 * h;
        sys.phi(s.q.as_slice(), s.t, &mut phi);
        let r = phi.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let periodic = every > 0 && (k + 1) % every == 0;
        if st.condition > watch || !r.is_finite() || r > 1e-3 || periodic {
            let want = exact.at(s.t)[0];
            println!(
                "step {k} t = {:.4} cond {:.2e} |phi| {r:.2e} crank_err {:.3e} coupler {:.2e} newton {}",
                s.t, st.condition, s.q[3 * body + 2] - want, s.q[3 * c1 + 2], st.newton_iterations
            );
            if r > 1.0 || !r.is_finite() {
                break;
            }
        }
    }
    let want = cl.tracked_point(exact.at(s.t)[0]);
    let q = s.q.as_slice();
    let p = [
        q[3 * body] + 0.2 * q[3 * body + 2].cos(),
        q[3 * body + 1] + 0.2 * q[3 * body + 2].sin(),
    ];
    println!(
        "end t = {} error {:.3e}",
        s.t,
        ((p[0] - want[0]).powi(2) + (p[1] - want[1]).powi(2)).sqrt()
    );
    Ok(())
}
