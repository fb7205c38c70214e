//! Closed-loop reference models on a parallelogram branch: `N` parallelogram loops in a row
//! ([`n_four_bar`]), three cranks under one coupler ([`double_parallelogram`]) and a pantograph
//! ([`pantograph`]).
//!
//! All three share one layout. Every moving body is a uniform rod of 1 kg. The *cranks* are
//! rods of length `crank` pivoted at one end to ground points on the x-axis; the *couplers*
//! (and the pantograph's cross bar) are horizontal rods pinned to points of the cranks. On the
//! parallelogram branch every crank has the same absolute angle `theta` and every coupler
//! translates (angle 0), so each body's centre of mass moves on a circle
//! `r_b = (p_b, 0) + rho_b (cos theta, sin theta)` about a fixed point: one degree of freedom,
//! constant reduced inertia and a potential proportional to `sin theta` (see
//! [`super::CrankMotion`] and `docs/closed-loops.md`). [`ClosedLoop`] describes a mechanism by
//! its geometry and gives its branch states, its tracked point and the [`System`].
//!
//! Gravity is [`LOOP_GRAVITY`] along `-y`. Angles are measured from the x-axis, so the cranks
//! hang straight down at `theta = -pi/2`. At `theta = 0` and `theta = pi` all rods are
//! collinear (the *flat* configurations): the constraint Jacobian loses rank there and the
//! parallelogram branch crosses the anti-parallelogram ones.

use crate::body::{Body, BodyRef};
use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::joints::Joint;
use crate::system::System;
use crate::timefn::TimeFunction;

/// Gravity (m/s^2, along `-y`) of the closed-loop models and of their exact motions.
pub const LOOP_GRAVITY: f64 = 9.81;

/// The most loops [`n_four_bar`] accepts (a model of `6 N + 3` coordinates).
pub const MAX_LOOPS: usize = 100_000;

/// The mass of every rod (kg).
const ROD_MASS: f64 = 1.0;

/// A closed-loop mechanism of this module, by its geometry (validated on construction).
///
/// Its bodies' coordinates are those of the [`System`] that [`ClosedLoop::system`] builds, in
/// the same order, so [`ClosedLoop::branch_state`] gives states of that system.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ClosedLoop {
    pub(super) shape: Shape,
    pub(super) crank: f64,
    pub(super) ground: f64,
}

/// Which mechanism, with its own parameter.
#[derive(Clone, Copy, Debug, PartialEq)]
pub(super) enum Shape {
    /// `loops` parallelograms in a row.
    NFourBar { loops: usize },
    /// Three cranks under one coupler.
    DoubleParallelogram,
    /// A parallelogram with a cross bar at `ratio * crank` from the ground pivots.
    Pantograph { ratio: f64 },
}

/// A moving body on the branch: centre of mass at `(base, 0) + radius (cos theta, sin theta)`,
/// angle `theta` if it `rotates`, else 0.
struct Part {
    name: String,
    length: f64,
    base: f64,
    radius: f64,
    rotates: bool,
}

/// A revolute joint: point `pa` of body `a` (`None`: ground, `pa` global) on point `pb` of
/// body `b`.
struct Pin {
    name: String,
    a: Option<usize>,
    pa: [f64; 2],
    b: usize,
    pb: [f64; 2],
}

fn bad(element: &str, parameter: &'static str, value: f64, reason: &'static str) -> ModelError {
    ModelError::InvalidParameter {
        element: element.to_string(),
        parameter,
        value,
        reason,
    }
}

impl ClosedLoop {
    /// `loops` parallelogram loops in a row (see [`n_four_bar`]). Errors
    /// ([`ModelError::InvalidParameter`] naming the parameter): `loops` not in
    /// `1..=`[`MAX_LOOPS`]; `crank` or `ground` not positive and finite.
    pub fn n_four_bar(loops: usize, crank: f64, ground: f64) -> Result<Self, ModelError> {
        let element = "n-loop four-bar";
        if loops == 0 {
            return Err(bad(element, "loops", 0.0, "must be at least 1"));
        }
        if loops > MAX_LOOPS {
            return Err(bad(
                element,
                "loops",
                loops as f64,
                "is more than MAX_LOOPS = 100000",
            ));
        }
        Self::with(Shape::NFourBar { loops }, crank, ground)
    }

    /// Three cranks under one coupler (see [`double_parallelogram`]). Errors: `crank` or
    /// `ground` not positive and finite.
    pub fn double_parallelogram(crank: f64, ground: f64) -> Result<Self, ModelError> {
        Self::with(Shape::DoubleParallelogram, crank, ground)
    }

