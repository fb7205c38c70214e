//! `mbd animate` for models with spatial bodies: a self-contained 3D page.
//!
//! The page (template `animate3d.html`, inline CSS and JavaScript, no network access, no
//! libraries) embeds the trajectory and the model's geometry as JSON and draws with inline SVG
//! through its own perspective camera:
//!
//! * each spatial body as its **equivalent inertia box** ([`equivalent_box`]): the uniform box
//!   with the body's mass and principal moments, centred at the centre of mass, its edges along
//!   the directors `d_1, d_2, d_3` (a zero half-extent, a flat plate or a thin rod, is drawn
//!   with a small thickness: 0.6 % of the scene's half diagonal);
//! * each spatial point mass as a small sphere (radius 2 % of the scene's half diagonal) at its
//!   position (`class="point-mass"`, after the spatial bodies in the page's body list);
//! * a dot at every centre of mass, every joint's marker points (a square for a point on
//!   ground), lines from each centre of mass to its body's joint points (chains read as
//!   chains), lines for distance joints and spring-dampers;
//! * the path of the `--trace` point over the whole run and a dot at it;
//! * a ground grid (round step) under the scene, an axes triad labelled `x`, `y`, `z`, a legend,
//!   play/pause, a time slider and a readout.
//!
//! Planar bodies of a mixed model are drawn as dots at their centres of mass in the `z = 0`
//! plane (the legend says so).
//!
//! The camera orbits the centre of the box that holds every drawn point of every frame at
//! azimuth `az` (about `z`, from `x`) and elevation `el`: eye `C = T + L (cos el cos az,
//! cos el sin az, sin el)`, `L = 3.5 R` (`T` and `R` the centre and half diagonal of the box
//! holding the scene, the grid and the axes triad), forward `f = (T - C)/L`,
//! right `r = (-sin az, cos az, 0)`, up `u = r x f`; a world point `X` is drawn at
//! `(cx + F r.(X-C)/f.(X-C), cy - F u.(X-C)/f.(X-C))`, `F` the focal length in pixels (the
//! scene's bounding sphere fills 92 % of the smaller side of the plot area at zoom 1). The
//! `<svg id="stage">` publishes it as `data-matrix` (the 3 x 4 matrix `P`, rows
//! `F r + cx f`, `-F u + cy f`, `f`, each with its translation `-P_k . C`, so that
//! `(u w, v w, w) = P (X, 1)`), `data-az`, `data-el` (degrees), `data-zoom`, `data-focal`,
//! `data-distance`, `data-target`, `data-eye`, `data-cx`, `data-cy`, and the frame shown as
//! `data-frame`, `data-t`; `window.mbdCamera` holds the same numbers and
//! `window.mbdSetCamera(az, el, zoom)` moves the camera. A URL hash `#t=1.25&az=30&el=20&zoom=2`
//! opens the page paused at that time with that camera.

use crate::args::TraceSpec;
use crate::error::CliError;
use mbd_model::spatial::{SpatialBodyRef, SpatialForceKind};
use mbd_model::System;
use serde::Serialize;

/// Half-extents `(a, b, c)` (m) of the uniform box with mass `mass` and principal moments
/// `moments` about its centre of mass: its equivalent inertia box.
///
/// A uniform box of half-extents `a, b, c` along its principal axes has
/// `J_1 = m (b^2 + c^2) / 3`, `J_2 = m (a^2 + c^2) / 3`, `J_3 = m (a^2 + b^2) / 3`
/// (`m ((2b)^2 + (2c)^2) / 12`). Hence `J_2 + J_3 - J_1 = 2 m a^2 / 3`, i.e.
///
/// ```text
/// a = sqrt(3 (J_2 + J_3 - J_1) / (2 m)) = sqrt(3 E_1 / m),
/// ```
///
/// `E_1 = int X_1^2 dm` the second moment (docs/spatial.md), and likewise `b`, `c`. The
/// triangle inequality `J_1 <= J_2 + J_3` of every rigid body makes the root real; a flat plate
/// (`J_3 = J_1 + J_2`) has `c = 0`. A round-off negative `J_2 + J_3 - J_1` is taken as 0.
///
/// ```
/// // the heavy top of examples/models/heavy_top.toml
/// let [a, b, c] = mbd_cli::animate3d::equivalent_box(1.0, [0.3, 0.3, 0.1]);
/// assert!((a - 0.15f64.sqrt()).abs() < 1e-15 && (b - a).abs() < 1e-15);
/// assert!((c - 0.75f64.sqrt()).abs() < 1e-15);
/// ```
pub fn equivalent_box(mass: f64, moments: [f64; 3]) -> [f64; 3] {
    std::array::from_fn(|i| {
        let e = 0.5 * (moments[(i + 1) % 3] + moments[(i + 2) % 3] - moments[i]);
        (3.0 * e.max(0.0) / mass).sqrt()
    })
}

