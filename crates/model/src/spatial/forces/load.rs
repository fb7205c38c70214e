//! Applied loads on a spatial body: a force at a body point, or a torque, with components in
//! global or body axes given as functions of time.

use super::SW;
use crate::check;
use crate::error::ModelError;
use crate::spatial::joints::{dot3, SpatialFrame};
use crate::timefn::TimeFunction;
use mbd_jet::Scalar;
use nalgebra::{Matrix3, Vector3};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The axes a vector is given in: a load's components, a body's initial angular velocity.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize, Deserialize, JsonSchema)]
#[serde(rename_all = "snake_case")]
pub enum Axes {
    /// The global (inertial) axes: a load keeps its direction in space.
    #[default]
    Global,
    /// The body's axes: a load turns with the body (a follower load, e.g. a thruster or a
    /// motor's torque).
    Body,
}

/// A force or torque on one spatial body: components as functions of time in `frame`, and
/// for a force its point of application.
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialLoad {
    /// The point of application (body frame, from the centre of mass, m); unused by a torque.
    pub point: [f64; 3],
    /// The components (N or N m) along the axes of `frame`.
    pub components: [TimeFunction; 3],
    /// The axes of the components.
    pub frame: Axes,
    /// Body-frame components to principal-frame ones (`A^T` once lowered; the identity for
    /// global loads and before lowering).
    pub(crate) to_principal: Matrix3<f64>,
}

impl SpatialLoad {
    /// A load with these components.
    pub fn new(point: [f64; 3], components: [TimeFunction; 3], frame: Axes) -> Self {
        SpatialLoad {
            point,
            components,
            frame,
            to_principal: Matrix3::identity(),
        }
    }

    /// Whether the load is constant in global axes (a force of this kind is conservative).
    pub(crate) fn is_constant_global(&self) -> bool {
        self.frame == Axes::Global && self.components.iter().all(|c| c.is_constant())
    }

    /// The components at time `t`.
    fn at(&self, t: f64) -> [f64; 3] {
        std::array::from_fn(|k| self.components[k].eval(t)[0])
    }

    /// The load's global vector at time `t` on the body frame `f`.
    fn global(&self, f: &SpatialFrame<f64>, t: f64) -> [f64; 3] {
        let u = self.at(t);
        match self.frame {
            Axes::Global => u,
            Axes::Body => f.direction((self.to_principal * Vector3::from(u)).into()),
        }
    }

    /// `-F . P`: the potential of a constant global force (zero otherwise).
    pub(crate) fn force_potential<T: Scalar>(&self, f: &SpatialFrame<T>) -> T {
        if !self.is_constant_global() {
            return T::cst(0.0);
        }
        let p = f.point(self.point);
        -dot3(p, self.at(0.0).map(T::cst))
    }

    /// Adds the generalised force of the force, `(F, p_1 F, p_2 F, p_3 F)`, to the first
    /// body's entries of `out`.
    pub(crate) fn add_force(&self, f: &SpatialFrame<f64>, t: f64, out: &mut [f64; SW]) {
        let g = self.global(f, t);
        for c in 0..3 {
            out[c] += g[c];
            for i in 0..3 {
                out[3 + 3 * i + c] += self.point[i] * g[c];
            }
        }
    }

    /// Adds the generalised force of the torque, `1/2 tau x d_i` on director `i`, to the first
    /// body's entries of `out`.
    pub(crate) fn add_torque(&self, f: &SpatialFrame<f64>, t: f64, out: &mut [f64; SW]) {
        let tau = Vector3::from(self.global(f, t));
        for (i, d) in f.d.iter().enumerate() {
            let q = tau.cross(&Vector3::from(*d)) * 0.5;
            for c in 0..3 {
                out[3 + 3 * i + c] += q[c];
            }
        }
    }

    /// Checks the point (forces only) and the components; errors name `element`.
    pub(crate) fn validate(&self, element: &str, force: bool) -> Result<(), ModelError> {
        if force {
            for &x in &self.point {
                check::finite(element, "point", x)?;
            }
        }
        let names = if force {
            ["fx", "fy", "fz"]
        } else {
            ["tx", "ty", "tz"]
        };
        for (c, name) in self.components.iter().zip(names) {
            check::time_function(element, name, c)?;
        }
        Ok(())
    }
}
