//! Solver names on the command line and the integrators they build.

use mbd_model::System;
use mbd_solve::{
    AdaptiveIntegrator, ButcherTableau, Index1Options, Index1Rk, Integrator, SolveError,
};
use std::fmt;
use std::str::FromStr;

/// The solvers `mbd run --solver` accepts.
const SOLVERS: &str = "rk4, rk4-projected, symplectic:S[:gamma=G] (e.g. symplectic:2, \
                       symplectic:2:gamma=1), symplectic:1:modified, symplectic:2:modified, \
                       index1:dopri5, \
                       tangent:rk4, tangent:dopri5, firefly-gauss";

/// A solver chosen on the command line.
#[derive(Clone, Debug, PartialEq)]
pub enum SolverSpec {
    /// Classic RK4 on the index-1 form, no stabilisation (`rk4`).
    Rk4,
    /// RK4 with post-step projection onto the constraints (`rk4-projected`).
    Rk4Projected,
    /// Paper A's (s,s) Galerkin variational integrator (`symplectic:S[:gamma=G]`,
    /// `symplectic:1:modified`, `symplectic:2:modified`).
    Symplectic {
        /// Number of Gauss points, order `2s`.
        s: usize,
        /// Preadjustment parameter (0: plain scheme).
        gamma: f64,
        /// The parameter-free modified-Lagrangian preadjustment (s = 1 or 2).
        modified: bool,
    },
    /// DOPRI5 5(4) on the index-1 form, no stabilisation (`index1:dopri5`), fixed or adaptive
    /// steps.
    Index1Dopri5,
    /// Paper B's tangent-space parameterisation with RK4 (`tangent:rk4`).
    TangentRk4,
    /// Paper B's tangent-space parameterisation with DOPRI5 (`tangent:dopri5`), fixed or
    /// adaptive steps.
    TangentDopri5,
    /// Paper C's firefly-algorithm DAE solver (`firefly-gauss`).
    FireflyGauss,
}

impl SolverSpec {
    /// Whether the solver has an embedded error estimate (so `--tol` works).
    pub fn has_error_estimate(&self) -> bool {
        matches!(self, SolverSpec::Index1Dopri5 | SolverSpec::TangentDopri5)
    }

    /// Builds the adaptive integrator for `sys` (for [`mbd_solve::run_adaptive`]); an
    /// [`SolveError::Unsupported`] error for a solver without an embedded error estimate.
    pub fn build_adaptive(&self, sys: &System) -> Result<Box<dyn AdaptiveIntegrator>, SolveError> {
        Ok(match self {
            SolverSpec::Index1Dopri5 => Box::new(index1_dopri5(sys)?),
            SolverSpec::TangentDopri5 => Box::new(mbd_tangent::TangentRk::dopri5(sys)?),
            _ => {
                return Err(SolveError::Unsupported(format!(
                    "'{self}' has no embedded error estimate"
                )))
            }
        })
    }

    /// Builds the fixed-step integrator for `sys`.
    pub fn build(&self, sys: &System) -> Result<Box<dyn Integrator>, SolveError> {
        Ok(match self {
            SolverSpec::Rk4 => Box::new(mbd_rk4::Rk4::new(sys, mbd_rk4::Rk4Options::plain())?),
            SolverSpec::Rk4Projected => {
                Box::new(mbd_rk4::Rk4::new(sys, mbd_rk4::Rk4Options::projected())?)
            }
            SolverSpec::Symplectic { s, gamma, modified } => {
                let mut o = mbd_symplectic::SymplecticOptions::new(*s).with_gamma(*gamma);
                if *modified {
                    o = o.with_preadjust(mbd_symplectic::PreadjustMode::ModifiedLagrangian);
                }
                Box::new(mbd_symplectic::Galerkin::new(sys, o)?)
            }
            SolverSpec::Index1Dopri5 => Box::new(index1_dopri5(sys)?),
            SolverSpec::TangentRk4 => Box::new(mbd_tangent::TangentRk::rk4(sys)?),
            SolverSpec::TangentDopri5 => Box::new(mbd_tangent::TangentRk::dopri5(sys)?),
            SolverSpec::FireflyGauss => Box::new(mbd_firefly_gauss::FireflyGauss::new(
                sys,
                mbd_firefly_gauss::FaDaeOptions::default(),
            )?),
        })
    }
}

/// DOPRI5 on the index-1 form with the default options (no Baumgarte, no projection).
fn index1_dopri5(sys: &System) -> Result<Index1Rk, SolveError> {
    Index1Rk::new(sys, ButcherTableau::dopri5(), Index1Options::default())
}

