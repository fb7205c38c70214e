//! Validation of a model's spatial bodies and joints, and the lowering of joint markers from
//! the bodies' frames to their principal frames.

use super::body::SpatialBody;
use super::forces::SpatialForce;
use super::joints::{Marker, SpatialJoint};
use super::system::{SpatialJointEntry, SpatialPart};
use crate::check::invalid;
use crate::error::ModelError;
use std::collections::HashSet;

/// What the builder collects for the spatial part.
#[derive(Clone, Debug, Default)]
pub(crate) struct SpatialInput {
    pub(crate) bodies: Vec<SpatialBody>,
    pub(crate) joints: Vec<SpatialJointEntry>,
    pub(crate) forces: Vec<SpatialForce>,
    pub(crate) gravity: [f64; 3],
}

impl SpatialInput {
    /// Validates and assembles the spatial part after `q0` planar coordinates and `r0` planar
    /// rows; `body_names`, `joint_names` and `force_names` hold the planar names (spatial
    /// names must differ from them and from each other).
    pub(crate) fn build(
        self,
        q0: usize,
        r0: usize,
        body_names: &mut HashSet<String>,
        joint_names: &mut HashSet<String>,
        force_names: &mut HashSet<String>,
    ) -> Result<SpatialPart, ModelError> {
        let SpatialInput {
            bodies,
            joints,
            forces,
            gravity,
        } = self;
        for &g in &gravity {
            crate::check::finite("spatial gravity", "gravity", g)?;
        }
        let (mut q_init, mut v_init) = (Vec::new(), Vec::new());
        for b in &bodies {
            crate::check::body_name(body_names, &b.name)?;
            let (q, v) = b.natural_state()?;
            let kinetic: f64 = b
                .inertia
                .mass_diagonal()
                .iter()
                .zip(&v)
                .map(|(m, v)| 0.5 * m * v * v)
                .sum();
            if !kinetic.is_finite() {
                return Err(invalid(
                    format!("spatial body '{}'", b.name),
                    "velocity and angular_velocity give a kinetic energy that overflows f64"
                        .to_string(),
                ));
            }
            q_init.extend(q);
            v_init.extend(v);
        }
        let nb = bodies.len();
        let mut lowered = Vec::with_capacity(joints.len());
        for j in &joints {
            let element = format!("spatial joint '{}'", j.name);
            if !joint_names.insert(j.name.clone()) {
                return Err(ModelError::DuplicateName {
                    kind: "joint",
                    name: j.name.clone(),
                });
            }
            let (a, b) = (side(&element, j.a, nb)?, side(&element, j.b, nb)?);
            if a == b {
                return Err(ModelError::SameBody {
                    joint: j.name.clone(),
                    body: a.map_or_else(|| "ground".to_string(), |k| bodies[k].name.clone()),
                });
            }
            // markers from the body frame to the principal frame: p' = A^T p, axes' = A^T axes
            let lower = |k: Option<usize>, m: &Marker| match k {
                None => *m,
                Some(k) => {
                    let at = bodies[k].inertia.axes().transpose();
                    Marker::with_axes((at * nalgebra::Vector3::from(m.point)).into(), at * m.axes)
                }
            };
            match (&j.motion, j.joint.is_driver()) {
                (None, true) => {
                    return Err(invalid(
                        element,
                        "a driver needs its motion (SystemBuilder::add_spatial_driver; `motion` \
                         in a model file)"
                            .to_string(),
                    ))
                }
                (Some(_), false) => {
                    return Err(invalid(
                        element,
                        "only the driver kinds (slide_driver, distance_driver, angle_driver) take a motion"
                            .to_string(),
                    ))
                }
                (Some(f), true) => crate::check::time_function(&element, "motion", f)?,
                (None, false) => {}
            }
            let (ma, mb) = j.joint.markers();
            let joint = SpatialJoint::new(j.joint.kind(), lower(a, ma), lower(b, mb))
                .map_err(|e| invalid(element.clone(), e.to_string()))?;
            lowered.push(joint);
        }
        let (lowered_forces, force_attach) = lower_forces(&bodies, &forces, force_names)?;
        let mut part = SpatialPart::new(bodies, joints, lowered, gravity, q0, r0, q_init, v_init);
        part.forces = forces;
        part.lowered_forces = lowered_forces;
        part.force_attach = force_attach;
        Ok(part)
    }
}

