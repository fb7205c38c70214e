//! This crate's entry in the solver registry: `tangent:rk4` and `tangent:dopri5`.

use crate::{TangentOptions, TangentRk};
use mbd_solve::registry::{SolverFamily, SolverSpec, SolverVariant, SpecArgs};
use mbd_solve::{ButcherTableau, SolveError};

/// Paper B's tangent-space parameterisation with RK4 (`tangent:rk4`) or DOPRI5
/// (`tangent:dopri5`, fixed steps or adaptive with a tolerance).
pub static SOLVERS: SolverFamily = SolverFamily {
    crate_name: "mbd-tangent",
    heads: &["tangent"],
    syntax: "tangent:rk4, tangent:dopri5",
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
    let dopri5 = match args.parts.as_slice() {
        [m] if m == "rk4" => false,
        [m] if m == "dopri5" => true,
        _ => {
            return Err(
                args.error("the tangent family takes one method: tangent:rk4 or tangent:dopri5")
            )
        }
    };
    let (spec, label, order) = if dopri5 {
        ("tangent:dopri5", "tangent-space DOPRI5", 5)
    } else {
        ("tangent:rk4", "tangent-space RK4", 4)
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
            TangentOptions::default(),
        )?))
    }))
}
