//! Random spatial chains through every solver: open chains of four bodies hung from ground by
//! the six spatial joint kinds (spherical, revolute, universal, cylindrical, prismatic,
//! planar) at random marker axes, with random masses, principal moments (every other body a
//! flat plate, `J1 = J2 + J3`: a zero director mass `E_1`), orientations and initial
//! velocities, under gravity. Written as model files (the file reader and the assembly check
//! run too) from a seeded generator, so every run is the same.
//!
//! Each solver's end state must agree with a reference run (projected RK4 at a tenth of the
//! step) and the energy (the model is conservative) must be kept, both to bounds about a
//! hundred times the worst measured over the six chains (the test prints them: from 2e-14 for
//! the modified (2,2) scheme to 5e-7 for symplectic (1,1) at `h = 2.5e-4`, its order 2). A
//! wrong constraint Jacobian, a wrong `gamma` term of one joint or a wrong director mass
//! changes the motion by O(1) within the run.

mod common;
use common::end_state;
use mbd::prelude::*;

/// A small deterministic generator (xorshift64*), so the test needs no random-number crate.
struct Rng(u64);

impl Rng {
    fn next(&mut self) -> f64 {
        self.0 ^= self.0 >> 12;
        self.0 ^= self.0 << 25;
        self.0 ^= self.0 >> 27;
        let x = self.0.wrapping_mul(0x2545_f491_4f6c_dd1d);
        (x >> 11) as f64 / (1u64 << 53) as f64
    }

    fn uniform(&mut self, a: f64, b: f64) -> f64 {
        a + (b - a) * self.next()
    }

    /// A rotation matrix (rows) from a random unit quaternion.
    fn rotation(&mut self) -> [[f64; 3]; 3] {
        let mut q = [0.0; 4];
        let mut n = 0.0;
        while n < 1e-3 {
            for x in &mut q {
                *x = self.uniform(-1.0, 1.0);
            }
            n = q.iter().map(|x| x * x).sum::<f64>().sqrt();
        }
        let [w, x, y, z] = q.map(|c| c / n);
        [
            [
                1.0 - 2.0 * (y * y + z * z),
                2.0 * (x * y - w * z),
                2.0 * (x * z + w * y),
            ],
            [
                2.0 * (x * y + w * z),
                1.0 - 2.0 * (x * x + z * z),
                2.0 * (y * z - w * x),
            ],
            [
                2.0 * (x * z - w * y),
                2.0 * (y * z + w * x),
                1.0 - 2.0 * (x * x + y * y),
            ],
        ]
    }
}

/// `R^T v` (a global vector in the body frame of orientation `R`).
fn to_body(r: &[[f64; 3]; 3], v: [f64; 3]) -> [f64; 3] {
    [0, 1, 2].map(|i| (0..3).map(|k| r[k][i] * v[k]).sum())
}

fn column(r: &[[f64; 3]; 3], j: usize) -> [f64; 3] {
    [r[0][j], r[1][j], r[2][j]]
}

fn vec3(v: [f64; 3]) -> String {
    format!("[{:?}, {:?}, {:?}]", v[0], v[1], v[2])
}

const KINDS: [&str; 6] = [
    "spherical",
    "revolute",
    "universal",
    "cylindrical",
    "prismatic",
    "planar",
];

/// The model file of a random chain of `bodies` bodies; joint `k` is of kind
/// `KINDS[(k + first_kind) % 6]`.
fn chain(seed: u64, bodies: usize, first_kind: usize) -> String {
    let mut rng = Rng(seed.wrapping_mul(0x9e37_79b9_7f4a_7c15) | 1);
    let mut s = String::from("spatial_gravity = [0.0, 0.0, -9.81]\n");
    let mut prev: Option<([f64; 3], [[f64; 3]; 3])> = None;
    // the next joint's point, global
    let mut p = [0.0; 3];
    for k in 0..bodies {
        let r = rng.rotation();
        let x = p.map(|c| c + rng.uniform(-0.5, 0.5));
        let (a, b) = (rng.uniform(0.01, 0.1), rng.uniform(0.01, 0.1));
        // every other body a flat plate (J1 = J2 + J3: E_1 = 0)
        let c = if k % 2 == 0 {
            a + b
        } else {
            rng.uniform((a - b).abs() + 1e-3, a + b)
        };
        let w = [0; 3].map(|_| rng.uniform(-2.0, 2.0));
        let v = [0; 3].map(|_| rng.uniform(-1.0, 1.0));
        s += &format!(
            "[[spatial_bodies]]\nname = \"b{k}\"\nmass = {:?}\nmoments = {}\nposition = {}\n\
             orientation = {{ matrix = [{}, {}, {}] }}\nangular_velocity = {}\nvelocity = {}\n",
            rng.uniform(0.5, 3.0),
            vec3([c, a, b]),
            vec3(x),
            vec3(r[0]),
            vec3(r[1]),
            vec3(r[2]),
            vec3(w),
            vec3(v),
        );
        // the joint's markers coincide: the same point and the same axes, in each body's frame
        let axes = rng.rotation();
        let (body_a, pa, axes_a) = match prev {
            None => ("ground".to_string(), p, [0, 1, 2].map(|j| column(&axes, j))),
            Some((xa, ra)) => (
                format!("b{}", k - 1),
                to_body(&ra, [0, 1, 2].map(|i| p[i] - xa[i])),
                [0, 1, 2].map(|j| to_body(&ra, column(&axes, j))),
            ),
        };
        let pb = to_body(&r, [0, 1, 2].map(|i| p[i] - x[i]));
        let axes_b = [0, 1, 2].map(|j| to_body(&r, column(&axes, j)));
        s += &format!(
            "[[spatial_joints]]\ntype = \"{}\"\nname = \"j{k}\"\nbody_a = \"{body_a}\"\n\
             body_b = \"b{k}\"\npoint_a = {}\npoint_b = {}\naxes_a = [{}, {}, {}]\n\
             axes_b = [{}, {}, {}]\n",
            KINDS[(k + first_kind) % KINDS.len()],
            vec3(pa),
            vec3(pb),
            vec3(axes_a[0]),
            vec3(axes_a[1]),
            vec3(axes_a[2]),
            vec3(axes_b[0]),
            vec3(axes_b[1]),
            vec3(axes_b[2]),
        );
        p = x.map(|c| c + rng.uniform(-0.5, 0.5));
        prev = Some((x, r));
    }
    s
}

