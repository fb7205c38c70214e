use super::*;

/// Double-double numbers (`hi + lo`, about 32 digits) for the reference integration: near
/// the separatrix the flips' timing is as sensitive to rounding as `|w|^2 / (L^2 - 2T J_mid)`,
/// too much for a double-precision reference.
#[derive(Clone, Copy, Debug, Default)]
struct Dd(f64, f64);

impl Dd {
    fn quick(a: f64, b: f64) -> Dd {
        let s = a + b;
        Dd(s, b - (s - a))
    }
    fn add(self, o: Dd) -> Dd {
        let s = self.0 + o.0;
        let bb = s - self.0;
        let e = (self.0 - (s - bb)) + (o.0 - bb);
        Dd::quick(s, e + self.1 + o.1)
    }
    fn mul(self, o: Dd) -> Dd {
        let p = self.0 * o.0;
        let e = self.0.mul_add(o.0, -p) + (self.0 * o.1 + self.1 * o.0);
        Dd::quick(p, e)
    }
    fn neg(self) -> Dd {
        Dd(-self.0, -self.1)
    }
    fn div(self, b: f64) -> Dd {
        let q1 = self.0 / b;
        let r = self.add(Dd(q1, 0.0).mul(Dd(b, 0.0)).neg());
        let q2 = r.0 / b;
        let r2 = r.add(Dd(q2, 0.0).mul(Dd(b, 0.0)).neg());
        let q = Dd::quick(q1, q2);
        q.add(Dd(r2.0 / b, 0.0))
    }
}

/// One Taylor-series step (order 24, Horner sum, double-double) of Euler's equations and
/// `R' = R [w]x` (`R` row-major): an independent reference, its truncation far below rounding
/// for steps `|w| h <= 0.05`.
fn taylor_step(j: [f64; 3], w: [Dd; 3], r: [Dd; 9], h: Dd) -> ([Dd; 3], [Dd; 9]) {
    const ORDER: usize = 24;
    let coef = [0, 1, 2].map(|i| Dd(j[(i + 1) % 3] - j[(i + 2) % 3], 0.0).div(j[i]));
    let mut wc = [[Dd::default(); 3]; ORDER + 1];
    let mut rc = [[Dd::default(); 9]; ORDER + 1];
    (wc[0], rc[0]) = (w, r);
    for n in 0..ORDER {
        let mut s = [Dd::default(); 3];
        let mut dr = [Dd::default(); 9];
        for k in 0..=n {
            let (x, y) = (wc[k], wc[n - k]);
            for i in 0..3 {
                s[i] = s[i].add(x[(i + 1) % 3].mul(y[(i + 2) % 3]));
            }
            // R [y]x
            let yx = [
                [Dd::default(), y[2].neg(), y[1]],
                [y[2], Dd::default(), y[0].neg()],
                [y[1].neg(), y[0], Dd::default()],
            ];
            let rk = rc[k];
            for row in 0..3 {
                for col in 0..3 {
                    let mut acc = dr[3 * row + col];
                    for q in 0..3 {
                        acc = acc.add(rk[3 * row + q].mul(yx[q][col]));
                    }
                    dr[3 * row + col] = acc;
                }
            }
        }
        let div = (n + 1) as f64;
        wc[n + 1] = [0, 1, 2].map(|i| coef[i].mul(s[i]).div(div));
        rc[n + 1] = dr.map(|x| x.div(div));
    }
    let (mut w1, mut r1) = (wc[ORDER], rc[ORDER]);
    for n in (0..ORDER).rev() {
        w1 = [0, 1, 2].map(|i| w1[i].mul(h).add(wc[n][i]));
        r1 = [0, 1, 2, 3, 4, 5, 6, 7, 8].map(|i| r1[i].mul(h).add(rc[n][i]));
    }
    (w1, r1)
}

