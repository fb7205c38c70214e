//! `mbd animate`: a self-contained HTML page animating a result CSV.
//!
//! The page (template `animate.html`, inline CSS and JavaScript, no network access) embeds the
//! trajectory and the model's geometry as JSON and draws with inline SVG: each body as the
//! polygon through its joint and force attachment points and its centre of mass (a line when
//! there are only two such points), a dot at every centre of mass, circles at the joints,
//! triangles at ground pins, dashed guides of prismatic joints on ground, and springs. The SVG
//! element publishes its world-to-pixel transform as `data-scale`, `data-ox`, `data-oy`
//! (`px = ox + scale x`, `py = oy - scale y`) and the frame shown as `data-frame`, `data-t`.
//! A URL hash `#t=1.25` opens the page paused at the frame nearest that time.

use crate::args::AnimateArgs;
use crate::error::CliError;
use crate::table::Table;
use mbd_model::{BodyRef, System};
use serde::Serialize;

/// Width of the drawing in SVG units (pixels at 100 % zoom).
pub const WIDTH: f64 = 800.0;
/// Height of the drawing.
pub const HEIGHT: f64 = 600.0;
/// Free border around the mechanism's extent.
const MARGIN: f64 = 40.0;

#[derive(Serialize)]
struct BodyGeom {
    name: String,
    /// Local points (body frame, relative to the centre of mass) in drawing order.
    outline: Vec<[f64; 2]>,
}

#[derive(Serialize)]
struct JointGeom {
    name: String,
    kind: &'static str,
    a: i64,
    pa: Option<[f64; 2]>,
    b: i64,
    pb: Option<[f64; 2]>,
    axis: Option<[f64; 2]>,
}

#[derive(Serialize)]
struct SpringGeom {
    name: String,
    a: i64,
    pa: [f64; 2],
    b: i64,
    pb: [f64; 2],
}

/// The world-to-pixel transform `px = ox + scale x`, `py = oy - scale y`.
#[derive(Clone, Copy, Debug, Serialize, PartialEq)]
pub struct View {
    /// Drawing width.
    pub width: f64,
    /// Drawing height.
    pub height: f64,
    /// Pixels per metre.
    pub scale: f64,
    /// Pixel x of the world origin.
    pub ox: f64,
    /// Pixel y of the world origin.
    pub oy: f64,
}

#[derive(Serialize)]
struct Page<'a> {
    model: &'a str,
    view: View,
    bodies: Vec<BodyGeom>,
    joints: Vec<JointGeom>,
    springs: Vec<SpringGeom>,
    t: Vec<f64>,
    q: Vec<Vec<f64>>,
}

fn index(r: BodyRef) -> i64 {
    r.index().map_or(-1, |i| i as i64)
}

fn joint_geom(sys: &System) -> Vec<JointGeom> {
    sys.joints()
        .iter()
        .map(|j| {
            let sk = j.sketch();
            let (a, pa, b, pb, axis) = (index(sk.a), sk.point_a, index(sk.b), sk.point_b, sk.axis);
            JointGeom {
                name: j.name.clone(),
                kind: j.kind_name(),
                a,
                pa,
                b,
                pb,
                axis,
            }
        })
        .collect()
}

fn spring_geom(sys: &System) -> Vec<SpringGeom> {
    sys.forces()
        .iter()
        .filter_map(|f| {
            let sk = f.sketch()?;
            Some(SpringGeom {
                name: f.name.clone(),
                a: index(sk.a),
                pa: sk.point_a?,
                b: index(sk.b),
                pb: sk.point_b?,
            })
        })
        .collect()
}

