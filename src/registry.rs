//! The one solver registry: every solver crate of the workspace, one line each.

use mbd_solve::registry::{Registry, SolverFamily};
use std::sync::OnceLock;

/// The registered solver families, in the order `mbd solvers` lists them. Adding a solver
/// crate: export a `SolverFamily` from it (see `docs/architecture.md`, "How to add a solver")
/// and add one line here.
static FAMILIES: &[&SolverFamily] = &[
    &mbd_rk4::SOLVERS,
    &mbd_solve::registry::INDEX1,
    &mbd_symplectic::SOLVERS,
    &mbd_tangent::SOLVERS,
    &mbd_firefly_gauss::SOLVERS,
];

/// The solver registry of this workspace: parse a spec string (`"symplectic:2"`,
/// `"tangent:dopri5"`, ...) into a [`mbd_solve::registry::SolverSpec`], list the solvers.
///
/// ```
/// let spec = mbd::registry().parse("symplectic:2:gamma=1")?;
/// assert_eq!(spec.order(), 4);
/// assert!(mbd::registry().variants().any(|(_, v)| v.spec == "tangent:dopri5"));
/// # Ok::<(), mbd::Error>(())
/// ```
pub fn registry() -> &'static Registry {
    static REGISTRY: OnceLock<Registry> = OnceLock::new();
    REGISTRY.get_or_init(|| {
        let mut r = Registry::new();
        for f in FAMILIES {
            // the families are this workspace's own; a clash is a programming error that the
            // tests catch (`registry_accepts_every_family`), so it is skipped here, not fatal
            let _ = r.register(f);
        }
        r
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn registry_accepts_every_family() {
        let mut r = Registry::new();
        for f in FAMILIES {
            r.register(f).expect("family registers");
        }
        assert_eq!(registry().families().len(), FAMILIES.len());
    }
}
