//! Every spatial joint: zero at an assembled configuration moved along its freedoms,
//! independent equations (with the internal constraints of both bodies), the motions it frees
//! in the null space of its Jacobian and the ones it locks outside it, and its parameter checks.

use super::*;
use crate::spatial::{internal_constraints, natural_coordinates, Orientation};
use nalgebra::{DMatrix, Rotation3, Unit, Vector3};

fn rot(axis: Vector3<f64>, angle: f64) -> Matrix3<f64> {
    *Rotation3::from_axis_angle(&Unit::new_normalize(axis), angle).matrix()
}

fn quat(q: [f64; 4]) -> Matrix3<f64> {
    Orientation::Quaternion(q).matrix().unwrap()
}

/// A marker frame and point moved: `(F, P) -> (F', P')`.
type Motion = fn(&Matrix3<f64>, Vector3<f64>) -> (Matrix3<f64>, Vector3<f64>);

/// A finite relative motion of `b` (its marker's frame and point after the motion, from the
/// assembled `F`, `P`) and the twists (angular velocity, velocity of the marker point) the
/// joint frees and locks, all in terms of the assembled marker axes `X`, `Y`, `Z` (the
/// columns of `F`).
struct Case {
    kind: SpatialJointKind,
    moved: Motion,
    free: Vec<[usize; 2]>,
    locked: Vec<[usize; 2]>,
}

/// Twist codes: `[0, k]` is a rotation about `b`'s marker axis `k` (0: X, 1: Y, 2: Z, the
/// columns of `f`), `[1, k]` a slide along it, `[2, k]` a rotation about `a`'s marker axis
/// `k` (the columns of `fa`).
fn twist(code: [usize; 2], f: &Matrix3<f64>, fa: &Matrix3<f64>) -> (Vector3<f64>, Vector3<f64>) {
    match code[0] {
        0 => (f.column(code[1]).into_owned(), Vector3::zeros()),
        1 => (Vector3::zeros(), f.column(code[1]).into_owned()),
        _ => (fa.column(code[1]).into_owned(), Vector3::zeros()),
    }
}

fn cases() -> Vec<Case> {
    let all_rot = vec![[0, 0], [0, 1], [0, 2]];
    let all_slide = vec![[1, 0], [1, 1], [1, 2]];
    vec![
        Case {
            kind: SpatialJointKind::Spherical,
            moved: |f, p| (rot(Vector3::new(0.3, -1.0, 0.5), 0.9) * f, p),
            free: all_rot.clone(),
            locked: all_slide.clone(),
        },
        Case {
            kind: SpatialJointKind::Revolute,
            moved: |f, p| (rot(f.column(2).into_owned(), 0.8) * f, p),
            free: vec![[0, 2]],
            locked: vec![[0, 0], [0, 1], [1, 0], [1, 1], [1, 2]],
        },
        Case {
            kind: SpatialJointKind::Universal,
            moved: |f, p| {
                (
                    rot(f.column(0).into_owned(), 0.6) * f * rot(Vector3::y(), -0.4),
                    p,
                )
            },
            free: vec![[2, 0], [0, 1]],
            locked: vec![[0, 2], [1, 0], [1, 1], [1, 2]],
        },
        Case {
            kind: SpatialJointKind::Cylindrical,
            moved: |f, p| {
                (
                    rot(f.column(2).into_owned(), -1.1) * f,
                    p + 0.7 * f.column(2),
                )
            },
            free: vec![[0, 2], [1, 2]],
            locked: vec![[0, 0], [0, 1], [1, 0], [1, 1]],
        },
        Case {
            kind: SpatialJointKind::Prismatic,
            moved: |f, p| (*f, p - 0.4 * f.column(2)),
            free: vec![[1, 2]],
            locked: vec![[0, 0], [0, 1], [0, 2], [1, 0], [1, 1]],
        },
        Case {
            kind: SpatialJointKind::Planar,
            moved: |f, p| {
                (
                    rot(f.column(2).into_owned(), 2.0) * f,
                    p + 0.3 * f.column(0) - 0.8 * f.column(1),
                )
            },
            free: vec![[0, 2], [1, 0], [1, 1]],
            locked: vec![[0, 0], [0, 1], [1, 2]],
        },
        Case {
            kind: SpatialJointKind::Weld,
            moved: |f, p| (*f, p),
            free: vec![],
            locked: [all_rot.clone(), all_slide.clone()].concat(),
        },
        Case {
            kind: SpatialJointKind::Distance { length: 0.9 },
            moved: |f, p| {
                let u = Vector3::new(0.2, -0.5, 0.4).normalize();
                (rot(Vector3::new(1.0, 1.0, 0.0), 0.7) * f, p + 0.9 * u)
            },
            free: all_rot,
            locked: vec![],
        },
    ]
}

