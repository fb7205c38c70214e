//! This crate's entry in the solver registry: `tangent:rk4` and `tangent:dopri5`, each with
//! the option `euclidean` (paper B's chart metric instead of the step-weighted one).

use crate::{ChartMetric, TangentOptions, TangentRk};
use mbd_solve::registry::{SolverFamily, SolverSpec, SolverVariant, SpecArgs};
use mbd_solve::{ButcherTableau, SolveError};

/// Paper B's tangent-space parameterisation with RK4 (`tangent:rk4`) or DOPRI5
/// (`tangent:dopri5`, fixed steps or adaptive with a tolerance); `:euclidean` builds the chart
/// in paper B's Euclidean metric of `(q, v)` ([`ChartMetric::Euclidean`]).
pub static SOLVERS: SolverFamily = SolverFamily {
    crate_name: "mbd-tangent",
    heads: &["tangent"],
    syntax: "tangent:rk4[:euclidean], tangent:dopri5[:euclidean]",
    variants: &[
        SolverVariant {
            spec: "tangent:rk4",
            label: "tangent-space RK4",
            description: "paper B: RK4 on the state equations of a tangent-space chart (constraints kept to 1e-13)",
            order: 4,
            adaptive: false,
            scales: true,
            relative_cost: 3.5,
            refuses: "",
            compared: true,
        },
        SolverVariant {
            spec: "tangent:dopri5",
            label: "tangent-space DOPRI5",
            description: "paper B with Dormand-Prince 5(4): fixed steps, or adaptive with --tol",
            order: 5,
            adaptive: true,
            scales: true,
            relative_cost: 6.0,
            refuses: "",
            compared: true,
        },
    ],
    parse,
};

fn parse(args: &SpecArgs) -> Result<SolverSpec, SolveError> {
    let (method, option) = match args.parts.as_slice() {
        [m] => (m.as_str(), None),
        [m, o] => (m.as_str(), Some(o.as_str())),
        _ => {
            return Err(args.error(
                "the tangent family takes a method and at most one option: tangent:rk4, \
                 tangent:dopri5, tangent:rk4:euclidean",
            ))
        }
    };
    let dopri5 = match method {
        "rk4" => false,
        "dopri5" => true,
        _ => {
            return Err(
                args.error("the tangent family takes one method: tangent:rk4 or tangent:dopri5")
            )
        }
    };
    let metric = match option {
        None => ChartMetric::StepWeighted,
        Some("euclidean") => ChartMetric::Euclidean,
        Some(o) => {
            return Err(args.error(format!(
                "unknown option '{o}'; the tangent family's one option is euclidean (paper B's \
                 chart metric), e.g. tangent:rk4:euclidean"
            )))
        }
    };
    let (spec, label, order) = match (dopri5, metric) {
        (true, ChartMetric::Euclidean) => (
            "tangent:dopri5:euclidean",
            "tangent-space DOPRI5, Euclidean chart",
            5,
        ),
        (true, _) => ("tangent:dopri5", "tangent-space DOPRI5", 5),
        (false, ChartMetric::Euclidean) => (
            "tangent:rk4:euclidean",
            "tangent-space RK4, Euclidean chart",
            4,
        ),
        (false, _) => ("tangent:rk4", "tangent-space RK4", 4),
    };
    Ok(SolverSpec::new(spec, label, order, dopri5, move |sys| {
        let tableau = if dopri5 {
            ButcherTableau::dopri5()
        } else {
            ButcherTableau::rk4()
        };
        Ok(Box::new(TangentRk::new(
            sys,
            tableau,
            TangentOptions {
                metric,
                ..TangentOptions::default()
            },
        )?))
    }))
}