/// Validates the force elements (names unique among all forces, bodies known, parameters) and
/// lowers their points and load axes to the principal frames; returns them with their bodies.
#[allow(clippy::type_complexity)]
fn lower_forces(
    bodies: &[SpatialBody],
    forces: &[SpatialForce],
    force_names: &mut HashSet<String>,
) -> Result<(Vec<SpatialForce>, Vec<[Option<usize>; 2]>), ModelError> {
    let nb = bodies.len();
    let (mut lowered, mut attach) = (Vec::new(), Vec::new());
    for f in forces {
        let element = format!("spatial force '{}'", f.name);
        if !force_names.insert(f.name.clone()) {
            return Err(ModelError::DuplicateName {
                kind: "force",
                name: f.name.clone(),
            });
        }
        let (a, b) = (side(&element, f.a, nb)?, side(&element, f.b, nb)?);
        if a.is_none() && b.is_none() {
            return Err(invalid(
                element,
                "acts on ground only: attach it to a spatial body".to_string(),
            ));
        }
        f.validate()?;
        let axes = |k: Option<usize>| k.map(|k| bodies[k].inertia.axes());
        lowered.push(f.lowered(axes(a), axes(b)));
        attach.push([a, b]);
    }
    Ok((lowered, attach))
}

/// The spatial body an element's side names (`None`: ground); an error names the element when
/// the handle is past the model's `nb` spatial bodies.
fn side(element: &str, r: super::SpatialBodyRef, nb: usize) -> Result<Option<usize>, ModelError> {
    match r.index() {
        Some(k) if k >= nb => Err(ModelError::UnknownBody {
            element: element.to_string(),
            body: format!("spatial #{k} (the model has {nb} spatial bodies)"),
        }),
        k => Ok(k),
    }
}

impl crate::SystemBuilder {
    /// Sets the gravity vector of the spatial bodies (m/s^2), e.g. `[0.0, 0.0, -9.81]` (the
    /// planar bodies have theirs, [`crate::SystemBuilder::set_gravity`]).
    pub fn set_spatial_gravity(&mut self, g: [f64; 3]) -> &mut Self {
        self.spatial.gravity = g;
        self
    }
    /// Adds a spatial body (natural coordinates, docs/spatial.md) and returns its handle.
    pub fn add_spatial_body(
        &mut self,
        body: crate::spatial::SpatialBody,
    ) -> crate::spatial::SpatialBodyHandle {
        self.spatial.bodies.push(body);
        crate::spatial::SpatialBodyHandle(self.spatial.bodies.len() - 1)
    }
    /// Adds a spatial joint between spatial bodies (or ground); its markers are in the bodies'
    /// frames (ground: global). Returns its index among the spatial joints.
    pub fn add_spatial_joint(
        &mut self,
        name: impl Into<String>,
        a: impl Into<crate::spatial::SpatialBodyRef>,
        b: impl Into<crate::spatial::SpatialBodyRef>,
        joint: crate::spatial::SpatialJoint,
    ) -> usize {
        self.spatial.joints.push(crate::spatial::SpatialJointEntry {
            name: name.into(),
            a: a.into(),
            b: b.into(),
            joint,
            motion: None,
        });
        self.spatial.joints.len() - 1
    }
    /// Adds a spatial driver (a joint of a driver kind,
    /// [`crate::spatial::SpatialJointKind::SlideDriver`],
    /// [`crate::spatial::SpatialJointKind::DistanceDriver`] or
    /// [`crate::spatial::SpatialJointKind::AngleDriver`]) whose slide, distance (m) or angle
    /// (rad) follows `motion`, a function of time. Returns its index among the spatial joints; `build`
    /// checks the kind and the function.
    pub fn add_spatial_driver(
        &mut self,
        name: impl Into<String>,
        a: impl Into<crate::spatial::SpatialBodyRef>,
        b: impl Into<crate::spatial::SpatialBodyRef>,
        joint: crate::spatial::SpatialJoint,
        motion: crate::timefn::TimeFunction,
    ) -> usize {
        let k = self.add_spatial_joint(name, a, b, joint);
        self.spatial.joints[k].motion = Some(motion);
        k
    }
    /// Adds a force element on spatial bodies (spring-damper, force or torque; points and
    /// load axes in the bodies' frames). Returns its index among the spatial force elements.
    pub fn add_spatial_force(&mut self, force: crate::spatial::SpatialForce) -> usize {
        self.spatial.forces.push(force);
        self.spatial.forces.len() - 1
    }
}