    /// A pantograph (see [`pantograph`]). Errors: `crank` or `ground` not positive and finite,
    /// `ratio` not in the open interval `(0, 1)`.
    pub fn pantograph(crank: f64, ground: f64, ratio: f64) -> Result<Self, ModelError> {
        if !(ratio > 0.0 && ratio < 1.0) {
            return Err(bad(
                "pantograph",
                "ratio",
                ratio,
                "must lie strictly between 0 and 1",
            ));
        }
        Self::with(Shape::Pantograph { ratio }, crank, ground)
    }

    fn with(shape: Shape, crank: f64, ground: f64) -> Result<Self, ModelError> {
        let s = ClosedLoop {
            shape,
            crank,
            ground,
        };
        for (name, v) in [("crank", crank), ("ground", ground)] {
            if !(v.is_finite() && v > 0.0) {
                return Err(bad(s.element(), name, v, "must be positive and finite"));
            }
        }
        Ok(s)
    }

    /// The mechanism's name in error messages: `"n-loop four-bar"`, `"double parallelogram"`
    /// or `"pantograph"`.
    pub fn element(&self) -> &'static str {
        match self.shape {
            Shape::NFourBar { .. } => "n-loop four-bar",
            Shape::DoubleParallelogram => "double parallelogram",
            Shape::Pantograph { .. } => "pantograph",
        }
    }

    /// The crank length (m).
    pub fn crank(&self) -> f64 {
        self.crank
    }

    /// The ground spacing of neighbouring crank pivots (m).
    pub fn ground(&self) -> f64 {
        self.ground
    }

    /// Number of moving bodies (`3 x` that coordinates).
    pub fn n_bodies(&self) -> usize {
        match self.shape {
            Shape::NFourBar { loops } => 2 * loops + 1,
            Shape::DoubleParallelogram | Shape::Pantograph { .. } => 4,
        }
    }

    /// Number of constraint equations of the free model (two per revolute joint; a driven
    /// model has one more).
    pub fn n_equations(&self) -> usize {
        match self.shape {
            Shape::NFourBar { loops } => 2 * (3 * loops + 1),
            Shape::DoubleParallelogram | Shape::Pantograph { .. } => 12,
        }
    }

    /// Number of redundant equations away from the flat configurations: 0 for
    /// [`n_four_bar`], 1 for [`double_parallelogram`] and [`pantograph`] (whose constraint
    /// Jacobian has rank `n_equations() - 1` there).
    pub fn redundant(&self) -> usize {
        match self.shape {
            Shape::NFourBar { .. } => 0,
            Shape::DoubleParallelogram | Shape::Pantograph { .. } => 1,
        }
    }

    /// The bodies, in the system's order, with their place on the branch.
    fn parts(&self) -> Vec<Part> {
        let (l, d) = (self.crank, self.ground);
        let crank = |i: usize, base: f64| Part {
            name: format!("crank{i}"),
            length: l,
            base,
            radius: 0.5 * l,
            rotates: true,
        };
        let rider = |name: String, length: f64, base: f64, radius: f64| Part {
            name,
            length,
            base,
            radius,
            rotates: false,
        };
        match self.shape {
            // interleaved (crank0, coupler1, crank1, ...): neighbours in the loop are
            // neighbours in q, so Phi_q is banded
            Shape::NFourBar { loops } => {
                let mut parts = Vec::with_capacity(2 * loops + 1);
                parts.push(crank(0, 0.0));
                for k in 1..=loops {
                    let x0 = (k - 1) as f64 * d;
                    parts.push(rider(format!("coupler{k}"), d, x0 + 0.5 * d, l));
                    parts.push(crank(k, k as f64 * d));
                }
                parts
            }
            Shape::DoubleParallelogram => vec![
                crank(0, 0.0),
                crank(1, d),
                crank(2, 2.0 * d),
                rider("coupler".into(), 2.0 * d, d, l),
            ],
            Shape::Pantograph { ratio } => vec![
                crank(0, 0.0),
                crank(1, d),
                rider("coupler".into(), d, 0.5 * d, l),
                rider("bar".into(), d, 0.5 * d, ratio * l),
            ],
        }
    }

    /// The revolute joints, in the system's order.
    fn pins(&self) -> Vec<Pin> {
        let (l, d) = (self.crank, self.ground);
        let (foot, tip) = ([-0.5 * l, 0.0], [0.5 * l, 0.0]);
        let pin = |name: String, a: Option<usize>, pa: [f64; 2], b: usize, pb: [f64; 2]| Pin {
            name,
            a,
            pa,
            b,
            pb,
        };
        let ground = |name: String, x: f64, b: usize| pin(name, None, [x, 0.0], b, foot);
        match self.shape {
            Shape::NFourBar { loops } => {
                let mut pins = Vec::with_capacity(3 * loops + 1);
                pins.push(ground("G0".into(), 0.0, 0));
                for k in 1..=loops {
                    let (left, coupler, right) = (2 * k - 2, 2 * k - 1, 2 * k);
                    let half = 0.5 * d;
                    pins.push(pin(format!("A{k}"), Some(left), tip, coupler, [-half, 0.0]));
                    pins.push(pin(format!("B{k}"), Some(coupler), [half, 0.0], right, tip));
                    pins.push(ground(format!("G{k}"), k as f64 * d, right));
                }
                pins
            }
            Shape::DoubleParallelogram => vec![
                ground("G0".into(), 0.0, 0),
                ground("G1".into(), d, 1),
                ground("G2".into(), 2.0 * d, 2),
                pin("A".into(), Some(0), tip, 3, [-d, 0.0]),
                pin("M".into(), Some(1), tip, 3, [0.0, 0.0]),
                pin("B".into(), Some(3), [d, 0.0], 2, tip),
            ],
            Shape::Pantograph { ratio } => {
                let mid = [(ratio - 0.5) * l, 0.0];
                let half = 0.5 * d;
                vec![
                    ground("G0".into(), 0.0, 0),
                    ground("G1".into(), d, 1),
                    pin("A".into(), Some(0), tip, 2, [-half, 0.0]),
                    pin("B".into(), Some(2), [half, 0.0], 1, tip),
                    pin("C".into(), Some(0), mid, 3, [-half, 0.0]),
                    pin("D".into(), Some(3), [half, 0.0], 1, mid),
                ]
            }
        }
    }

    /// The state `(q, v)` of the system (in its coordinate order) on the parallelogram branch
    /// at crank angle `theta` (rad) and crank speed `theta_dot` (rad/s): crank `i` at
    /// `(x_i + crank/2 cos theta, crank/2 sin theta, theta)`, every coupler or bar translated
    /// by `rho (cos theta, sin theta)` from its place on the x-axis (`rho = crank` for
    /// couplers, `ratio * crank` for the pantograph's bar), velocities the time derivatives.
    /// Any angle is allowed, the flat ones included; non-finite inputs give non-finite states.
    pub fn branch_state(&self, theta: f64, theta_dot: f64) -> (Vec<f64>, Vec<f64>) {
        let (s, c) = theta.sin_cos();
        let parts = self.parts();
        let mut q = Vec::with_capacity(3 * parts.len());
        let mut v = Vec::with_capacity(3 * parts.len());
        for p in &parts {
            let (angle, rate) = if p.rotates {
                (theta, theta_dot)
            } else {
                (0.0, 0.0)
            };
            q.extend([p.base + p.radius * c, p.radius * s, angle]);
            v.extend([-p.radius * s * theta_dot, p.radius * c * theta_dot, rate]);
        }
        (q, v)
    }

    /// The tracked point at crank angle `theta`: the tip of the last crank (the one farthest
    /// along `+x`), `(x_last + crank cos theta, crank sin theta)` with `x_last = N ground`,
    /// `2 ground` or `ground` for [`n_four_bar`], [`double_parallelogram`] and [`pantograph`].
    /// It is the point `[crank / 2, 0]` of the body [`ClosedLoop::tracked_body`].
    pub fn tracked_point(&self, theta: f64) -> [f64; 2] {
        let (s, c) = theta.sin_cos();
        let last = match self.shape {
            Shape::NFourBar { loops } => loops as f64 * self.ground,
            Shape::DoubleParallelogram => 2.0 * self.ground,
            Shape::Pantograph { .. } => self.ground,
        };
        [last + self.crank * c, self.crank * s]
    }

    /// The name of the body carrying the tracked point: `crankN`, `crank2` or `crank1`.
    pub fn tracked_body(&self) -> String {
        match self.shape {
            Shape::NFourBar { loops } => format!("crank{loops}"),
            Shape::DoubleParallelogram => "crank2".into(),
            Shape::Pantograph { .. } => "crank1".into(),
        }
    }

    /// The model, its initial state on the parallelogram branch at crank angle `angle` (rad)
    /// and crank speed `speed` (rad/s) ([`ClosedLoop::branch_state`], consistent as built);
    /// `driven` adds the angle driver `crank_drive` on `crank0`,
    /// `theta = angle + speed t` (rheonomic). Errors ([`ModelError::InvalidParameter`]):
    /// `angle` or `speed` not finite; and whatever [`SystemBuilder::build`] rejects. A flat
    /// `angle` (0 or `pi`: all links collinear) starts the mechanism on a singular
    /// configuration ([`System::singular_start_equations`]).
    pub fn system(&self, angle: f64, speed: f64, driven: bool) -> Result<System, ModelError> {
        let element = self.element();
        for (name, v) in [("angle", angle), ("speed", speed)] {
            if !v.is_finite() {
                return Err(bad(element, name, v, "must be finite"));
            }
        }
        let (q, v) = self.branch_state(angle, speed);
        let mut b = SystemBuilder::new();
        b.set_gravity([0.0, -LOOP_GRAVITY]);
        let handles: Vec<_> = self
            .parts()
            .into_iter()
            .enumerate()
            .map(|(i, p)| {
                let (qi, vi) = (&q[3 * i..3 * i + 3], &v[3 * i..3 * i + 3]);
                b.add_body(
                    Body::new(p.name)
                        .rod(ROD_MASS, p.length)
                        .position(qi[0], qi[1], qi[2])
                        .velocity(vi[0], vi[1], vi[2]),
                )
            })
            .collect();
        for p in self.pins() {
            let a = p.a.map_or(BodyRef::Ground, |i| handles[i].into());
            b.add_joint(Joint::revolute(p.name, a, p.pa, handles[p.b], p.pb));
        }
        if driven {
            b.add_joint(Joint::angle_driver(
                "crank_drive",
                BodyRef::Ground,
                handles[0],
                TimeFunction::linear(angle, speed),
            ));
        }
        b.build()
    }
}

