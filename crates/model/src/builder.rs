//! The builder of a [`System`] and the validation that turns bodies, joints and forces into one.

use crate::body::{Body, BodyHandle, BodyRef};
use crate::error::ModelError;
use crate::force::{Force, ForceKind};
use crate::joint::{Joint, JointKind};
use crate::system::*;
use nalgebra::DVector;

/// Collects bodies, joints and forces; [`SystemBuilder::build`] validates them into a [`System`].
#[derive(Clone, Debug, Default)]
pub struct SystemBuilder {
    pub(crate) bodies: Vec<Body>,
    pub(crate) joints: Vec<Joint>,
    pub(crate) forces: Vec<Force>,
    pub(crate) gravity: [f64; 2],
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
    /// Adds a body and returns its handle.
    pub fn add_body(&mut self, body: Body) -> BodyHandle {
        self.bodies.push(body);
        BodyHandle(self.bodies.len() - 1)
    }
    /// Adds a joint and returns its handle.
    pub fn add_joint(&mut self, joint: Joint) -> JointHandle {
        self.joints.push(joint);
        JointHandle(self.joints.len() - 1)
    }
    /// Adds a force element and returns its handle.
    pub fn add_force(&mut self, force: Force) -> ForceHandle {
        self.forces.push(force);
        ForceHandle(self.forces.len() - 1)
    }
    /// Validates the model and assembles it. Checks names, parameters, attachments, and the rank
    /// of `Phi_q` at the bodies' initial positions (redundant constraints are an error naming the
    /// joints involved).
    pub fn build(self) -> Result<System, ModelError> {
        System::new(self)
    }
}

fn check_finite(element: &str, parameter: &'static str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be finite",
        })
    }
}

fn check_positive(element: &str, parameter: &'static str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be positive and finite",
        })
    }
}

fn check_nonneg(element: &str, parameter: &'static str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be non-negative and finite",
        })
    }
}

fn check_point(element: &str, parameter: &'static str, p: [f64; 2]) -> Result<(), ModelError> {
    check_finite(element, parameter, p[0])?;
    check_finite(element, parameter, p[1])
}

fn check_timefn(
    element: &str,
    parameter: &'static str,
    f: &crate::TimeFunction,
) -> Result<(), ModelError> {
    if f.is_finite() {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value: f64::NAN,
            reason: "time function coefficients must be finite",
        })
    }
}

impl System {
    pub(crate) fn new(b: SystemBuilder) -> Result<System, ModelError> {
        let SystemBuilder {
            bodies,
            mut joints,
            forces,
            gravity,
        } = b;
        if bodies.is_empty() {
            return Err(ModelError::Empty);
        }
        check_finite("gravity", "gravity", gravity[0])?;
        check_finite("gravity", "gravity", gravity[1])?;
        let mut names = std::collections::HashSet::new();
        for body in &bodies {
            if body.name.eq_ignore_ascii_case("ground") {
                return Err(ModelError::DuplicateName {
                    kind: "body (reserved for the ground)",
                    name: body.name.clone(),
                });
            }
            if !names.insert(body.name.as_str()) {
                return Err(ModelError::DuplicateName {
                    kind: "body",
                    name: body.name.clone(),
                });
            }
            check_positive(&body.name, "mass", body.mass)?;
            check_positive(&body.name, "inertia", body.inertia)?;
            for &p in &body.position {
                check_finite(&body.name, "position", p)?;
            }
            for &v in &body.velocity {
                check_finite(&body.name, "velocity", v)?;
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
            let single = matches!(j.kind, JointKind::Absolute { .. });
            if a == bb && !(single && a.is_some()) {
                return Err(ModelError::SameBody {
                    joint: j.name.clone(),
                    body: body_name(a),
                });
            }
            let name = j.name.clone();
            match &mut j.kind {
                JointKind::Revolute { pa, pb, .. } => {
                    check_point(&name, "point_a", *pa)?;
                    check_point(&name, "point_b", *pb)?;
                }
                JointKind::Weld { pa, pb, angle, .. } => {
                    check_point(&name, "point_a", *pa)?;
                    check_point(&name, "point_b", *pb)?;
                    check_finite(&name, "angle", *angle)?;
                }
                JointKind::Prismatic {
                    pa,
                    pb,
                    axis,
                    angle,
                    ..
                } => {
                    check_point(&name, "point_a", *pa)?;
                    check_point(&name, "point_b", *pb)?;
                    check_point(&name, "axis", *axis)?;
                    check_finite(&name, "angle", *angle)?;
                    let len = (axis[0] * axis[0] + axis[1] * axis[1]).sqrt();
                    check_positive(&name, "axis length", len)?;
                    *axis = [axis[0] / len, axis[1] / len];
                }
                JointKind::Distance { pa, pb, length, .. } => {
                    check_point(&name, "point_a", *pa)?;
                    check_point(&name, "point_b", *pb)?;
                    check_positive(&name, "length", *length)?;
                }
                JointKind::Absolute { point, value, .. } => {
                    check_point(&name, "point", *point)?;
                    check_finite(&name, "value", *value)?;
                }
                JointKind::AngleDriver { f, .. } => check_timefn(&name, "f", f)?,
            }
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
            let single = matches!(f.kind, ForceKind::Force { .. } | ForceKind::Torque { .. });
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
            match &f.kind {
                ForceKind::SpringDamper {
                    pa,
                    pb,
                    stiffness,
                    damping,
                    rest_length,
                    ..
                } => {
                    check_point(&f.name, "point_a", *pa)?;
                    check_point(&f.name, "point_b", *pb)?;
                    check_nonneg(&f.name, "stiffness", *stiffness)?;
                    check_nonneg(&f.name, "damping", *damping)?;
                    check_nonneg(&f.name, "rest_length", *rest_length)?;
                }
                ForceKind::RotarySpringDamper {
                    stiffness,
                    damping,
                    rest_angle,
                    ..
                } => {
                    check_nonneg(&f.name, "stiffness", *stiffness)?;
                    check_nonneg(&f.name, "damping", *damping)?;
                    check_finite(&f.name, "rest_angle", *rest_angle)?;
                }
                ForceKind::Force { point, fx, fy, .. } => {
                    check_point(&f.name, "point", *point)?;
                    check_timefn(&f.name, "fx", fx)?;
                    check_timefn(&f.name, "fy", fy)?;
                }
                ForceKind::Torque { torque, .. } => check_timefn(&f.name, "torque", torque)?,
            }
            force_attach.push(Attach { a, b: bb });
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
        let mass =
            DVector::from_iterator(n, bodies.iter().flat_map(|b| [b.mass, b.mass, b.inertia]));
        let inv_mass = mass.map(|x| 1.0 / x);
        let sys = System {
            bodies,
            joints,
            forces,
            gravity,
            joint_attach,
            force_attach,
            row_offset,
            n,
            m,
            mass,
            inv_mass,
            eq_joint,
        };
        sys.check_inertia_scale()?;
        let (q0, _) = sys.initial_guess();
        sys.check_rank(q0.as_slice(), 0.0)?;
        Ok(sys)
    }

    // ---------------------------------------------------------------- layout and names
}
