//! The solver registry: how a solver crate makes itself known to every front end (the `mbd`
//! facade's run object, the CLI, the report) without any of them naming it.
//!
//! A solver crate exports one [`SolverFamily`]: the heads of its spec strings (`"tangent"` for
//! `tangent:rk4`), a parse function from a [`SpecArgs`] to a [`SolverSpec`] (a canonical spec
//! string, the method's order, whether it steps adaptively, and how to build the integrator
//! for a system), and the [`SolverVariant`]s it offers (the rows of `mbd solvers`, the solvers
//! the report compares). The facade lists the families once (`mbd::registry()`); adding a
//! solver crate is the crate plus one line there.
//!
//! ```
//! use mbd_model::models;
//! use mbd_solve::registry::{Registry, INDEX1};
//!
//! let mut registry = Registry::new();
//! registry.register(&INDEX1)?;
//! let spec = registry.parse("index1:dopri5")?;
//! assert_eq!(spec.to_string(), "index1:dopri5");
//! assert!(spec.adaptive() && spec.order() == 5);
//! let sys = models::pendulum(1.0, 1.0, 0.3, 9.81)?;
//! let mut integ = spec.build(&sys)?;
//! assert!(integ.as_adaptive().is_some());
//! // unknown names list what is registered
//! let e = registry.parse("rk5").unwrap_err().to_string();
//! assert!(e.contains("unknown solver 'rk5'") && e.contains("index1:dopri5"), "{e}");
//! # Ok::<(), mbd_solve::SolveError>(())
//! ```

use crate::error::SolveError;
use crate::index1::{Index1Options, Index1Rk};
use crate::integrator::Integrator;
use crate::tableau::ButcherTableau;
use mbd_model::System;
use std::fmt;
use std::sync::Arc;

/// The integrator a [`SolverSpec`] builds: any solver, movable to another thread.
pub type BoxedIntegrator = Box<dyn Integrator + Send>;

type BuildFn = dyn Fn(&System) -> Result<BoxedIntegrator, SolveError> + Send + Sync;

/// One concrete solver a family offers: a row of `mbd solvers` and a solver the report
/// compares.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SolverVariant {
    /// A spec string that parses to this solver, e.g. `"symplectic:2"`.
    pub spec: &'static str,
    /// The name reports and figures use, e.g. `"symplectic (2,2)"`.
    pub label: &'static str,
    /// One line on what it is.
    pub description: &'static str,
    /// Convergence order in the step size.
    pub order: u32,
    /// Whether it has an embedded error estimate (adaptive steps with a tolerance).
    pub adaptive: bool,
    /// Whether its cost per step grows linearly with the number of bodies (it is then in the
    /// report's cost-against-size study).
    pub scales: bool,
    /// Rough cost of a step relative to plain RK4 on a small mechanism; the report sizes its
    /// sweeps by it (solvers above 20 skip the longest runs).
    pub relative_cost: f64,
    /// What it refuses (empty if nothing beyond a valid model): checked when it is built.
    pub refuses: &'static str,
    /// Whether the report's cross-solver experiments (orders, work-precision, long-time
    /// energy, cost) include it. `false` only for a variant that differs from a compared one by
    /// an option whose effect those experiments cannot show (the unpolished FA-DAE, whose error
    /// is set by its optimiser's stopping rule rather than by `h`, beside the polished one).
    pub compared: bool,
}

/// How a parsed spec string is checked: the whole text, its head (before the first `:`) and
/// the parts after it, lower-cased and trimmed.
#[derive(Clone, Debug)]
pub struct SpecArgs<'a> {
    /// The text as given.
    pub text: &'a str,
    /// The head, e.g. `"symplectic"`.
    pub head: String,
    /// The parts after the head, e.g. `["2", "gamma=1"]`.
    pub parts: Vec<String>,
}

impl<'a> SpecArgs<'a> {
    /// Splits `text` at `:` (lower-cased, trimmed). An empty part is kept (and refused by
    /// [`SpecArgs::options`]).
    pub fn new(text: &'a str) -> Self {
        let lower = text.trim().to_ascii_lowercase();
        let mut it = lower.split(':').map(|p| p.trim().to_string());
        let head = it.next().unwrap_or_default();
        SpecArgs {
            text,
            head,
            parts: it.collect(),
        }
    }

    /// The error for this spec: [`SolveError::SolverSpec`] with `reason`.
    pub fn error(&self, reason: impl Into<String>) -> SolveError {
        SolveError::SolverSpec {
            spec: self.text.to_string(),
            reason: reason.into(),
        }
    }