/// The smallest drawn half-extent, as a fraction of the scene's half diagonal: the thickness
/// of a flat plate's box.
const THIN: f64 = 0.006;

/// A point mass's drawn radius, as a fraction of the scene's half diagonal.
const POINT: f64 = 0.02;

#[derive(Serialize)]
struct Body3 {
    name: String,
    /// Index of the centre of mass's `x` in a frame's coordinates (directors follow, but for a
    /// point mass).
    off: usize,
    /// A spatial point mass (3 coordinates, drawn as a sphere of radius `drawn[0]`).
    point: bool,
    /// The equivalent box's half-extents along `d_1, d_2, d_3`.
    half: [f64; 3],
    /// The drawn half-extents: `half`, none below `THIN` times the scene's half diagonal.
    drawn: [f64; 3],
}

#[derive(Serialize)]
struct Planar {
    name: String,
    off: usize,
}

/// A joint or a spring-damper between two points: `a`, `b` spatial body indices (-1: ground),
/// points in the principal frames (ground: global).
#[derive(Serialize)]
struct Link {
    name: String,
    kind: &'static str,
    a: i64,
    pa: [f64; 3],
    b: i64,
    pb: [f64; 3],
}

#[derive(Debug, Serialize)]
struct Trace {
    /// Spatial body index.
    body: usize,
    /// The point in the body's principal frame.
    point: [f64; 3],
    /// What the legend calls it.
    label: String,
}

/// The world box `[lo, hi]` that holds every drawn point of every frame.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
struct Scene {
    lo: [f64; 3],
    hi: [f64; 3],
}

/// The page's data (serialised into the page as JSON).
#[derive(Serialize)]
struct Page3<'a> {
    model: &'a str,
    scene: Scene,
    bodies: Vec<Body3>,
    planar: Vec<Planar>,
    joints: Vec<Link>,
    springs: Vec<Link>,
    trace: Trace,
    t: Vec<f64>,
    q: Vec<Vec<f64>>,
}

/// `p` (body frame) in spatial body `k`'s principal frame, `A^T p` (ground, a point mass:
/// unchanged), and the page's body index (-1: ground; point masses after the bodies).
fn lower(sys: &System, r: SpatialBodyRef, p: [f64; 3]) -> (i64, [f64; 3]) {
    match r {
        SpatialBodyRef::Ground => (-1, p),
        SpatialBodyRef::PointMass(h) => ((sys.spatial_bodies().len() + h.index()) as i64, p),
        SpatialBodyRef::Body(h) => (h.index() as i64, to_principal(sys, h.index(), p)),
    }
}

/// `p` (body frame of spatial body `k`) in its principal frame, `A^T p`.
fn to_principal(sys: &System, k: usize, p: [f64; 3]) -> [f64; 3] {
    let a = sys.spatial_bodies()[k].inertia.axes();
    std::array::from_fn(|i| (0..3).map(|j| a[(j, i)] * p[j]).sum())
}

fn link(
    sys: &System,
    name: &str,
    kind: &'static str,
    a: SpatialBodyRef,
    pa: [f64; 3],
    b: SpatialBodyRef,
    pb: [f64; 3],
) -> Link {
    let (a, pa) = lower(sys, a, pa);
    let (b, pb) = lower(sys, b, pb);
    Link {
        name: name.to_string(),
        kind,
        a,
        pa,
        b,
        pb,
    }
}