/// The reference `(w, R)` at each of `times` (ascending from 0, or descending from 0).
fn reference(body: &TorqueFreeBody, times: &[f64]) -> Vec<(Vector3<f64>, Matrix3<f64>)> {
    let mut w = [0, 1, 2].map(|i| Dd(body.omega0[i], 0.0));
    let mut r = [0, 1, 2, 3, 4, 5, 6, 7, 8].map(|i| Dd(body.r0[(i / 3, i % 3)], 0.0));
    let mut t = Dd::default();
    let hmax = 0.05 / body.omega0.amax().max(1e-300);
    let mut out = Vec::new();
    for &target in times {
        let span = Dd(target, 0.0).add(t.neg());
        let steps = (span.0.abs() / hmax).ceil().max(1.0);
        let h = span.div(steps);
        for _ in 0..steps as usize {
            (w, r) = taylor_step(body.j, w, r, h);
        }
        t = Dd(target, 0.0);
        out.push((
            Vector3::from_fn(|i, _| w[i].0 + w[i].1),
            Matrix3::from_fn(|i, k| r[3 * i + k].0 + r[3 * i + k].1),
        ));
    }
    out
}

fn rot(axis: [f64; 3], angle: f64) -> Matrix3<f64> {
    let n = Vector3::from(axis).normalize();
    let k = n.cross_matrix();
    let (s, c) = angle.sin_cos();
    Matrix3::identity() + k * s + k * k * (1.0 - c)
}

/// A general initial rotation.
fn r0() -> Matrix3<f64> {
    rot([0.3, -0.5, 0.8], 1.1)
}

fn body(j: [f64; 3], w: [f64; 3]) -> TorqueFreeBody {
    TorqueFreeBody::new(j, Vector3::from(w), r0()).expect("valid test body")
}

/// Moments in every order (even and odd permutations), both sides of the separatrix, near
/// the separatrix, two equal moments, a flat plate (`J3 = J1 + J2`).
fn cases() -> Vec<(TorqueFreeBody, TorqueFreeMotion)> {
    use TorqueFreeMotion::*;
    vec![
        (body([1.0, 2.0, 3.0], [0.3, 0.5, 1.0]), AboutLargest),
        (body([1.0, 2.0, 3.0], [1.0, 0.5, 0.3]), AboutSmallest),
        (body([2.0, 3.0, 1.0], [-0.5, 1.0, 0.3]), AboutLargest),
        (body([3.0, 1.0, 2.0], [0.2, -1.2, 0.7]), AboutSmallest),
        (body([3.0, 2.0, 1.0], [0.4, -0.6, -0.9]), AboutSmallest),
        (body([1.0, 2.0, 3.0], [1e-3, 1.0, 1e-3]), AboutLargest),
        (body([1.0, 2.0, 3.0], [-2e-3, 1.0, 1e-3]), AboutSmallest),
        (body([1.0, 1.0, 2.0], [0.3, 0.4, 1.0]), AboutLargest),
        (body([2.0, 2.0, 1.0], [0.3, -0.4, 1.0]), AboutSmallest),
        (body([1.0, 3.0, 3.0], [0.5, 0.4, 1.0]), AboutSmallest),
        (body([1.0, 1.5, 2.5], [0.7, -0.2, 0.4]), AboutLargest),
        (body([1.0, 2.0, 3.0], [0.0, 1.0, 0.5]), AboutLargest),
        // nearly equal largest moments, spun about the largest: the precession rate varies
        // sharply near the flips
        (body([1.0, 2.9, 3.0], [0.05, 0.5, 1.0]), AboutLargest),
    ]
}

fn rel(a: Vector3<f64>, b: Vector3<f64>) -> f64 {
    (a - b).norm() / b.norm()
}

#[test]
fn gauss_legendre_is_exact_to_degree_15() {
    let mut worst: f64 = 0.0;
    for k in 0..16 {
        let q = gauss(&|x| x.powi(k), 1.0, 1);
        worst = worst.max((q - 1.0 / (k + 1) as f64).abs());
    }
    assert!(worst < 4e-16, "{worst:e}");
    let q = gauss(&f64::sin, std::f64::consts::PI, 4);
    assert!((q - 2.0).abs() < 1e-14, "{q}");
}

