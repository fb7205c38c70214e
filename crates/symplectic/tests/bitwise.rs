//! The integrator's steps bit for bit: 100 steps of `h = 0.01` of each scheme (plain, paper A's
//! `W_s` with `gamma = 1`, the modified Lagrangian) on a few models, every coordinate and
//! velocity of the end state against its bit pattern (`f64::to_bits`) captured from the code
//! before the preadjustment was restructured into terms. A refactoring of the preadjustment
//! must leave these unchanged; a deliberate change of the numerics must capture them again
//! (`cargo test -p mbd-symplectic --test bitwise -- --ignored --nocapture` prints the table).
//! Every case takes a new Jacobian at each step (`JacobianReuse::Never`, as when the bits were
//! captured; the default keeps the sparse path's factorisation, which moves the end state
//! within the Newton tolerance).
use mbd_model::{models, System};
use mbd_solve::{Integrator, State};
use mbd_symplectic::{Galerkin, JacobianReuse, PreadjustMode, SymplecticOptions};

const STEPS: usize = 100;
const H: f64 = 0.01;

fn model(name: &str) -> System {
    match name {
        "pendulum" => models::paper_a_double_pendulum().unwrap(),
        "chain30" => models::n_link_chain(30).unwrap(),
        "rod_spring" => models::rod_with_spring().unwrap(),
        "elastic" => models::elastic_pendulum().unwrap(),
        other => panic!("unknown model {other}"),
    }
}

fn options(scheme: &str) -> SymplecticOptions {
    let ml = PreadjustMode::ModifiedLagrangian;
    let opts = match scheme {
        "plain11" => SymplecticOptions::new(1),
        "plain22" => SymplecticOptions::new(2),
        "paper11" => SymplecticOptions::new(1).with_gamma(1.0),
        "paper22" => SymplecticOptions::new(2).with_gamma(1.0),
        "paper33" => SymplecticOptions::new(3).with_gamma(1.0),
        "modified11" => SymplecticOptions::new(1).with_preadjust(ml),
        "modified22" => SymplecticOptions::new(2).with_preadjust(ml),
        other => panic!("unknown scheme {other}"),
    };
    opts.with_jacobian_reuse(JacobianReuse::Never)
}

/// The cases: (model, scheme, whether the stage solve is sparse).
const CASES: [(&str, &str, bool); 19] = [
    ("pendulum", "plain11", false),
    ("pendulum", "plain22", false),
    ("pendulum", "paper11", false),
    ("pendulum", "paper22", false),
    ("pendulum", "paper33", false),
    ("pendulum", "modified11", false),
    ("pendulum", "modified22", false),
    ("chain30", "plain11", true),
    ("chain30", "plain22", true),
    ("chain30", "modified11", true),
    ("chain30", "modified22", true),
    ("chain30", "paper22", false),
    ("rod_spring", "paper22", false),
    ("rod_spring", "paper33", false),
    ("rod_spring", "modified11", false),
    ("rod_spring", "modified22", false),
    ("elastic", "paper22", false),
    ("elastic", "modified11", false),
    ("elastic", "modified22", false),
];

/// The bits of `q` then `v` after `STEPS` steps of `h = H` from the consistent initial state.
fn end_bits(model_name: &str, scheme: &str, sparse: bool) -> Vec<u64> {
    let sys = model(model_name);
    let mut o = options(scheme);
    if !sparse {
        // (the dense path, as when the bits were captured: `Auto` puts gamma on a 30-link
        // chain on the sparse path since 2026-11-28)
        o.linear_solver = mbd_solve::LinearSolver::Dense;
    }
    let mut g = Galerkin::new(&sys, o).unwrap();
    assert_eq!(g.is_sparse(), sparse, "{model_name} {scheme}: stage solve");
    let mut st = State::consistent(&sys, 0.0).unwrap();
    for _ in 0..STEPS {
        g.step(&sys, &mut st, H).unwrap();
    }
    st.q.iter()
        .chain(st.v.iter())
        .map(|x| x.to_bits())
        .collect()
}

#[test]
fn end_states_are_unchanged_bit_for_bit() {
    let expected_all = expected();
    assert_eq!(expected_all.len(), CASES.len());
    let mut failed = Vec::new();
    for (&(model_name, scheme, sparse), (label, expected)) in CASES.iter().zip(&expected_all) {
        let label = label.as_str();
        assert_eq!(label, format!("{model_name} {scheme}"));
        let got = end_bits(model_name, scheme, sparse);
        assert_eq!(got.len(), expected.len(), "{label}: length");
        let differ = got.iter().zip(expected).filter(|(a, b)| a != b).count();
        if differ > 0 {
            let worst = got
                .iter()
                .zip(expected)
                .map(|(&a, &b)| (f64::from_bits(a) - f64::from_bits(b)).abs())
                .fold(0.0, f64::max);
            eprintln!(
                "{label}: {differ} of {} values differ (by up to {worst:.3e})",
                got.len()
            );
            failed.push(label);
        }
    }
    assert!(failed.is_empty(), "changed end states: {failed:?}");
}

/// Prints the case lines of `bitwise_end_states.txt` from the current code (to capture them
/// again after a deliberate change).
#[test]
#[ignore]
fn print_end_states() {
    for &(model_name, scheme, sparse) in &CASES {
        let bits = end_bits(model_name, scheme, sparse);
        let list: Vec<String> = bits.iter().map(|b| format!("{b:016x}")).collect();
        println!("{model_name} {scheme}: {}", list.join(" "));
    }
}

/// The pinned end states: `label: hex hex ...` per case, `#` comments.
fn expected() -> Vec<(String, Vec<u64>)> {
    include_str!("bitwise_end_states.txt")
        .lines()
        .filter(|l| !l.starts_with('#') && !l.trim().is_empty())
        .map(|l| {
            let (label, bits) = l.split_once(": ").expect("label: bits");
            let bits = bits
                .split_whitespace()
                .map(|h| u64::from_str_radix(h, 16).expect("hex bits"))
                .collect();
            (label.to_string(), bits)
        })
        .collect()
}
