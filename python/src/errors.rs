//! The library's errors as Python exceptions: every [`mbd::Error`] (and every refusal of a
//! run's options) becomes an instance of a class of `mbd._errors` (`ModelError`,
//! `SolveError`, `SingularConfigurationError`, ...) with the message, the Rust variant's name
//! (`kind`), the element at fault (`element`) and the variant's fields (`details`).

use mbd::model::ModelError;
use mbd::solve::SolveError;
use pyo3::prelude::*;
use pyo3::types::PyDict;

/// A value of an error's field.
#[derive(Clone, Debug)]
pub enum Detail {
    /// A number.
    Num(f64),
    /// A count.
    Count(usize),
    /// A name or message.
    Text(String),
}

/// A failure described for Python: which exception class, and what to attach to it. Plain
/// data (`Send`), so it crosses from the threads that run members back to Python.
#[derive(Clone, Debug)]
pub struct Failure {
    /// The class's name in `mbd._errors`.
    pub class: &'static str,
    /// The message (the Rust error's `Display`).
    pub message: String,
    /// The Rust variant's name (`Singular`, `UnknownBody`, ...).
    pub kind: String,
    /// The element at fault (a body, joint, force or equation name), where the error names one.
    pub element: Option<String>,
    /// The variant's fields.
    pub details: Vec<(&'static str, Detail)>,
}

impl Failure {
    /// A refusal of a run's options (an end time, a count): `InvalidArgumentError`.
    pub fn argument(message: impl Into<String>) -> Self {
        Failure {
            class: "InvalidArgumentError",
            message: message.into(),
            kind: "InvalidArgument".into(),
            element: None,
            details: Vec::new(),
        }
    }

    /// The Python exception (an instance of the class, with its attributes set).
    pub fn to_pyerr(&self, py: Python<'_>) -> PyErr {
        match self.instance(py) {
            Ok(e) => PyErr::from_value(e),
            Err(e) => e,
        }
    }