impl fmt::Display for SolverSpec {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            SolverSpec::Rk4 => write!(f, "rk4"),
            SolverSpec::Rk4Projected => write!(f, "rk4-projected"),
            SolverSpec::Symplectic {
                s, modified: true, ..
            } => write!(f, "symplectic:{s}:modified"),
            SolverSpec::Symplectic { s, gamma, .. } if *gamma == 0.0 => {
                write!(f, "symplectic:{s}")
            }
            SolverSpec::Symplectic { s, gamma, .. } => write!(f, "symplectic:{s}:gamma={gamma}"),
            SolverSpec::Index1Dopri5 => write!(f, "index1:dopri5"),
            SolverSpec::TangentRk4 => write!(f, "tangent:rk4"),
            SolverSpec::TangentDopri5 => write!(f, "tangent:dopri5"),
            SolverSpec::FireflyGauss => write!(f, "firefly-gauss"),
        }
    }
}

impl FromStr for SolverSpec {
    type Err = String;

    /// Parses a solver name; the error lists the solvers.
    fn from_str(text: &str) -> Result<Self, String> {
        let unknown = || format!("unknown solver '{text}'; use one of: {SOLVERS}");
        let t = text.trim().to_ascii_lowercase();
        match t.as_str() {
            "rk4" => return Ok(SolverSpec::Rk4),
            "rk4-projected" => return Ok(SolverSpec::Rk4Projected),
            "index1:dopri5" => return Ok(SolverSpec::Index1Dopri5),
            "tangent:rk4" => return Ok(SolverSpec::TangentRk4),
            "tangent:dopri5" => return Ok(SolverSpec::TangentDopri5),
            "firefly-gauss" => return Ok(SolverSpec::FireflyGauss),
            _ => {}
        }
        let mut parts = t.split(':');
        if parts.next() != Some("symplectic") {
            return Err(unknown());
        }
        let s = match parts.next() {
            Some(p) => match p.parse::<usize>() {
                Ok(s) if (1..=8).contains(&s) => s,
                _ => {
                    return Err(format!(
                        "solver '{text}': S must be a whole number from 1 to 8 (the number of \
                         Gauss points; order 2S), e.g. symplectic:2"
                    ))
                }
            },
            None => {
                return Err(format!(
                    "solver '{text}': give the number of Gauss points S, e.g. symplectic:2"
                ))
            }
        };
        let (mut gamma, mut modified) = (0.0, false);
        for p in parts {
            if p == "modified" {
                modified = true;
            } else if let Some(g) = p.strip_prefix("gamma=") {
                gamma = match g.parse::<f64>() {
                    Ok(g) if g.is_finite() => g,
                    _ => {
                        return Err(format!(
                            "solver '{text}': gamma must be a finite number, e.g. \
                             symplectic:2:gamma=1"
                        ))
                    }
                };
            } else {
                return Err(format!(
                    "solver '{text}': unknown option '{p}'; use gamma=G or modified, e.g. \
                     symplectic:2:gamma=1 or symplectic:1:modified"
                ));
            }
        }
        if modified && (s > 2 || gamma != 0.0) {
            return Err(format!(
                "solver '{text}': the modified-Lagrangian preadjustment needs S = 1 or 2 and \
                 no gamma: use symplectic:1:modified or symplectic:2:modified"
            ));
        }
        Ok(SolverSpec::Symplectic { s, gamma, modified })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_round_trip() {
        for name in [
            "rk4",
            "rk4-projected",
            "symplectic:2",
            "symplectic:3:gamma=0.5",
            "symplectic:1:modified",
            "index1:dopri5",
            "tangent:rk4",
            "tangent:dopri5",
            "firefly-gauss",
        ] {
            let spec: SolverSpec = name.parse().unwrap();
            assert_eq!(spec.to_string(), name);
        }
    }

    #[test]
    fn bad_names_say_what_to_use() {
        let e = "rk5".parse::<SolverSpec>().unwrap_err();
        assert!(
            e.contains("unknown solver 'rk5'")
                && e.contains("index1:dopri5")
                && e.contains("tangent:dopri5"),
            "{e}"
        );
        let e = "symplectic:x".parse::<SolverSpec>().unwrap_err();
        assert!(e.contains("S must be a whole number"), "{e}");
        let e = "symplectic:2:gamma=abc".parse::<SolverSpec>().unwrap_err();
        assert!(e.contains("gamma must be a finite number"), "{e}");
        let e = "symplectic:3:modified".parse::<SolverSpec>().unwrap_err();
        assert!(e.contains("needs S = 1 or 2"), "{e}");
        let e = "symplectic:2:modified:gamma=1"
            .parse::<SolverSpec>()
            .unwrap_err();
        assert!(e.contains("no gamma"), "{e}");
        assert!(matches!(
            "symplectic:2:modified".parse::<SolverSpec>(),
            Ok(SolverSpec::Symplectic {
                s: 2,
                modified: true,
                ..
            })
        ));
        let e = "symplectic:2:foo".parse::<SolverSpec>().unwrap_err();
        assert!(e.contains("unknown option 'foo'"), "{e}");
    }

    #[test]
    fn only_dopri5_has_an_error_estimate() {
        assert!(SolverSpec::TangentDopri5.has_error_estimate());
        assert!(SolverSpec::Index1Dopri5.has_error_estimate());
        assert!(!SolverSpec::Rk4.has_error_estimate());
        assert!(!SolverSpec::TangentRk4.has_error_estimate());
    }
}
