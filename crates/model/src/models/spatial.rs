//! Spatial example models (natural coordinates, docs/spatial.md).

use crate::builder::SystemBuilder;
use crate::error::ModelError;
use crate::spatial::{
    Marker, Orientation, SpatialBody, SpatialBodyRef, SpatialForce, SpatialInertia, SpatialJoint,
    SpatialJointKind,
};
use crate::system::System;
use nalgebra::{Matrix3, Rotation3, Vector3};

/// Distance from a top's tip to its centre of mass (m).
pub const TOP_LENGTH: f64 = 0.5;

/// A heavy top: a 1 kg body with principal moments `moments` about its centre of mass
/// (symmetry axis along its body `z`), its tip held at the origin by a spherical joint and its
/// centre of mass [`TOP_LENGTH`] up its axis from the tip; tilted by `tilt` (rad) about the
/// global `x` axis, spinning at `spin` (rad/s) about its own axis, gravity 9.81 m/s^2 along
/// `-z`. `moments = [a, a, 2a]` is a flat disc on a massless axle (`E_3 = 0`, a singular mass
/// matrix); `[a, 2a, a]` puts the symmetry elsewhere and is the classic singular case too.
///
/// ```
/// let top = mbd_model::models::heavy_top([0.3, 0.3, 0.1], 0.3, 20.0)?;
/// assert_eq!((top.n_coords(), top.n_constraints(), top.dof()), (12, 9, 3));
/// # Ok::<(), mbd_model::ModelError>(())
/// ```
pub fn heavy_top(moments: [f64; 3], tilt: f64, spin: f64) -> Result<System, ModelError> {
    let inertia = SpatialInertia::principal(1.0, moments)
        .map_err(|e| crate::check::invalid("spatial body 'top'".into(), e.to_string()))?;
    let r = *Rotation3::from_axis_angle(&Vector3::x_axis(), tilt).matrix();
    let axis = r * Vector3::z();
    let x = axis * TOP_LENGTH;
    let w = axis * spin;
    let v = w.cross(&x);
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let top = b.add_spatial_body(
        SpatialBody::new("top", inertia)
            .position(x.into())
            .orientation(Orientation::Matrix(r))
            .velocity(v.into())
            .angular_velocity(w.into()),
    );
    let joint = SpatialJoint::new(
        SpatialJointKind::Spherical,
        Marker::at([0.0; 3]),
        Marker::at([0.0, 0.0, -TOP_LENGTH]),
    )
    .map_err(|e| crate::check::invalid("spatial joint 'tip'".into(), e.to_string()))?;
    b.add_spatial_joint("tip", SpatialBodyRef::Ground, top, joint);
    b.build()
}

/// A torque-free body: principal moments `moments`, 1 kg, at the origin with its axes along
/// the global ones, spinning at `omega` (global axes), no gravity and no joint.
pub fn free_body(moments: [f64; 3], omega: [f64; 3]) -> Result<System, ModelError> {
    let inertia = SpatialInertia::principal(1.0, moments)
        .map_err(|e| crate::check::invalid("spatial body 'body'".into(), e.to_string()))?;
    let mut b = SystemBuilder::new();
    b.add_spatial_body(
        SpatialBody::new("body", inertia)
            .orientation(Orientation::Matrix(Matrix3::identity()))
            .angular_velocity(omega),
    );
    b.build()
}

/// The inertia of a bar of square cross-section: `mass` (kg), `length` along its first
/// principal axis, side `side` (m); the principal axes are the columns of `axes` (body frame).
fn bar(
    element: &str,
    mass: f64,
    length: f64,
    side: f64,
    axes: Matrix3<f64>,
) -> Result<SpatialInertia, ModelError> {
    let axial = mass * side * side / 6.0;
    let cross = mass * (length * length + side * side) / 12.0;
    SpatialInertia::principal_with_axes(mass, [axial, cross, cross], axes)
        .map_err(|e| crate::check::invalid(element.to_string(), e.to_string()))
}

/// A spatial joint of `kind` between markers `a` and `b`, its errors naming the joint.
fn joint(
    name: &str,
    kind: SpatialJointKind,
    a: Marker,
    b: Marker,
) -> Result<SpatialJoint, ModelError> {
    SpatialJoint::new(kind, a, b)
        .map_err(|e| crate::check::invalid(format!("spatial joint '{name}'"), e.to_string()))
}

