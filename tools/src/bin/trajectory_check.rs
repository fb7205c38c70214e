//! Prints the end states of fixed-step runs of several solvers on several models, every number
//! to round-trip precision, one line per (solver, model): a before/after cross-check of changes
//! that must not change results beyond round-off (compare two outputs with
//! `trajectory_check compare A B`).
//!
//! `cargo run --release -p mbd-tools --bin trajectory_check [steps] > out.txt`
use mbd::model::{models, Body, BodyRef, Coordinate, Force, Joint, System, SystemBuilder};
use mbd::rk4::{Rk4, Rk4Options};
use mbd::solve::{ButcherTableau, Index1Options, Index1Rk, Integrator, LinearSolver, State};
use mbd::symplectic::{Galerkin, SymplecticOptions};
use mbd::tangent::TangentRk;

/// Every joint kind in one consistent mechanism (revolute, distance, weld, prismatic,
/// absolute y and angle) with a spring-damper.
fn mixed() -> Result<System, Box<dyn std::error::Error>> {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let p1 = b.add_body(
        Body::new("p1")
            .rod(1.0, 1.0)
            .position(0.5, 0.0, 0.0)
            .velocity(0.0, 1.0, 2.0),
    );
    let p2 = b.add_body(Body::new("p2").rod(0.7, 0.6).position(1.6, 0.0, 0.0));
    let p3 = b.add_body(Body::new("p3").rod(0.4, 0.5).position(2.061, 0.155, 0.3));
    let s4 = b.add_body(
        Body::new("s4")
            .mass(0.5)
            .inertia(0.01)
            .position(2.72, -1.0, 0.0),
    );
    let s5 = b.add_body(
        Body::new("s5")
            .mass(0.3)
            .inertia(0.02)
            .position(-1.0, 0.5, 0.4),
    );
    b.add_joint(Joint::revolute(
        "r1",
        BodyRef::Ground,
        [0.0, 0.0],
        p1,
        [-0.5, 0.0],
    ));
    b.add_joint(Joint::distance("d12", p1, [0.5, 0.0], p2, [-0.3, 0.0], 0.3));
    b.add_joint(Joint::weld("w23", p2, [0.3, 0.0], p3, [-0.2, -0.1], 0.3));
    b.add_joint(Joint::prismatic(
        "pr4",
        BodyRef::Ground,
        [0.0, -1.0],
        s4,
        [0.0, 0.0],
        [1.0, 0.0],
        0.0,
    ));
    b.add_joint(Joint::distance("d34", p3, [0.25, 0.0], s4, [0.0, 0.0], 1.3));
    b.add_joint(Joint::absolute("s5y", s5, [0.1, 0.0], Coordinate::Y, 0.5));
    b.add_joint(Joint::absolute(
        "s5a",
        s5,
        [0.0, 0.0],
        Coordinate::Angle,
        0.4,
    ));
    b.add_force(Force::spring_damper(
        "k",
        p1,
        [0.0, 0.0],
        s5,
        [0.0, 0.0],
        30.0,
        1.0,
        0.5,
    ));
    Ok(b.build()?)
}

