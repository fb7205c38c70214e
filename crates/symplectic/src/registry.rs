//! This crate's entry in the solver registry: `symplectic:S[:gamma=G]` and
//! `symplectic:S:modified`.

use crate::{Galerkin, PreadjustMode, SymplecticOptions};
use mbd_model::System;
use mbd_solve::registry::{SolverFamily, SolverSpec, SolverVariant, SpecArgs};
use mbd_solve::SolveError;

/// Largest number of Gauss points a spec string may ask for.
const MAX_S: usize = 8;

/// Paper A's (s,s) Galerkin variational integrator: `symplectic:S` (plain, order 2S),
/// `symplectic:S:gamma=G` (paper A's preadjustment) and `symplectic:1:modified`,
/// `symplectic:2:modified` (the parameter-free modified Lagrangian).
pub static SOLVERS: SolverFamily = SolverFamily {
    crate_name: "mbd-symplectic",
    heads: &["symplectic"],
    syntax: "symplectic:S[:gamma=G] (S = 1..8), symplectic:1:modified, symplectic:2:modified",
    variants: &[
        SolverVariant {
            spec: "symplectic:1",
            label: "symplectic (1,1)",
            description: "paper A: (1,1) Galerkin variational integrator (midpoint), plain",
            order: 2,
            adaptive: false,
            scales: true,
            relative_cost: 3.0,
            refuses: "",
            compared: true,
        },
        SolverVariant {
            spec: "symplectic:2",
            label: "symplectic (2,2)",
            description: "paper A: (2,2) Galerkin variational integrator, plain (gamma=G for the preadjusted scheme)",
            order: 4,
            adaptive: false,
            scales: true,
            relative_cost: 8.0,
            refuses: "",
            compared: true,
        },
        SolverVariant {
            spec: "symplectic:1:modified",
            label: "symplectic (1,1), modified Lagrangian",
            description: "(1,1) with the parameter-free modified-Lagrangian preadjustment (order 4: the h^2 error term removed; order 2 with planar drivers)",
            order: 4,
            adaptive: false,
            scales: true,
            relative_cost: 8.0,
            refuses: "non-conservative force elements (dampers, time-varying loads)",
            compared: true,
        },
        SolverVariant {
            spec: "symplectic:2:modified",
            label: "symplectic (2,2), modified Lagrangian",
            description: "(2,2) with the parameter-free modified-Lagrangian preadjustment (order 6: the h^4 error term removed; order 4 with drivers)",
            order: 6,
            adaptive: false,
            scales: true,
            relative_cost: 20.0,
            refuses: "non-conservative force elements (dampers, time-varying loads)",
            compared: true,
        },
    ],
    parse,
};

fn parse(args: &SpecArgs) -> Result<SolverSpec, SolveError> {
    let opts = args.options()?;
    let s = match opts.first() {
        Some((p, None)) => match p.parse::<usize>() {
            Ok(s) if (1..=MAX_S).contains(&s) => s,
            _ => {
                return Err(args.error(format!(
                    "S must be a whole number from 1 to {MAX_S} (the number of Gauss points; \
                     order 2S), e.g. symplectic:2"
                )))
            }
        },
        _ => return Err(args.error("give the number of Gauss points S first, e.g. symplectic:2")),
    };
    let (mut gamma, mut modified) = (0.0, false);
    for (k, v) in &opts[1..] {
        match (k.as_str(), v) {
            ("modified", None) => modified = true,
            ("gamma", Some(g)) => gamma = args.number("gamma", Some(g))?,
            _ => {
                return Err(args.error(format!(
                    "unknown option '{k}'; use gamma=G or modified, e.g. symplectic:2:gamma=1 \
                     or symplectic:1:modified"
                )))
            }
        }
    }
    if modified && (s > 2 || gamma != 0.0) {
        return Err(args.error(
            "the modified-Lagrangian preadjustment needs S = 1 or 2 and no gamma: use \
             symplectic:1:modified or symplectic:2:modified",
        ));
    }
    let (spec, label) = if modified {
        (
            format!("symplectic:{s}:modified"),
            format!("symplectic ({s},{s}), modified Lagrangian"),
        )
    } else if gamma == 0.0 {
        (format!("symplectic:{s}"), format!("symplectic ({s},{s})"))
    } else {
        (
            format!("symplectic:{s}:gamma={gamma}"),
            format!("symplectic ({s},{s}), gamma = {gamma}"),
        )
    };
    // the modified Lagrangian removes the leading error term of the (s,s) scheme
    let order = 2 * s as u32 + if modified { 2 } else { 0 };
    let spec = SolverSpec::new(spec, label, order, false, move |sys| {
        let mut o = SymplecticOptions::new(s).with_gamma(gamma);
        if modified {
            o = o.with_preadjust(PreadjustMode::ModifiedLagrangian);
        }
        Ok(Box::new(Galerkin::new(sys, o)?))
    });
    Ok(if modified {
        spec.with_caveat(move |sys| rheonomic_caveat(sys, s))
    } else {
        spec
    })
}

/// The modified Lagrangian on a rheonomic model (drivers): its terms are derived for
/// constraints that do not depend on time, and the scheme keeps the plain (s,s) order 2s on
/// planar drivers (measured: docs/symplectic.md section 5a, "Rheonomic constraints (drivers),
/// measured"; the (1,1) scheme measured order 4 on spatial angle drivers, which the caveat
/// does not promise).
fn rheonomic_caveat(sys: &System, s: usize) -> Option<String> {
    if !sys.is_rheonomic() {
        return None;
    }
    Some(format!(
        "the modified-Lagrangian terms are derived for constraints that do not depend on time, \
         and this model has drivers: expect symplectic:{s}:modified to keep only the plain \
         (s,s) scheme's order {} (not {}) there, with a smaller error constant",
        2 * s,
        2 * s + 2
    ))
}
