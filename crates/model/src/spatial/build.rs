//! Validation of a model's spatial bodies and joints, and the lowering of joint markers from
//! the bodies' frames to their principal frames.

use super::body::SpatialBody;
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
    pub(crate) gravity: [f64; 3],
}

impl SpatialInput {
    /// Validates and assembles the spatial part after `q0` planar coordinates and `r0` planar
    /// rows; `body_names` and `joint_names` hold the planar names (spatial names must differ
    /// from them and from each other).
    pub(crate) fn build(
        self,
        q0: usize,
        r0: usize,
        body_names: &mut HashSet<String>,
        joint_names: &mut HashSet<String>,
    ) -> Result<SpatialPart, ModelError> {
        let SpatialInput {
            bodies,
            joints,
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
            let side = |r: super::SpatialBodyRef| -> Result<Option<usize>, ModelError> {
                match r.index() {
                    Some(k) if k >= nb => Err(ModelError::UnknownBody {
                        element: element.clone(),
                        body: format!("spatial #{k} (the model has {nb} spatial bodies)"),
                    }),
                    k => Ok(k),
                }
            };
            let (a, b) = (side(j.a)?, side(j.b)?);
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
            let (ma, mb) = j.joint.markers();
            let joint = SpatialJoint::new(j.joint.kind(), lower(a, ma), lower(b, mb))
                .map_err(|e| invalid(element.clone(), e.to_string()))?;
            lowered.push(joint);
        }
        Ok(SpatialPart::new(
            bodies, joints, lowered, gravity, q0, r0, q_init, v_init,
        ))
    }
}