fn energy(sys: &System, s: &State) -> f64 {
    sys.energy(s.q.as_slice(), s.v.as_slice())
}

/// Every solver on six random chains (each joint kind at each place of the chain once).
#[test]
fn every_solver_agrees_on_random_spatial_chains_with_every_joint_kind() {
    const T: f64 = 0.3;
    // FA-DAE's swarm makes it the slowest: a shorter run
    const T_FA: f64 = 0.05;
    // (solver, plan, bound on the end state's distance from the reference, bound on the
    // energy change relative to the energy scale): about a hundred times the worst measured
    let solvers: [(&str, Plan, f64, f64); 9] = [
        ("rk4", RunConfig::new(T, 1e-3).into(), 1e-8, 1e-8),
        ("rk4-projected", RunConfig::new(T, 1e-3).into(), 1e-8, 1e-8),
        (
            "index1:dopri5",
            AdaptiveConfig::new(T, 1e-10).into(),
            1e-8,
            1e-8,
        ),
        ("symplectic:1", RunConfig::new(T, 2.5e-4).into(), 5e-5, 5e-6),
        ("symplectic:2", RunConfig::new(T, 1e-3).into(), 1e-9, 1e-9),
        (
            "symplectic:2:modified",
            RunConfig::new(T, 1e-3).into(),
            1e-11,
            1e-12,
        ),
        ("tangent:rk4", RunConfig::new(T, 1e-3).into(), 1e-8, 1e-8),
        (
            "tangent:dopri5",
            AdaptiveConfig::new(T, 1e-10).into(),
            1e-9,
            1e-9,
        ),
        (
            "firefly-gauss:polish",
            RunConfig::new(T_FA, 1e-3).into(),
            1e-9,
            1e-9,
        ),
    ];
    let mut worst = vec![(0.0f64, 0.0f64); solvers.len()];
    for first_kind in 0..KINDS.len() {
        let text = chain(first_kind as u64 + 1, 4, first_kind);
        let sys = System::from_toml(&text).unwrap_or_else(|e| panic!("{e}\n{text}"));
        let start = State::consistent(&sys, 0.0).unwrap();
        let h0 = energy(&sys, &start);
        // the energy's scale: kinetic energy and the potential's range over the chain
        let scale = h0.abs().max(sys.kinetic(start.v.as_slice())).max(1.0);
        let reference = end_state(&sys, "rk4-projected", RunConfig::new(T, 1e-4));
        let reference_fa = end_state(&sys, "rk4-projected", RunConfig::new(T_FA, 1e-4));
        for (i, (spec, plan, q_bound, e_bound)) in solvers.iter().enumerate() {
            let end = end_state(&sys, spec, *plan);
            let reference = if spec.starts_with("firefly") {
                &reference_fa
            } else {
                &reference
            };
            let dq = end
                .q
                .iter()
                .zip(reference.q.iter())
                .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
            let de = (energy(&sys, &end) - h0).abs() / scale;
            assert!(
                dq <= *q_bound && de <= *e_bound,
                "chain {first_kind}, {spec}: |q - q_ref| = {dq:.2e} (bound {q_bound:.0e}), \
                 energy change {de:.2e} (bound {e_bound:.0e})\n{text}"
            );
            worst[i] = (worst[i].0.max(dq), worst[i].1.max(de));
        }
    }
    for ((spec, ..), (dq, de)) in solvers.iter().zip(&worst) {
        println!("{spec}: worst |q - q_ref| {dq:.1e}, energy change {de:.1e}");
    }
}

/// The generator writes chains whose markers coincide: each model starts consistent (the
/// projection moves no coordinate), so the test runs the motion it describes.
#[test]
fn the_random_chains_start_assembled() {
    for first_kind in 0..KINDS.len() {
        let text = chain(first_kind as u64 + 1, 4, first_kind);
        let file = mbd::model::ModelFile::from_toml(&text).unwrap();
        let sys = file.build().unwrap();
        let (q0, _) = sys.initial_guess();
        let start = State::consistent(&sys, 0.0).unwrap();
        let moved = start
            .q
            .iter()
            .zip(q0.iter())
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(moved < 1e-12, "chain {first_kind}: moved {moved:.1e}");
    }
}
