//! # mbd-model
//!
//! Planar and spatial rigid multibody systems in absolute Cartesian coordinates, ready for DAE
//! solvers.
//!
//! Body `i` has coordinates `q_i = (x_i, y_i, theta_i)` (centre of mass and rotation); spatial
//! bodies ([`spatial`]) follow the planar ones with 12 natural coordinates each
//! ([`SystemBuilder::add_spatial_body`]), then spatial point masses with 3 each, their position
//! ([`SystemBuilder::add_spatial_point_mass`], [`spatial::SpatialPointMass`]: mass matrix
//! `m I3`, no internal constraint, joints and forces at their point only). A
//! [`System`] is built from [`Body`]s, [`Joint`]s and [`Force`]s with a [`SystemBuilder`] or read
//! from a JSON/TOML [`ModelFile`], and validated on the way. It then evaluates everything a solver
//! of the index-3 equations
//!
//! ```text
//! M q'' + Phi_q^T lambda = Q(q, q', t),    Phi(q, t) = 0
//! ```
//!
//! needs: `M` (constant, diagonal), `Phi`, `Phi_q` (dense or as triplets), `Phi_t`, the
//! acceleration right-hand side `gamma`, the lambda-weighted constraint Hessian, the applied
//! forces with the potential, its gradient and Hessian, energies, point kinematics, and a
//! consistent initial state projected from a guess.
//!
//! Joint and force equations are written once over a generic scalar and differentiated in
//! forward mode (dual-number jets), so Jacobians, `gamma` and Hessians are exact.
//!
//! ```
//! use mbd_model::{Body, BodyRef, Joint, SystemBuilder};
//!
//! let mut b = SystemBuilder::new();
//! b.set_gravity([0.0, -9.81]);
//! // a 1 m, 1 kg rod hanging from the origin
//! let rod = b.add_body(Body::new("rod").rod(1.0, 1.0).position(0.0, -0.5, -std::f64::consts::FRAC_PI_2));
//! b.add_joint(Joint::revolute("pivot", BodyRef::Ground, [0.0, 0.0], rod, [-0.5, 0.0]));
//! let sys = b.build()?;
//! assert_eq!((sys.n_coords(), sys.n_constraints(), sys.dof()), (3, 2, 1));
//!
//! // the stored initial state (here already consistent; `mbd_solve::consistent_state`
//! // projects a guess onto the constraints)
//! let (q0, v0) = sys.initial_guess();
//! let mut phi = vec![0.0; sys.n_constraints()];
//! sys.phi(q0.as_slice(), 0.0, &mut phi);
//! assert!(phi.iter().all(|r| r.abs() < 1e-12));
//! assert!((sys.energy(q0.as_slice(), v0.as_slice()) + 9.81 * 0.5).abs() < 1e-12);
//! # Ok::<(), mbd_model::ModelError>(())
//! ```
#![warn(missing_docs)]
// Index loops over the fixed-size local jets (6 variables, 6x6 Hessians) read like the maths.
#![allow(clippy::needless_range_loop)]

mod assembly;
mod body;
mod body_blocks;
mod builder;
mod cache;
mod check;
mod constraints;
mod dynamics;
mod element;
mod element_hessians;
mod error;
mod file;
#[cfg(any(test, feature = "fixtures"))]
pub mod fixtures;
pub mod forces;
mod generic_rank;
mod init;
pub mod jet;
pub mod joints;
mod kinematics;
mod local_rows;
pub mod models;
mod rows;
mod scale;
mod sensors;
pub mod spatial;
mod system;
mod timefn;

pub use assembly::{JointInitial, JointInitialSpec};
pub use body::{Body, BodyHandle, BodyRef, Coord, Inputs};
pub use builder::SystemBuilder;
pub use cache::BodyAngles;
pub use element::Sketch;
pub use element_hessians::ElementHessian;
pub use error::{num as format_number, ModelError};
pub use file::{
    read_text, BodyKind, BodySpec, EulerSpec, ForceSpec, InitialInput, JointSpec, ModelFile,
    OrientationSpec, SpatialBodyKind, SpatialBodySpec, SpatialForceSpec, SpatialJointSpec,
    SpatialJointType, SpatialPointForceSpec, SpatialSpringDamperSpec, SpatialTorqueSpec,
    MAX_MODEL_FILE_BYTES,
};
pub use forces::{Force, ForceKind};
pub use init::{RedundantConstraints, RedundantEquation, SPARSE_RANK_THRESHOLD};
pub use jet::{Basis, PolyJet, MAX_DIRS};
pub use joints::RevoluteSide;
pub use joints::{Coordinate, Joint, JointKind};
pub use scale::{MAX_INERTIA_RATIO, MAX_MASS_RATIO};
pub use sensors::{Sensor, SensorKind, SensorSpec};
pub use system::{Attach, ForceHandle, JointElement, JointHandle, System};
pub use timefn::{
    Extrapolation, Interpolation, Table, TableError, TableSpec, TimeFunction, MAX_TABLE_FILE_BYTES,
};

pub use nalgebra;
