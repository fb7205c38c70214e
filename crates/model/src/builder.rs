//! The builder of a [`System`] and the validation that turns bodies, joints and forces into one.

use crate::body::{Body, BodyHandle, BodyRef};
use crate::check::{self, invalid};
use crate::element::norm;
use crate::error::ModelError;
use crate::forces::Force;
use crate::init::RedundantConstraints;
use crate::joints::{Coordinate, Joint};
use crate::sensors::{Sensor, SensorKind};
use crate::system::*;
use nalgebra::DVector;

/// Collects bodies, joints and forces; [`SystemBuilder::build`] validates them into a [`System`].
#[derive(Clone, Debug, Default)]
pub struct SystemBuilder {
    pub(crate) bodies: Vec<Body>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) forces: Vec<Force>,
    pub(crate) sensors: Vec<Sensor>,
    pub(crate) gravity: [f64; 2],
    /// Per body: the frame its local points are given in and whether it is a point mass.
    pub(crate) frames: Vec<BodyFrame>,
    /// The first handle given to [`SystemBuilder::set_body_frame`] without a body.
    unknown_frame: Option<usize>,
    /// What `build` does with redundant equations.
    pub(crate) redundant: RedundantConstraints,
    /// Initial joint coordinates for assembly.
    pub(crate) joint_initials: Vec<(JointHandle, crate::JointInitial)>,
    /// Spatial bodies, joints and gravity.
    pub(crate) spatial: crate::spatial::build::SpatialInput,
}

/// How a body was added (builder side only: the [`System`] keeps centre-of-mass poses).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub(crate) struct BodyFrame {
    /// The centre of mass in the body frame.
    com: [f64; 2],
    /// A point mass: rotation eliminated, attached at its centre only.
    point_mass: bool,
}