/// Length of each rod of [`spatial_double_pendulum`] (m).
pub const DOUBLE_PENDULUM_ROD: f64 = 1.0;

/// A spatial double pendulum: two bars (1 kg, [`DOUBLE_PENDULUM_ROD`] long, square section
/// 0.05 m, long axis along their body `z`), the first hung from the origin by a spherical joint,
/// the second from the first's lower end by another, gravity 9.81 m/s^2 along `-z`. Both start
/// straight in the `x`-`z` plane, the first tilted 0.6 rad and the second 1.1 rad from the
/// downward vertical (body frames turned about `y`: `euler xyz [0, angle, 0]`), turning about
/// the vertical at 1.5 and 2.5 rad/s: velocities out of their plane, so the motion is
/// genuinely spatial (and chaotic). Consistent initial state (the velocities are rigid motions
/// that keep the joints together). The angular momentum about the vertical through the pivot
/// and the energy are conserved. Model file: `examples/models/spatial_double_pendulum.toml`.
///
/// ```
/// let p = mbd_model::models::spatial_double_pendulum()?;
/// // 2 x 12 natural coordinates, 2 x 6 director constraints and two ball joints of 3
/// assert_eq!((p.n_coords(), p.n_constraints(), p.dof()), (24, 18, 6));
/// assert_eq!(p.n_redundant(), 0);
/// # Ok::<(), mbd_model::ModelError>(())
/// ```
pub fn spatial_double_pendulum() -> Result<System, ModelError> {
    let l = DOUBLE_PENDULUM_ROD;
    // the bars' long axis is their body z: principal axes (z, x, y) for moments (axial, cross,
    // cross)
    let along_z = Matrix3::from_columns(&[Vector3::z(), Vector3::x(), Vector3::y()]);
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let mut prev = SpatialBodyRef::Ground;
    // the upper end of the current bar and its velocity
    let (mut top, mut top_v) = (Vector3::zeros(), Vector3::zeros());
    for (k, (tilt, spin)) in [(0.6, 1.5), (1.1, 2.5)].into_iter().enumerate() {
        let name = format!("rod{}", k + 1);
        let orientation = Orientation::Euler(crate::spatial::EulerSequence::Xyz, [0.0, tilt, 0.0]);
        let r = orientation
            .matrix()
            .map_err(|e| crate::check::invalid(format!("spatial body '{name}'"), e))?;
        // body z points up the bar, towards its upper joint
        let up = r * Vector3::z();
        let x = top - up * (0.5 * l);
        let omega = Vector3::new(0.0, 0.0, spin);
        let v = top_v + omega.cross(&(x - top));
        let body = b.add_spatial_body(
            SpatialBody::new(
                name.clone(),
                bar(&format!("spatial body '{name}'"), 1.0, l, 0.05, along_z)?,
            )
            .position(x.into())
            .orientation(orientation)
            .velocity(v.into())
            .angular_velocity(omega.into()),
        );
        let upper = Marker::at([0.0, 0.0, 0.5 * l]);
        let (jname, a) = match prev {
            SpatialBodyRef::Ground => ("shoulder", Marker::at([0.0; 3])),
            SpatialBodyRef::Body(_) | SpatialBodyRef::PointMass(_) => {
                ("elbow", Marker::at([0.0, 0.0, -0.5 * l]))
            }
        };
        b.add_spatial_joint(
            jname,
            prev,
            body,
            joint(jname, SpatialJointKind::Spherical, a, upper)?,
        );
        prev = SpatialBodyRef::Body(body);
        top = x - up * (0.5 * l);
        top_v = v + omega.cross(&(top - x));
    }
    b.build()
}

/// Marker axes whose `z` is the global (body) `x` axis: the columns `(y, z, x)`.
fn z_along_x() -> Matrix3<f64> {
    Matrix3::from_columns(&[Vector3::y(), Vector3::z(), Vector3::x()])
}

/// Marker axes whose `z` is the global (body) `y` axis: the columns `(z, x, y)`.
fn z_along_y() -> Matrix3<f64> {
    Matrix3::from_columns(&[Vector3::z(), Vector3::x(), Vector3::y()])
}