/// Each body's outline: its centre of mass and attachment points, ordered by angle around
/// their mean so the polygon does not cross itself.
fn body_geom(sys: &System, joints: &[JointGeom], springs: &[SpringGeom]) -> Vec<BodyGeom> {
    sys.bodies()
        .iter()
        .enumerate()
        .map(|(i, b)| {
            let i = i as i64;
            let mut pts: Vec<[f64; 2]> = vec![[0.0, 0.0]];
            let mut add = |p: [f64; 2]| {
                if !pts
                    .iter()
                    .any(|o| (o[0] - p[0]).abs() + (o[1] - p[1]).abs() < 1e-12)
                {
                    pts.push(p);
                }
            };
            for j in joints {
                if let (true, Some(p)) = (j.a == i, j.pa) {
                    add(p);
                }
                if let (true, Some(p)) = (j.b == i, j.pb) {
                    add(p);
                }
            }
            for s in springs {
                if s.a == i {
                    add(s.pa);
                }
                if s.b == i {
                    add(s.pb);
                }
            }
            if pts.len() > 2 {
                let n = pts.len() as f64;
                let cx = pts.iter().map(|p| p[0]).sum::<f64>() / n;
                let cy = pts.iter().map(|p| p[1]).sum::<f64>() / n;
                pts.sort_by(|p, q| {
                    let ap = (p[1] - cy).atan2(p[0] - cx);
                    let aq = (q[1] - cy).atan2(q[0] - cx);
                    ap.total_cmp(&aq)
                });
            }
            BodyGeom {
                name: b.name.clone(),
                outline: pts,
            }
        })
        .collect()
}

fn world(q: &[f64], body: i64, p: [f64; 2]) -> [f64; 2] {
    if body < 0 {
        return p;
    }
    let k = 3 * body as usize;
    let (s, c) = q[k + 2].sin_cos();
    [q[k] + c * p[0] - s * p[1], q[k + 1] + s * p[0] + c * p[1]]
}