/// The spatial joints and the spatial spring-dampers.
fn links(sys: &System) -> (Vec<Link>, Vec<Link>) {
    let joints = sys
        .spatial_joints()
        .iter()
        .map(|j| {
            let (ma, mb) = j.joint.markers();
            let kind = j.joint.type_name();
            link(sys, &j.name, kind, j.a, ma.point, j.b, mb.point)
        })
        .collect();
    let springs = sys
        .spatial_forces()
        .iter()
        .filter_map(|f| match &f.kind {
            SpatialForceKind::SpringDamper(s) => {
                Some(link(sys, &f.name, "spring", f.a, s.point_a, f.b, s.point_b))
            }
            _ => None,
        })
        .collect();
    (joints, springs)
}

/// Resolves `--trace` against the model (default: the last spatial body's centre of mass, or
/// the last point mass): the page's body index (point masses after the spatial bodies), the
/// point in its principal frame and the legend's label. An unknown or planar body is an error
/// naming it and listing the spatial bodies.
fn resolve_trace(sys: &System, spec: Option<&TraceSpec>) -> Result<Trace, CliError> {
    let bodies = sys.spatial_bodies();
    let names: Vec<&str> = bodies
        .iter()
        .map(|b| b.name.as_str())
        .chain(sys.spatial_point_masses().iter().map(|p| p.name.as_str()))
        .collect();
    let Some(spec) = spec else {
        let k = match bodies.len() {
            0 => names.len().checked_sub(1).ok_or_else(|| {
                CliError::Usage("--trace: the model has no spatial bodies".to_string())
            })?,
            nb => nb - 1,
        };
        return Ok(Trace {
            body: k,
            point: [0.0; 3],
            label: format!("{} (centre of mass)", names[k]),
        });
    };
    let Some(k) = names.iter().position(|n| *n == spec.body) else {
        let planar = sys.bodies().iter().any(|b| b.name == spec.body);
        return Err(CliError::Usage(format!(
            "--trace: '{}' is {}; the spatial bodies are: {}",
            spec.body,
            if planar {
                "a planar body (the 3D page traces a point of a spatial body)"
            } else {
                "not a body of the model"
            },
            names.join(", ")
        )));
    };
    // a point mass's trace is its position
    let point = match bodies.get(k) {
        Some(_) => to_principal(sys, k, spec.point.unwrap_or([0.0; 3])),
        None => [0.0; 3],
    };
    let label = match spec.point {
        None => format!("{} (centre of mass)", spec.body),
        Some(p) => format!("{} point ({}, {}, {}) m", spec.body, p[0], p[1], p[2]),
    };
    Ok(Trace {
        body: k,
        point,
        label,
    })
}

/// Checks `--trace` against the model before the CSV is read (the same errors as the page).
pub fn check_trace(sys: &System, spec: Option<&TraceSpec>) -> Result<(), CliError> {
    resolve_trace(sys, spec).map(|_| ())
}

/// World position of `p` (principal frame of the page's body `k`, or global when `k < 0`; a
/// point mass: its position) in the frame `q` (all coordinates).
fn world(q: &[f64], bodies: &[Body3], k: i64, p: [f64; 3]) -> [f64; 3] {
    let Some(b) = usize::try_from(k).ok().and_then(|k| bodies.get(k)) else {
        return p;
    };
    let o = b.off;
    if b.point {
        return [q[o], q[o + 1], q[o + 2]];
    }
    std::array::from_fn(|c| q[o + c] + (0..3).map(|i| p[i] * q[o + 3 + 3 * i + c]).sum::<f64>())
}

/// The eight corners of a box of half-extents `h` (principal frame), all sign patterns.
fn corners(h: [f64; 3]) -> impl Iterator<Item = [f64; 3]> {
    (0..8).map(move |m| std::array::from_fn(|i| if m >> i & 1 == 1 { h[i] } else { -h[i] }))
}

