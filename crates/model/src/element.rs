//! What joints and forces share: the drawing of an element ([`Sketch`]) and the body-fixed
//! points the builder converts between body frames ([`Anchor`]).

use crate::body::BodyRef;

/// How a joint or a force element is drawn (the CLI's animation reads it): its two sides, the
/// body-fixed point on each side where it has one, and the sliding axis of a prismatic joint.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Sketch {
    /// The first side.
    pub a: BodyRef,
    /// The point on `a` (body frame, relative to the centre of mass), if the element has one.
    pub point_a: Option<[f64; 2]>,
    /// The second side (ground for single-body elements).
    pub b: BodyRef,
    /// The point on `b`, if the element has one.
    pub point_b: Option<[f64; 2]>,
    /// Unit sliding axis in `a`'s frame (prismatic joints).
    pub axis: Option<[f64; 2]>,
}

impl Sketch {
    /// An element sliding a point of `b` along an axis of `a` (prismatic joints, slide
    /// drivers); `axis` is normalised here (a zero one draws no axis).
    pub(crate) fn sliding(
        a: BodyRef,
        pa: [f64; 2],
        b: BodyRef,
        pb: [f64; 2],
        axis: [f64; 2],
    ) -> Sketch {
        let n = axis[0].hypot(axis[1]);
        Sketch {
            a,
            point_a: Some(pa),
            b,
            point_b: Some(pb),
            axis: (n > 0.0).then(|| [axis[0] / n, axis[1] / n]),
        }
    }
}

/// A body-fixed point of an element with the body it is on and the name of its parameter
/// (`point_a`, `point_b`, `point`): what body-frame lowering and point-mass checks visit.
pub(crate) struct Anchor<'a> {
    /// The body the point is on.
    pub(crate) body: BodyRef,
    /// The parameter's name in the model file and in error messages.
    pub(crate) field: &'static str,
    /// The point, relative to the body's centre of mass after lowering.
    pub(crate) point: &'a mut [f64; 2],
}

impl<'a> Anchor<'a> {
    pub(crate) fn new(body: BodyRef, field: &'static str, point: &'a mut [f64; 2]) -> Self {
        Anchor { body, field, point }
    }
}

/// `|p|`: the lever arm of a body-fixed point about the centre of mass.
pub(crate) fn norm(p: [f64; 2]) -> f64 {
    p[0].hypot(p[1])
}