/// `loops` parallelogram four-bars in a row: `N + 1` equal cranks and `N` couplers, one degree
/// of freedom, no redundant equation.
///
/// Geometry: crank `i` (`i = 0..=N`; body `crank{i}`, uniform rod, 1 kg, length `crank`) is
/// pivoted at one end to the ground point `(i ground, 0)` by the joint `G{i}`; coupler `k`
/// (`k = 1..=N`; body `coupler{k}`, uniform rod, 1 kg, length `ground`) is pinned by its left
/// end to the tip of crank `k - 1` (joint `A{k}`) and by its right end to the tip of crank `k`
/// (joint `B{k}`). Bodies are ordered `crank0, coupler1, crank1, ..., couplerN, crankN`;
/// each body's x-axis points from its first joint to its second. Counting:
/// `3 (2N + 1)` coordinates, `2 (3N + 1)` equations, one degree of freedom, `Phi_q` of full
/// rank away from the flat configurations.
///
/// On the parallelogram branch every crank has the angle `theta` and every coupler
/// translates; the initial state is that branch's at `theta = angle`, `theta' = speed`,
/// consistent as built. At `theta = 0` and `pi` every loop is flat: `Phi_q` loses `N` ranks
/// (each crank can then turn on its own to first order).
///
/// Parameters (m, rad, rad/s; errors are [`ModelError::InvalidParameter`] naming the
/// parameter):
///
/// * `loops` — `N`, from 1 to [`MAX_LOOPS`];
/// * `crank` — crank length, positive and finite;
/// * `ground` — pivot spacing and coupler length, positive and finite;
/// * `angle` — initial crank angle from the x-axis, finite, not flat (`|sin(angle)| >= 1e-6`);
/// * `speed` — initial crank speed, finite;
/// * `driven` — adds the angle driver `crank_drive` on `crank0`, `theta = angle + speed t`
///   (rheonomic, no degree of freedom left).
///
/// Gravity [`LOOP_GRAVITY`] along `-y`. `loops = 1` is [`super::parallelogram_four_bar`]
/// with other names. The exact free motion is [`super::CrankMotion::n_four_bar`].
pub fn n_four_bar(
    loops: usize,
    crank: f64,
    ground: f64,
    angle: f64,
    speed: f64,
    driven: bool,
) -> Result<System, ModelError> {
    ClosedLoop::n_four_bar(loops, crank, ground)?.system(angle, speed, driven)
}

