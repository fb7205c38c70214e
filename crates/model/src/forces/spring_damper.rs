//! The linear point-to-point spring-damper.

use super::{Force, ForceKind, ForceType, LocalState};
use crate::body::BodyRef;
use crate::check;
use crate::element::{Anchor, Sketch};
use crate::error::ModelError;
use crate::file::ForceSpec;
use crate::jet::{dot, point, sub2, DirJet, Frame, Scalar};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// Linear point-to-point spring-damper: `V = k/2 (l - l0)^2` with `l = |P_b - P_a|`, damping
/// force `c ldot` along the line.
#[derive(Clone, Debug, PartialEq)]
pub struct SpringDamper {
    /// First body.
    pub a: BodyRef,
    /// Point on `a`.
    pub pa: [f64; 2],
    /// Second body.
    pub b: BodyRef,
    /// Point on `b`.
    pub pb: [f64; 2],
    /// Stiffness (>= 0).
    pub stiffness: f64,
    /// Damping (>= 0).
    pub damping: f64,
    /// Rest length (>= 0).
    pub rest_length: f64,
}

impl ForceType for SpringDamper {
    const KIND: &'static str = "spring_damper";
    fn bodies(&self) -> (BodyRef, BodyRef) {
        (self.a, self.b)
    }
    #[inline(always)]
    fn potential<T: Scalar>(&self, qa: &Frame<T>, qb: &Frame<T>) -> T {
        let d = sub2(point(qb, self.pb), point(qa, self.pa));
        if self.rest_length == 0.0 {
            // k/2 |d|^2: the same energy, but smooth (no square root) where the attachment
            // points coincide
            return dot(d, d) * (0.5 * self.stiffness);
        }
        let e = dot(d, d).sqrt() - self.rest_length;
        e * e * (0.5 * self.stiffness)
    }
    fn is_nonconservative(&self) -> bool {
        self.damping != 0.0
    }
    fn dissipative(&self) -> bool {
        true
    }
    fn nonconservative(&self, s: &LocalState, _t: f64, out: &mut [f64; 6]) {
        if self.damping == 0.0 {
            return;
        }
        let ja = Frame::new(std::array::from_fn(|i| DirJet::var(i, s.qa[i], s.va[i])));
        let jb = Frame::new(std::array::from_fn(|i| {
            DirJet::var(i + 3, s.qb[i], s.vb[i])
        }));
        let d = sub2(point(&jb, self.pb), point(&ja, self.pa));
        if dot(d, d).v == 0.0 {
            // coincident points: the line of action is undefined and the bounded force has no
            // limit; take zero instead of 0/0
            return;
        }
        let l = dot(d, d).sqrt();
        // l.d1 = ldot; the force is -c ldot grad(l)
        let f = -self.damping * l.d1;
        for k in 0..6 {
            out[k] += f * l.g[k];
        }
    }
    fn anchors(&mut self) -> [Option<Anchor<'_>>; 2] {
        [
            Some(Anchor::new(self.a, "point_a", &mut self.pa)),
            Some(Anchor::new(self.b, "point_b", &mut self.pb)),
        ]
    }
    fn length(&self) -> Option<f64> {
        Some(self.rest_length)
    }
    fn validate(&self, element: &str) -> Result<(), ModelError> {
        check::point(element, "point_a", self.pa)?;
        check::point(element, "point_b", self.pb)?;
        check::nonneg(element, "stiffness", self.stiffness)?;
        check::nonneg(element, "damping", self.damping)?;
        check::nonneg(element, "rest_length", self.rest_length)
    }
    fn sketch(&self) -> Option<Sketch> {
        Some(Sketch {
            a: self.a,
            point_a: Some(self.pa),
            b: self.b,
            point_b: Some(self.pb),
            axis: None,
        })
    }
    fn to_spec(&self, name: String, name_of: &dyn Fn(BodyRef) -> String) -> ForceSpec {
        ForceSpec::SpringDamper(SpringDamperSpec {
            name,
            body_a: name_of(self.a),
            point_a: self.pa,
            body_b: name_of(self.b),
            point_b: self.pb,
            stiffness: self.stiffness,
            damping: self.damping,
            rest_length: self.rest_length,
        })
    }
}

/// A spring-damper in a model file (see [`SpringDamper`]).
#[derive(Clone, Debug, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct SpringDamperSpec {
    /// Unique element name.
    pub name: String,
    /// First body (`ground` for the ground).
    pub body_a: String,
    /// Point on `body_a` (body frame), m.
    #[serde(default)]
    pub point_a: [f64; 2],
    /// Second body.
    pub body_b: String,
    /// Point on `body_b`, m.
    #[serde(default)]
    pub point_b: [f64; 2],
    /// Stiffness, N/m (>= 0).
    pub stiffness: f64,
    /// Damping, N s/m (>= 0).
    #[serde(default)]
    pub damping: f64,
    /// Rest length, m (>= 0).
    pub rest_length: f64,
}

impl SpringDamperSpec {
    pub(crate) fn to_force(
        &self,
        find: &dyn Fn(&str, &str) -> Result<BodyRef, ModelError>,
    ) -> Result<Force, ModelError> {
        let element = format!("force '{}'", self.name);
        let kind = SpringDamper {
            a: find(&element, &self.body_a)?,
            pa: self.point_a,
            b: find(&element, &self.body_b)?,
            pb: self.point_b,
            stiffness: self.stiffness,
            damping: self.damping,
            rest_length: self.rest_length,
        };
        Ok(Force::new(self.name.clone(), ForceKind::SpringDamper(kind)))
    }
}
