//! Ready-made models used by the papers, the examples and the tests.
//!
//! Conventions: links are uniform rods along their body x-axis, centre of mass at mid-length,
//! angles measured from the global x-axis (so "hanging straight down" is `-pi/2`), gravity along
//! `-y`.

use crate::body::{Body, BodyRef};
use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::joints::Joint;
use crate::system::System;
use crate::timefn::TimeFunction;
use std::f64::consts::FRAC_PI_2;

/// Parameters of an open chain of uniform rods pinned end to end, the first pinned to ground at
/// the origin.
#[derive(Clone, Debug, PartialEq)]
pub struct ChainParams {
    /// Mass of each link.
    pub masses: Vec<f64>,
    /// Length of each link.
    pub lengths: Vec<f64>,
    /// Initial absolute angle of each link (from the x-axis).
    pub angles: Vec<f64>,
    /// Gravity (m/s^2) along -y.
    pub g: f64,
}

/// An open chain of rods (`links` = 1: single pendulum; 2: double pendulum / manipulator).
pub fn chain(p: &ChainParams) -> Result<System, ModelError> {
    let k = p.masses.len();
    if p.lengths.len() != k || p.angles.len() != k {
        return Err(ModelError::Dimension {
            what: "chain lengths/angles (must match masses)",
            expected: k,
            got: p.lengths.len().min(p.angles.len()),
        });
    }
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -p.g]);
    let mut prev = BodyRef::Ground;
    let mut prev_end = [0.0, 0.0];
    let mut tip = [0.0, 0.0];
    for i in 0..k {
        let (l, th) = (p.lengths[i], p.angles[i]);
        let (s, c) = th.sin_cos();
        let cx = tip[0] + 0.5 * l * c;
        let cy = tip[1] + 0.5 * l * s;
        let h = b.add_body(
            Body::new(format!("link{}", i + 1))
                .rod(p.masses[i], l)
                .position(cx, cy, th),
        );
        b.add_joint(Joint::revolute(
            format!("pin{}", i + 1),
            prev,
            prev_end,
            h,
            [-0.5 * l, 0.0],
        ));
        prev = h.into();
        prev_end = [0.5 * l, 0.0];
        tip = [tip[0] + l * c, tip[1] + l * s];
    }
    b.build()
}

/// Single uniform rod pendulum: mass `m`, length `l`, released at rest `angle0` from the downward
/// vertical. Small-amplitude angular frequency `omega^2 = 3 g / (2 l)`.
pub fn pendulum(m: f64, l: f64, angle0: f64, g: f64) -> Result<System, ModelError> {
    chain(&ChainParams {
        masses: vec![m],
        lengths: vec![l],
        angles: vec![-FRAC_PI_2 + angle0],
        g,
    })
}

/// A uniform rod (1 kg, 1 m, g = 9.81) pinned at one end to the origin, released at rest 45
/// degrees from the downward vertical, with a spring (30 N/m, rest length 0.5 m, no damping)
/// from its tip to the ground point `(0.6, -1.6)`: a conservative model with a constraint and a
/// non-linear potential (`Hess V != 0`, which gravity alone does not give).
pub fn rod_with_spring() -> Result<System, ModelError> {
    let th = std::f64::consts::FRAC_PI_4;
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let rod = b.add_body(Body::new("rod").rod(1.0, 1.0).position(
        0.5 * th.sin(),
        -0.5 * th.cos(),
        th - FRAC_PI_2,
    ));
    b.add_joint(Joint::revolute(
        "pin",
        BodyRef::Ground,
        [0.0, 0.0],
        rod,
        [-0.5, 0.0],
    ));
    b.add_force(crate::forces::Force::spring_damper(
        "spring",
        rod,
        [0.5, 0.0],
        BodyRef::Ground,
        [0.6, -1.6],
        30.0,
        0.0,
        0.5,
    ));
    b.build()
}

/// An elastic pendulum without constraints: one uniform rod (1 kg, 1 m, g = 9.81) hanging from
/// the ground origin by a spring (50 N/m, rest length 1 m, no damping) attached at its end, at
/// rest at `(0.9, -1.0)` with angle `-0.8` rad. A conservative model with `m = 0`.
pub fn elastic_pendulum() -> Result<System, ModelError> {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let r = b.add_body(Body::new("rod").rod(1.0, 1.0).position(0.9, -1.0, -0.8));
    b.add_force(crate::forces::Force::spring_damper(
        "spring",
        BodyRef::Ground,
        [0.0, 0.0],
        r,
        [-0.5, 0.0],
        50.0,
        0.0,
        1.0,
    ));
    b.build()
}

