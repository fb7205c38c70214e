//! Repartitioning with a single constraint: a pendulum held by a distance joint.
//!
//! Released horizontally, the bob starts with `x` dependent (`dPhi/dx = x / L = 1`,
//! `dPhi/dy = 0`); at the bottom of the swing `dPhi/dx -> 0`, so `x` must become independent
//! there, and `y` near the turning points. A 1x1 dependent block is perfectly conditioned on its
//! own (its pivot ratio is always 1), so only a criterion relative to the whole Jacobian row can
//! see this. The rod pendulum on a revolute joint (two constraints, the angle independent
//! throughout) is the yardstick of accuracy.

use mbd_firefly_gauss::{FaDaeOptions, FireflyGauss};
use mbd_model::{models, Body, BodyRef, Joint, System, SystemBuilder};
use mbd_solve::linalg::max_abs;
use mbd_solve::{Integrator, State};
use std::f64::consts::{FRAC_PI_2, PI};

const G: f64 = 9.81;

/// A bob (1 kg, centroidal inertia 0.01) at (1, 0), held at its centre by a 1 m distance joint
/// to the origin: one constraint on three coordinates, the bob's rotation is free.
fn distance_pendulum() -> System {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -G]);
    let bob = b.add_body(
        Body::new("bob")
            .mass(1.0)
            .inertia(0.01)
            .position(1.0, 0.0, 0.0),
    );
    b.add_joint(Joint::distance(
        "string",
        BodyRef::Ground,
        [0.0, 0.0],
        bob,
        [0.0, 0.0],
        1.0,
    ));
    b.build().expect("distance pendulum")
}

/// Complete elliptic integral of the first kind, `K(k)`, by the arithmetic-geometric mean.
fn ellip_k(k: f64) -> f64 {
    let (mut a, mut b) = (1.0f64, (1.0 - k * k).sqrt());
    for _ in 0..30 {
        (a, b) = (0.5 * (a + b), (a * b).sqrt());
    }
    PI / (2.0 * a)
}

/// Exact period of a pendulum released at rest `a0` from the bottom, small-amplitude angular
/// frequency `omega0`.
fn exact_period(a0: f64, omega0: f64) -> f64 {
    4.0 / omega0 * ellip_k((0.5 * a0).sin())
}

/// The swing angle from the downward vertical of the body centre and its rate.
fn angle(q: &[f64], v: &[f64]) -> (f64, f64) {
    let (x, y) = (q[0], q[1]);
    (x.atan2(-y), (x * v[1] - y * v[0]) / (x * x + y * y))
}

/// What a run did, step by step.
struct Swing {
    /// Worst relative error of the period measured from successive bottom passages.
    period_error: f64,
    /// Bottom passages.
    passages: usize,
    /// Per step: the bob's `x` at the step's start, the dependent coordinates used, whether the
    /// step re-chose the partition, the quality of the block before the choice.
    steps: Vec<(f64, Vec<usize>, bool, f64)>,
}

fn swing(sys: &System, opts: FaDaeOptions, period: f64, t_end: f64, h: f64) -> Swing {
    let mut s = State::consistent(sys, 0.0).expect("consistent state");
    let mut fa = FireflyGauss::new(sys, opts).expect("valid options");
    fa.reset();
    let n = (t_end / h).round() as usize;
    let mut crossings = Vec::new();
    let mut steps = Vec::new();
    for _ in 0..n {
        let (x0, t0) = (s.q[0], s.t);
        let (p0, d0) = angle(s.q.as_slice(), s.v.as_slice());
        fa.step(sys, &mut s, h).expect("step");
        let info = *fa.last_step();
        steps.push((
            x0,
            fa.partition().dependent.clone(),
            info.repartitioned,
            info.partition_quality,
        ));
        let (p1, d1) = angle(s.q.as_slice(), s.v.as_slice());
        if p0 * p1 < 0.0 || p1 == 0.0 {
            // the crossing time on the cubic Hermite interpolant of the angle, by bisection
            let f = |u: f64| {
                let (u2, u3) = (u * u, u * u * u);
                (2.0 * u3 - 3.0 * u2 + 1.0) * p0
                    + (u3 - 2.0 * u2 + u) * h * d0
                    + (3.0 * u2 - 2.0 * u3) * p1
                    + (u3 - u2) * h * d1
            };
            let (mut lo, mut hi) = (0.0, 1.0);
            for _ in 0..60 {
                let mid = 0.5 * (lo + hi);
                if (f(mid) < 0.0) == (p0 < 0.0) {
                    lo = mid;
                } else {
                    hi = mid;
                }
            }
            crossings.push(t0 + 0.5 * (lo + hi) * h);
        }
    }
    let errors: Vec<f64> = crossings
        .windows(2)
        .map(|w| (2.0 * (w[1] - w[0]) - period) / period)
        .collect();
    let period_error = max_abs(&errors);
    Swing {
        period_error,
        passages: crossings.len(),
        steps,
    }
}

