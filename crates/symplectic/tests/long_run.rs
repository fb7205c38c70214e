//! Energy without drift over 1e5 steps and constraints at round-off at every step.
use mbd_model::models;
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, SymplecticOptions};

#[test]
fn no_energy_drift_over_1e5_steps() {
    let sys = models::pendulum(1.0, 1.0, 1.0, 9.81).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let n = 100_000;
    let h = 0.05;
    let mut g = Galerkin::new(&sys, SymplecticOptions::new(1)).unwrap();
    let mut st = s0.clone();
    let h0 = sys.energy(st.q.as_slice(), st.v.as_slice());
    let (mut first, mut last) = (0.0f64, 0.0f64);
    let (mut max_phi, mut max_phid) = (0.0f64, 0.0f64);
    let mut r = vec![0.0; sys.n_constraints()];
    for k in 1..=n {
        g.step(&sys, &mut st, h).unwrap();
        st.t = k as f64 * h;
        let e = (sys.energy(st.q.as_slice(), st.v.as_slice()) - h0).abs();
        if k <= n / 10 {
            first = first.max(e);
        }
        if k > n - n / 10 {
            last = last.max(e);
        }
        sys.phi(st.q.as_slice(), st.t, &mut r);
        max_phi = r.iter().fold(max_phi, |a, &b| a.max(b.abs()));
        sys.phi_dot(st.q.as_slice(), st.v.as_slice(), st.t, &mut r);
        max_phid = r.iter().fold(max_phid, |a, &b| a.max(b.abs()));
    }
    println!(
        "1e5 steps: max |dH| first tenth {first:.4e}, last tenth {last:.4e}, ratio {:.4}; max |Phi| {max_phi:.2e}, max |Phi_q v| {max_phid:.2e}",
        last / first
    );
    assert!(last <= 2.0 * first, "energy drift: {first} -> {last}");
    assert!(max_phi <= 1e-12 && max_phid <= 1e-12);
}

/// The long-run requirement on the paper-C manipulator (a chaotic double pendulum whose
/// links spin up to hundreds of radians): over 1e5 steps of h = 0.01 s, constraints at position
/// and velocity level <= 1e-12 at every step and no energy drift, for s = 1 and s = 2.
#[test]
fn manipulator_constraints_and_energy_over_1e5_steps() {
    let sys = models::manipulator().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let (n, h) = (100_000, 0.01);
    let h0 = sys.energy(s0.q.as_slice(), s0.v.as_slice());
    let m = sys.n_constraints();
    let (mut phi, mut phid) = (vec![0.0; m], vec![0.0; m]);
    for s in [1, 2] {
        let mut g = Galerkin::new(&sys, SymplecticOptions::new(s)).unwrap();
        let mut st = s0.clone();
        let (mut first, mut last) = (0.0f64, 0.0f64);
        let (mut max_phi, mut max_phid, mut max_angle) = (0.0f64, 0.0f64, 0.0f64);
        for k in 1..=n {
            g.step(&sys, &mut st, h).unwrap();
            let e = (sys.energy(st.q.as_slice(), st.v.as_slice()) - h0).abs();
            if k <= n / 10 {
                first = first.max(e);
            }
            if k > n - n / 10 {
                last = last.max(e);
            }
            sys.phi_and_phi_dot(st.q.as_slice(), st.v.as_slice(), st.t, &mut phi, &mut phid);
            max_phi = phi.iter().fold(max_phi, |a, &b| a.max(b.abs()));
            max_phid = phid.iter().fold(max_phid, |a, &b| a.max(b.abs()));
            max_angle = max_angle.max(st.q[2].abs()).max(st.q[5].abs());
        }
        println!(
            "({s},{s}): max |dH| first tenth {first:.3e}, last tenth {last:.3e}; max |Phi| {max_phi:.2e}, max |Phidot| {max_phid:.2e}, max |angle| {max_angle:.0} rad"
        );
        assert!(
            last <= 2.0 * first,
            "s = {s}: energy drift {first} -> {last}"
        );
        assert!(
            max_phi <= 1e-12 && max_phid <= 1e-12,
            "s = {s}: max |Phi| {max_phi:e}, max |Phidot| {max_phid:e}"
        );
    }
}