/// Paper A's two-body pendulum (project choice): two uniform rods, 1 kg, 1 m, g = 9.81, both
/// released at rest 30 degrees from the downward vertical.
pub fn paper_a_double_pendulum() -> Result<System, ModelError> {
    let a = -FRAC_PI_2 + 30f64.to_radians();
    chain(&ChainParams {
        masses: vec![1.0, 1.0],
        lengths: vec![1.0, 1.0],
        angles: vec![a, a],
        g: 9.81,
    })
}

/// Paper C's two-link manipulator (project choice): m1 = m2 = 1 kg, L1 = L2 = 1 m, g = 9.81,
/// theta1(0) = pi/3, theta2(0) = 0, at rest. H0 = 12.7436 J.
pub fn manipulator() -> Result<System, ModelError> {
    chain(&ChainParams {
        masses: vec![1.0, 1.0],
        lengths: vec![1.0, 1.0],
        angles: vec![std::f64::consts::FRAC_PI_3, 0.0],
        g: 9.81,
    })
}

/// An `n`-link pendulum chain of 1 kg, 1 m rods, released at rest at 30 degrees from the
/// downward vertical (used for scaling studies).
pub fn n_link_chain(n: usize) -> Result<System, ModelError> {
    let a = -FRAC_PI_2 + 30f64.to_radians();
    chain(&ChainParams {
        masses: vec![1.0; n],
        lengths: vec![1.0; n],
        angles: vec![a; n],
        g: 9.81,
    })
}

/// Geometry and initial motion of a slider-crank ([`slider_crank_with`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SliderCrankParams {
    /// Crank length `r` (m; a 1 kg rod pinned to ground at the origin).
    pub crank: f64,
    /// Connecting-rod length `l` (m; a 1 kg rod). `r <= l` keeps every crank angle reachable;
    /// `r = l` has singular configurations.
    pub rod: f64,
    /// Initial crank angle (rad).
    pub angle: f64,
    /// Initial crank speed (rad/s): the velocity guess, or the driver's speed if `driven`.
    pub speed: f64,
    /// Drive the crank at constant `speed` (an angle driver from `angle`: rheonomic, zero
    /// degrees of freedom).
    pub driven: bool,
}

impl Default for SliderCrankParams {
    /// The project's slider-crank: crank 0.15 m, rod 0.5 m, 45 degrees, 6 rad/s, free.
    fn default() -> Self {
        SliderCrankParams {
            crank: 0.15,
            rod: 0.5,
            angle: 45f64.to_radians(),
            speed: 6.0,
            driven: false,
        }
    }
}

/// A slider-crank (closed loop): crank 0.15 m (1 kg) pinned to ground at the origin, connecting
/// rod 0.5 m (1 kg), slider block 0.5 kg on a horizontal prismatic joint through the origin,
/// gravity -y. Initial crank angle 45 degrees, crank spinning at 6 rad/s (a guess: use
/// `mbd_solve::consistent_state`).
pub fn slider_crank() -> Result<System, ModelError> {
    slider_crank_with(&SliderCrankParams::default())
}

