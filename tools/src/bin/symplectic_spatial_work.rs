//! The Newton work of the (s,s) scheme on `models::spatial_chain(N)` (or, with `planar`,
//! `models::n_link_chain(N)`), h = 1e-3, through direct steps: Newton iterations, residuals and stage Jacobians per step, and the sizes of the sparse
//! stage matrix and of its LU factors (per unknown), for the cost exponent's breakdown.
//!
//! `cargo run --release -p mbd-tools --bin symplectic_spatial_work [s] [modified] [planar] [N ...]`
use mbd::model::models;
use mbd::solve::{Integrator, State};
use mbd::symplectic::{Galerkin, PreadjustMode, SymplecticOptions};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    let s: usize = args.first().and_then(|a| a.parse().ok()).unwrap_or(2);
    let modified = args.iter().any(|a| a == "modified");
    let planar = args.iter().any(|a| a == "planar");
    let mut ns: Vec<usize> = args.iter().skip(1).filter_map(|a| a.parse().ok()).collect();
    if ns.is_empty() {
        ns = vec![100, 1000];
    }
    for &n in &ns {
        let sys = if planar {
            models::n_link_chain(n)?
        } else {
            models::spatial_chain(n)?
        };
        let mut st = State::consistent(&sys, 0.0)?;
        let mut opts = SymplecticOptions::new(s);
        if modified {
            opts = opts.with_preadjust(PreadjustMode::ModifiedLagrangian);
        }
        let mut g = Galerkin::new(&sys, opts)?;
        let steps = std::env::var("STEPS")
            .ok()
            .and_then(|v| v.parse().ok())
            .unwrap_or((40_000 / n).clamp(64, 400));
        let (mut it, mut ev) = (0usize, 0usize);
        let j0 = g.jacobian_count();
        for _ in 0..steps {
            let r = g.step(&sys, &mut st, 1e-3)?;
            it += r.newton_iterations;
            ev += r.rhs_evals;
        }
        let (nnz, fnnz) = g.sparse_nnz();
        let dim = s * (sys.n_coords() + sys.n_constraints());
        let k = steps as f64;
        println!(
            "N {n:>5} ({s},{s}){}: {steps} steps, {:.2} iterations, {:.2} residuals, {:.4} Jacobians per step; stage matrix {dim} unknowns, {nnz} entries ({:.2}/unknown), LU {fnnz} ({:.2}/unknown)",
            if modified { " modified" } else { "" },
            it as f64 / k,
            ev as f64 / k,
            (g.jacobian_count() - j0) as f64 / k,
            nnz as f64 / dim as f64,
            fnnz as f64 / dim as f64,
        );
    }
    Ok(())
}