impl SystemBuilder {
    /// An empty model with zero gravity.
    pub fn new() -> Self {
        Self::default()
    }
    /// Sets the gravity vector (m/s^2), e.g. `[0.0, -9.81]`. It may be zero.
    pub fn set_gravity(&mut self, g: [f64; 2]) -> &mut Self {
        self.gravity = g;
        self
    }
    /// Adds a body and returns its handle. Its local points (in joints and forces) are
    /// relative to its centre of mass, unless [`SystemBuilder::set_body_frame`] says otherwise.
    pub fn add_body(&mut self, body: Body) -> BodyHandle {
        self.bodies.push(body);
        self.frames.push(BodyFrame::default());
        BodyHandle(self.bodies.len() - 1)
    }
    /// Adds a point mass `mass` at `position` with `velocity`: a body whose rotation
    /// [`SystemBuilder::build`] eliminates by an absolute-angle joint named
    /// `<name>:point_mass` (added after the other joints), with a nominal inertia `m l^2`
    /// (`l`: the largest distance-joint length, spring rest length or attachment-point distance
    /// of the model, 1 m if none; it scales nothing). Joints and forces attach to it at its
    /// centre only (`[0, 0]`, or the centre of mass of its [`SystemBuilder::set_body_frame`]);
    /// joints and forces on its angle (weld, prismatic, angle driver, absolute angle, torque,
    /// rotary spring) are errors of `build`.
    pub fn add_point_mass(
        &mut self,
        name: impl Into<String>,
        mass: f64,
        position: [f64; 2],
        velocity: [f64; 2],
    ) -> BodyHandle {
        let h = self.add_body(Body {
            name: name.into(),
            mass,
            inertia: f64::NAN,
            position: [position[0], position[1], 0.0],
            velocity: [velocity[0], velocity[1], 0.0],
            inputs: crate::Inputs::default(),
        });
        self.frames[h.0].point_mass = true;
        h
    }
    /// Gives `body`'s local points in a body frame whose centre of mass is at `com` (like a CAD
    /// part): the body's `position` and `velocity` are then those of the frame's origin, and
    /// every local point on it (joints and forces, added before or after) is in that frame.
    /// [`SystemBuilder::build`] converts all of them to the centre of mass. An unknown handle
    /// or a non-finite `com` is an error of `build`.
    pub fn set_body_frame(&mut self, body: BodyHandle, com: [f64; 2]) -> &mut Self {
        if let Some(f) = self.frames.get_mut(body.0) {
            f.com = com;
        } else {
            self.unknown_frame.get_or_insert(body.0);
        }
        self
    }
    /// Marks which of `body`'s initial values are inputs (see [`crate::Inputs`]; for a body
    /// added with [`crate::Body::input_position`] / [`crate::Body::input_velocity`] this is
    /// not needed). An unknown handle is ignored here and reported by `build` wherever the
    /// handle is used.
    pub fn set_inputs(&mut self, body: BodyHandle, inputs: crate::Inputs) -> &mut Self {
        if let Some(b) = self.bodies.get_mut(body.0) {
            b.inputs = inputs;
        }
        self
    }
    /// Adds a joint and returns its handle.
    pub fn add_joint(&mut self, joint: Joint) -> JointHandle {
        self.joints.push(joint);
        JointHandle(self.joints.len() - 1)
    }
    /// Gives a revolute joint's initial relative angle `theta_b - theta_a` or a prismatic
    /// joint's initial slide, and/or its rate: the consistent initial state places the bodies
    /// from them and keeps them exactly (assembly from joint coordinates; see
    /// [`crate::JointInitial`]). Another joint kind, a handle without a joint, a joint given
    /// twice or a non-finite value is an error of `build`.
    ///
    /// ```
    /// use mbd_model::{Body, BodyRef, Joint, JointInitial, SystemBuilder};
    /// let mut b = SystemBuilder::new();
    /// let rod = b.add_body(Body::new("rod").rod(1.0, 1.0));
    /// let pivot = b.add_joint(Joint::revolute("pivot", BodyRef::Ground, [0.0, 0.0], rod, [-0.5, 0.0]));
    /// b.set_joint_initial(pivot, JointInitial::coordinate(-1.0).with_rate(2.0));
    /// let sys = b.build()?;
    /// let (q, v) = sys.initial_guess();
    /// assert_eq!(q[2], -1.0);
    /// assert!((q[0] - 0.5 * (-1.0f64).cos()).abs() < 1e-15);
    /// assert_eq!(v[2], 2.0);
    /// # Ok::<(), mbd_model::ModelError>(())
    /// ```
    pub fn set_joint_initial(
        &mut self,
        joint: JointHandle,
        initial: crate::JointInitial,
    ) -> &mut Self {
        self.joint_initials.push((joint, initial));
        self
    }
    /// Adds a sensor (see [`Sensor`]): its quantities become output columns.
    pub fn add_sensor(&mut self, sensor: Sensor) -> &mut Self {
        self.sensors.push(sensor);
        self
    }
    /// Adds a force element and returns its handle.
    pub fn add_force(&mut self, force: Force) -> ForceHandle {
        self.forces.push(force);
        ForceHandle(self.forces.len() - 1)
    }
    /// What [`SystemBuilder::build`] does with constraint equations that depend on others at
    /// the initial configuration: [`RedundantConstraints::Allow`] (the default) builds the
    /// system and lists them in [`System::redundant_equations`];
    /// [`RedundantConstraints::Reject`] makes them an error.
    pub fn redundant_constraints(&mut self, policy: RedundantConstraints) -> &mut Self {
        self.redundant = policy;
        self
    }
    /// Validates the model and assembles it. Checks names, parameters, attachments, and the rank
    /// of `Phi_q` at the bodies' initial positions: equations that depend on earlier ones are
    /// listed in [`System::redundant_equations`] (or, with [`RedundantConstraints::Reject`], an
    /// error naming the first and the joints involved). Give positions that satisfy the
    /// constraints (to about `1e-9` relative) for the dependency to be seen: at a configuration
    /// off the constraints the rows are independent in floating point and the redundancy shows
    /// only when the consistent state is projected (as a rank error).
    pub fn build(mut self) -> Result<System, ModelError> {
        self.lower_frames()?;
        System::new(self)
    }
}

