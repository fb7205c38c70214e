//! Spatial point masses: a particle with 3 coordinates (its position), mass matrix `m I3`, no
//! internal constraints and no rotational inertia (docs/spatial.md, "Point masses").

use crate::check::invalid;
use crate::error::ModelError;

/// Handle of a spatial point mass inside a model, given by
/// [`crate::SystemBuilder::add_spatial_point_mass`]; it converts into a
/// [`super::SpatialBodyRef`], so joints, forces and sensors take it where they take a spatial
/// body.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct SpatialPointMassHandle(pub(crate) usize);

impl SpatialPointMassHandle {
    /// The point mass's position among the model's spatial point masses (insertion order).
    pub fn index(self) -> usize {
        self.0
    }
}

/// A spatial point mass: a particle of mass `mass` at `position` moving with `velocity`. Its
/// coordinates in the model are its position `(x, y, z)`, after every spatial rigid body's
/// (see [`crate::System::spatial_point_mass_offset`]); it has a point (its position) but no
/// axes, so it takes the joints whose equations use only a point on its side.
///
/// ```
/// use mbd_model::spatial::SpatialPointMass;
/// let bob = SpatialPointMass::new("bob", 2.0).position([1.0, 0.0, 0.0]).velocity([0.0, 1.0, 0.0]);
/// assert_eq!(bob.mass, 2.0);
/// ```
#[derive(Clone, Debug, PartialEq)]
pub struct SpatialPointMass {
    /// Unique name (among planar and spatial bodies).
    pub name: String,
    /// Mass (kg), positive and finite.
    pub mass: f64,
    /// Initial position, global (m).
    pub position: [f64; 3],
    /// Initial velocity, global (m/s).
    pub velocity: [f64; 3],
}

impl SpatialPointMass {
    /// A point mass at the origin, at rest.
    pub fn new(name: impl Into<String>, mass: f64) -> Self {
        SpatialPointMass {
            name: name.into(),
            mass,
            position: [0.0; 3],
            velocity: [0.0; 3],
        }
    }
    /// Sets the initial position.
    pub fn position(mut self, x: [f64; 3]) -> Self {
        self.position = x;
        self
    }
    /// Sets the initial velocity.
    pub fn velocity(mut self, v: [f64; 3]) -> Self {
        self.velocity = v;
        self
    }

    /// Checks the mass and the initial state; errors name the point mass and the field.
    pub(crate) fn validate(&self) -> Result<(), ModelError> {
        let element = format!("spatial point mass '{}'", self.name);
        crate::check::positive(&element, "mass", self.mass)?;
        for (field, v) in [("position", self.position), ("velocity", self.velocity)] {
            if v.iter().any(|x| !x.is_finite()) {
                return Err(invalid(element, format!("{field} {v:?} must be finite")));
            }
        }
        let v2: f64 = self.velocity.iter().map(|v| v * v).sum();
        if !(0.5 * self.mass * v2).is_finite() {
            return Err(invalid(
                element,
                "velocity gives a kinetic energy that overflows f64".to_string(),
            ));
        }
        Ok(())
    }
}

impl super::system::SpatialPart {
    /// The first coordinate of the point masses: after every spatial body's 12.
    pub(crate) fn point_offset(&self) -> usize {
        self.q0 + 12 * self.bodies.len()
    }

    /// The number of slots: spatial bodies, then point masses.
    pub(crate) fn n_slots(&self) -> usize {
        self.bodies.len() + self.points.len()
    }

    /// Slot `k`'s first coordinate and width: 12 for a rigid body, 3 for a point mass.
    pub(crate) fn slot_block(&self, k: usize) -> (usize, usize) {
        let ns = self.bodies.len();
        if k < ns {
            (self.q0 + 12 * k, 12)
        } else {
            (self.point_offset() + 3 * (k - ns), 3)
        }
    }

    /// Slot `k`'s mass (0 past the last slot).
    pub(crate) fn slot_mass(&self, k: usize) -> f64 {
        let ns = self.bodies.len();
        match self.bodies.get(k) {
            Some(b) => b.inertia.mass(),
            None => self.points.get(k - ns).map_or(0.0, |p| p.mass),
        }
    }

    /// Slot `k`'s 12 local coordinates and velocities at `(q, v)` (`v = None`: at rest): a
    /// rigid body's natural coordinates, or a point mass's position with the global axes as
    /// constant directors.
    pub(crate) fn local_state(
        &self,
        k: usize,
        q: &[f64],
        v: Option<&[f64]>,
    ) -> ([f64; 12], [f64; 12]) {
        let (o, w) = self.slot_block(k);
        let (mut ql, mut vl) = (super::system::IDENTITY, [0.0; 12]);
        ql[..w].copy_from_slice(&q[o..o + w]);
        if let Some(v) = v {
            vl[..w].copy_from_slice(&v[o..o + w]);
        }
        (ql, vl)
    }
}

/// A side's local state from [`super::system::SpatialPart::local_state`] as the slices the
/// joints' jets take.
pub(crate) fn as_side(l: &Option<([f64; 12], [f64; 12])>) -> Option<(&[f64], &[f64])> {
    l.as_ref().map(|(q, v)| (&q[..], &v[..]))
}

#[cfg(test)]
#[path = "point_mass_tests.rs"]
mod tests;