/// A slider-crank of the given geometry (see [`slider_crank`] for the layout); an error names
/// the parameter if a length is not positive and finite, the angle or speed is not finite, or
/// the rod cannot reach the slider's line at the initial angle (`|r sin(angle)| > l`).
pub fn slider_crank_with(p: &SliderCrankParams) -> Result<System, ModelError> {
    let bad = |parameter: &'static str, value: f64, reason: &'static str| {
        Err(ModelError::InvalidParameter {
            element: "slider-crank".into(),
            parameter,
            value,
            reason,
        })
    };
    let (r, l, th, w) = (p.crank, p.rod, p.angle, p.speed);
    for (name, v) in [("crank", r), ("rod", l)] {
        if !(v.is_finite() && v > 0.0) {
            return bad(name, v, "must be positive and finite");
        }
    }
    for (name, v) in [("angle", th), ("speed", w)] {
        if !v.is_finite() {
            return bad(name, v, "must be finite");
        }
    }
    let a = [r * th.cos(), r * th.sin()];
    if a[1].abs() > l {
        return bad(
            "rod",
            l,
            "shorter than the crank pin's height at the initial angle",
        );
    }
    // slider x from the rod length: (xs - ax)^2 + ay^2 = l^2
    let xs = a[0] + (l * l - a[1] * a[1]).sqrt();
    let phi = (-a[1]).atan2(xs - a[0]);
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let crank = b.add_body(
        Body::new("crank")
            .rod(1.0, r)
            .position(0.5 * a[0], 0.5 * a[1], th)
            .velocity(-0.5 * r * th.sin() * w, 0.5 * r * th.cos() * w, w),
    );
    let rod = b.add_body(
        Body::new("rod")
            .rod(1.0, l)
            .position(0.5 * (a[0] + xs), 0.5 * a[1], phi),
    );
    let slider = b.add_body(
        Body::new("slider")
            .mass(0.5)
            .inertia(0.01)
            .position(xs, 0.0, 0.0),
    );
    b.add_joint(Joint::revolute(
        "crank_pin",
        BodyRef::Ground,
        [0.0, 0.0],
        crank,
        [-0.5 * r, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "crank_rod",
        crank,
        [0.5 * r, 0.0],
        rod,
        [-0.5 * l, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "rod_slider",
        rod,
        [0.5 * l, 0.0],
        slider,
        [0.0, 0.0],
    ));
    b.add_joint(Joint::prismatic(
        "slide",
        BodyRef::Ground,
        [0.0, 0.0],
        slider,
        [0.0, 0.0],
        [1.0, 0.0],
        0.0,
    ));
    if p.driven {
        b.add_joint(Joint::angle_driver(
            "crank_drive",
            BodyRef::Ground,
            crank,
            TimeFunction::linear(th, w),
        ));
    }
    b.build()
}

/// A crank-rocker four-bar linkage (closed loop): ground pivots at (0,0) and (1,0), crank 0.4 m,
/// coupler 1.2 m, rocker 0.8 m (1 kg uniform rods), gravity -y, crank at 60 degrees spinning at
/// 4 rad/s (a guess: use `mbd_solve::consistent_state`).
pub fn four_bar() -> Result<System, ModelError> {
    let (lc, lk, lr) = (0.4, 1.2, 0.8);
    let d = [1.0, 0.0];
    let th = 60f64.to_radians();
    let a = [lc * th.cos(), lc * th.sin()];
    // B: intersection of circle(A, lk) and circle(D, lr), upper branch
    let dx = [d[0] - a[0], d[1] - a[1]];
    let dist = (dx[0] * dx[0] + dx[1] * dx[1]).sqrt();
    let along = (lk * lk - lr * lr + dist * dist) / (2.0 * dist);
    let h = (lk * lk - along * along).max(0.0).sqrt();
    let e = [dx[0] / dist, dx[1] / dist];
    let bpt = [
        a[0] + along * e[0] - h * e[1],
        a[1] + along * e[1] + h * e[0],
    ];
    let phi = (bpt[1] - a[1]).atan2(bpt[0] - a[0]);
    let psi = (bpt[1] - d[1]).atan2(bpt[0] - d[0]);
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let w = 4.0;
    let crank = b.add_body(
        Body::new("crank")
            .rod(1.0, lc)
            .position(0.5 * a[0], 0.5 * a[1], th)
            .velocity(-0.5 * lc * th.sin() * w, 0.5 * lc * th.cos() * w, w),
    );
    let coupler = b.add_body(Body::new("coupler").rod(1.0, lk).position(
        0.5 * (a[0] + bpt[0]),
        0.5 * (a[1] + bpt[1]),
        phi,
    ));
    let rocker = b.add_body(Body::new("rocker").rod(1.0, lr).position(
        0.5 * (d[0] + bpt[0]),
        0.5 * (d[1] + bpt[1]),
        psi,
    ));
    b.add_joint(Joint::revolute(
        "A0",
        BodyRef::Ground,
        [0.0, 0.0],
        crank,
        [-0.5 * lc, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "A",
        crank,
        [0.5 * lc, 0.0],
        coupler,
        [-0.5 * lk, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "B",
        coupler,
        [0.5 * lk, 0.0],
        rocker,
        [0.5 * lr, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "B0",
        BodyRef::Ground,
        d,
        rocker,
        [-0.5 * lr, 0.0],
    ));
    b.build()
}

/// A parallelogram four-bar (closed loop): ground pivots `A0 = (0, 0)` and `B0 = (ground, 0)`,
/// crank and rocker of length `crank`, coupler of length `ground` (1 kg uniform rods), gravity
/// -y, on the parallelogram branch (rocker parallel to the crank, coupler horizontal).
///
/// * `crank` — crank and rocker length (m), positive and finite;
/// * `ground` — ground link and coupler length (m), positive and finite;
/// * `angle` — initial crank angle (rad), finite and not a flat configuration
///   (`|sin(angle)| >= 1e-6`);
/// * `speed` — initial crank speed (rad/s), finite; the state is consistent as built;
/// * `driven` — drive the crank at constant `speed` (an angle driver `crank_drive` from
///   `angle`: rheonomic, no degree of freedom left).
///
/// Joints `A0` (ground-crank), `A` (crank-coupler), `B` (coupler-rocker) and `B0`
/// (rocker-ground); the rocker's body x-axis points from `B0` to `B`. At crank angles `0` and
/// `pi` all links are collinear (the *flat* configurations): `Phi_q` loses rank there (the
/// closing loop's equations become dependent) and the parallelogram branch crosses the crossed
/// (anti-parallelogram) branch. Free, released at `speed`, the crank turns through them if its
/// kinetic energy `(2/3 + 1) crank^2 speed^2 / 2` exceeds the potential rise
/// `2 g crank (1 - sin(angle))` to the top. Started flat (`angle` 0 or `pi`), the mechanism
/// starts on a singular configuration (`System::singular_start_equations`).
pub fn parallelogram_four_bar(
    crank: f64,
    ground: f64,
    angle: f64,
    speed: f64,
    driven: bool,
) -> Result<System, ModelError> {
    let bad = |parameter: &'static str, value: f64, reason: &'static str| {
        Err(ModelError::InvalidParameter {
            element: "parallelogram four-bar".into(),
            parameter,
            value,
            reason,
        })
    };
    let (l, d, th, w) = (crank, ground, angle, speed);
    for (name, v) in [("crank", l), ("ground", d)] {
        if !(v.is_finite() && v > 0.0) {
            return bad(name, v, "must be positive and finite");
        }
    }
    for (name, v) in [("angle", th), ("speed", w)] {
        if !v.is_finite() {
            return bad(name, v, "must be finite");
        }
    }
    let (s, c) = th.sin_cos();
    let a = [l * c, l * s];
    // crank and rocker: centre of mass velocity (-l/2 sin, l/2 cos) w; coupler translates with A
    let vh = [-0.5 * l * s * w, 0.5 * l * c * w];
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let crank_b = b.add_body(
        Body::new("crank")
            .rod(1.0, l)
            .position(0.5 * a[0], 0.5 * a[1], th)
            .velocity(vh[0], vh[1], w),
    );
    let coupler = b.add_body(
        Body::new("coupler")
            .rod(1.0, d)
            .position(a[0] + 0.5 * d, a[1], 0.0)
            .velocity(2.0 * vh[0], 2.0 * vh[1], 0.0),
    );
    let rocker = b.add_body(
        Body::new("rocker")
            .rod(1.0, l)
            .position(d + 0.5 * a[0], 0.5 * a[1], th)
            .velocity(vh[0], vh[1], w),
    );
    b.add_joint(Joint::revolute(
        "A0",
        BodyRef::Ground,
        [0.0, 0.0],
        crank_b,
        [-0.5 * l, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "A",
        crank_b,
        [0.5 * l, 0.0],
        coupler,
        [-0.5 * d, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "B",
        coupler,
        [0.5 * d, 0.0],
        rocker,
        [0.5 * l, 0.0],
    ));
    b.add_joint(Joint::revolute(
        "B0",
        BodyRef::Ground,
        [d, 0.0],
        rocker,
        [-0.5 * l, 0.0],
    ));
    if driven {
        b.add_joint(Joint::angle_driver(
            "crank_drive",
            BodyRef::Ground,
            crank_b,
            TimeFunction::linear(th, w),
        ));
    }
    b.build()
}

mod andrews;
pub use andrews::andrews_squeezer;
mod loops;
pub use loops::{
    double_parallelogram, n_four_bar, pantograph, ClosedLoop, LOOP_GRAVITY, MAX_LOOPS,
};
mod exact;
pub use exact::{CrankMotion, Regime};
mod spatial;
pub use spatial::{
    bricard, free_body, heavy_top, spatial_double_pendulum, spatial_slider_crank, sprung_rod,
    BRICARD_POINTS, DOUBLE_PENDULUM_ROD, TOP_LENGTH,
};
mod tumbling;
pub use tumbling::{TorqueFreeBody, TorqueFreeMotion};
mod spatial_chain;
pub use spatial_chain::{spatial_chain, SPATIAL_CHAIN_LINK};