/// The spatial slider-crank of Haug (E. J. Haug, *Computer-Aided Kinematics and Dynamics of
/// Mechanical Systems*, Allyn and Bacon 1989, the spatial slider-crank example), under gravity
/// 9.81 m/s^2 along `-z`:
///
/// * the crank (0.12 kg, principal moments `(1e-4, 1e-5, 1e-4)` kg m^2, 0.08 m long along its
///   body `y`) turns on a revolute joint about the global `x` axis through `O = (0, 0.1,
///   0.12)`, its centre of mass 0.04 m from `O`; it starts pointing up (`+z`), its body frame
///   turned by 90 degrees about `x`;
/// * the connecting rod (0.5 kg, moments `(4e-4, 4e-3, 4e-3)`, 0.3 m long along its body `x`)
///   joins the crank pin `B = (0, 0.1, 0.2)` by a spherical joint and the slider at
///   `C = (0.2, 0, 0)` by a universal joint: the cross's arm on the slider along the global `y`,
///   its arm on the rod along the rod's body `y`, the direction `(1, 0, 1)/sqrt 2` (both
///   perpendicular to the rod `u = (2, -1, -2)/3`; the rod's frame is `(u, w, u x w)`);
/// * the slider (2 kg, moments `1e-4` each) moves on a prismatic joint along the global `x`
///   axis.
///
/// 3 bodies (36 coordinates), 18 director constraints and 5 + 3 + 4 + 5 joint equations: one
/// degree of freedom (a spherical joint at both ends of the rod would leave its spin free; the
/// universal joint locks it). The crank starts with angular velocity `crank_speed` (rad/s)
/// about the global `x` axis, every body moving consistently with it (slider speed
/// `0.04 crank_speed`). Model file: `examples/models/spatial_slider_crank.toml` (crank speed
/// `-2 pi`).
///
/// ```
/// let sc = mbd_model::models::spatial_slider_crank(-2.0 * std::f64::consts::PI)?;
/// assert_eq!((sc.n_coords(), sc.n_constraints(), sc.dof()), (36, 35, 1));
/// assert_eq!(sc.n_redundant(), 0);
/// # Ok::<(), mbd_model::ModelError>(())
/// ```
pub fn spatial_slider_crank(crank_speed: f64) -> Result<System, ModelError> {
    crate::check::finite("spatial slider-crank", "crank_speed", crank_speed)?;
    let pivot = Vector3::new(0.0, 0.1, 0.12);
    let (crank_len, rod_len) = (0.08, 0.3);
    // the crank's body y along +z: a quarter turn about x, written exactly
    let crank_r = Matrix3::new(1.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 1.0, 0.0);
    let pin = pivot + Vector3::z() * crank_len;
    let slider_x = Vector3::new(0.2, 0.0, 0.0);
    let d = slider_x - pin;
    let u = d / rod_len;
    let w = Vector3::new(1.0, 0.0, 1.0) / 2f64.sqrt();
    let rod_r = Matrix3::from_columns(&[u, w, u.cross(&w)]);
    // velocities: the crank turns about x, the slider keeps the rod's length, and the rod
    // turns about the universal joint's two arms (w and the global y)
    let omega_c = Vector3::new(crank_speed, 0.0, 0.0);
    let v_pin = omega_c.cross(&(pin - pivot));
    let v_slider = Vector3::x() * (d.dot(&v_pin) / d.x);
    let dv = v_slider - v_pin;
    let a = nalgebra::Matrix3x2::from_columns(&[w.cross(&d), Vector3::y().cross(&d)]);
    let ab = (a.transpose() * a)
        .try_inverse()
        .map(|inv| inv * a.transpose() * dv)
        .ok_or_else(|| {
            crate::check::invalid(
                "spatial slider-crank".into(),
                "the rod's angular velocity".into(),
            )
        })?;
    let omega_r = w * ab[0] + Vector3::y() * ab[1];
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let principal = |name: &str, m: f64, j: [f64; 3]| {
        SpatialInertia::principal(m, j)
            .map_err(|e| crate::check::invalid(format!("spatial body '{name}'"), e.to_string()))
    };
    let crank_x = pivot + Vector3::z() * (0.5 * crank_len);
    let crank = b.add_spatial_body(
        SpatialBody::new("crank", principal("crank", 0.12, [1e-4, 1e-5, 1e-4])?)
            .position(crank_x.into())
            .orientation(Orientation::Matrix(crank_r))
            .velocity(omega_c.cross(&(crank_x - pivot)).into())
            .angular_velocity(omega_c.into()),
    );
    let rod = b.add_spatial_body(
        SpatialBody::new("rod", principal("rod", 0.5, [4e-4, 4e-3, 4e-3])?)
            .position((pin + d * 0.5).into())
            .orientation(Orientation::Matrix(rod_r))
            .velocity(((v_pin + v_slider) * 0.5).into())
            .angular_velocity(omega_r.into()),
    );
    let slider = b.add_spatial_body(
        SpatialBody::new("slider", principal("slider", 2.0, [1e-4; 3])?)
            .position(slider_x.into())
            .velocity(v_slider.into()),
    );
    let half = 0.5 * crank_len;
    b.add_spatial_joint(
        "crank_pivot",
        SpatialBodyRef::Ground,
        crank,
        joint(
            "crank_pivot",
            SpatialJointKind::Revolute,
            Marker::with_axes(pivot.into(), z_along_x()),
            Marker::with_axes([0.0, -half, 0.0], z_along_x()),
        )?,
    );
    b.add_spatial_joint(
        "crank_pin",
        crank,
        rod,
        joint(
            "crank_pin",
            SpatialJointKind::Spherical,
            Marker::at([0.0, half, 0.0]),
            Marker::at([-0.5 * rod_len, 0.0, 0.0]),
        )?,
    );
    b.add_spatial_joint(
        "cardan",
        slider,
        rod,
        joint(
            "cardan",
            SpatialJointKind::Universal,
            Marker::with_axes([0.0; 3], z_along_x()),
            Marker::at([0.5 * rod_len, 0.0, 0.0]),
        )?,
    );
    b.add_spatial_joint(
        "slide",
        SpatialBodyRef::Ground,
        slider,
        joint(
            "slide",
            SpatialJointKind::Prismatic,
            Marker::with_axes([0.0; 3], z_along_x()),
            Marker::with_axes([0.0; 3], z_along_x()),
        )?,
    );
    b.build()
}