#[test]
fn classification_and_periods() {
    for (b, motion) in cases() {
        assert_eq!(b.motion(), motion, "{:?}", b.omega0);
        assert!(b.period().is_some_and(|p| p.is_finite() && p > 0.0));
    }
    // two equal moments: plain precession at (J3 - J1) / J1 w3
    let b = body([1.0, 1.0, 2.0], [0.3, 0.4, 1.0]);
    let p = b.period().expect("periodic");
    assert!((p - 2.0 * std::f64::consts::PI).abs() < 1e-14, "{p}");
}

#[test]
fn omega_matches_taylor_integration() {
    let mut worst: f64 = 0.0;
    for (b, _) in cases() {
        let p = b.period().expect("periodic");
        for sign in [1.0, -1.0] {
            let times: Vec<f64> = (1..=30).map(|i| sign * 3.0 * p * i as f64 / 30.0).collect();
            for (t, (w, _)) in times.iter().zip(reference(&b, &times)) {
                worst = worst.max(rel(b.omega(*t), w));
            }
        }
    }
    assert!(worst < 2e-13, "{worst:e}");
}

#[test]
fn rotation_matches_taylor_integration() {
    let mut worst: f64 = 0.0;
    for (b, _) in cases() {
        let p = b.period().expect("periodic");
        for sign in [1.0, -1.0] {
            let times: Vec<f64> = (1..=12).map(|i| sign * 2.0 * p * i as f64 / 12.0).collect();
            for (t, (_, r)) in times.iter().zip(reference(&b, &times)) {
                worst = worst.max((b.rotation(*t) - r).amax());
            }
        }
        assert!((b.rotation(0.0) - b.r0).amax() < 1e-15);
    }
    assert!(worst < 2e-13, "{worst:e}");
}

#[test]
fn invariants_along_the_solution() {
    let (mut de, mut dl, mut dlg) = (0.0f64, 0.0f64, 0.0f64);
    for (b, _) in cases() {
        let p = b.period().expect("periodic");
        let (e, lg) = (b.energy(), b.angular_momentum_global());
        for i in 0..40 {
            let t = -1.3 * p + 0.0917 * p * i as f64;
            let w = b.omega(t);
            let jw = Vector3::from_fn(|k, _| b.j[k] * w[k]);
            de = de.max((0.5 * w.dot(&jw) - e).abs() / e);
            dl = dl.max((jw.norm() - lg.norm()).abs() / lg.norm());
            dlg = dlg.max(rel(b.rotation(t) * jw, lg));
        }
    }
    assert!(
        de < 1e-14 && dl < 1e-14 && dlg < 1e-14,
        "{de:e} {dl:e} {dlg:e}"
    );
}

#[test]
fn two_equal_moments_precess_uniformly() {
    // J1 = J2: w3 constant, (w1, w2) turn at Omega = (J3 - J1) / J1 w3
    let b = body([1.0, 1.0, 2.0], [0.3, 0.4, 1.0]);
    let mut worst: f64 = 0.0;
    for t in [-7.0f64, 0.4, 3.0, 25.0] {
        let (s, c) = t.sin_cos();
        let exact = Vector3::new(0.3 * c - 0.4 * s, 0.3 * s + 0.4 * c, 1.0);
        worst = worst.max(rel(b.omega(t), exact));
    }
    assert!(worst < 1e-14, "{worst:e}");
}

#[test]
fn steady_spins_about_each_principal_axis() {
    for axis in 0..3 {
        let mut w = [0.0; 3];
        w[axis] = 1.7;
        let b = body([1.0, 2.0, 3.0], w);
        assert_eq!(b.motion(), TorqueFreeMotion::Steady);
        assert_eq!(b.period(), None);
        assert!(b.flip_times(100.0).is_empty());
        let mut e = [0.0; 3];
        e[axis] = 1.0;
        for t in [-3.0, 0.5, 1e4] {
            assert_eq!(b.omega(t), Vector3::from(w));
            let exact = r0() * rot(e, 1.7 * t);
            assert!((b.rotation(t) - exact).amax() < 1e-12, "{axis} {t}");
        }
    }
    // any axis of the plane of equal moments, and rest
    let b = body([1.0, 2.0, 2.0], [0.0, 0.6, -0.8]);
    assert_eq!(b.motion(), TorqueFreeMotion::Steady);
    let b = body([1.0, 2.0, 3.0], [0.0; 3]);
    assert_eq!((b.omega(2.0), b.rotation(2.0)), (Vector3::zeros(), r0()));
}

