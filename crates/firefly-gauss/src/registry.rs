//! This crate's entry in the solver registry: `firefly-gauss[:polish][:seed=N]`.

use crate::{FaDaeOptions, FireflyGauss};
use mbd_solve::registry::{SolverFamily, SolverSpec, SolverVariant, SpecArgs};
use mbd_solve::SolveError;

/// Paper C's firefly-algorithm DAE solver: `firefly-gauss` (the paper's method with the
/// default options), `firefly-gauss:polish` (a Gauss-Newton polish of the swarm's best
/// point), and `seed=N` for the root seed (default 0; runs are deterministic for a seed).
pub static SOLVERS: SolverFamily = SolverFamily {
    crate_name: "mbd-firefly-gauss",
    heads: &["firefly-gauss"],
    syntax: "firefly-gauss[:polish][:seed=N]",
    variants: &[
        SolverVariant {
            spec: "firefly-gauss",
            label: "FA-DAE",
            description: "paper C: interpolation + Gauss quadrature, each step minimised by the firefly algorithm (seeded, deterministic)",
            order: 4,
            adaptive: false,
            scales: false,
            relative_cost: 300.0,
            refuses: "mechanisms without a degree of freedom (fully driven: nothing to optimise); spatial models above 600 equations (its acceleration solves are dense)",
            compared: false,
        },
        SolverVariant {
            spec: "firefly-gauss:polish",
            label: "FA-DAE + Gauss-Newton polish",
            description: "FA-DAE with a Gauss-Newton polish of the swarm's best point (the discretisation's own accuracy)",
            order: 4,
            adaptive: false,
            scales: false,
            relative_cost: 300.0,
            refuses: "mechanisms without a degree of freedom (fully driven: nothing to optimise); spatial models above 600 equations (its acceleration solves are dense)",
            compared: true,
        },
    ],
    parse,
};

fn parse(args: &SpecArgs) -> Result<SolverSpec, SolveError> {
    let mut options = FaDaeOptions::default();
    for (k, v) in args.options()? {
        match (k.as_str(), v) {
            ("polish", None) => options.polish = true,
            ("seed", Some(v)) => {
                options.seed = v.parse::<u64>().map_err(|_| {
                    args.error(format!(
                        "seed must be a whole number from 0 to {}, e.g. firefly-gauss:seed=7 \
                         (got '{v}')",
                        u64::MAX
                    ))
                })?
            }
            _ => {
                return Err(args.error(format!(
                    "unknown option '{k}'; use polish or seed=N, e.g. firefly-gauss:polish:seed=7"
                )))
            }
        }
    }
    let mut spec = String::from("firefly-gauss");
    let mut label = String::from("FA-DAE");
    if options.polish {
        spec.push_str(":polish");
        label.push_str(" + Gauss-Newton polish");
    }
    if options.seed != 0 {
        spec.push_str(&format!(":seed={}", options.seed));
        label.push_str(&format!(", seed {}", options.seed));
    }
    Ok(SolverSpec::new(spec, label, 4, false, move |sys| {
        Ok(Box::new(FireflyGauss::new(sys, options.clone())?))
    }))
}
