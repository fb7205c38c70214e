//! Parameter checks shared by the builder, the joints and the forces: each error names the
//! element and the parameter at fault.

use crate::error::ModelError;
use crate::timefn::TimeFunction;

/// An element-level error with a free-form message.
pub(crate) fn invalid(element: String, message: String) -> ModelError {
    ModelError::InvalidElement { element, message }
}

/// `value` must be finite.
pub(crate) fn finite(element: &str, parameter: &'static str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be finite",
        })
    }
}

/// `value` must be positive and finite.
pub(crate) fn positive(
    element: &str,
    parameter: &'static str,
    value: f64,
) -> Result<(), ModelError> {
    if value.is_finite() && value > 0.0 {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be positive and finite",
        })
    }
}

/// `value` must be non-negative and finite.
pub(crate) fn nonneg(element: &str, parameter: &'static str, value: f64) -> Result<(), ModelError> {
    if value.is_finite() && value >= 0.0 {
        Ok(())
    } else {
        Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value,
            reason: "must be non-negative and finite",
        })
    }
}

/// Both coordinates of a point must be finite.
pub(crate) fn point(element: &str, parameter: &'static str, p: [f64; 2]) -> Result<(), ModelError> {
    finite(element, parameter, p[0])?;
    finite(element, parameter, p[1])
}

/// A direction must be finite and non-zero; it is normalised in place (the sliding axis of a
/// prismatic joint or slide driver).
pub(crate) fn unit_axis(
    element: &str,
    parameter: &'static str,
    axis: &mut [f64; 2],
) -> Result<(), ModelError> {
    point(element, parameter, *axis)?;
    let len = (axis[0] * axis[0] + axis[1] * axis[1]).sqrt();
    positive(element, "axis length", len)?;
    *axis = [axis[0] / len, axis[1] / len];
    Ok(())
}

/// Every coefficient of a time function must be finite, and a step's or ramp's end after its
/// start.
pub(crate) fn time_function(
    element: &str,
    parameter: &'static str,
    f: &TimeFunction,
) -> Result<(), ModelError> {
    if !f.is_finite() {
        return Err(ModelError::InvalidParameter {
            element: element.to_string(),
            parameter,
            value: f64::NAN,
            reason: "time function coefficients must be finite",
        });
    }
    match f.invalid_reason() {
        None => Ok(()),
        Some(reason) => Err(ModelError::InvalidElement {
            element: element.to_string(),
            message: format!("time function '{parameter}': {reason}"),
        }),
    }
}

/// Checks a body's name: not the reserved `ground` (any case) and not already in `names` (all
/// bodies, planar and spatial), which it joins.
pub(crate) fn body_name(
    names: &mut std::collections::HashSet<String>,
    name: &str,
) -> Result<(), ModelError> {
    if name.eq_ignore_ascii_case("ground") {
        return Err(ModelError::DuplicateName {
            kind: "body (reserved for the ground)",
            name: name.to_string(),
        });
    }
    if !names.insert(name.to_string()) {
        return Err(ModelError::DuplicateName {
            kind: "body",
            name: name.to_string(),
        });
    }
    Ok(())
}