/// Three equal cranks under one coupler: one degree of freedom and one redundant equation.
///
/// Geometry: cranks `crank0`, `crank1`, `crank2` (uniform rods, 1 kg, length `crank`) pivoted
/// at one end to the ground points `(0, 0)`, `(ground, 0)`, `(2 ground, 0)` (joints `G0`,
/// `G1`, `G2`); one `coupler` (uniform rod, 1 kg, length `2 ground`) pinned by its left end to
/// the tip of `crank0` (joint `A`), by its middle to the tip of `crank1` (joint `M`) and by its
/// right end to the tip of `crank2` (joint `B`). Counting: 12 coordinates, 12 equations.
///
/// Why one equation is redundant: without `crank1` and `M` the model is a parallelogram
/// four-bar (one degree of freedom, full rank); there the coupler translates, so its middle
/// moves on the circle of radius `crank` about `(ground, 0)`, which is exactly what `crank1`
/// (3 coordinates, 4 equations) imposes. Away from the flat configurations the velocities
/// allowed by `Phi_q v = 0` are those of the branch (all cranks at one speed, coupler
/// translating): a one-dimensional space, so `Phi_q` has rank 11 and one of the 12 equations
/// is a combination of the others. At `theta = 0` and `pi` (flat) the rank drops to 10.
///
/// Parameters as for [`n_four_bar`] (without `loops`): `crank`, `ground` positive and finite,
/// `angle` finite and not flat (`|sin(angle)| >= 1e-6`), `speed` finite; `driven` adds the
/// angle driver `crank_drive` on `crank0`. The initial state is on the parallelogram branch,
/// consistent as built. Gravity [`LOOP_GRAVITY`] along `-y`. The exact free motion is
/// [`super::CrankMotion::double_parallelogram`].
pub fn double_parallelogram(
    crank: f64,
    ground: f64,
    angle: f64,
    speed: f64,
    driven: bool,
) -> Result<System, ModelError> {
    ClosedLoop::double_parallelogram(crank, ground)?.system(angle, speed, driven)
}

