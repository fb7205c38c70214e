//! Cross-solver agreement on the manipulator at t = 2 s: tangent-space RK4 against RK4 on the
//! index-1 form with projection (`mbd_solve::Index1Rk`, the engine of `mbd-rk4`), both against
//! an independent DOPRI5 reference. (The comparison with the symplectic scheme belongs to the
//! workspace tests, which see both crates.)

mod common;

use common::state_error;
use mbd_model::models;
use mbd_solve::{
    reference_trajectory, run, ButcherTableau, Index1Options, Index1Rk, NoObserver,
    ProjectionSettings, RunConfig, State,
};
use mbd_tangent::TangentRk;

#[test]
fn tangent_rk4_agrees_with_projected_rk4_at_2s() {
    let sys = models::manipulator().expect("model");
    let s0 = State::consistent(&sys, 0.0).expect("state");
    let r = reference_trajectory(&sys, &s0, 2.0, 1, 16_000, ButcherTableau::dopri5()).expect("ref");
    let mut rows = vec![];
    for h in [1e-3, 5e-4, 2.5e-4] {
        let mut a = s0.clone();
        let mut tg = TangentRk::rk4(&sys).expect("tangent");
        run(
            &mut tg,
            &sys,
            &mut a,
            RunConfig::new(2.0, h),
            &mut NoObserver,
        )
        .expect("run");
        let mut b = s0.clone();
        let opts = Index1Options {
            projection: Some(ProjectionSettings::default()),
            ..Default::default()
        };
        let mut pr = Index1Rk::new(&sys, ButcherTableau::rk4(), opts).expect("rk4");
        run(
            &mut pr,
            &sys,
            &mut b,
            RunConfig::new(2.0, h),
            &mut NoObserver,
        )
        .expect("run");
        let ea = state_error(&a, &r.q[1], &r.v[1]);
        let eb = state_error(&b, &r.q[1], &r.v[1]);
        let dab = state_error(&a, b.q.as_slice(), b.v.as_slice());
        println!("h {h:e}: |tangent - ref| {ea:e}, |rk4+proj - ref| {eb:e}, |tangent - rk4+proj| {dab:e}");
        rows.push((h, ea, eb, dab));
    }
    for w in rows.windows(2) {
        let (ra, rb) = (w[0].1 / w[1].1, w[0].2 / w[1].2);
        // halving h divides a 4th-order error by 16 (accept 11..23)
        assert!((11.0..23.0).contains(&ra), "tangent ratio {ra}");
        assert!((11.0..23.0).contains(&rb), "rk4+proj ratio {rb}");
        // and the two solvers' difference shrinks at the same rate
        let rd = w[0].3 / w[1].3;
        assert!((11.0..23.0).contains(&rd), "difference ratio {rd}");
    }
    let (_, ea, eb, dab) = rows[1];
    // at h = 1e-3 both are within their O(h^4) error of the reference and of each other
    assert!(ea < 1e-6 && eb < 1e-6, "{ea} {eb}");
    assert!(dab <= ea + eb);
}