    /// The parts split into positional values (before the first `key=value` or flag) are not
    /// distinguished here: every part is returned as `(key, Some(value))` for `key=value` and
    /// `(part, None)` otherwise, in order. Errors for an empty part and for a key or flag given
    /// twice (`symplectic:2:gamma=1:gamma=2`).
    pub fn options(&self) -> Result<Vec<(String, Option<String>)>, SolveError> {
        let mut out: Vec<(String, Option<String>)> = Vec::with_capacity(self.parts.len());
        for p in &self.parts {
            if p.is_empty() {
                return Err(self.error("an empty part between ':' separators"));
            }
            let (k, v) = match p.split_once('=') {
                Some((k, v)) => (k.trim().to_string(), Some(v.trim().to_string())),
                None => (p.clone(), None),
            };
            if out.iter().any(|(o, _)| *o == k) {
                return Err(self.error(format!("'{k}' is given twice")));
            }
            out.push((k, v));
        }
        Ok(out)
    }

    /// Errors unless the spec has no parts (a solver without options).
    pub fn no_options(&self) -> Result<(), SolveError> {
        match self.parts.first() {
            None => Ok(()),
            Some(p) => Err(self.error(format!("'{}' takes no options (got '{p}')", self.head))),
        }
    }

    /// Parses a finite number given as the value of `key`.
    pub fn number(&self, key: &str, value: Option<&str>) -> Result<f64, SolveError> {
        match value.map(str::parse::<f64>) {
            Some(Ok(x)) if x.is_finite() => Ok(x),
            _ => Err(self.error(format!(
                "{key} must be a finite number, e.g. {key}=1 (got '{}')",
                value.unwrap_or("")
            ))),
        }
    }
}

/// A solver crate's entry in the registry.
#[derive(Clone, Copy)]
pub struct SolverFamily {
    /// The crate that registers it, e.g. `"mbd-tangent"`.
    pub crate_name: &'static str,
    /// The heads of its spec strings, e.g. `["tangent"]`; unique across the registry.
    pub heads: &'static [&'static str],
    /// The spec syntax for help texts, e.g. `"tangent:rk4 | tangent:dopri5"`.
    pub syntax: &'static str,
    /// The solvers it offers.
    pub variants: &'static [SolverVariant],
    /// Parses a spec whose head is one of [`SolverFamily::heads`].
    pub parse: fn(&SpecArgs) -> Result<SolverSpec, SolveError>,
}

impl fmt::Debug for SolverFamily {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SolverFamily")
            .field("crate_name", &self.crate_name)
            .field("heads", &self.heads)
            .field("variants", &self.variants.len())
            .finish()
    }
}

/// A parsed solver choice: its canonical spec string, its order, whether it steps adaptively,
/// and how to build the integrator for a system. Cheap to clone; the same spec builds the same
/// integrator for every system.
#[derive(Clone)]
pub struct SolverSpec {
    spec: String,
    label: String,
    order: u32,
    adaptive: bool,
    build: Arc<BuildFn>,
    caveat: Option<Arc<CaveatFn>>,
}

/// What a solver says about a model it runs with less than its nominal properties.
type CaveatFn = dyn Fn(&System) -> Option<String> + Send + Sync;

impl SolverSpec {
    /// A spec with its canonical string, report label, order, adaptivity and constructor.
    pub fn new(
        spec: impl Into<String>,
        label: impl Into<String>,
        order: u32,
        adaptive: bool,
        build: impl Fn(&System) -> Result<BoxedIntegrator, SolveError> + Send + Sync + 'static,
    ) -> Self {
        SolverSpec {
            spec: spec.into(),
            label: label.into(),
            order,
            adaptive,
            build: Arc::new(build),
            caveat: None,
        }
    }

    /// Adds the check behind [`SolverSpec::caveat`]: for a model the solver runs, but with
    /// less than its nominal order or another stated limitation, a sentence saying what holds
    /// instead.
    pub fn with_caveat(
        mut self,
        caveat: impl Fn(&System) -> Option<String> + Send + Sync + 'static,
    ) -> Self {
        self.caveat = Some(Arc::new(caveat));
        self
    }

    /// What this solver's results on `sys` do not have of its nominal properties (e.g. the
    /// modified-Lagrangian schemes on a model with drivers keep the plain scheme's order), as
    /// a sentence for a warning; `None` when the model gets everything [`SolverSpec::order`]
    /// and the registry's description promise.
    pub fn caveat(&self, sys: &System) -> Option<String> {
        self.caveat.as_ref().and_then(|c| c(sys))
    }

    /// The canonical spec string (parses back to this solver).
    pub fn spec(&self) -> &str {
        &self.spec
    }

    /// The name reports use.
    pub fn label(&self) -> &str {
        &self.label
    }

