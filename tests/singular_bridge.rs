//! The acceleration bridge through singular configurations (`mbd_solve::SingularBridge`,
//! docs/singular.md): on the free 2-four-bar, which turns over through flat configurations,
//! projected RK4 and tangent DOPRI5 keep their accuracy with it and lose it without; away from
//! singular configurations it changes nothing, bit for bit.

use mbd::model::models::ClosedLoop;
use mbd::prelude::*;
use mbd::solve::{run, ButcherTableau, NoObserver, RunStats};

/// The free 2-four-bar (cranks 0.4 m, ground 1 m) released at 6 rad/s from 1 rad.
fn free_two_four_bar() -> (System, ClosedLoop) {
    let cl = ClosedLoop::n_four_bar(2, 0.4, 1.0).unwrap();
    (cl.system(1.0, 6.0, false).unwrap(), cl)
}

/// Runs `integ` to `t_end` with step `h`: the run's statistics and the crank angle's error
/// against the exact (elliptic-function) motion.
fn crank_error(integ: &mut dyn Integrator, h: f64, t_end: f64) -> (RunStats, f64) {
    let (sys, cl) = free_two_four_bar();
    let body = sys.body_handle(&cl.tracked_body()).unwrap().index();
    let mut s = State::consistent(&sys, 0.0).unwrap();
    let stats = run(
        integ,
        &sys,
        &mut s,
        RunConfig::new(t_end, h),
        &mut NoObserver,
    )
    .unwrap();
    let exact = cl.motion(1.0, 6.0).unwrap().at(t_end)[0];
    (stats, (s.q[3 * body + 2] - exact).abs())
}

fn rk4_projected(sys: &System, bridge: bool) -> Rk4 {
    let opts = Rk4Options {
        bridge,
        ..Rk4Options::projected()
    };
    Rk4::new(sys, opts).unwrap()
}

/// At h = 1e-4 a stage of the step ending at t = 1.8773 lands 2.3e-6 rad from a flat
/// configuration (condition estimate 2.3e10): without the bridge the crank leaves that passage
/// with its rate 3e-4 rad/s off (4.75e-3 rad by t = 10); with it the error stays at rounding.
#[test]
fn projected_rk4_keeps_its_accuracy_through_the_flat_configurations() {
    let (sys, _) = free_two_four_bar();
    let (h, t_end) = (1e-4, 2.2);
    let (with, e_with) = crank_error(&mut rk4_projected(&sys, true), h, t_end);
    let (without, e_without) = crank_error(&mut rk4_projected(&sys, false), h, t_end);
    eprintln!(
        "crank error at t = {t_end}: {e_with:.3e} with the bridge ({} stages bridged), \
         {e_without:.3e} without",
        with.bridged_stages
    );
    assert!(e_with < 1e-10, "with the bridge: {e_with:e}");
    assert!(e_without > 1e-6, "without the bridge: {e_without:e}");
    assert!(with.bridged_stages > 0 && without.bridged_stages == 0);
    assert!(with.warning().is_some_and(|w| w.contains("stage(s)")));
}

/// Tangent DOPRI5 at h = 1e-3: a stage of the step ending at t = 1.878 is solved at condition
/// 2.3e10; the bridge keeps the error after the passage near the one before it.
#[test]
fn tangent_dopri5_keeps_its_accuracy_through_the_flat_configurations() {
    let (sys, _) = free_two_four_bar();
    let tangent = |bridge: bool| {
        let opts = TangentOptions {
            bridge,
            ..TangentOptions::default()
        };
        TangentRk::new(&sys, ButcherTableau::dopri5(), opts).unwrap()
    };
    let (h, t_end) = (1e-3, 2.5);
    let (with, e_with) = crank_error(&mut tangent(true), h, t_end);
    let (_, e_without) = crank_error(&mut tangent(false), h, t_end);
    eprintln!(
        "crank error at t = {t_end}: {e_with:.3e} with the bridge ({} stages bridged), \
         {e_without:.3e} without",
        with.bridged_stages
    );
    assert!(with.bridged_stages > 0);
    assert!(
        e_with < 0.1 * e_without,
        "with {e_with:e}, without {e_without:e}"
    );
}

/// Away from singular configurations the bridge never acts: the same steps bit for bit on two
/// closed loops and a chain (a badly scaled chain, whose condition estimate stays high all
/// along, is crates/symplectic/tests/scaling.rs's RK4 reference).
#[test]
fn away_from_singular_configurations_nothing_changes() {
    let models = [
        models::four_bar().unwrap(),
        models::slider_crank().unwrap(),
        models::n_link_chain(4).unwrap(),
    ];
    for sys in models {
        let end = |bridge: bool| {
            let mut rk = rk4_projected(&sys, bridge);
            let mut s = State::consistent(&sys, 0.0).unwrap();
            let stats = run(
                &mut rk,
                &sys,
                &mut s,
                RunConfig::new(1.0, 1e-3),
                &mut NoObserver,
            )
            .unwrap();
            (s, stats.bridged_stages)
        };
        let ((a, na), (b, nb)) = (end(true), end(false));
        assert_eq!((na, nb), (0, 0));
        assert_eq!(a.q.as_slice(), b.q.as_slice());
        assert_eq!(a.v.as_slice(), b.v.as_slice());
    }
}

/// docs/singular.md states the bridge's constants as the code has them.
#[test]
fn the_docs_state_the_bridge_constants() {
    use mbd::solve::{
        BRIDGE_CONDITION, BRIDGE_DISAGREEMENT, BRIDGE_MAX_CONSTRAINTS, BRIDGE_MEMORY, BRIDGE_POINTS,
    };
    let doc =
        std::fs::read_to_string(concat!(env!("CARGO_MANIFEST_DIR"), "/docs/singular.md")).unwrap();
    for stated in [
        format!("`BRIDGE_POINTS = {BRIDGE_POINTS}`"),
        format!("`BRIDGE_MEMORY = {BRIDGE_MEMORY}`"),
        format!("`BRIDGE_CONDITION = {BRIDGE_CONDITION:e}`"),
        format!("`BRIDGE_DISAGREEMENT = {BRIDGE_DISAGREEMENT}`"),
        format!("`BRIDGE_MAX_CONSTRAINTS = {BRIDGE_MAX_CONSTRAINTS}`"),
    ] {
        assert!(
            doc.contains(&stated),
            "docs/singular.md does not state {stated}"
        );
    }
}