/// A pantograph: a parallelogram four-bar whose two cranks are joined a second time by a cross
/// bar parallel to the coupler; one degree of freedom and one redundant equation.
///
/// Design. A drawing pantograph is a linkage of parallelograms sharing bars: points of its
/// bars stay homothetic about a fixed point, so one traces a scaled copy of another's path.
/// Here: cranks `crank0` and `crank1` (uniform rods, 1 kg, length `crank`) pivoted at one end
/// to `(0, 0)` and `(ground, 0)` (joints `G0`, `G1`); the `coupler` (uniform rod, 1 kg, length
/// `ground`) pinned to the crank tips (joints `A` on `crank0`, `B` on `crank1`); the cross
/// `bar` (uniform rod, 1 kg, length `ground`) pinned to the points at distance
/// `ratio * crank` from the pivots along the cranks (joints `C` on `crank0`, `D` on `crank1`).
/// The cranks are the long sides of two stacked parallelograms (ground, bar) and (bar,
/// coupler); on the branch the bar and the coupler translate, and the bar's middle is the
/// image of the coupler's middle under the homothety of centre `(ground / 2, 0)` and ratio
/// `ratio`: it draws the coupler's circle scaled by `ratio`.
///
/// Why one equation is redundant: without the bar (3 coordinates, 4 equations) the model is a
/// parallelogram four-bar; on its branch `C` and `D` stay at distance `ground` and level, which
/// is all the bar imposes. Counting: 12 coordinates, 12 equations, and away from the flat
/// configurations the velocities with `Phi_q v = 0` form a one-dimensional space (both cranks
/// at one speed, coupler and bar translating), so `Phi_q` has rank 11: one equation is a
/// combination of the others. At `theta = 0` and `pi` (flat) the rank drops to 10.
///
/// Parameters: `crank`, `ground` positive and finite (m); `ratio` strictly between 0 and 1;
/// `angle` finite and not flat (`|sin(angle)| >= 1e-6`, rad); `speed` finite (rad/s);
/// `driven` adds the angle driver `crank_drive` on `crank0`. Errors are
/// [`ModelError::InvalidParameter`] naming the parameter. The initial state is on the
/// parallelogram branch, consistent as built. Gravity [`LOOP_GRAVITY`] along `-y`. The exact
/// free motion is [`super::CrankMotion::pantograph`].
pub fn pantograph(
    crank: f64,
    ground: f64,
    ratio: f64,
    angle: f64,
    speed: f64,
    driven: bool,
) -> Result<System, ModelError> {
    ClosedLoop::pantograph(crank, ground, ratio)?.system(angle, speed, driven)
}
