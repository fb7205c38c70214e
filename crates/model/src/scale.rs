//! Scales of a mechanism: its characteristic length, the natural unit of each constraint
//! equation, and the build-time check that no body's inertia is negligible against its mass.

use crate::element::norm;
use crate::error::ModelError;
use crate::system::System;

/// `m r^2 / J` above which a body's rotational inertia counts as negligible (see
/// [`ModelError::NegligibleInertia`]). The Schur complement `Phi_q M^-1 Phi_q^T` of a body pinned
/// at lever arm `r` has condition about `1 + m r^2 / J`; beyond `1e12` an index-1 solve keeps at
/// most four significant digits, and near `1e14` every solver reports a singular matrix.
pub const MAX_INERTIA_RATIO: f64 = 1e12;

/// Largest ratio of two bodies' masses (planar bodies, spatial bodies and spatial point masses;
/// see [`ModelError::MassRatio`]). The Schur complement `Phi_q M^-1 Phi_q^T` of two joined
/// bodies has condition about the ratio of their masses: beyond `1e12` an index-1 solve keeps at
/// most four significant digits, and the consistent initial state's projection reports a
/// singular matrix.
pub const MAX_MASS_RATIO: f64 = 1e12;

impl System {
    /// Rejects a model whose heaviest and lightest bodies' masses differ by more than
    /// [`MAX_MASS_RATIO`] (a mass of 1e-300 kg beside one of 2 kg: the projection of the
    /// initial state failed with "singular projection matrix ... check the initial positions").
    pub(crate) fn check_mass_ratio(&self) -> Result<(), ModelError> {
        let masses = self
            .bodies
            .iter()
            .map(|b| (b.name.as_str(), b.mass))
            .chain(
                self.spatial
                    .bodies
                    .iter()
                    .map(|b| (b.name.as_str(), b.inertia.mass())),
            )
            .chain(
                self.spatial
                    .points
                    .iter()
                    .map(|p| (p.name.as_str(), p.mass)),
            );
        let (mut light, mut heavy) = (("", f64::INFINITY), ("", 0.0f64));
        for (name, m) in masses {
            if m < light.1 {
                light = (name, m);
            }
            if m > heavy.1 {
                heavy = (name, m);
            }
        }
        let ratio = heavy.1 / light.1;
        if ratio > MAX_MASS_RATIO {
            return Err(ModelError::MassRatio {
                light: light.0.to_string(),
                light_mass: light.1,
                heavy: heavy.0.to_string(),
                heavy_mass: heavy.1,
                ratio,
            });
        }
        Ok(())
    }

    /// Body points of joint `j` as `(body index, lever arm from the centre of mass)` pairs.
    fn joint_lever_arms(&self, ji: usize) -> [(Option<usize>, f64); 2] {
        let at = self.joint_attach[ji];
        let [pa, pb] = self.joints[ji].lever_arms();
        let side = |body: Option<usize>, p: Option<[f64; 2]>| match p {
            Some(p) => (body, norm(p)),
            None => (None, 0.0),
        };
        [side(at.a, pa), side(at.b, pb)]
    }

    /// The mechanism's characteristic length: the largest lever arm of a joint point on a body
    /// (distance from the body's centre of mass), distance-joint length or radius of gyration
    /// `sqrt(J / m)`; 1 if all of them are zero. Used to scale constraint tolerances (e.g. the
    /// run loop's drift guard) so that they mean the same for a watch mechanism and a crane.
    pub fn length_scale(&self) -> f64 {
        let mut l = 0.0f64;
        for ji in 0..self.joints.len() {
            for (body, r) in self.joint_lever_arms(ji) {
                if body.is_some() {
                    l = l.max(r);
                }
            }
            if let Some(length) = self.joints[ji].length() {
                l = l.max(length);
            }
        }
        for b in &self.bodies {
            l = l.max((b.inertia / b.mass).sqrt());
        }
        l = l.max(self.spatial.length_scale());
        if l > 0.0 && l.is_finite() {
            l
        } else {
            1.0
        }
    }

    /// The natural unit of constraint equation `row`: 1 (radian) for angle equations (the angle
    /// rows of prismatic and weld joints, fixed angles, angle drivers), the
    /// [`System::length_scale`] for equations in lengths. `|Phi_row| / equation_scale(row)` is
    /// a relative violation.
    pub fn equation_scale(&self, row: usize) -> f64 {
        if row >= self.m || self.is_angle_equation(row) {
            1.0
        } else if row >= self.spatial.r0 {
            self.spatial.equation_scale(row, self.length_scale())
        } else {
            self.length_scale()
        }
    }

    /// [`System::equation_scale`] of every equation, with the length scale computed once.
    pub fn equation_scales(&self) -> Vec<f64> {
        let l = self.length_scale();
        (0..self.m)
            .map(|r| {
                if self.is_angle_equation(r) {
                    1.0
                } else if r >= self.spatial.r0 {
                    self.spatial.equation_scale(r, l)
                } else {
                    l
                }
            })
            .collect()
    }

    /// Whether equation `row` is an angle equation (false for rows out of range).
    fn is_angle_equation(&self, row: usize) -> bool {
        self.eq_joint.get(row).is_some_and(|&ji| {
            self.joints[ji].equation_labels()[row - self.row_offset[ji]] == "angle"
        })
    }

    /// Rejects a body whose inertia is negligible against its mass times the square of the
    /// lever arm of a joint point on it (`m r^2 / J >` [`MAX_INERTIA_RATIO`]).
    pub(crate) fn check_inertia_scale(&self) -> Result<(), ModelError> {
        for ji in 0..self.joints.len() {
            for (body, r) in self.joint_lever_arms(ji) {
                let Some(bi) = body else { continue };
                let b = &self.bodies[bi];
                let ratio = b.mass * r * r / b.inertia;
                if ratio > MAX_INERTIA_RATIO {
                    return Err(ModelError::NegligibleInertia {
                        body: b.name.clone(),
                        inertia: b.inertia,
                        mass: b.mass,
                        joint: self.joints[ji].name.clone(),
                        lever: r,
                        ratio,
                    });
                }
            }
        }
        Ok(())
    }
}