    /// Convergence order in the step size.
    pub fn order(&self) -> u32 {
        self.order
    }

    /// Whether the solver has an embedded error estimate (runs with a tolerance).
    pub fn adaptive(&self) -> bool {
        self.adaptive
    }

    /// Builds the integrator for `sys` (its workspace sized for it); the solver's own checks
    /// (e.g. a conservative model for the modified-Lagrangian preadjustment) are errors here.
    pub fn build(&self, sys: &System) -> Result<BoxedIntegrator, SolveError> {
        (self.build)(sys)
    }
}

impl fmt::Display for SolverSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(&self.spec)
    }
}

impl fmt::Debug for SolverSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.debug_struct("SolverSpec")
            .field("spec", &self.spec)
            .field("order", &self.order)
            .field("adaptive", &self.adaptive)
            .finish()
    }
}

impl PartialEq for SolverSpec {
    fn eq(&self, other: &Self) -> bool {
        self.spec == other.spec
    }
}

/// The registered solver families, addressed by spec strings.
#[derive(Clone, Debug, Default)]
pub struct Registry {
    families: Vec<&'static SolverFamily>,
}

impl Registry {
    /// An empty registry.
    pub fn new() -> Self {
        Registry::default()
    }

    /// Adds a family; an error if one of its heads is taken or a variant's spec does not parse
    /// to a solver of its family with the variant's order and adaptivity.
    pub fn register(&mut self, family: &'static SolverFamily) -> Result<(), SolveError> {
        for head in family.heads {
            if let Some(other) = self.family_of(head) {
                return Err(SolveError::SolverSpec {
                    spec: head.to_string(),
                    reason: format!(
                        "registered twice (by {} and {})",
                        other.crate_name, family.crate_name
                    ),
                });
            }
        }
        for v in family.variants {
            let args = SpecArgs::new(v.spec);
            if !family.heads.contains(&args.head.as_str()) {
                return Err(args.error(format!(
                    "a variant of {} whose head is not one of its heads",
                    family.crate_name
                )));
            }
            let spec = (family.parse)(&args)?;
            if spec.order != v.order || spec.adaptive != v.adaptive {
                return Err(args.error(format!(
                    "{} lists order {} and adaptive = {}, its parser says {} and {}",
                    family.crate_name, v.order, v.adaptive, spec.order, spec.adaptive
                )));
            }
        }
        self.families.push(family);
        Ok(())
    }

    fn family_of(&self, head: &str) -> Option<&'static SolverFamily> {
        self.families
            .iter()
            .copied()
            .find(|f| f.heads.contains(&head))
    }

    /// Parses a spec string (case and surrounding blanks ignored) through the family its head
    /// names. Errors name the spec and say what is wrong; an unknown head lists every
    /// registered syntax.
    pub fn parse(&self, text: &str) -> Result<SolverSpec, SolveError> {
        let args = SpecArgs::new(text);
        match self.family_of(&args.head) {
            Some(f) => (f.parse)(&args),
            None => Err(SolveError::UnknownSolver {
                spec: text.to_string(),
                known: self.syntax_list(),
            }),
        }
    }

    /// The registered families, in registration order.
    pub fn families(&self) -> &[&'static SolverFamily] {
        &self.families
    }

    /// `e`, an error of building a solver for `sys`, completed with what the registry knows:
    /// a refusal of redundant constraint equations ([`crate::refuse_redundant`]) gets the
    /// list of the registered solvers that build for `sys` (tried one by one: an error path).
    /// Other errors are returned unchanged.
    pub fn with_advice(&self, sys: &mbd_model::System, e: SolveError) -> SolveError {
        match e {
            SolveError::Unsupported(msg)
                if sys.n_redundant() > 0 && msg.contains("redundant constraint") =>
            {
                let ok: Vec<&str> = self
                    .variants()
                    .filter(|(_, v)| self.parse(v.spec).and_then(|spec| spec.build(sys)).is_ok())
                    .map(|(_, v)| v.spec)
                    .collect();
                SolveError::Unsupported(format!(
                    "{msg}; the solvers that run this model: {}",
                    ok.join(", ")
                ))
            }
            other => other,
        }
    }

    /// Every registered variant with its family, in registration order.
    pub fn variants(
        &self,
    ) -> impl Iterator<Item = (&'static SolverFamily, &'static SolverVariant)> + '_ {
        self.families
            .iter()
            .flat_map(|f| f.variants.iter().map(move |v| (*f, v)))
    }

    /// The variant whose spec is `spec` (exactly), if registered.
    pub fn variant(&self, spec: &str) -> Option<&'static SolverVariant> {
        self.variants().map(|(_, v)| v).find(|v| v.spec == spec)
    }

    /// Every family's syntax, comma-separated (for help texts and errors).
    pub fn syntax_list(&self) -> String {
        self.families
            .iter()
            .map(|f| f.syntax)
            .collect::<Vec<_>>()
            .join(", ")
    }

    /// A Markdown table of every variant: spec, order, adaptive, O(N), what it refuses, and
    /// the description. The README and the CLI docs carry this table (a test compares them).
    pub fn markdown_table(&self) -> String {
        let mut s = String::from(
            "| solver | order | adaptive (`--tol`) | O(N) per step | refuses | what |\n\
             |---|---|---|---|---|---|\n",
        );
        for (_, v) in self.variants() {
            s.push_str(&format!(
                "| `{}` | {} | {} | {} | {} | {} |\n",
                v.spec,
                v.order,
                if v.adaptive { "yes" } else { "no" },
                if v.scales { "yes" } else { "no" },
                if v.refuses.is_empty() { "-" } else { v.refuses },
                v.description
            ));
        }
        s
    }
}