/// The 12 + 12 coordinates of bodies `a` and `b` with `b` placed so that its marker sits at the
/// global frame `f` and point `p`.
fn place(
    joint: &SpatialJoint,
    xa: Vector3<f64>,
    ra: &Matrix3<f64>,
    f: &Matrix3<f64>,
    p: Vector3<f64>,
) -> [f64; 24] {
    let (_, mb) = joint.markers();
    let rb = f * mb.axes.transpose();
    let xb = p - rb * Vector3::from(mb.point);
    let mut q = [0.0; 24];
    q[..12].copy_from_slice(&natural_coordinates(xa, ra));
    q[12..].copy_from_slice(&natural_coordinates(xb, &rb));
    q
}

fn eval(joint: &SpatialJoint, q: &[f64; 24]) -> Vec<f64> {
    let qa: [f64; 12] = std::array::from_fn(|k| q[k]);
    let qb: [f64; 12] = std::array::from_fn(|k| q[12 + k]);
    let mut out = [0.0; 6];
    joint.eval(&SpatialFrame::new(&qa), &SpatialFrame::new(&qb), &mut out);
    out[..joint.n_equations()].to_vec()
}

/// Rows: the internal constraints of `a` and `b`, then the joint; central differences (exact
/// for these quadratics up to round-off).
fn jacobian(joint: &SpatialJoint, q: &[f64; 24]) -> DMatrix<f64> {
    let f = |q: &[f64; 24]| -> Vec<f64> {
        let qa: [f64; 12] = std::array::from_fn(|k| q[k]);
        let qb: [f64; 12] = std::array::from_fn(|k| q[12 + k]);
        [
            internal_constraints(&qa).to_vec(),
            internal_constraints(&qb).to_vec(),
            eval(joint, q),
        ]
        .concat()
    };
    let rows = 12 + joint.n_equations();
    let mut j = DMatrix::zeros(rows, 24);
    let h = 1e-3;
    for c in 0..24 {
        let (mut qp, mut qm) = (*q, *q);
        qp[c] += h;
        qm[c] -= h;
        let (fp, fm) = (f(&qp), f(&qm));
        for r in 0..rows {
            j[(r, c)] = (fp[r] - fm[r]) / (2.0 * h);
        }
    }
    j
}