/// The transform that fits every drawn point of every frame into the drawing.
fn fit_view(
    frames: &[Vec<f64>],
    bodies: &[BodyGeom],
    joints: &[JointGeom],
    springs: &[SpringGeom],
) -> View {
    let (mut lo, mut hi) = ([f64::INFINITY; 2], [f64::NEG_INFINITY; 2]);
    let mut grow = |p: [f64; 2]| {
        for k in 0..2 {
            if p[k].is_finite() {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
    };
    for q in frames {
        for (i, b) in bodies.iter().enumerate() {
            for &p in &b.outline {
                grow(world(q, i as i64, p));
            }
        }
    }
    for j in joints {
        for (body, p) in [(j.a, j.pa), (j.b, j.pb)] {
            if let (-1, Some(p)) = (body, p) {
                grow(p);
            }
        }
    }
    for s in springs {
        for (body, p) in [(s.a, s.pa), (s.b, s.pb)] {
            if body == -1 {
                grow(p);
            }
        }
    }
    if !(lo[0] <= hi[0] && lo[1] <= hi[1]) {
        lo = [-1.0, -1.0];
        hi = [1.0, 1.0];
    }
    let span = [(hi[0] - lo[0]).max(1e-9), (hi[1] - lo[1]).max(1e-9)];
    let scale = ((WIDTH - 2.0 * MARGIN) / span[0]).min((HEIGHT - 2.0 * MARGIN) / span[1]);
    let (cx, cy) = (0.5 * (lo[0] + hi[0]), 0.5 * (lo[1] + hi[1]));
    View {
        width: WIDTH,
        height: HEIGHT,
        scale,
        ox: 0.5 * WIDTH - scale * cx,
        oy: 0.5 * HEIGHT + scale * cy,
    }
}

fn html_escape(s: &str) -> String {
    s.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// Builds the page for a trajectory of `sys` (`t` and, per frame, all coordinates).
pub fn page(title: &str, sys: &System, t: Vec<f64>, q: Vec<Vec<f64>>) -> Result<String, CliError> {
    let joints = joint_geom(sys);
    let springs = spring_geom(sys);
    let bodies = body_geom(sys, &joints, &springs);
    let view = fit_view(&q, &bodies, &joints, &springs);
    let data = Page {
        model: title,
        view,
        bodies,
        joints,
        springs,
        t,
        q,
    };
    let json = serde_json::to_string(&data).map_err(|e| CliError::Plot {
        path: title.to_string(),
        message: e.to_string(),
    })?;
    // keep the JSON from closing its <script> element
    let json = json.replace("</", "<\\/");
    Ok(include_str!("animate.html")
        .replace("__TITLE__", &html_escape(title))
        .replace("__DATA__", &json))
}

/// Reads the CSV and the model, checks that they belong together and writes the page.
pub fn animate(args: &AnimateArgs) -> Result<(), CliError> {
    let sys = crate::model::load(&args.model)?;
    let table = Table::read(&args.csv)?;
    let names = sys.coordinate_names();
    let missing: Vec<&str> = std::iter::once("t")
        .chain(names.iter().map(String::as_str))
        .filter(|n| !table.names.iter().any(|c| c == n))
        .collect();
    if !missing.is_empty() {
        return Err(CliError::Mismatch {
            csv: args.csv.display().to_string(),
            model: args.model.display().to_string(),
            missing: missing.join(", "),
        });
    }
    let t = table.column("t")?;
    let cols: Vec<usize> = names
        .iter()
        .map(|n| table.column_index(n))
        .collect::<Result<_, _>>()?;
    let q: Vec<Vec<f64>> = table
        .rows
        .iter()
        .map(|r| cols.iter().map(|&k| r[k]).collect())
        .collect();
    let title = format!(
        "{} ({})",
        args.model.display(),
        args.csv
            .file_name()
            .map(|f| f.to_string_lossy())
            .unwrap_or_default()
    );
    let html = page(&title, &sys, t, q)?;
    std::fs::write(&args.out, html).map_err(|e| CliError::write(&args.out, e))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn geometry_and_view_of_the_slider_crank() {
        let sys = mbd_model::models::slider_crank().unwrap();
        let joints = joint_geom(&sys);
        let springs = spring_geom(&sys);
        let bodies = body_geom(&sys, &joints, &springs);
        // every body has its centre of mass and its joint points, without repeats
        for (i, b) in bodies.iter().enumerate() {
            assert!(b.outline.contains(&[0.0, 0.0]), "{}", b.name);
            for j in &joints {
                if j.b == i as i64 {
                    assert!(b.outline.contains(&j.pb.unwrap()), "{} {}", b.name, j.name);
                }
            }
        }
        let (q, _) = sys.initial_guess();
        let mut q2 = q.as_slice().to_vec();
        q2[0] += 3.0; // a frame far to the right
        let frames = vec![q.as_slice().to_vec(), q2];
        let v = fit_view(&frames, &bodies, &joints, &springs);
        for f in &frames {
            for (i, b) in bodies.iter().enumerate() {
                for &p in &b.outline {
                    let w = world(f, i as i64, p);
                    let (x, y) = (v.ox + v.scale * w[0], v.oy - v.scale * w[1]);
                    assert!((MARGIN - 1e-9..=WIDTH - MARGIN + 1e-9).contains(&x), "{x}");
                    assert!((MARGIN - 1e-9..=HEIGHT - MARGIN + 1e-9).contains(&y), "{y}");
                }
            }
        }
    }

    #[test]
    fn names_cannot_break_out_of_the_page() {
        let mut b = mbd_model::SystemBuilder::new();
        let h = b.add_body(mbd_model::Body::new("</script><b>x").rod(1.0, 1.0));
        b.add_joint(mbd_model::Joint::revolute(
            "pin",
            mbd_model::BodyRef::Ground,
            [0.0, 0.0],
            h,
            [-0.5, 0.0],
        ));
        let sys = b.build().unwrap();
        let html = page("<title>", &sys, vec![0.0], vec![vec![0.5, 0.0, 0.0]]).unwrap();
        assert_eq!(
            html.matches("</script>").count(),
            2,
            "only the page's own scripts close"
        );
        assert!(html.contains("&lt;title&gt;"));
    }
}