/// A named solver set-up.
type Solver = (&'static str, Box<dyn Integrator>);

fn systems() -> Result<Vec<(String, System)>, Box<dyn std::error::Error>> {
    let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../examples/models/");
    Ok(vec![
        ("manipulator".into(), models::manipulator()?),
        ("slider_crank".into(), models::slider_crank()?),
        ("four_bar".into(), models::four_bar()?),
        ("chain5".into(), models::n_link_chain(5)?),
        ("chain30".into(), models::n_link_chain(30)?),
        ("mixed".into(), mixed()?),
        (
            "driven_arm".into(),
            System::from_path(format!("{root}driven_three_link_arm.json"))?,
        ),
        (
            "crank_spring".into(),
            System::from_path(format!("{root}slider_crank_spring.toml"))?,
        ),
    ])
}

fn solvers(sys: &System) -> Result<Vec<Solver>, Box<dyn std::error::Error>> {
    let dense = |o: Rk4Options| Rk4Options {
        linear: LinearSolver::Dense,
        ..o
    };
    let sparse = |o: Rk4Options| Rk4Options {
        linear: LinearSolver::Sparse,
        ..o
    };
    let mut v: Vec<Solver> = vec![
        ("rk4", Box::new(Rk4::new(sys, Rk4Options::plain())?)),
        (
            "rk4-dense",
            Box::new(Rk4::new(sys, dense(Rk4Options::plain()))?),
        ),
        (
            "rk4-sparse",
            Box::new(Rk4::new(sys, sparse(Rk4Options::plain()))?),
        ),
        (
            "rk4-baumgarte",
            Box::new(Rk4::new(sys, Rk4Options::baumgarte(5.0, 5.0))?),
        ),
        (
            "rk4-projected",
            Box::new(Rk4::new(sys, Rk4Options::projected())?),
        ),
        (
            "rk4-projected-sparse",
            Box::new(Rk4::new(sys, sparse(Rk4Options::projected()))?),
        ),
        (
            "dopri5",
            Box::new(Index1Rk::new(
                sys,
                ButcherTableau::dopri5(),
                Index1Options::default(),
            )?),
        ),
        ("tangent-rk4", Box::new(TangentRk::rk4(sys)?)),
    ];
    if sys.n_coords() <= 15 {
        v.push((
            "symplectic2",
            Box::new(Galerkin::new(sys, SymplecticOptions::new(2))?),
        ));
    }
    Ok(v)
}

fn run(steps: usize) -> Result<(), Box<dyn std::error::Error>> {
    for (name, sys) in systems()? {
        let s0 = State::consistent(&sys, 0.0)?;
        for (sname, mut integ) in solvers(&sys)? {
            let mut s = s0.clone();
            let h = if sname == "symplectic2" { 1e-2 } else { 1e-3 };
            let k = if sname == "symplectic2" {
                steps / 10
            } else {
                steps
            };
            let mut line = format!("{name} {sname}");
            let mut ok = true;
            for _ in 0..k {
                if let Err(e) = integ.step(&sys, &mut s, h) {
                    line += &format!(" ERROR {e}");
                    ok = false;
                    break;
                }
            }
            if ok {
                for x in s.q.iter().chain(s.v.iter()) {
                    line += &format!(" {x:e}");
                }
            }
            println!("{line}");
        }
    }
    Ok(())
}

fn compare(a: &str, b: &str) -> Result<(), Box<dyn std::error::Error>> {
    let (a, b) = (std::fs::read_to_string(a)?, std::fs::read_to_string(b)?);
    let mut worst_all = 0.0f64;
    for (la, lb) in a.lines().zip(b.lines()) {
        let (wa, wb): (Vec<&str>, Vec<&str>) = (la.split(' ').collect(), lb.split(' ').collect());
        let key = format!("{} {}", wa[0], wa[1]);
        if wa[..2] != wb[..2] || wa.len() != wb.len() {
            println!("{key}: MISMATCH of lines");
            continue;
        }
        let xa: Vec<f64> = wa[2..].iter().filter_map(|s| s.parse().ok()).collect();
        let xb: Vec<f64> = wb[2..].iter().filter_map(|s| s.parse().ok()).collect();
        let scale = xa.iter().fold(0.0f64, |m, x| m.max(x.abs())).max(1e-300);
        let worst = xa
            .iter()
            .zip(&xb)
            .fold(0.0f64, |m, (x, y)| m.max((x - y).abs()))
            / scale;
        worst_all = worst_all.max(worst);
        println!(
            "{key:40} {worst:.2e}{}",
            if la == lb { " (identical)" } else { "" }
        );
    }
    println!("worst relative difference: {worst_all:.2e}");
    Ok(())
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let args: Vec<String> = std::env::args().skip(1).collect();
    if args.first().map(String::as_str) == Some("compare") {
        return compare(&args[1], &args[2]);
    }
    run(args.first().and_then(|s| s.parse().ok()).unwrap_or(1000))
}
