//! The modified-Lagrangian preadjustment (s = 1 and s = 2) on mechanisms it was not derived or
//! tuned on: closed loops (four-bar, slider-crank, Andrews' squeezer with its spring and drive),
//! the paper-C manipulator, a 50-link chain and an elastic pendulum (no constraints). On every one the largest energy error of the run
//! falls at least 20x below the plain scheme's (measured 48x to 34000x), Newton converges, and
//! the constraints stay at round-off.
use mbd_model::{models, System};
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, PreadjustMode, SymplecticOptions};

/// Max |H - H0| and max |Phi| over `n` steps of `h` from the model's consistent initial state.
fn run(sys: &System, o: SymplecticOptions, h: f64, n: usize) -> (f64, f64) {
    let mut g = Galerkin::new(sys, o).unwrap();
    let mut st = State::consistent(sys, 0.0).unwrap();
    let h0 = sys.energy(st.q.as_slice(), st.v.as_slice());
    let mut phi = vec![0.0; sys.n_constraints()];
    let (mut dh, mut mp) = (0.0f64, 0.0f64);
    for _ in 0..n {
        g.step(sys, &mut st, h).unwrap();
        dh = dh.max((sys.energy(st.q.as_slice(), st.v.as_slice()) - h0).abs());
        sys.phi(st.q.as_slice(), st.t, &mut phi);
        mp = phi.iter().fold(mp, |a, &b| a.max(b.abs()));
    }
    (dh, mp)
}

#[test]
fn energy_error_falls_on_other_mechanisms() {
    let cases: [(&str, System, f64, usize); 6] = [
        (
            "elastic pendulum",
            models::elastic_pendulum().unwrap(),
            0.02,
            1000,
        ),
        ("four-bar", models::four_bar().unwrap(), 0.01, 1000),
        ("slider-crank", models::slider_crank().unwrap(), 0.01, 1000),
        (
            "Andrews' squeezer",
            models::andrews_squeezer().unwrap(),
            1e-4,
            300,
        ),
        ("manipulator", models::manipulator().unwrap(), 0.01, 1000),
        (
            "50-link chain",
            models::n_link_chain(50).unwrap(),
            0.005,
            100,
        ),
    ];
    for (name, sys, h, n) in &cases {
        for s in [1, 2] {
            let (plain, _) = run(sys, SymplecticOptions::new(s), *h, *n);
            let o = SymplecticOptions::new(s).with_preadjust(PreadjustMode::ModifiedLagrangian);
            let (modified, phi) = run(sys, o, *h, *n);
            println!(
                "{name}, s = {s}: max |dH| plain {plain:.3e}, modified {modified:.3e} ({:.0}x); \
                 max |Phi| {phi:.1e}",
                plain / modified
            );
            assert!(
                modified < plain / 20.0,
                "{name}, s = {s}: {modified} vs {plain}"
            );
            assert!(phi < 1e-12, "{name}, s = {s}: max |Phi| {phi}");
        }
    }
}