#[test]
fn separatrix_crosses_once_and_matches_integration() {
    // J = [3, 4, 6]: L^2 = 2 T J_mid when 6 (6 - 4) w3^2 = 3 (4 - 3) w1^2, w1 = 2 w3
    let b = body([3.0, 4.0, 6.0], [0.2, 1.0, 0.1]);
    assert_eq!(b.motion(), TorqueFreeMotion::Separatrix);
    assert_eq!(b.period(), None);
    let flips = b.flip_times(-100.0);
    assert_eq!(flips.len(), 1, "{flips:?}");
    let tf = flips[0];
    assert!(b.flip_times(100.0).is_empty());
    assert!(b.omega(tf)[1].abs() < 1e-14);
    assert!(b.omega(tf - 1.0)[1] < 0.0 && b.omega(tf + 1.0)[1] > 0.0);
    let times: Vec<f64> = (1..=20).map(|i| i as f64).collect();
    let (mut dw, mut dr) = (0.0f64, 0.0f64);
    for sign in [1.0, -1.0] {
        let times: Vec<f64> = times.iter().map(|t| sign * t).collect();
        for (t, (w, r)) in times.iter().zip(reference(&b, &times)) {
            dw = dw.max(rel(b.omega(*t), w));
            dr = dr.max((b.rotation(*t) - r).amax());
        }
    }
    assert!(dw < 1e-13 && dr < 1e-13, "{dw:e} {dr:e}");
    // towards the intermediate axis both ways, with L fixed
    let lg = b.angular_momentum_global();
    for t in [-1e4, 1e4] {
        let w = b.omega(t);
        assert!(w[0].abs() < 1e-300 && w[2].abs() < 1e-300, "{w:?}");
        let jw = Vector3::new(3.0 * w[0], 4.0 * w[1], 6.0 * w[2]);
        assert!(rel(b.rotation(t) * jw, lg) < 1e-12);
    }
}

#[test]
fn large_and_negative_times_repeat_with_the_period() {
    let mut worst: f64 = 0.0;
    let mut turn: f64 = 0.0;
    for (b, _) in cases() {
        let p = b.period().expect("periodic");
        for t in [0.7, -3.1, 1e4, -1e4] {
            worst = worst.max(rel(b.omega(t + p), b.omega(t)));
        }
        // one period turns the body about L by the same angle at any time
        let q = |t: f64| b.rotation(t + p) * b.rotation(t).transpose();
        turn = turn.max((q(1e4) - q(0.3)).amax());
    }
    assert!(worst < 1e-12, "{worst:e}");
    assert!(turn < 1e-11, "{turn:e}");
}

