use mbd_analysis::period;
use mbd_model::models;
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, PreadjustMode, SymplecticOptions};
fn err(deg: f64, h: f64, o: SymplecticOptions, periods: f64) -> f64 {
    let th = deg.to_radians();
    let sys = models::pendulum(1.0, 1.0, th, 9.81).unwrap();
    let te = period::pendulum_period((1.5f64 * 9.81).sqrt(), th).unwrap();
    let mut st = State::consistent(&sys, 0.0).unwrap();
    let mut g = Galerkin::new(&sys, o).unwrap();
    let n = (periods * te / h).ceil() as usize + 4;
    let mut psi = vec![st.q[2] + std::f64::consts::FRAC_PI_2];
    for _ in 0..n {
        g.step(&sys, &mut st, h).unwrap();
        psi.push(st.q[2] + std::f64::consts::FRAC_PI_2);
    }
    period::oscillation_period(&psi, 0.0, h, 6).unwrap() / te - 1.0
}
fn main() {
    let s: usize = std::env::args().nth(1).map_or(2, |x| x.parse().unwrap());
    for deg in [10.0, 45.0, 90.0, 120.0] {
        for modified in [false, true] {
            let mut o = SymplecticOptions::new(s);
            if modified {
                o = o.with_preadjust(PreadjustMode::ModifiedLagrangian);
            }
            let e: Vec<f64> = [0.1, 0.05, 0.025]
                .iter()
                .map(|&h| err(deg, h, o, 40.0))
                .collect();
            let o1 = (e[0] / e[1]).abs().log2();
            let o2 = (e[1] / e[2]).abs().log2();
            println!(
                "s={s} {deg} deg modified={modified}: {:.3e} {:.3e} {:.3e} orders {o1:.2} {o2:.2}",
                e[0], e[1], e[2]
            );
        }
    }
}
