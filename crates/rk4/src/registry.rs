//! This crate's entry in the solver registry: `rk4` and `rk4-projected`.

use crate::{Rk4, Rk4Options};
use mbd_solve::registry::{SolverFamily, SolverSpec, SolverVariant, SpecArgs};
use mbd_solve::SolveError;

/// The RK4 family: `rk4` (plain, the constraints drift) and `rk4-projected` (post-step
/// projection onto the position and velocity constraints).
pub static SOLVERS: SolverFamily = SolverFamily {
    crate_name: "mbd-rk4",
    heads: &["rk4", "rk4-projected"],
    syntax: "rk4, rk4-projected",
    variants: &[
        SolverVariant {
            spec: "rk4",
            label: "RK4 (index-1, plain)",
            description:
                "classic RK4 on the index-1 form, no stabilisation (the constraints drift)",
            order: 4,
            adaptive: false,
            scales: true,
            relative_cost: 1.0,
            refuses: "",
            compared: true,
        },
        SolverVariant {
            spec: "rk4-projected",
            label: "RK4 (index-1, projection)",
            description: "RK4 with post-step projection onto Phi = 0 and Phi_q v = 0",
            order: 4,
            adaptive: false,
            scales: true,
            relative_cost: 1.5,
            refuses: "",
            compared: true,
        },
    ],
    parse,
};

fn parse(args: &SpecArgs) -> Result<SolverSpec, SolveError> {
    args.no_options()?;
    let projected = args.head == "rk4-projected";
    let (spec, label) = if projected {
        ("rk4-projected", "RK4 (index-1, projection)")
    } else {
        ("rk4", "RK4 (index-1, plain)")
    };
    Ok(SolverSpec::new(spec, label, 4, false, move |sys| {
        let options = if projected {
            Rk4Options::projected()
        } else {
            Rk4Options::plain()
        };
        Ok(Box::new(Rk4::new(sys, options)?))
    }))
}