/// The index-1 Runge-Kutta family of this crate ([`Index1Rk`] with DOPRI5, no stabilisation):
/// `index1:dopri5`, fixed or adaptive steps.
pub static INDEX1: SolverFamily = SolverFamily {
    crate_name: "mbd-solve",
    heads: &["index1"],
    syntax: "index1:dopri5",
    variants: &[SolverVariant {
        spec: "index1:dopri5",
        label: "DOPRI5 (index-1, plain)",
        description:
            "Dormand-Prince 5(4) on the index-1 form, no stabilisation (the constraints drift)",
        order: 5,
        adaptive: true,
        scales: true,
        relative_cost: 1.5,
        refuses: "",
        compared: true,
    }],
    parse: parse_index1,
};

fn parse_index1(args: &SpecArgs) -> Result<SolverSpec, SolveError> {
    match args.parts.as_slice() {
        [m] if m == "dopri5" => Ok(SolverSpec::new(
            "index1:dopri5",
            "DOPRI5 (index-1, plain)",
            5,
            true,
            |sys| {
                Ok(Box::new(Index1Rk::new(
                    sys,
                    ButcherTableau::dopri5(),
                    Index1Options::default(),
                )?))
            },
        )),
        _ => Err(args.error("the index-1 family has one method: index1:dopri5")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn dummy(_: &SpecArgs) -> Result<SolverSpec, SolveError> {
        Ok(SolverSpec::new("x", "x", 1, false, |_| {
            Err(SolveError::Unsupported("dummy".into()))
        }))
    }

    #[test]
    fn heads_are_unique_and_variants_checked() {
        let mut r = Registry::new();
        r.register(&INDEX1).expect("first");
        let e = r.register(&INDEX1).unwrap_err();
        assert!(e.to_string().contains("registered twice"), "{e}");
        static BAD: SolverFamily = SolverFamily {
            crate_name: "bad",
            heads: &["bad"],
            syntax: "bad",
            variants: &[SolverVariant {
                spec: "bad",
                label: "bad",
                description: "",
                order: 2,
                adaptive: false,
                scales: false,
                relative_cost: 1.0,
                refuses: "",
                compared: true,
            }],
            parse: dummy,
        };
        let e = r.register(&BAD).unwrap_err();
        assert!(e.to_string().contains("lists order 2"), "{e}");
    }

    #[test]
    fn spec_args_refuse_repeats_and_empty_parts() {
        let a = SpecArgs::new(" Symplectic:2:gamma=1:gamma=2 ");
        assert_eq!(a.head, "symplectic");
        let e = a.options().unwrap_err().to_string();
        assert!(e.contains("'gamma' is given twice"), "{e}");
        let e = SpecArgs::new("tangent::rk4").options().unwrap_err();
        assert!(e.to_string().contains("empty part"), "{e}");
        let a = SpecArgs::new("x:gamma=abc");
        let e = a.number("gamma", Some("abc")).unwrap_err().to_string();
        assert!(e.contains("gamma must be a finite number"), "{e}");
        assert!(a.number("gamma", Some("inf")).is_err());
        assert_eq!(a.number("gamma", Some("-0.5")).ok(), Some(-0.5));
    }

    #[test]
    fn index1_parses_and_refuses_other_methods() {
        let mut r = Registry::new();
        r.register(&INDEX1).expect("register");
        assert_eq!(
            r.parse(" INDEX1:DOPRI5 ").expect("parse").spec(),
            "index1:dopri5"
        );
        let e = r.parse("index1:rk4").unwrap_err().to_string();
        assert!(e.contains("index1:dopri5"), "{e}");
        assert!(r.markdown_table().contains("| `index1:dopri5` | 5 | yes |"));
    }
}