/// The box holding every box corner, joint and spring point, trace point and planar centre of
/// mass of every frame (a unit box around the origin when there is none or it is not finite).
fn scene(
    frames: &[Vec<f64>],
    bodies: &[Body3],
    planar: &[Planar],
    links: &[&Link],
    trace: &Trace,
) -> Scene {
    let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
    let mut grow = |p: [f64; 3]| {
        if p.iter().all(|x| x.is_finite()) {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    };
    for q in frames {
        for (k, b) in bodies.iter().enumerate() {
            for c in corners(b.half) {
                grow(world(q, bodies, k as i64, c));
            }
        }
        for l in links {
            grow(world(q, bodies, l.a, l.pa));
            grow(world(q, bodies, l.b, l.pb));
        }
        grow(world(q, bodies, trace.body as i64, trace.point));
        for p in planar {
            grow([q[p.off], q[p.off + 1], 0.0]);
        }
    }
    if !(0..3).all(|k| lo[k] <= hi[k]) {
        return Scene {
            lo: [-1.0; 3],
            hi: [1.0; 3],
        };
    }
    Scene { lo, hi }
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// The page's bodies: the spatial bodies (boxes), then the point masses (spheres), their drawn
/// sizes still to be set against the scene.
fn page_bodies(sys: &System) -> Vec<Body3> {
    let q0 = sys.spatial_offset();
    let mut bodies: Vec<Body3> = sys
        .spatial_bodies()
        .iter()
        .enumerate()
        .map(|(k, b)| {
            let half = equivalent_box(b.inertia.mass(), b.inertia.moments());
            Body3 {
                name: b.name.clone(),
                off: q0 + 12 * k,
                point: false,
                half,
                drawn: half,
            }
        })
        .collect();
    let qp = sys.spatial_point_mass_offset();
    bodies.extend(
        sys.spatial_point_masses()
            .iter()
            .enumerate()
            .map(|(k, p)| Body3 {
                name: p.name.clone(),
                off: qp + 3 * k,
                point: true,
                half: [0.0; 3],
                drawn: [0.0; 3],
            }),
    );
    bodies
}

/// Builds the 3D page for a trajectory of `sys` (`t` and, per frame, all coordinates in the
/// order of [`System::coordinate_names`]) with the path of the `trace` point.
pub fn page(
    title: &str,
    sys: &System,
    trace: Option<&TraceSpec>,
    t: Vec<f64>,
    q: Vec<Vec<f64>>,
) -> Result<String, CliError> {
    let trace = resolve_trace(sys, trace)?;
    let n = sys.coordinate_names().len();
    if let Some((i, r)) = q.iter().enumerate().find(|(_, r)| r.len() != n) {
        return Err(CliError::Usage(format!(
            "frame {i} has {} coordinates, the model {n}",
            r.len()
        )));
    }
    let mut bodies = page_bodies(sys);
    let planar = sys
        .bodies()
        .iter()
        .enumerate()
        .map(|(k, b)| Planar {
            name: b.name.clone(),
            off: 3 * k,
        })
        .collect::<Vec<_>>();
    let (joints, springs) = links(sys);
    let all: Vec<&Link> = joints.iter().chain(&springs).collect();
    let scene = scene(&q, &bodies, &planar, &all, &trace);
    let radius = (0..3)
        .map(|k| (scene.hi[k] - scene.lo[k]).powi(2))
        .sum::<f64>()
        .sqrt()
        * 0.5;
    let thin = THIN * if radius > 0.0 { radius } else { 1.0 };
    for b in &mut bodies {
        b.drawn = if b.point {
            [POINT * if radius > 0.0 { radius } else { 1.0 }; 3]
        } else {
            b.half.map(|h| h.max(thin))
        };
    }
    let data = Page3 {
        model: title,
        scene,
        bodies,
        planar,
        joints,
        springs,
        trace,
        t,
        q,
    };
    let json = serde_json::to_string(&data).map_err(|e| CliError::Plot {
        path: title.to_string(),
        message: e.to_string(),
    })?;
    // keep the JSON from closing its <script> element
    let json = json.replace("</", "<\\/");
    Ok(include_str!("animate3d.html")
        .replace("__TITLE__", &html_escape(title))
        .replace("__DATA__", &json))
}

#[cfg(test)]
#[path = "animate3d_tests.rs"]
mod tests;
