//! Validation of a model's spatial bodies and joints, and the lowering of joint markers from
//! the bodies' frames to their principal frames.

use super::body::SpatialBody;
use super::forces::SpatialForce;
use super::joints::{Marker, SpatialJoint};
use super::point_mass::{SpatialPointMass, SpatialPointMassHandle};
use super::system::{SpatialJointEntry, SpatialPart};
use crate::check::invalid;
use crate::error::ModelError;
use std::collections::HashSet;

/// What the builder collects for the spatial part.
#[derive(Clone, Debug, Default)]
pub(crate) struct SpatialInput {
    pub(crate) bodies: Vec<SpatialBody>,
    pub(crate) points: Vec<SpatialPointMass>,
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
            points,
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
        for p in &points {
            crate::check::body_name(body_names, &p.name)?;
            p.validate()?;
            q_init.extend(p.position);
            v_init.extend(p.velocity);
        }
        let names = Names {
            bodies: &bodies,
            points: &points,
        };
        let mut lowered = Vec::with_capacity(joints.len());
        for j in &joints {
            let element = format!("spatial joint '{}'", j.name);
            if !joint_names.insert(j.name.clone()) {
                return Err(ModelError::DuplicateName {
                    kind: "joint",
                    name: j.name.clone(),
                });
            }
            let (a, b) = (names.side(&element, j.a)?, names.side(&element, j.b)?);
            if a == b {
                return Err(ModelError::SameBody {
                    joint: j.name.clone(),
                    body: names.name(a),
                });
            }
            names.check_joint(j)?;
            // markers from the body frame to the principal frame: p' = A^T p, axes' = A^T axes
            // (a point mass has no frame: its marker stays as given)
            let lower = |k: Option<usize>, m: &Marker| match k.filter(|&k| k < bodies.len()) {
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
        let (lowered_forces, force_attach) = lower_forces(&names, &forces, force_names)?;
        let mut part = SpatialPart::new(
            bodies, points, joints, lowered, gravity, q0, r0, q_init, v_init,
        );
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
    names: &Names,
    forces: &[SpatialForce],
    force_names: &mut HashSet<String>,
) -> Result<(Vec<SpatialForce>, Vec<[Option<usize>; 2]>), ModelError> {
    let bodies = names.bodies;
    let (mut lowered, mut attach) = (Vec::new(), Vec::new());
    for f in forces {
        let element = format!("spatial force '{}'", f.name);
        if !force_names.insert(f.name.clone()) {
            return Err(ModelError::DuplicateName {
                kind: "force",
                name: f.name.clone(),
            });
        }
        let (a, b) = (names.side(&element, f.a)?, names.side(&element, f.b)?);
        if a.is_none() && b.is_none() {
            return Err(invalid(
                element,
                "acts on ground only: attach it to a spatial body".to_string(),
            ));
        }
        f.validate()?;
        names.check_force(f)?;
        let axes = |k: Option<usize>| k.and_then(|k| bodies.get(k)).map(|b| b.inertia.axes());
        lowered.push(f.lowered(axes(a), axes(b)));
        attach.push([a, b]);
    }
    Ok((lowered, attach))
}

/// The spatial bodies and point masses of a model, to resolve and check elements' sides.
struct Names<'a> {
    bodies: &'a [SpatialBody],
    points: &'a [SpatialPointMass],
}

impl Names<'_> {
    /// The slot an element's side names (`None`: ground); an error names the element when the
    /// handle is past the model's spatial bodies or point masses.
    fn side(&self, element: &str, r: super::SpatialBodyRef) -> Result<Option<usize>, ModelError> {
        let (nb, np) = (self.bodies.len(), self.points.len());
        match r {
            super::SpatialBodyRef::Body(h) if h.0 >= nb => Err(ModelError::UnknownBody {
                element: element.to_string(),
                body: format!("spatial #{} (the model has {nb} spatial bodies)", h.0),
            }),
            super::SpatialBodyRef::PointMass(h) if h.0 >= np => Err(ModelError::UnknownBody {
                element: element.to_string(),
                body: format!("point mass #{} (the model has {np} point masses)", h.0),
            }),
            r => Ok(r.slot(nb)),
        }
    }