#[test]
fn intermediate_axis_flips() {
    // spun about the intermediate axis of J = [1, 2, 3] with a small perturbation
    let b = body([1.0, 2.0, 3.0], [1e-3, 1.0, 1e-3]);
    assert_eq!(b.intermediate_axis(), 1);
    let p = b.period().expect("periodic");
    // near the separatrix: K ~ ln(4 / k'), k'^2 = 3 (w3/w2)^2 - (w1/w2)^2 = 2e-6
    let lambda = (1.0f64 / 3.0).sqrt();
    let k_approx = (4.0 / 2e-6f64.sqrt()).ln();
    assert!((p * lambda / 4.0 - k_approx).abs() < 1e-3, "{p}");
    let flips = b.flip_times(4.0 * p);
    assert_eq!(flips.len(), 8, "{flips:?}");
    let mut worst: f64 = 0.0;
    for (i, &t) in flips.iter().enumerate() {
        worst = worst.max(b.omega(t)[1].abs());
        let before = b.omega(t - 0.5)[1];
        let after = b.omega(t + 0.5)[1];
        assert!(before * after < 0.0, "{t}");
        if i > 0 {
            assert!((t - flips[i - 1] - 0.5 * p).abs() < 1e-12 * p);
        }
    }
    assert!(worst < 1e-13, "{worst:e}");
    // the integrated omega_2 changes sign within 1e-9 of each flip time
    let times: Vec<f64> = flips.iter().flat_map(|&t| [t - 1e-9, t + 1e-9]).collect();
    let refs = reference(&b, &times);
    for pair in refs.chunks(2) {
        assert!(pair[0].0[1] * pair[1].0[1] < 0.0);
    }
    // backwards and into negative times
    let back = b.flip_times(-2.0 * p);
    assert_eq!(back.len(), 4);
    assert!(back.windows(2).all(|w| w[0] < w[1]));
    // bounded output for absurd ends
    assert_eq!(b.flip_times(1e300).len(), 1 << 20);
    assert!(b.flip_times(f64::NAN).is_empty());
}

#[test]
fn bad_input_names_the_parameter() {
    let w = Vector3::new(0.1, 1.0, 0.1);
    let name = |r: Result<TorqueFreeBody, ModelError>| match r {
        Err(ModelError::InvalidParameter { parameter, .. }) => parameter,
        other => panic!("{other:?}"),
    };
    assert_eq!(name(TorqueFreeBody::new([0.0, 1.0, 1.0], w, r0())), "J1");
    assert_eq!(
        name(TorqueFreeBody::new([1.0, f64::NAN, 1.0], w, r0())),
        "J2"
    );
    assert_eq!(name(TorqueFreeBody::new([1.0, 1.0, -2.0], w, r0())), "J3");
    assert_eq!(name(TorqueFreeBody::new([1.0, 3.0, 1.5], w, r0())), "J2");
    let bad_w = Vector3::new(0.0, f64::INFINITY, 0.0);
    assert_eq!(
        name(TorqueFreeBody::new([1.0, 2.0, 3.0], bad_w, r0())),
        "omega0"
    );
    let huge = Vector3::new(1e300, 0.0, 0.0);
    assert_eq!(
        name(TorqueFreeBody::new([1e10, 2e10, 3e10], huge, r0())),
        "omega0"
    );
    let skew = r0() * Matrix3::new(1.0, 1e-6, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0);
    assert_eq!(name(TorqueFreeBody::new([1.0, 2.0, 3.0], w, skew)), "R0");
    let reflect = -r0();
    assert_eq!(name(TorqueFreeBody::new([1.0, 2.0, 3.0], w, reflect)), "R0");
    let nan = Matrix3::from_element(f64::NAN);
    assert_eq!(name(TorqueFreeBody::new([1.0, 2.0, 3.0], w, nan)), "R0");
    // the flat plate's equality is allowed
    assert!(TorqueFreeBody::new([1.0, 2.0, 3.0], w, r0()).is_ok());
}

#[test]
fn motion_scales_with_the_moments_and_the_rate() {
    // J -> a J leaves the motion unchanged; w0 -> s w0 gives s w(s t), R(s t)
    let b = body([1.0, 2.0, 3.0], [0.3, -0.5, 1.0]);
    let s = 1e3;
    let c = TorqueFreeBody::new(
        [1e-6, 2e-6, 3e-6],
        Vector3::new(300.0, -500.0, 1000.0),
        r0(),
    )
    .expect("valid");
    assert_eq!(c.motion(), b.motion());
    let (mut dw, mut dr): (f64, f64) = (0.0, 0.0);
    for t in [-2.5, 0.1, 7.0] {
        dw = dw.max(rel(c.omega(t / s), s * b.omega(t)));
        dr = dr.max((c.rotation(t / s) - b.rotation(t)).amax());
    }
    assert!(dw < 1e-14 && dr < 1e-14, "{dw:e} {dr:e}");
    let p = b.period().expect("periodic");
    let q = c.period().expect("periodic");
    assert!((q * s - p).abs() < 1e-14 * p);
}
