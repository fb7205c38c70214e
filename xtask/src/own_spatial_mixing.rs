//! `own-spatial`, Newton mixing: the Anderson mixing of the symplectic stage equations' Newton
//! updates (docs/symplectic.md, "Anderson mixing") on a chain of spatial rods, where the (1,1)
//! modified scheme's plain updates contracted only linearly while its sparse position block
//! was a diagonal (it cut them 1.29x at 1000 rods). With the exact block (docs/symplectic.md
//! section 5a) they contract fast there and the mixing does not start: the claim is that it
//! costs no iteration and leaves the end state where it was. Newton iterations per step with
//! and without it, through the public run loop.

use crate::report::{fmt_e, Claim, Ctx, Section};
use mbd::model::models::spatial_chain;
use mbd::prelude::*;
use mbd::solve::linalg::max_abs_diff;
use mbd::symplectic::DEFAULT_ANDERSON_DEPTH;

/// The smallest factor by which the mixing must lower the Newton iterations per step (1: it
/// may not raise them).
const MIN_GAIN: f64 = 1.0;

/// How far apart the end states with and without the mixing may be (both converge each step to
/// the Newton tolerance, about 1e-14 relative).
const SAME_STATE: f64 = 1e-10;

/// The (1,1) modified scheme on the chain with and without the mixing.
pub(crate) fn mixing(ctx: &Ctx, sec: &mut Section) -> Result<(), String> {
    // quick: a shorter chain at a longer step, where the plain updates contract as slowly
    let (n, h, steps) = if ctx.quick {
        (100, 1e-2, 12)
    } else {
        (1000, 1e-3, 20)
    };
    let sys = spatial_chain(n).map_err(|e| e.to_string())?;
    let t_end = h * steps as f64;
    let run = |depth: usize| -> Result<(f64, State), String> {
        let o = SymplecticOptions {
            anderson_depth: depth,
            ..SymplecticOptions::new(1).with_preadjust(PreadjustMode::ModifiedLagrangian)
        };
        let g = Galerkin::new(&sys, o).map_err(|e| e.to_string())?;
        let mut sim = Simulation::with_integrator(sys.clone(), g).map_err(|e| e.to_string())?;
        let stats = sim
            .run(RunConfig::new(t_end, h))
            .map_err(|e| format!("symplectic:1:modified, anderson_depth = {depth}: {e}"))?;
        let per_step = stats.newton_iterations as f64 / stats.steps.max(1) as f64;
        Ok((per_step, sim.state().clone()))
    };
    let (on, a) = run(DEFAULT_ANDERSON_DEPTH)?;
    let (off, b) = run(0)?;
    let dq = max_abs_diff(a.q.as_slice(), b.q.as_slice());
    let gain = off / on;
    sec.setting(
        "Newton mixing",
        format!(
            "models::spatial_chain({n}), symplectic:1:modified at h = {h:e}, {steps} steps \
             from rest, Newton iterations per step with the default Anderson depth \
             ({DEFAULT_ANDERSON_DEPTH}) and with anderson_depth = 0"
        ),
    );
    sec.claims.push(Claim::check(
        format!(
            "on a {n}-rod spatial chain at h = {h:e}, mixing the Newton updates does not raise \
             the (1,1) modified scheme's Newton iterations per step (gain at least {MIN_GAIN}x), \
             the end state the same to {SAME_STATE:e}"
        ),
        gain >= MIN_GAIN && dq <= SAME_STATE,
        format!(
            "{off:.2} -> {on:.2} iterations per step ({gain:.2}x); end states {} apart in q",
            fmt_e(dq)
        ),
    ));
    Ok(())
}
