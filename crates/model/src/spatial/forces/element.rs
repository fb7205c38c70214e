//! The hook of the spatial force elements' potential for derivative passes outside the model
//! (the symplectic crate's modified-Lagrangian series): an element's potential as a generic
//! function of its local variables, and the global column of each, as
//! [`crate::System::force_elements`] with [`crate::Force::potential`] is for planar elements.

use super::{SpatialForce, SpatialForceKind};
use crate::spatial::system::{SpatialPart, SW};
use mbd_jet::Scalar;

/// The number of local variables of a spatial element: twelve per side, the first body's
/// natural coordinates `(x, d_1, d_2, d_3)` and then the second's (a point mass fills the first
/// three of its side, ground none).
pub const SPATIAL_LOCAL_WIDTH: usize = SW;

/// One spatial force element as a derivative pass sees it (from
/// [`crate::System::spatial_force_elements`]): its local columns and its potential over a
/// generic scalar.
///
/// ```
/// use mbd_model::spatial::{SpatialBody, SpatialBodyRef, SpatialForce, SpatialInertia};
/// use mbd_model::SystemBuilder;
/// let mut b = SystemBuilder::new();
/// let inertia = SpatialInertia::principal(1.0, [0.1, 0.2, 0.25])?;
/// let body = b.add_spatial_body(SpatialBody::new("box", inertia));
/// // from the body's centre (at the origin) to the global point (0, 0, 1): length 1, rest 0.5
/// b.add_spatial_force(SpatialForce::spring_damper(
///     "spring", body, [0.0; 3], SpatialBodyRef::Ground, [0.0, 0.0, 1.0], 10.0, 0.0, 0.5,
/// ));
/// let sys = b.build()?;
/// let (q, _) = sys.initial_guess();
/// let e = sys.spatial_force_elements().next().ok_or("no element")?;
/// assert!(e.has_potential());
/// // the body's coordinates are its side's local variables; ground's side has no column
/// let cols = e.columns();
/// assert_eq!(cols[0], sys.body_block(0).map(|(o, _)| o));
/// assert!(cols[12..].iter().all(|c| c.is_none()));
/// // k/2 (l - L)^2 at q
/// let v = e.potential(|_, c| q[c]);
/// assert!((v - 0.5 * 10.0 * 0.25).abs() < 1e-12);
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
#[derive(Clone, Copy, Debug)]
pub struct SpatialForceElement<'a> {
    part: &'a SpatialPart,
    k: usize,
}

impl<'a> SpatialForceElement<'a> {
    pub(crate) fn new(part: &'a SpatialPart, k: usize) -> Self {
        SpatialForceElement { part, k }
    }

    /// The element as given (points and load axes in the bodies' frames).
    pub fn force(&self) -> &'a SpatialForce {
        &self.part.forces[self.k]
    }

    /// The global column of each local variable (`None` on ground and on a point mass's
    /// directors, which are constants).
    pub fn columns(&self) -> [Option<usize>; SW] {
        let sides = self.part.force_attach[self.k];
        std::array::from_fn(|l| self.part.col(sides, l))
    }

    /// Whether the element has a potential: a spring (nonzero stiffness) or a constant force in
    /// global axes. Torques and other loads have none ([`SpatialForceElement::potential`] is
    /// zero for them).
    pub fn has_potential(&self) -> bool {
        match &self.force().kind {
            SpatialForceKind::SpringDamper(s) => s.stiffness != 0.0,
            SpatialForceKind::Force(l) => l.is_constant_global(),
            SpatialForceKind::Torque(_) => false,
        }
    }

    /// The potential of the element's conservative part with local variable `l` made by
    /// `var(l, column)`; `var` is called for the local variables that have a column
    /// ([`SpatialForceElement::columns`]), the others are the constants of ground and of a
    /// point mass's axes.
    pub fn potential<T: Scalar>(&self, var: impl Fn(usize, usize) -> T) -> T {
        let sides = self.part.force_attach[self.k];
        let [fa, fb] = self.part.frames(sides, var);
        self.part.lowered_forces[self.k].potential(&fa, &fb)
    }
}