impl SystemBuilder {
    /// Lowers body frames and point masses (see [`SystemBuilder::add_point_mass`] and
    /// [`SystemBuilder::set_body_frame`]): centre-of-mass poses and local points, the point
    /// masses' nominal inertia and angle joints. The one implementation the model-file
    /// resolver uses too.
    fn lower_frames(&mut self) -> Result<(), ModelError> {
        if let Some(i) = self.unknown_frame {
            return Err(ModelError::InvalidElement {
                element: format!("body #{i}"),
                message: format!(
                    "set_body_frame on a body that does not exist (the model has {} bodies)",
                    self.bodies.len()
                ),
            });
        }
        // the initial state must be finite before the frame lowering mixes its entries (an
        // infinite angular velocity times a zero offset would be reported as NaN)
        for body in &self.bodies {
            for &p in &body.position {
                check::finite(&body.name, "position", p)?;
            }
            for &v in &body.velocity {
                check::finite(&body.name, "velocity", v)?;
            }
        }
        let frames = std::mem::take(&mut self.frames);
        let frame = |r: BodyRef| r.index().and_then(|i| frames.get(i).copied());
        let names: Vec<String> = self.bodies.iter().map(|b| b.name.clone()).collect();
        let name = |r: BodyRef| r.index().map_or("ground", |i| names[i].as_str());
        for (body, f) in self.bodies.iter_mut().zip(&frames) {
            let c = f.com;
            if !(c[0].is_finite() && c[1].is_finite()) {
                return Err(invalid(
                    format!("body '{}'", body.name),
                    format!("body frame: centre of mass {c:?} must be finite"),
                ));
            }
            // inputs are on the centre of mass's coordinates: with a frame offset, an x or y
            // input would not be the value given (the origin's)
            let moved = c != [0.0, 0.0];
            let xy = |m: [bool; 3]| m[0] || m[1];
            if moved && (xy(body.inputs.position) || xy(body.inputs.velocity)) {
                return Err(invalid(
                    format!("body '{}'", body.name),
                    "inputs on x or y need the body frame's origin at the centre of mass (no \
                     'com'): the given values are the origin's, the kept ones the centre of \
                     mass's; mark theta inputs, or give the centre of mass's values"
                        .into(),
                ));
            }
            // r_com = r_o + R(theta) c;  v_com = v_o + omega x R(theta) c
            let (sn, cs) = body.position[2].sin_cos();
            let rc = [cs * c[0] - sn * c[1], sn * c[0] + cs * c[1]];
            let w = body.velocity[2];
            body.position[0] += rc[0];
            body.position[1] += rc[1];
            body.velocity[0] -= w * rc[1];
            body.velocity[1] += w * rc[0];
        }
        // a local point in its body's frame, relative to the centre of mass; on a point mass it
        // must be the centre
        let local = |element: &str, field: &str, r: BodyRef, p: &mut [f64; 2]| {
            let Some(f) = frame(r) else { return Ok(()) };
            let given = *p;
            *p = [p[0] - f.com[0], p[1] - f.com[1]];
            if f.point_mass && *p != [0.0, 0.0] {
                return Err(invalid(
                    element.to_string(),
                    format!(
                        "field '{field}' = {given:?} on point mass '{}': a point mass attaches \
                         only at its centre ({:?})",
                        name(r),
                        f.com
                    ),
                ));
            }
            Ok(())
        };
        let no_rotation = |element: &str, kind: &str, bodies: &[BodyRef]| {
            for &r in bodies {
                if frame(r).is_some_and(|f| f.point_mass) {
                    let b = name(r);
                    return Err(invalid(
                        element.to_string(),
                        format!(
                            "a {kind} acts on the angle of point mass '{b}', which has no \
                             rotation; make '{b}' a rigid body"
                        ),
                    ));
                }
            }
            Ok(())
        };
        let nominal = self.nominal_length();
        for j in &mut self.joints {
            let element = format!("joint '{}'", j.name);
            if let Some(kind) = j.rotation_use() {
                let (a, b) = j.bodies();
                no_rotation(&element, kind, &[a, b])?;
            }
            for anchor in j.anchors().into_iter().flatten() {
                local(&element, anchor.field, anchor.body, anchor.point)?;
            }
        }
        for f in &mut self.forces {
            let element = format!("force '{}'", f.name);
            if let Some(kind) = f.rotation_use() {
                let (a, b) = f.bodies();
                no_rotation(&element, kind, &[a, b])?;
            }
            for anchor in f.anchors().into_iter().flatten() {
                local(&element, anchor.field, anchor.body, anchor.point)?;
            }
        }
        for s in &mut self.sensors {
            let element = format!("sensor '{}'", s.name);
            if let SensorKind::Point { body, point } = &mut s.kind {
                local(&element, "point", *body, point)?;
            }
        }
        for (i, f) in frames.iter().enumerate() {
            if f.point_mass {
                let b = &mut self.bodies[i];
                b.inertia = b.mass * nominal * nominal;
                self.joints.push(Joint::absolute(
                    format!("{}:point_mass", b.name),
                    BodyHandle(i),
                    [0.0, 0.0],
                    Coordinate::Angle,
                    0.0,
                ));
            }
        }
        Ok(())
    }