/// The joint points of [`bricard`] (m): link `k` (1 to 5) runs from `BRICARD_POINTS[k - 1]`
/// to `BRICARD_POINTS[k]`, the ground closes the loop from the last point to the first.
pub const BRICARD_POINTS: [[f64; 3]; 6] = [
    [0.0, 0.0, 0.0],
    [1.0, 0.0, 0.0],
    [1.0, 0.0, -1.0],
    [1.0, -1.0, -1.0],
    [0.0, -1.0, -1.0],
    [0.0, -1.0, 0.0],
];

/// The Bricard linkage, benchmark A04 of the IFToMM library of computational benchmark
/// problems for multibody dynamics (M. González et al., "A benchmarking system for MBS
/// simulation software", Multibody System Dynamics 16, 2006;
/// `lim.ii.udc.es/mbsbenchmark/dist/A04/A04_specification.xml`): five bars of 1 m and 1 kg
/// (square section 0.1 m) and six revolute joints closing a loop with the ground, released at
/// rest under gravity 9.81 m/s^2. Grübler's count gives no freedom (5 x 6 - 6 x 5 = 0), but the
/// joint axes make it mobile with one degree of freedom: one equation is redundant.
///
/// The geometry is the benchmark's, as other codes give it (the EXUDYN test model
/// `bricardMechanism.py`, simEngine3D's Bricard driver), turned by 90 degrees about `x` so that
/// the benchmark's vertical `y` is `z` here: the joints sit at [`BRICARD_POINTS`] (the corners
/// of the unit cube `(0, 0, 0), (1, 0, 0), (1, 0, -1), (1, -1, -1), (0, -1, -1), (0, -1, 0)`),
/// each joint's axis perpendicular to the two bars it joins (`z`, `y`, `x`, `z`, `y`, `x` in
/// turn), the ground bar from the last point to the first along `+y`. The bodies' frames are
/// the global axes at the start (their principal axes, the bar first, given in the body frame),
/// so each marker is its global point less the bar's centre. Gravity along `-z`.
/// Model file: `examples/models/bricard.toml`.
///
/// ```
/// let b = mbd_model::models::bricard()?;
/// // 5 x 12 coordinates, 5 x 6 director constraints, 6 x 5 hinge equations: 60 equations of
/// // rank 59
/// assert_eq!((b.n_coords(), b.n_constraints()), (60, 60));
/// assert_eq!((b.n_redundant(), b.dof()), (1, 1));
/// # Ok::<(), mbd_model::ModelError>(())
/// ```
pub fn bricard() -> Result<System, ModelError> {
    let p = BRICARD_POINTS.map(Vector3::from);
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let mut links = Vec::new();
    for k in 0..5 {
        let name = format!("link{}", k + 1);
        let along = p[k + 1] - p[k];
        // principal axes (the bar, then two across it), a right-handed permutation of the
        // global axes
        let axes = match along.iamax() {
            0 => Matrix3::identity(),
            1 => z_along_x(),
            _ => z_along_y(),
        };
        let inertia = bar(&format!("spatial body '{name}'"), 1.0, 1.0, 0.1, axes)?;
        let centre = (p[k] + p[k + 1]) * 0.5;
        links.push((
            b.add_spatial_body(SpatialBody::new(name, inertia).position(centre.into())),
            centre,
        ));
    }
    // joint k at point k: ground-link1, link1-link2, ..., link5-ground; the hinge axes
    let axes = [
        Matrix3::identity(),
        z_along_y(),
        z_along_x(),
        Matrix3::identity(),
        z_along_y(),
        z_along_x(),
    ];
    for (k, ax) in axes.into_iter().enumerate() {
        let name = format!("hinge{}", k + 1);
        let side = |i: Option<usize>| match i {
            None => (SpatialBodyRef::Ground, Marker::with_axes(p[k].into(), ax)),
            Some(i) => {
                let (h, c) = links[i];
                (
                    SpatialBodyRef::Body(h),
                    Marker::with_axes((p[k] - c).into(), ax),
                )
            }
        };
        let (a, b_) = match k {
            0 => (side(None), side(Some(0))),
            5 => (side(Some(4)), side(None)),
            _ => (side(Some(k - 1)), side(Some(k))),
        };
        b.add_spatial_joint(
            name.clone(),
            a.0,
            b_.0,
            joint(&name, SpatialJointKind::Revolute, a.1, b_.1)?,
        );
    }
    b.build()
}

