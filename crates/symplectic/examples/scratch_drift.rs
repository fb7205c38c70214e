use mbd_model::models;
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, PreadjustMode, SymplecticOptions};
fn main() {
    let deg: f64 = std::env::args().nth(1).map_or(90.0, |s| s.parse().unwrap());
    let h: f64 = std::env::args()
        .nth(2)
        .map_or(0.025, |s| s.parse().unwrap());
    let sys = models::pendulum(1.0, 1.0, deg.to_radians(), 9.81).unwrap();
    let s0 = State::consistent(&sys, 0.0).unwrap();
    let variants: Vec<(&str, SymplecticOptions)> = vec![
        ("plain", SymplecticOptions::new(2)),
        (
            "mod default",
            SymplecticOptions::new(2).with_preadjust(PreadjustMode::ModifiedLagrangian),
        ),
        ("mod tol1e-17", {
            let mut o = SymplecticOptions::new(2).with_preadjust(PreadjustMode::ModifiedLagrangian);
            o.newton.tol = 1e-17;
            o
        }),
        ("mod jac_every1", {
            let mut o = SymplecticOptions::new(2).with_preadjust(PreadjustMode::ModifiedLagrangian);
            o.newton.jacobian_every = 1;
            o
        }),
        ("mod pred0", {
            let mut o = SymplecticOptions::new(2).with_preadjust(PreadjustMode::ModifiedLagrangian);
            o.predictor_order = 0;
            o
        }),
        ("plain tol1e-17", {
            let mut o = SymplecticOptions::new(2);
            o.newton.tol = 1e-17;
            o
        }),
    ];
    let n = (160.0 / h) as usize;
    for (name, o) in variants {
        let mut g = Galerkin::new(&sys, o).unwrap();
        let mut st = s0.clone();
        let h0 = sys.energy(st.q.as_slice(), st.v.as_slice());
        let mut es = Vec::new();
        let mut its = 0;
        for _ in 0..n {
            its += g.step(&sys, &mut st, h).unwrap().newton_iterations;
            es.push(sys.energy(st.q.as_slice(), st.v.as_slice()) - h0);
        }
        let k = n / 10;
        let a: f64 = es[..k].iter().sum::<f64>() / k as f64;
        let b: f64 = es[n - k..].iter().sum::<f64>() / k as f64;
        println!(
            "{name:16} drift {:.3e}  its/step {:.2}",
            b - a,
            its as f64 / n as f64
        );
    }
}