#[test]
fn every_joint_holds_along_its_freedoms_and_locks_the_rest() {
    let xa = Vector3::new(0.4, -0.2, 1.1);
    let ra = quat([0.9, 0.2, -0.3, 0.25]);
    let ma = Marker::with_axes([0.1, 0.3, -0.2], quat([0.5, -0.5, 0.3, 0.6]));
    let mb = Marker::with_axes([-0.25, 0.05, 0.4], quat([0.2, 0.7, 0.1, -0.4]));
    for case in cases() {
        let joint = SpatialJoint::new(case.kind, ma, mb).unwrap();
        let n = joint.n_equations();
        // the assembled marker frame and point, then the finite motion along the freedoms
        let f0 = ra * ma.axes;
        let p0 = xa + ra * Vector3::from(ma.point);
        let (f, p) = (case.moved)(&f0, p0);
        let q = place(&joint, xa, &ra, &f, p);
        let phi = eval(&joint, &q);
        assert!(
            phi.iter().all(|e| e.abs() < 1e-14),
            "{:?}: {phi:?}",
            case.kind
        );
        // independent equations: rank 12 + n with the internal constraints
        let j = jacobian(&joint, &q);
        let sv = j.singular_values();
        let smallest = sv.iter().fold(f64::INFINITY, |m, &s| m.min(s));
        assert!(
            smallest > 1e-3 * sv.max(),
            "{:?}: singular values {sv:?}",
            case.kind
        );
        // the distance joint's two slides across the rod are checked below
        let across = usize::from(matches!(case.kind, SpatialJointKind::Distance { .. }));
        assert_eq!(case.free.len() + 2 * across, 6 - n, "{:?}", case.kind);
        // twists of b about its marker point: d_i' = w x d_i, x_b' = v + w x (x_b - P)
        let velocity = |w: Vector3<f64>, v: Vector3<f64>| -> DMatrix<f64> {
            let rb: Matrix3<f64> = Matrix3::from_fn(|r, c| q[15 + 3 * c + r]);
            let xb = Vector3::new(q[12], q[13], q[14]);
            let mut qd = DMatrix::zeros(24, 1);
            let vx = v + w.cross(&(xb - p));
            for k in 0..3 {
                qd[12 + k] = vx[k];
            }
            for i in 0..3 {
                let di = w.cross(&rb.column(i).into_owned());
                for k in 0..3 {
                    qd[15 + 3 * i + k] = di[k];
                }
            }
            qd
        };
        let joint_rows = |qd: &DMatrix<f64>| (j.rows(12, n) * qd).amax();
        for code in &case.free {
            let (w, v) = twist(*code, &f, &f0);
            let r = joint_rows(&velocity(w, v));
            assert!(
                r < 1e-12,
                "{:?} frees {code:?}: Phi_q qd = {r:e}",
                case.kind
            );
        }
        for code in &case.locked {
            let (w, v) = twist(*code, &f, &f0);
            let r = joint_rows(&velocity(w, v));
            assert!(r > 1e-2, "{:?} locks {code:?}: Phi_q qd = {r:e}", case.kind);
        }
        if across == 1 {
            let rod = (p - p0).normalize();
            let side = rod.cross(&Vector3::new(0.3, 0.1, 0.9)).normalize();
            for (v, free) in [(rod, false), (side, true), (rod.cross(&side), true)] {
                let r = joint_rows(&velocity(Vector3::zeros(), v));
                assert_eq!(r < 1e-12, free, "distance, slide {v:?}: {r:e}");
            }
        }
        // a twist of both bodies together (a rigid motion of the pair) leaves every joint alone
        let w = Vector3::new(0.3, 0.8, -0.5);
        let mut qd = velocity(w, Vector3::new(0.1, 0.2, 0.3));
        for k in 0..3 {
            qd[k] = 0.1 * [1.0, 2.0, 3.0][k] + w.cross(&(xa - p))[k];
        }
        for i in 0..3 {
            let di = w.cross(&ra.column(i).into_owned());
            for k in 0..3 {
                qd[3 + 3 * i + k] = di[k];
            }
        }
        let r = joint_rows(&qd);
        assert!(
            r < 1e-12,
            "{:?}: rigid motion of the pair gives {r:e}",
            case.kind
        );
    }
}

#[test]
fn ground_is_the_global_frame() {
    let g = SpatialFrame::<f64>::ground();
    assert_eq!(g.point([1.0, 2.0, 3.0]), [1.0, 2.0, 3.0]);
    assert_eq!(g.direction([0.0, 0.0, 1.0]), [0.0, 0.0, 1.0]);
}

#[test]
fn bad_parameters_name_the_field() {
    let ok = Marker::at([0.0; 3]);
    let e = SpatialJoint::new(
        SpatialJointKind::Spherical,
        Marker::at([f64::NAN, 0.0, 0.0]),
        ok,
    )
    .unwrap_err();
    assert_eq!(e.field, "marker_a.point");
    let skew = Marker::with_axes(
        [0.0; 3],
        Matrix3::new(1.0, 0.1, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0, 1.0),
    );
    let e = SpatialJoint::new(SpatialJointKind::Revolute, ok, skew).unwrap_err();
    assert_eq!(e.field, "marker_b.axes");
    assert!(e.to_string().contains("rotation"), "{e}");
    let mirror = Marker::with_axes(
        [0.0; 3],
        Matrix3::from_diagonal(&Vector3::new(1.0, 1.0, -1.0)),
    );
    assert_eq!(
        SpatialJoint::new(SpatialJointKind::Weld, mirror, ok)
            .unwrap_err()
            .field,
        "marker_a.axes"
    );
    for length in [0.0, -1.0, f64::INFINITY] {
        let e = SpatialJoint::new(SpatialJointKind::Distance { length }, ok, ok).unwrap_err();
        assert_eq!(e.field, "length");
    }
}