fn opts(polish: bool) -> FaDaeOptions {
    FaDaeOptions::default().polish(polish)
}

const H: f64 = 0.01;
const T_END: f64 = 5.5;

#[test]
fn distance_pendulum_is_as_accurate_as_the_revolute_one() {
    let dist = distance_pendulum();
    let rod = models::pendulum(1.0, 1.0, FRAC_PI_2, G).expect("rod pendulum");
    // point mass on a 1 m string; uniform 1 m rod pinned at its end (omega0^2 = 3 g / 2)
    let (t_dist, t_rod) = (
        exact_period(FRAC_PI_2, G.sqrt()),
        exact_period(FRAC_PI_2, (1.5 * G).sqrt()),
    );
    for polish in [true, false] {
        let d = swing(&dist, opts(polish), t_dist, T_END, H);
        let r = swing(&rod, opts(polish), t_rod, T_END, H);
        println!(
            "polish {polish}: period error distance {:.3e}, revolute {:.3e}; repartitions {}",
            d.period_error,
            r.period_error,
            d.steps.iter().filter(|s| s.2).count()
        );
        // T = 2.368 s and 1.933 s: five and six bottom passages in 5.5 s
        assert_eq!((d.passages, r.passages), (5, 6));
        // measured (h = 0.01): revolute 2e-9 to 1e-8; distance joint before the relative
        // criterion 3e-6 (pure) and 1e-5 (polished), after it 1e-9 to 1e-8
        assert!(
            d.period_error <= 1e-7 && d.period_error <= 10.0 * r.period_error.max(1e-9),
            "distance {:e} vs revolute {:e}",
            d.period_error,
            r.period_error
        );
        assert!(
            r.steps.iter().all(|s| !s.2),
            "the rod's angle stays independent"
        );
    }
}

#[test]
fn repartitioning_follows_the_swing_without_thrashing() {
    let sys = distance_pendulum();
    let o = opts(false);
    let threshold = o.repartition_threshold;
    let d = swing(&sys, o, exact_period(FRAC_PI_2, G.sqrt()), T_END, H);
    // near the bottom (|x| < 0.05 m, where dPhi/dx < 0.05 dPhi/dy) x is independent
    let near_bottom: Vec<_> = d.steps.iter().filter(|s| s.0.abs() < 0.05).collect();
    assert!(near_bottom.len() >= 5, "{}", near_bottom.len());
    for s in &near_bottom {
        assert_eq!(s.1, vec![1], "y dependent at the bottom: {s:?}");
    }
    // the block in use is never much worse than the best available one
    for s in &d.steps {
        assert!(s.2 || s.3 >= threshold, "{s:?}");
    }
    // at most one change per bottom passage (5) and turning point (4 after the start), each a
    // single switch: the switches are far apart
    let switches: Vec<usize> = (0..d.steps.len()).filter(|&k| d.steps[k].2).collect();
    assert!(
        (5..=9).contains(&switches.len()),
        "{} switches at steps {switches:?}",
        switches.len()
    );
    assert!(
        switches.windows(2).all(|w| w[1] - w[0] >= 20),
        "switches at steps {switches:?}"
    );
}

#[test]
fn threshold_zero_switches_repartitioning_off() {
    let sys = distance_pendulum();
    let o = FaDaeOptions {
        repartition_threshold: 0.0,
        ..opts(false)
    };
    let d = swing(&sys, o, exact_period(FRAC_PI_2, G.sqrt()), 1.0, H);
    assert!(d.steps.iter().all(|s| !s.2 && s.1 == vec![0]));
    // and the block it keeps loses its conditioning at the bottom
    let worst = d.steps.iter().map(|s| s.3).fold(1.0f64, f64::min);
    assert!(worst < 0.05, "{worst}");
}