    /// The name of slot `k` (`ground` for `None`).
    fn name(&self, k: Option<usize>) -> String {
        let nb = self.bodies.len();
        match k {
            None => "ground".to_string(),
            Some(k) if k < nb => self.bodies[k].name.clone(),
            Some(k) => self
                .points
                .get(k - nb)
                .map_or_else(String::new, |p| p.name.clone()),
        }
    }

    /// The point mass a side names, if it names one (resolved: its handle was checked).
    fn point_mass(&self, r: super::SpatialBodyRef) -> Option<&str> {
        r.point_mass()
            .and_then(|p| self.points.get(p))
            .map(|p| p.name.as_str())
    }

    /// A joint on a point mass: only kinds that use a point (no axes) on that side, and the
    /// marker at the point mass's position.
    fn check_joint(&self, j: &SpatialJointEntry) -> Result<(), ModelError> {
        let (ma, mb) = j.joint.markers();
        for (s, (r, m)) in [(j.a, ma), (j.b, mb)].into_iter().enumerate() {
            let Some(name) = self.point_mass(r) else {
                continue;
            };
            if j.joint.needs_axes(s) {
                return Err(ModelError::PointMassJoint {
                    joint: j.name.clone(),
                    kind: j.joint.type_name(),
                    point_mass: name.to_string(),
                });
            }
            if m.point != [0.0; 3] {
                return Err(ModelError::PointMassOffset {
                    element: format!("spatial joint '{}'", j.name),
                    point_mass: name.to_string(),
                    point: m.point,
                });
            }
        }
        Ok(())
    }

    /// A force element on a point mass: no torque, no body axes, its points at the position.
    fn check_force(&self, f: &SpatialForce) -> Result<(), ModelError> {
        use super::{Axes, SpatialForceKind};
        let element = format!("spatial force '{}'", f.name);
        let load = |what, name: &str| ModelError::PointMassLoad {
            element: element.clone(),
            point_mass: name.to_string(),
            what,
        };
        let offset = |point: [f64; 3], name: &str| ModelError::PointMassOffset {
            element: element.clone(),
            point_mass: name.to_string(),
            point,
        };
        let (pa, pb) = (self.point_mass(f.a), self.point_mass(f.b));
        match (&f.kind, pa) {
            (SpatialForceKind::Torque(_), Some(name)) => Err(load("torque", name)),
            (SpatialForceKind::Force(l), Some(name)) if l.frame == Axes::Body => {
                Err(load("body axes", name))
            }
            (SpatialForceKind::Force(l), Some(name)) if l.point != [0.0; 3] => {
                Err(offset(l.point, name))
            }
            (SpatialForceKind::SpringDamper(s), _) => {
                for (name, point) in [(pa, s.point_a), (pb, s.point_b)] {
                    if let (Some(name), true) = (name, point != [0.0; 3]) {
                        return Err(offset(point, name));
                    }
                }
                Ok(())
            }
            _ => Ok(()),
        }
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
    /// Adds a spatial point mass (3 coordinates, its position; docs/spatial.md, "Point masses")
    /// and returns its handle, which joints, forces and sensors take where they take a spatial
    /// body ([`crate::spatial::SpatialBodyRef::PointMass`]). `build` checks the mass (positive,
    /// finite) and the state, and rejects joints that need axes on it, marker or load points
    /// off it, and torques on it.
    pub fn add_spatial_point_mass(
        &mut self,
        name: impl Into<String>,
        mass: f64,
        position: [f64; 3],
        velocity: [f64; 3],
    ) -> SpatialPointMassHandle {
        self.add_spatial_point(
            SpatialPointMass::new(name, mass)
                .position(position)
                .velocity(velocity),
        )
    }
    /// Adds a spatial point mass given as a [`SpatialPointMass`] (see
    /// [`crate::SystemBuilder::add_spatial_point_mass`]).
    pub fn add_spatial_point(&mut self, point: SpatialPointMass) -> SpatialPointMassHandle {
        self.spatial.points.push(point);
        SpatialPointMassHandle(self.spatial.points.len() - 1)
    }
    /// Adds a spatial joint between spatial bodies or point masses (or ground); its markers
    /// are in the bodies' frames (ground: global; a point mass: its position, no axes).
    /// Returns its index among the spatial joints.
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