/// The jets of `mbd-jet` over the 24 coordinates of a joint's two bodies differentiate every
/// spatial joint: gradients equal central differences (exact for quadratics up to round-off),
/// `DirJet`'s second directional derivative equals `v^T H v` of the `HessJet`, and the
/// Hessian is the same at two configurations (the equations are quadratic).
#[test]
fn jets_differentiate_every_joint() {
    use mbd_jet::{DirJetN, HessJetN};
    let xa = Vector3::new(0.4, -0.2, 1.1);
    let ra = quat([0.9, 0.2, -0.3, 0.25]);
    let ma = Marker::with_axes([0.1, 0.3, -0.2], quat([0.5, -0.5, 0.3, 0.6]));
    let mb = Marker::with_axes([-0.25, 0.05, 0.4], quat([0.2, 0.7, 0.1, -0.4]));
    let dir: [f64; 24] = std::array::from_fn(|k| ((k as f64) * 0.37 + 0.2).sin());
    for case in cases() {
        let joint = SpatialJoint::new(case.kind, ma, mb).unwrap();
        let n = joint.n_equations();
        let (f, p) = (case.moved)(&(ra * ma.axes), xa + ra * Vector3::from(ma.point));
        let mut q = place(&joint, xa, &ra, &f, p);
        // off the constraints, so the values are not all zero
        q[20] += 0.05;
        let dj: [DirJetN<24>; 24] = std::array::from_fn(|k| DirJetN::var(k, q[k], dir[k]));
        let hj: [HessJetN<24>; 24] = std::array::from_fn(|k| HessJetN::var(k, q[k]));
        let (mut od, mut oh) = ([DirJetN::<24>::cst(0.0); 6], [HessJetN::<24>::cst(0.0); 6]);
        let (fa, fb) = split(&dj);
        joint.eval(&fa, &fb, &mut od);
        let (fa, fb) = split(&hj);
        joint.eval(&fa, &fb, &mut oh);
        let fd = jacobian(&joint, &q);
        let value = eval(&joint, &q);
        // a second configuration for the Hessian's constancy
        let q2: [f64; 24] = std::array::from_fn(|k| q[k] + 0.1 * ((k as f64) * 1.3).cos());
        let hj2: [HessJetN<24>; 24] = std::array::from_fn(|k| HessJetN::var(k, q2[k]));
        let mut oh2 = [HessJetN::<24>::cst(0.0); 6];
        let (fa, fb) = split(&hj2);
        joint.eval(&fa, &fb, &mut oh2);
        for r in 0..n {
            assert_eq!(od[r].v, value[r], "{:?} row {r}", case.kind);
            for c in 0..24 {
                let e = (od[r].g[c] - fd[(12 + r, c)]).abs();
                assert!(e < 1e-12, "{:?} row {r} col {c}: {e:e}", case.kind);
                assert_eq!(oh[r].g[c], od[r].g[c]);
            }
            let vhv: f64 = (0..24)
                .map(|i| {
                    (0..24)
                        .map(|j| dir[i] * oh[r].h[i][j] * dir[j])
                        .sum::<f64>()
                })
                .sum();
            assert!((od[r].d2 - vhv).abs() < 1e-13, "{:?} row {r}", case.kind);
            for i in 0..24 {
                for j in 0..24 {
                    assert!(
                        (oh[r].h[i][j] - oh2[r].h[i][j]).abs() < 1e-15,
                        "{:?} row {r}: H not constant",
                        case.kind
                    );
                }
            }
        }
    }
}

/// The frames of a joint's two bodies from the 24 local variables.
fn split<T: mbd_jet::Scalar>(v: &[T; 24]) -> (SpatialFrame<T>, SpatialFrame<T>) {
    (
        SpatialFrame::new(&std::array::from_fn(|k| v[k])),
        SpatialFrame::new(&std::array::from_fn(|k| v[12 + k])),
    )
}
