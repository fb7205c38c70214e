//! W_s: gradient against finite differences, the modal property, gamma = 0 bit for bit.
use mbd_model::{models, Body, BodyRef, Force, Joint, SystemBuilder};
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, Preadjustment, SymplecticOptions};

fn check_gradient(sys: &mbd_model::System, q: &[f64], label: &str) {
    let n = q.len();
    for s in 1..=4 {
        let mut w = Preadjustment::new(sys, s).unwrap();
        let mut g = vec![0.0; n];
        let w0 = w.gradient(sys, q, &mut g).unwrap();
        assert!((w0 - w.value(sys, q).unwrap()).abs() <= 1e-12 * w0.abs().max(1e-30));
        let scale = g.iter().fold(0.0f64, |a, &b| a.max(b.abs()));
        let mut worst = 0.0f64;
        for i in 0..n {
            let d = 1e-5;
            let mut qp = q.to_vec();
            qp[i] += d;
            let wp = w.value(sys, &qp).unwrap();
            qp[i] -= 2.0 * d;
            let wm = w.value(sys, &qp).unwrap();
            let fd = (wp - wm) / (2.0 * d);
            worst = worst.max((fd - g[i]).abs());
        }
        println!("{label} s={s}: W = {w0:.6e}, |grad| = {scale:.3e}, |grad - FD| = {worst:.2e}");
        assert!(
            worst <= 1e-7 * scale.max(1e-12),
            "{label} s={s}: {worst} vs {scale}"
        );
    }
}

#[test]
fn gradient_matches_finite_differences() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let mut st = State::consistent(&sys, 0.0).unwrap();
    st.q[2] += 0.0; // the paper's initial configuration (30 degrees, both rods)
    check_gradient(&sys, st.q.as_slice(), "double pendulum");
    let sc = models::slider_crank().unwrap();
    let st = State::consistent(&sc, 0.0).unwrap();
    check_gradient(&sc, st.q.as_slice(), "slider-crank");
    // springs and gravity together (non-zero potential Hessian and third derivatives)
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let a = b.add_body(Body::new("a").rod(1.0, 1.0).position(0.4, -0.3, -0.9));
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        a,
        [-0.5, 0.0],
    ));
    b.add_force(Force::spring_damper(
        "k",
        BodyRef::Ground,
        [1.0, 0.5],
        a,
        [0.5, 0.0],
        30.0,
        0.0,
        0.4,
    ));
    b.add_force(Force::rotary_spring_damper(
        "r",
        BodyRef::Ground,
        a,
        3.0,
        0.0,
        -1.2,
    ));
    let sys = b.build().unwrap();
    let st = State::consistent(&sys, 0.0).unwrap();
    check_gradient(&sys, st.q.as_slice(), "spring pendulum");
    // spatial bodies: natural coordinates, internal constraints among the rows
    for (sys, label) in [
        (
            models::heavy_top([0.3, 0.3, 0.1], 0.3, 20.0).unwrap(),
            "heavy top",
        ),
        (
            models::spatial_double_pendulum().unwrap(),
            "spatial double pendulum",
        ),
        (
            models::sprung_rod([0.05, 0.05, 0.002]).unwrap(),
            "sprung rod",
        ),
    ] {
        let st = State::consistent(&sys, 0.0).unwrap();
        check_gradient(&sys, st.q.as_slice(), label);
    }
}

/// About the hanging equilibrium W_s = 1/2 omega^(2s+2) eta^2 for the rod pendulum, with
/// eta the M-normalised modal coordinate: eta = sqrt(J_pivot) * phi.
#[test]
fn modal_form_at_equilibrium() {
    let sys = models::pendulum(1.0, 1.0, 0.0, 9.81).unwrap();
    let omega2 = 1.5 * 9.81;
    let jp = 1.0 / 3.0;
    let phi = 1e-4;
    let th = -std::f64::consts::FRAC_PI_2 + phi;
    let q = [0.5 * th.cos(), 0.5 * th.sin(), th];
    for s in 1..=4 {
        let mut w = Preadjustment::new(&sys, s).unwrap();
        let val = w.value(&sys, &q).unwrap();
        let modal = 0.5 * f64::powi(omega2, s as i32 + 1) * jp * phi * phi;
        assert!((val / modal - 1.0).abs() < 1e-6, "s={s}: {val} vs {modal}");
    }
}

#[test]
fn gamma_zero_is_the_plain_scheme_bit_for_bit() {
    let sys = models::paper_a_double_pendulum().unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    for s in 1..=3 {
        let plain = SymplecticOptions::new(s);
        // built through the preadjusted path: set gamma, then set it back to zero
        let adjusted_zero = SymplecticOptions::new(s).with_gamma(1.0).with_gamma(0.0);
        let mut a = Galerkin::new(&sys, plain).unwrap();
        let mut b = Galerkin::new(&sys, adjusted_zero).unwrap();
        let (mut sa, mut sb) = (s0.clone(), s0.clone());
        for _ in 0..200 {
            a.step(&sys, &mut sa, 0.04).unwrap();
            b.step(&sys, &mut sb, 0.04).unwrap();
        }
        let bits = |st: &State| -> Vec<u64> {
            st.q.iter()
                .chain(st.v.iter())
                .map(|x| x.to_bits())
                .collect()
        };
        assert_eq!(bits(&sa), bits(&sb), "s={s}");
        // and a non-zero gamma does change the result
        let mut c = Galerkin::new(&sys, SymplecticOptions::new(s).with_gamma(1.0)).unwrap();
        let mut sc = s0.clone();
        for _ in 0..200 {
            c.step(&sys, &mut sc, 0.04).unwrap();
        }
        assert_ne!(bits(&sa), bits(&sc));
    }
}

/// A spatial body with a zero second moment (the disc top, `E_3 = 0`: a singular mass
/// matrix): the augmented metric gives `W_s` whose gradient matches central differences (s =
/// 1..4).
#[test]
fn a_singular_mass_matrix_takes_the_augmented_metric() {
    let sys = models::heavy_top([0.25, 0.25, 0.5], 0.3, 20.0).unwrap();
    let st = State::consistent(&sys, 0.0).unwrap();
    check_gradient(&sys, st.q.as_slice(), "disc top");
}
