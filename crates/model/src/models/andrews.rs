//! Andrews' squeezer mechanism (the seven-body closed-loop benchmark).

use crate::body::{Body, BodyRef};
use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::joints::Joint;
use crate::system::System;
use crate::timefn::TimeFunction;

/// Andrews' squeezer mechanism: the seven-body closed-loop benchmark of Schiehlen (1990), Hairer
/// & Wanner (*Solving ODEs II*, section VII.7) and the IVP test set of Mazzia et al. (`andrews`),
/// written in absolute coordinates.
///
/// The benchmark describes the mechanism by seven relative angles
/// `(beta, Theta, gamma, Phi, delta, Omega, epsilon)`; here each body carries its own absolute
/// `(x, y, theta)` of its centre of mass, with
///
/// | body | absolute angle | pivot / points (local, relative to the centre of mass) |
/// |---|---|---|
/// | `K1` crank | `beta` | `O = (-ra, 0)` on ground `(0, 0)`, `P = (rr - ra, 0)` |
/// | `K2` rod | `beta + Theta` | `P = (da, 0)`, `E = (da - d, 0)` |
/// | `K3` triangle | `gamma` | `B = (-sb, sa)`, `E = (-sb, sa - ss)`, spring point `D = (sd - sb, sa - sc)` |
/// | `K4` rod | `Phi + delta` | `F = (0, e - ea)`, `E = (0, -ea)` |
/// | `K5` triangle | `delta` | `A = (-ta, -tb)`, `F = (zt - ta, -tb)` |
/// | `K6` rod | `Omega + epsilon` | `G = (fa - zf, 0)`, `E = (fa, 0)` |
/// | `K7` triangle | `epsilon` | `A = (ub, ua)`, `G = (ub, ua - u)` |
///
/// so the relative angles are `beta = theta1`, `Theta = theta2 - theta1`, `gamma = theta3`,
/// `Phi = theta4 - theta5`, `delta = theta5`, `Omega = theta6 - theta7`, `epsilon = theta7`.
/// These local points reproduce the benchmark's kinematics exactly: its constraints `g1..g6`
/// say that the end `E` of `K2` is the point `E` of `K3`, `K4` and `K6`, and its mass matrix
/// puts the centres of mass of `K1` at `ra` from `O`, `K2` at `da` from `P`, `K4` at `ea` from
/// `E`, `K6` at `fa` from `E`, and those of `K3`, `K5`, `K7` at `B + R(gamma) (sb, -sa)`,
/// `A + R(delta) (ta, tb)` and `A + R(epsilon) (-ub, -ua)` (Schiehlen's figure; with gravity
/// off only their distances from the pivots enter the dynamics).
///
/// Joints (ten revolutes, 20 equations, 21 coordinates, one degree of freedom): `O` (ground–K1),
/// `P` (K1–K2), `E3` (K2–K3), `B` (ground–K3), `E4` (K2–K4), `F` (K4–K5), `A5` (ground–K5),
/// `E6` (K2–K6), `G` (K6–K7), `A7` (ground–K7).
///
/// Forces: the spring `spring` from `C = (xc, yc)` on ground to `D` on `K3`, `c0 = 4530` N/m,
/// rest length `l0 = 0.07785` m, no damping; the constant drive torque `mom = 0.033` N m on
/// `K1` (`drive`). Gravity is off, as in the benchmark.
///
/// Data (SI units), from the benchmark's table:
///
/// * masses `m1..m7 = 0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498` kg;
/// * inertias `I1..I7 = 2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7,
///   1.912e-5` kg m^2;
/// * fixed points `A = (xa, ya) = (-0.06934, -0.00227)`, `B = (xb, yb) = (-0.03635, 0.03273)`,
///   `C = (xc, yc) = (0.014, 0.072)`, `O = (0, 0)`;
/// * lengths `d = 0.028`, `da = 0.0115`, `e = 0.02`, `ea = 0.01421`, `rr = 0.007`,
///   `ra = 0.00092`, `ss = 0.035`, `sa = 0.01874`, `sb = 0.01043`, `sc = 0.018`, `sd = 0.02`,
///   `ta = 0.02308`, `tb = 0.00916`, `u = 0.04`, `ua = 0.01228`, `ub = 0.00449`, `zf = 0.02`,
///   `zt = 0.04`, `fa = 0.01421` m.
///
/// Initial state: the benchmark's consistent configuration, at rest:
/// `beta = -0.0617138900142764496358948458001`, `Theta = 0`,
/// `gamma = 0.455279819163070380255912382449`, `Phi = 0.222668390165885884674473185609`,
/// `delta = 0.487364979543842550225598953530`, `Omega = -Phi`,
/// `epsilon = 1.23054744454982119249735015568` rad; the absolute coordinates are computed from
/// them with the local points above (they satisfy `Phi = 0` to rounding).
pub fn andrews_squeezer() -> Result<System, ModelError> {
    use crate::forces::Force;
    // masses and centroidal inertias
    let m = [
        0.04325, 0.00365, 0.02373, 0.00706, 0.07050, 0.00706, 0.05498,
    ];
    let inertia = [
        2.194e-6, 4.410e-7, 5.255e-6, 5.667e-7, 1.169e-5, 5.667e-7, 1.912e-5,
    ];
    // fixed points
    let (xa, ya) = (-0.06934, -0.00227);
    let (xb, yb) = (-0.03635, 0.03273);
    let (xc, yc) = (0.014, 0.072);
    // geometry
    let (d, da, e, ea) = (0.028, 0.0115, 0.02, 0.01421);
    let (rr, ra) = (0.007, 0.00092);
    let (ss, sa, sb, sc, sd) = (0.035, 0.01874, 0.01043, 0.018, 0.02);
    let (ta, tb) = (0.02308, 0.00916);
    let (u, ua, ub) = (0.04, 0.01228, 0.00449);
    let (zf, zt, fa) = (0.02, 0.04, 0.01421);
    // spring and drive
    let (c0, l0, mom) = (4530.0, 0.07785, 0.033);
    // the benchmark's consistent initial relative angles
    let beta = -0.061_713_890_014_276_45_f64;
    let theta = 0.0_f64;
    let gamma = 0.455_279_819_163_070_4_f64;
    let phi = 0.222_668_390_165_885_9_f64;
    let delta = 0.487_364_979_543_842_55_f64;
    let omega = -0.222_668_390_165_885_9_f64;
    let epsilon = 1.230_547_444_549_821_2_f64;

    // absolute angles
    let th = [
        beta,
        beta + theta,
        gamma,
        phi + delta,
        delta,
        omega + epsilon,
        epsilon,
    ];
    // global position of the centre of mass given a pivot `p` (global) and the pivot's local
    // point `lp` on a body at angle `a`: c = p - R(a) lp
    let com = |p: [f64; 2], lp: [f64; 2], a: f64| {
        let (s, c) = a.sin_cos();
        [
            p[0] - (c * lp[0] - s * lp[1]),
            p[1] - (s * lp[0] + c * lp[1]),
        ]
    };
    let glob = |c: [f64; 2], lp: [f64; 2], a: f64| {
        let (s, co) = a.sin_cos();
        [c[0] + co * lp[0] - s * lp[1], c[1] + s * lp[0] + co * lp[1]]
    };
    // local points
    let k1_o = [-ra, 0.0];
    let k1_p = [rr - ra, 0.0];
    let k2_p = [da, 0.0];
    let k2_e = [da - d, 0.0];
    let k3_b = [-sb, sa];
    let k3_e = [-sb, sa - ss];
    let k3_d = [sd - sb, sa - sc];
    let k4_f = [0.0, e - ea];
    let k4_e = [0.0, -ea];
    let k5_a = [-ta, -tb];
    let k5_f = [zt - ta, -tb];
    let k6_g = [fa - zf, 0.0];
    let k6_e = [fa, 0.0];
    let k7_a = [ub, ua];
    let k7_g = [ub, ua - u];
    // centres of mass, walking the loops from the ground pivots O, B and A
    let c1 = com([0.0, 0.0], k1_o, th[0]);
    let pp = glob(c1, k1_p, th[0]);
    let c2 = com(pp, k2_p, th[1]);
    let c3 = com([xb, yb], k3_b, th[2]);
    let c5 = com([xa, ya], k5_a, th[4]);
    let pf = glob(c5, k5_f, th[4]);
    let c4 = com(pf, k4_f, th[3]);
    let c7 = com([xa, ya], k7_a, th[6]);
    let pg = glob(c7, k7_g, th[6]);
    let c6 = com(pg, k6_g, th[5]);
    let cs = [c1, c2, c3, c4, c5, c6, c7];

    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, 0.0]);
    let k: Vec<_> = (0..7)
        .map(|i| {
            b.add_body(
                Body::new(format!("K{}", i + 1))
                    .mass(m[i])
                    .inertia(inertia[i])
                    .position(cs[i][0], cs[i][1], th[i]),
            )
        })
        .collect();
    let g = BodyRef::Ground;
    b.add_joint(Joint::revolute("O", g, [0.0, 0.0], k[0], k1_o));
    b.add_joint(Joint::revolute("P", k[0], k1_p, k[1], k2_p));
    b.add_joint(Joint::revolute("E3", k[1], k2_e, k[2], k3_e));
    b.add_joint(Joint::revolute("B", g, [xb, yb], k[2], k3_b));
    b.add_joint(Joint::revolute("E4", k[1], k2_e, k[3], k4_e));
    b.add_joint(Joint::revolute("F", k[3], k4_f, k[4], k5_f));
    b.add_joint(Joint::revolute("A5", g, [xa, ya], k[4], k5_a));
    b.add_joint(Joint::revolute("E6", k[1], k2_e, k[5], k6_e));
    b.add_joint(Joint::revolute("G", k[5], k6_g, k[6], k7_g));
    b.add_joint(Joint::revolute("A7", g, [xa, ya], k[6], k7_a));
    b.add_force(Force::spring_damper(
        "spring",
        g,
        [xc, yc],
        k[2],
        k3_d,
        c0,
        0.0,
        l0,
    ));
    b.add_force(Force::torque("drive", k[0], TimeFunction::constant(mom)));
    b.build()
}