    /// The exception object itself (for an ensemble's failed member).
    pub fn instance<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyAny>> {
        let cls = py.import("mbd._errors")?.getattr(self.class)?;
        let details = PyDict::new(py);
        for (k, v) in &self.details {
            match v {
                Detail::Num(x) => details.set_item(k, x)?,
                Detail::Count(n) => details.set_item(k, n)?,
                Detail::Text(s) => details.set_item(k, s)?,
            }
        }
        let e = cls.call1((self.message.as_str(),))?;
        e.setattr("kind", self.kind.as_str())?;
        e.setattr("element", self.element.as_deref())?;
        e.setattr("details", details)?;
        Ok(e)
    }
}

/// The variant's name: the Debug text up to the first character that cannot be in a name.
fn variant_name(debug: &str) -> String {
    debug
        .chars()
        .take_while(|c| c.is_alphanumeric() || *c == '_')
        .collect()
}

fn model_failure(e: &ModelError) -> Failure {
    use Detail::{Num, Text};
    let (element, details): (Option<String>, Vec<(&'static str, Detail)>) = match e {
        ModelError::UnknownBody { element, body } => {
            (Some(element.clone()), vec![("body", Text(body.clone()))])
        }
        ModelError::NegligibleInertia {
            body, joint, ratio, ..
        } => (
            Some(body.clone()),
            vec![("joint", Text(joint.clone())), ("ratio", Num(*ratio))],
        ),
        ModelError::DuplicateName { kind, name } => (
            Some(name.clone()),
            vec![("element_kind", Text((*kind).into()))],
        ),
        ModelError::InvalidParameter {
            element,
            parameter,
            value,
            reason,
        } => (
            Some(element.clone()),
            vec![
                ("parameter", Text((*parameter).into())),
                ("value", Num(*value)),
                ("reason", Text((*reason).into())),
            ],
        ),
        ModelError::SameBody { joint, body } => {
            (Some(joint.clone()), vec![("body", Text(body.clone()))])
        }
        ModelError::Redundant { equation, joints } => (
            Some(equation.clone()),
            vec![("joints", Text(joints.join(", ")))],
        ),
        ModelError::InvalidElement { element, .. } => (Some(element.clone()), Vec::new()),
        ModelError::Parse { format, .. } => (None, vec![("format", Text((*format).into()))]),
        _ => (None, Vec::new()),
    };
    Failure {
        class: "ModelError",
        message: e.to_string(),
        kind: variant_name(&format!("{e:?}")),
        element,
        details,
    }
}

fn solve_failure(e: &SolveError) -> Failure {
    use Detail::{Count, Num, Text};
    if let SolveError::Model(m) = e {
        return model_failure(m);
    }
    let (class, element, details): (&'static str, Option<String>, Vec<(&'static str, Detail)>) =
        match e {
            SolveError::Singular { t, what, detail } => (
                "SingularConfigurationError",
                None,
                vec![
                    ("t", Num(*t)),
                    ("what", Text((*what).into())),
                    ("detail", Text(detail.clone())),
                ],
            ),
            SolveError::ConstraintDrift {
                t,
                level,
                equation,
                joint,
                residual,
                tolerance,
            } => (
                "ConstraintDriftError",
                Some(joint.clone()),
                vec![
                    ("t", Num(*t)),
                    ("level", Text((*level).into())),
                    ("equation", Text(equation.clone())),
                    ("residual", Num(*residual)),
                    ("tolerance", Num(*tolerance)),
                ],
            ),
            SolveError::UnknownSolver { spec, .. } | SolveError::SolverSpec { spec, .. } => {
                ("InvalidSolverSpec", Some(spec.clone()), Vec::new())
            }
            SolveError::StepSizeTooSmall { t, h, .. } => {
                ("StepSizeError", None, vec![("t", Num(*t)), ("h", Num(*h))])
            }
            SolveError::TooManyAttempts { t, attempts } => (
                "StepSizeError",
                None,
                vec![("t", Num(*t)), ("attempts", Count(*attempts))],
            ),
            SolveError::InvalidStep { h } => ("InvalidArgumentError", None, vec![("h", Num(*h))]),
            SolveError::InvalidInterval { t0, t_end, .. } => (
                "InvalidArgumentError",
                None,
                vec![("t0", Num(*t0)), ("t_end", Num(*t_end))],
            ),
            SolveError::InvalidParameter {
                parameter, value, ..
            } => (
                "InvalidArgumentError",
                Some((*parameter).into()),
                vec![("value", Num(*value))],
            ),
            SolveError::TooManySteps { steps, h, .. } => (
                "InvalidArgumentError",
                None,
                vec![("steps", Num(*steps)), ("h", Num(*h))],
            ),
            SolveError::Newton { t, residual, .. } => (
                "SolveError",
                None,
                vec![("t", Num(*t)), ("residual", Num(*residual))],
            ),
            SolveError::DegenerateDirectors { t, body } => {
                ("SolveError", Some(body.clone()), vec![("t", Num(*t))])
            }
            SolveError::NonFinite { t, what } => (
                "SolveError",
                None,
                vec![("t", Num(*t)), ("what", Text((*what).into()))],
            ),
            SolveError::OverdeterminedInputs { equation, .. } => {
                ("SolveError", Some(equation.clone()), Vec::new())
            }
            SolveError::RepeatedFailure { source, .. } => {
                let inner = solve_failure(source);
                (inner.class, inner.element, inner.details)
            }
            _ => ("SolveError", None, Vec::new()),
        };
    Failure {
        class,
        message: e.to_string(),
        kind: variant_name(&format!("{e:?}")),
        element,
        details,
    }
}

/// Describes any error of the library for Python.
pub fn failure(e: &mbd::Error) -> Failure {
    match e {
        mbd::Error::Model(m) => model_failure(m),
        mbd::Error::Solve(s) => solve_failure(s),
        other => Failure {
            class: match other {
                mbd::Error::Analysis(_) => "MbdError",
                _ => "SolveError",
            },
            message: other.to_string(),
            kind: variant_name(&format!("{other:?}")),
            element: None,
            details: Vec::new(),
        },
    }
}

impl From<mbd::Error> for Failure {
    fn from(e: mbd::Error) -> Self {
        failure(&e)
    }
}

impl From<ModelError> for Failure {
    fn from(e: ModelError) -> Self {
        model_failure(&e)
    }
}

impl From<SolveError> for Failure {
    fn from(e: SolveError) -> Self {
        failure(&mbd::Error::from(e))
    }
}