/// A conservative spatial pendulum with a non-linear potential: a 1 kg rod with principal
/// moments `moments` (axis along its body `z`) hung by a spherical joint at its upper end
/// (0.4 m above its centre of mass) from the origin, pulled sideways by an undamped spring
/// (40 N/m, rest length 0.3 m) from the ground point `(0.5, 0.3, -0.3)` to its lower end,
/// gravity 9.81 m/s^2 along `-z`; it starts hanging straight down, moving with angular velocity
/// `(0.5, -1.25, 2)` rad/s about its pivot (with `moments = [0.05, 0.05, 0.002]`: the model
/// file `examples/models/sprung_rod.toml`). The damped and driven variant is
/// `examples/models/spatial_spring_pendulum.toml`.
///
/// ```
/// let p = mbd_model::models::sprung_rod([0.05, 0.05, 0.002])?;
/// assert_eq!((p.n_coords(), p.n_constraints(), p.dof()), (12, 9, 3));
/// assert!(p.is_conservative());
/// # Ok::<(), mbd_model::ModelError>(())
/// ```
pub fn sprung_rod(moments: [f64; 3]) -> Result<System, ModelError> {
    let mut b = SystemBuilder::new();
    b.set_spatial_gravity([0.0, 0.0, -9.81]);
    let inertia = SpatialInertia::principal(1.0, moments)
        .map_err(|e| crate::check::invalid("spatial body 'rod'".into(), e.to_string()))?;
    let omega = Vector3::new(0.5, -1.25, 2.0);
    // the pivot at rest: v = omega x (x - pivot)
    let v = omega.cross(&Vector3::new(0.0, 0.0, -0.4));
    let rod = b.add_spatial_body(
        SpatialBody::new("rod", inertia)
            .position([0.0, 0.0, -0.4])
            .velocity(v.into())
            .angular_velocity(omega.into()),
    );
    b.add_spatial_joint(
        "pivot",
        SpatialBodyRef::Ground,
        rod,
        joint(
            "pivot",
            SpatialJointKind::Spherical,
            Marker::at([0.0; 3]),
            Marker::at([0.0, 0.0, 0.4]),
        )?,
    );
    b.add_spatial_force(SpatialForce::spring_damper(
        "spring",
        SpatialBodyRef::Ground,
        [0.5, 0.3, -0.3],
        rod,
        [0.0, 0.0, -0.4],
        40.0,
        0.0,
        0.3,
    ));
    b.build()
}
