//! The energy balance (`mbd_analysis::EnergyBalance`): on models whose energy is not conserved
//! (a damper, drivers), `H(t) - H(0) - W_external + E_dissipated` stays at the solver's
//! accuracy while `H` itself changes by a large fraction.

use mbd::prelude::*;
use mbd_analysis::EnergyBalance;

fn balance(sys: System, spec: &str, h: f64, t_end: f64) -> (EnergyBalance, f64) {
    let mut eb = EnergyBalance::new(&sys).unwrap();
    let mut sim = Simulation::new(sys, spec).unwrap();
    let h0 = sim
        .system()
        .energy(sim.state().q.as_slice(), sim.state().v.as_slice());
    sim.run_observed(RunConfig::new(t_end, h), &mut eb).unwrap();
    let s = sim.state();
    let change = (sim.system().energy(s.q.as_slice(), s.v.as_slice()) - h0).abs();
    (eb, change)
}

fn models() -> Vec<(&'static str, System)> {
    vec![
        (
            "damped slider-crank",
            System::from_path(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/examples/models/slider_crank_spring.toml"
            ))
            .unwrap(),
        ),
        (
            "driven three-link arm",
            System::from_path(concat!(
                env!("CARGO_MANIFEST_DIR"),
                "/examples/models/driven_three_link_arm.json"
            ))
            .unwrap(),
        ),
    ]
}

/// Symplectic (2,2) at h = 1e-3 over 2 s: the balance's residual at most 1e-8 of max |H| (the
/// issue's target; measured: 2.0e-9 on the damped slider-crank and 1.9e-13 on the driven
/// arm), while H changes by more than 1e-3 of it (so the balance, not conservation, closes
/// it).
#[test]
fn symplectic_22_closes_the_balance_to_1e_8() {
    for (name, sys) in models() {
        let (eb, change) = balance(sys, "symplectic:2", 1e-3, 2.0);
        let rel = eb.max_residual() / eb.max_energy();
        eprintln!(
            "{name}: residual {rel:.2e} of max|H|; H changed by {:.2e}; W_ext {:.4e} J, dissipated {:.4e} J",
            change / eb.max_energy(),
            eb.external_work(),
            eb.dissipated()
        );
        assert!(rel <= 1e-8, "{name}: {rel:e}");
        assert!(change > 1e-3 * eb.max_energy(), "{name}: {change:e}");
        assert!(eb.dissipated() >= 0.0);
    }
}

/// RK4 (projected) closes it to its order: halving h cuts the residual about 16x (measured
/// orders 3.9 and 4.0 between h = 2e-3 and 1e-3; between 4e-3 and 2e-3 the damped
/// slider-crank's spring, at omega h = 0.08, is not yet asymptotic: 3.5).
#[test]
fn rk4_closes_the_balance_at_its_order() {
    for (name, sys) in models() {
        let (a, _) = balance(sys.clone(), "rk4-projected", 2e-3, 1.0);
        let (b, _) = balance(sys, "rk4-projected", 1e-3, 1.0);
        let order = (a.max_residual() / b.max_residual()).log2();
        eprintln!(
            "{name}: residuals {:.2e}, {:.2e} of max|H|: order {order:.2}",
            a.max_residual() / a.max_energy(),
            b.max_residual() / b.max_energy()
        );
        assert!(order > 3.5, "{name}: order {order}");
    }
}