    /// The nominal length `l` of point masses (inertia `m l^2`): the largest distance-joint
    /// length, spring rest length or attachment-point distance from a frame origin, 1 m if
    /// none. So a point mass neither changes [`System::length_scale`] nor trips the
    /// inertia-scale check.
    fn nominal_length(&mut self) -> f64 {
        let mut l = 0.0f64;
        for j in &mut self.joints {
            l = l.max(j.length().unwrap_or(0.0));
            for anchor in j.anchors().into_iter().flatten() {
                l = l.max(norm(*anchor.point));
            }
        }
        for f in &self.forces {
            l = l.max(f.length().unwrap_or(0.0));
        }
        if l.is_finite() && l > 0.0 {
            l
        } else {
            1.0
        }
    }
}

impl System {
    pub(crate) fn new(b: SystemBuilder) -> Result<System, ModelError> {
        let SystemBuilder {
            bodies,
            mut joints,
            forces,
            sensors,
            gravity,
            frames: _,
            unknown_frame: _,
            redundant: policy,
            joint_initials,
            spatial,
        } = b;
        if bodies.is_empty() && spatial.bodies.is_empty() && spatial.points.is_empty() {
            return Err(ModelError::Empty);
        }
        let has_spatial = !spatial.bodies.is_empty() || !spatial.points.is_empty();
        if !joint_initials.is_empty() && has_spatial {
            return Err(invalid(
                "assembly".to_string(),
                "assembly from joint coordinates takes planar models only; place spatial \
                 bodies by their position and orientation"
                    .to_string(),
            ));
        }
        check::finite("gravity", "gravity", gravity[0])?;
        check::finite("gravity", "gravity", gravity[1])?;
        let mut names = std::collections::HashSet::new();
        for body in &bodies {
            check::body_name(&mut names, &body.name)?;
            check::positive(&body.name, "mass", body.mass)?;
            if !(body.inertia.is_finite() && body.inertia > 0.0) {
                return Err(ModelError::InvalidParameter {
                    element: body.name.clone(),
                    parameter: "inertia",
                    value: body.inertia,
                    reason: "must be positive and finite (a particle without rotation is a \
                             point mass: `kind = \"point_mass\"` in a model file, \
                             `SystemBuilder::add_point_mass` in code)",
                });
            }
            for &p in &body.position {
                check::finite(&body.name, "position", p)?;
            }
            for &v in &body.velocity {
                check::finite(&body.name, "velocity", v)?;
            }
            // finite entries whose kinetic energy overflows (|v| near 1e308) would make every
            // energy and residual infinite later, blamed on the solver
            let [vx, vy, w] = body.velocity;
            let kinetic = 0.5 * (body.mass * (vx * vx + vy * vy) + body.inertia * w * w);
            if !kinetic.is_finite() {
                let value = vx.abs().max(vy.abs()).max(w.abs());
                return Err(ModelError::InvalidParameter {
                    element: body.name.clone(),
                    parameter: "velocity",
                    value,
                    reason: "gives a kinetic energy that overflows f64",
                });
            }
        }
        let nb = bodies.len();
        let resolve = |element: &str, r: BodyRef| -> Result<Option<usize>, ModelError> {
            match r {
                BodyRef::Ground => Ok(None),
                BodyRef::Body(h) if h.0 < nb => Ok(Some(h.0)),
                BodyRef::Body(h) => Err(ModelError::UnknownBody {
                    element: element.to_string(),
                    body: format!("#{} (the model has {} bodies)", h.0, nb),
                }),
            }
        };
        let body_name = |i: Option<usize>| -> String {
            i.map_or_else(|| "ground".to_string(), |i| bodies[i].name.clone())
        };

        let mut jnames = std::collections::HashSet::new();
        let mut joint_attach = Vec::with_capacity(joints.len());
        for j in joints.iter_mut() {
            if !jnames.insert(j.name.clone()) {
                return Err(ModelError::DuplicateName {
                    kind: "joint",
                    name: j.name.clone(),
                });
            }
            let (ra, rb) = j.bodies();
            let a = resolve(&j.name, ra)?;
            let bb = resolve(&j.name, rb)?;
            let single = j.is_single_body();
            if a == bb && !(single && a.is_some()) {
                return Err(ModelError::SameBody {
                    joint: j.name.clone(),
                    body: body_name(a),
                });
            }
            j.validate()?;
            joint_attach.push(Attach { a, b: bb });
        }

        let mut fnames = std::collections::HashSet::new();
        let mut force_attach = Vec::with_capacity(forces.len());
        for f in &forces {
            if !fnames.insert(f.name.clone()) {
                return Err(ModelError::DuplicateName {
                    kind: "force",
                    name: f.name.clone(),
                });
            }
            let (ra, rb) = f.bodies();
            let a = resolve(&f.name, ra)?;
            let bb = resolve(&f.name, rb)?;
            let single = f.is_single_body();
            if single && a.is_none() {
                return Err(ModelError::SameBody {
                    joint: f.name.clone(),
                    body: "ground".into(),
                });
            }
            if !single && a == bb {
                return Err(ModelError::SameBody {
                    joint: f.name.clone(),
                    body: body_name(a),
                });
            }
            f.validate()?;
            force_attach.push(Attach { a, b: bb });
        }

        let mut snames = std::collections::HashSet::new();
        for sensor in &sensors {
            if !snames.insert(sensor.name.clone()) {
                return Err(ModelError::DuplicateName {
                    kind: "sensor",
                    name: sensor.name.clone(),
                });
            }
            let element = format!("sensor '{}'", sensor.name);
            match &sensor.kind {
                SensorKind::Point { body, .. } | SensorKind::Energy { body: Some(body) } => {
                    resolve(&element, *body)?;
                }
                _ => {}
            }
            if let Some(joint) = sensor.joint_read() {
                if joint.0 >= joints.len() {
                    return Err(invalid(
                        element,
                        format!(
                            "joint #{} does not exist (the model has {} joints)",
                            joint.0,
                            joints.len()
                        ),
                    ));
                }
            }
            sensor.validate()?;
            sensor.check_spatial(&spatial.bodies, &spatial.points, spatial.joints.len())?;
        }

        let n = 3 * nb;
        let mut row_offset = Vec::with_capacity(joints.len());
        let mut eq_joint = Vec::new();
        let mut m = 0;
        for (ji, j) in joints.iter().enumerate() {
            row_offset.push(m);
            for _ in 0..j.n_equations() {
                eq_joint.push(ji);
            }
            m += j.n_equations();
        }
        let spatial = spatial.build(n, m, &mut names, &mut jnames, &mut fnames)?;
        let n = n + 12 * spatial.bodies.len() + 3 * spatial.points.len();
        let m = m + spatial.m;
        let mass = DVector::from_iterator(
            n,
            bodies
                .iter()
                .flat_map(|b| [b.mass, b.mass, b.inertia])
                .chain(
                    spatial
                        .bodies
                        .iter()
                        .flat_map(|b| b.inertia.mass_diagonal())
                        .chain(spatial.points.iter().flat_map(|p| [p.mass; 3])),
                ),
        );
        let inv_mass = mass.map(|x| 1.0 / x);
        // the negated gradient of the gravity potential, as `potential_gradient` writes it
        let mut gravity_forces: Vec<f64> = bodies
            .iter()
            .flat_map(|b| [-(-b.mass * gravity[0]), -(-b.mass * gravity[1]), 0.0])
            .collect();
        spatial.gravity_forces(&mut gravity_forces);
        let mut sys = System {
            bodies,
            joints,
            forces,
            sensors,
            gravity,
            joint_attach,
            force_attach,
            row_offset,
            n,
            m,
            mass,
            inv_mass,
            eq_joint,
            gravity_forces,
            redundant: Vec::new(),
            singular_start: Vec::new(),
            revolute_rows: Vec::new(),
            joint_initials: Vec::new(),
            spatial,
        };
        sys.joint_initials = crate::assembly::validate(&sys.joints, &joint_initials)?;
        sys.revolute_rows = crate::constraints::RevoluteRow::table(&sys);
        sys.check_inertia_scale()?;
        sys.check_mass_ratio()?;
        let (q0, _) = sys.initial_guess();
        let found = sys.redundant_at(q0.as_slice(), 0.0)?;
        let split = sys.split_dependence(q0.as_slice(), 0.0, found)?;
        if policy == RedundantConstraints::Reject {
            if let Some(e) = split.redundant.into_iter().next() {
                return Err(ModelError::Redundant {
                    equation: e.equation,
                    joints: e.joints,
                });
            }
        } else {
            sys.redundant = split.redundant;
        }
        sys.singular_start = split.singular;
        Ok(sys)
    }

    // ---------------------------------------------------------------- layout and names
}
