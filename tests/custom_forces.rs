//! Force laws written outside the model crate (`mbd::model::forces::ForceLaw`): a user's
//! spring-damper reproduces the built-in one with every solver, a law's own Jacobian is used
//! by the implicit solver, the energy balance books a dissipative law as dissipation, and model
//! files name laws through a `ForceLaws` registry.

use mbd::model::forces::{ForceInput, ForceLaw, ForceLaws};
use mbd::model::{Body, BodyRef, Force, ForceSpec, Joint, ModelFile, SystemBuilder};
use mbd::prelude::*;
use mbd_analysis::EnergyBalance;
use serde_json::json;
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

/// A point-to-point spring-damper written as a user would: points in the bodies' centre-of-
/// mass frames, force `-(k (L - L0) + c dL/dt)` along the line from a's point to b's.
#[derive(Debug)]
struct UserSpring {
    pa: [f64; 2],
    pb: [f64; 2],
    k: f64,
    c: f64,
    rest: f64,
}

impl UserSpring {
    fn from_parameters(p: &serde_json::Value) -> Result<Arc<dyn ForceLaw>, String> {
        let get = |k: &str| {
            p[k].as_f64()
                .ok_or_else(|| format!("parameter '{k}' missing"))
        };
        let point = |k: &str| -> Result<[f64; 2], String> {
            let a = p[k]
                .as_array()
                .ok_or_else(|| format!("parameter '{k}' missing"))?;
            Ok([a[0].as_f64().unwrap_or(0.0), a[1].as_f64().unwrap_or(0.0)])
        };
        Ok(Arc::new(UserSpring {
            pa: point("point_a")?,
            pb: point("point_b")?,
            k: get("stiffness")?,
            c: get("damping")?,
            rest: get("rest_length")?,
        }))
    }
}

/// A body point's position and velocity.
fn point(q: &[f64; 3], v: &[f64; 3], p: [f64; 2]) -> ([f64; 2], [f64; 2], [f64; 2]) {
    let (s, c) = q[2].sin_cos();
    let r = [c * p[0] - s * p[1], s * p[0] + c * p[1]];
    let x = [q[0] + r[0], q[1] + r[1]];
    let xd = [v[0] - v[2] * r[1], v[1] + v[2] * r[0]];
    (x, xd, r)
}

impl ForceLaw for UserSpring {
    fn law(&self) -> &str {
        "user_spring"
    }
    fn force(&self, x: &ForceInput, out: &mut [f64; 6]) {
        let (xa, va, ra) = point(x.qa, x.va, self.pa);
        let (xb, vb, rb) = point(x.qb, x.vb, self.pb);
        let d = [xb[0] - xa[0], xb[1] - xa[1]];
        let l = d[0].hypot(d[1]);
        let u = [d[0] / l, d[1] / l];
        let ldot = u[0] * (vb[0] - va[0]) + u[1] * (vb[1] - va[1]);
        let f = -(self.k * (l - self.rest) + self.c * ldot);
        let fb = [f * u[0], f * u[1]];
        out[0] -= fb[0];
        out[1] -= fb[1];
        out[2] -= ra[0] * fb[1] - ra[1] * fb[0];
        out[3] += fb[0];
        out[4] += fb[1];
        out[5] += rb[0] * fb[1] - rb[1] * fb[0];
    }
    fn validate(&self) -> Result<(), String> {
        if self.k < 0.0 {
            return Err(format!("stiffness {} must not be negative", self.k));
        }
        Ok(())
    }
    fn parameters(&self) -> serde_json::Value {
        json!({"point_a": self.pa, "point_b": self.pb, "stiffness": self.k,
               "damping": self.c, "rest_length": self.rest})
    }
}

fn laws() -> ForceLaws {
    let mut laws = ForceLaws::new();
    laws.register("user_spring", UserSpring::from_parameters)
        .unwrap();
    laws
}

/// The example slider-crank's model file, its spring-damper replaced by the user's law with
/// the same parameters.
fn slider_crank_files() -> (ModelFile, ModelFile) {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/examples/models/slider_crank_spring.toml"
    );
    let text = std::fs::read_to_string(path).unwrap();
    let built_in = ModelFile::from_toml(&text).unwrap();
    let mut user = built_in.clone();
    let ForceSpec::SpringDamper(s) = &built_in.forces[0] else {
        panic!("the example's force is a spring-damper")
    };
    let custom = format!(
        "[[forces]]\ntype = \"custom\"\nname = \"return_spring\"\nlaw = \"user_spring\"\n\
         body_a = \"{}\"\nbody_b = \"{}\"\nparameters = {{ point_a = [{:?}, {:?}], point_b = \
         [{:?}, {:?}], stiffness = {:?}, damping = {:?}, rest_length = {:?} }}\n",
        s.body_a,
        s.body_b,
        s.point_a[0],
        s.point_a[1],
        s.point_b[0],
        s.point_b[1],
        s.stiffness,
        s.damping,
        s.rest_length
    );
    let extra = ModelFile::from_toml(&format!("bodies = []\n{custom}")).unwrap();
    user.forces = extra.forces;
    (built_in, user)
}

/// With every solver that runs non-conservative models, the user's law and the built-in
/// spring-damper give the same end state after 1 s (h = 1e-3) to 1e-9 (1e-7 for the unpolished firefly solver): the same forces at the
/// same points (the built-in's spring enters through its potential, the law's as a generalised
/// force). The modified-Lagrangian schemes refuse the law, naming it.
#[test]
fn a_user_spring_damper_matches_the_built_in_one_with_every_solver() {
    let (built_in, user) = slider_crank_files();
    let (a, b) = (built_in.build().unwrap(), user.build_with(&laws()).unwrap());
    assert!(!b.is_conservative());
    let mut compared = 0;
    for (_, v) in mbd::registry().variants() {
        let mut sb = match Simulation::new(b.clone(), v.spec) {
            Ok(s) => s,
            Err(e) => {
                assert!(v.spec.contains("modified"), "{}: {e}", v.spec);
                assert!(e.to_string().contains("return_spring"), "{}: {e}", v.spec);
                continue;
            }
        };
        let mut sa = Simulation::new(a.clone(), v.spec).unwrap();
        sa.run(RunConfig::new(1.0, 1e-3)).unwrap();
        sb.run(RunConfig::new(1.0, 1e-3)).unwrap();
        let d = (sa.state().q.clone() - sb.state().q.clone()).amax();
        // the unpolished firefly solver stops its swarm at its own tolerance (a round-off
        // difference in the objective moves the swarm's best point by about 1e-9)
        let tol = if v.spec == "firefly-gauss" {
            1e-7
        } else {
            1e-9
        };
        assert!(d < tol, "{}: end states differ by {d:e}", v.spec);
        compared += 1;
    }
    assert!(compared >= 7, "{compared}");
}

/// A rotary damper whose law gives its Jacobian; it counts how often it is asked.
#[derive(Debug)]
struct RotaryDamper {
    c: f64,
    jacobians: AtomicUsize,
    with_jacobian: bool,
}

impl ForceLaw for RotaryDamper {
    fn law(&self) -> &str {
        "rotary_damper"
    }
    fn force(&self, x: &ForceInput, out: &mut [f64; 6]) {
        let tau = self.c * (x.vb[2] - x.va[2]);
        out[2] += tau;
        out[5] -= tau;
    }
    fn jacobian(&self, _x: &ForceInput, dq: &mut [[f64; 6]; 6], dv: &mut [[f64; 6]; 6]) -> bool {
        if !self.with_jacobian {
            return false;
        }
        self.jacobians.fetch_add(1, Ordering::Relaxed);
        *dq = [[0.0; 6]; 6];
        *dv = [[0.0; 6]; 6];
        dv[2][2] = -self.c;
        dv[2][5] = self.c;
        dv[5][2] = self.c;
        dv[5][5] = -self.c;
        true
    }
    fn dissipative(&self) -> bool {
        true
    }
}

fn pendulum_with(law: Arc<RotaryDamper>) -> System {
    let mut b = SystemBuilder::new();
    b.set_gravity([0.0, -9.81]);
    let rod = b.add_body(
        Body::new("rod")
            .mass(1.0)
            .inertia(1.0 / 12.0)
            .position(0.5, 0.0, 0.0),
    );
    b.add_joint(Joint::revolute(
        "pivot",
        BodyRef::Ground,
        [0.0, 0.0],
        rod,
        [-0.5, 0.0],
    ));
    b.add_force(Force::custom("hinge_damper", BodyRef::Ground, rod, law));
    b.build().unwrap()
}

/// The implicit symplectic solver uses the law's Jacobian (it is asked for it), and reaches the
/// same end state as with central differences of the law (to 1e-10: the Jacobian only steers
/// Newton's iteration).
#[test]
fn the_implicit_solver_uses_a_laws_jacobian() {
    let run = |with_jacobian: bool| {
        let law = Arc::new(RotaryDamper {
            c: 0.3,
            jacobians: AtomicUsize::new(0),
            with_jacobian,
        });
        let mut sim = Simulation::new(pendulum_with(law.clone()), "symplectic:2").unwrap();
        sim.run(RunConfig::new(1.0, 1e-2)).unwrap();
        (sim.state().q.clone(), law.jacobians.load(Ordering::Relaxed))
    };
    let (qa, asked) = run(true);
    let (qb, not_asked) = run(false);
    assert!(asked > 0 && not_asked == 0, "{asked} {not_asked}");
    let d = (qa - qb).amax();
    assert!(d < 1e-10, "{d:e}");
}

/// `System::nonconservative_jacobian` agrees with central differences of the whole force
/// vector, for a law without a Jacobian (element differences) and with one (analytic).
#[test]
fn nonconservative_jacobian_matches_differences_of_the_forces() {
    let (_, user) = slider_crank_files();
    let law = Arc::new(RotaryDamper {
        c: 0.7,
        jacobians: AtomicUsize::new(0),
        with_jacobian: true,
    });
    for sys in [user.build_with(&laws()).unwrap(), pendulum_with(law)] {
        let n = sys.n_coords();
        let q: Vec<f64> = (0..n).map(|i| 0.3 + 0.17 * i as f64).collect();
        let v: Vec<f64> = (0..n).map(|i| 0.5 - 0.11 * i as f64).collect();
        let (mut jq, mut jv) = (vec![0.0; n * n], vec![0.0; n * n]);
        sys.nonconservative_jacobian(&q, &v, 0.2, |i, j, dq, dv| {
            jq[i * n + j] += dq;
            jv[i * n + j] += dv;
        });
        let f = |q: &[f64], v: &[f64]| {
            let mut out = vec![0.0; n];
            sys.nonconservative_forces(q, v, 0.2, &mut out);
            out
        };
        for j in 0..n {
            let e = 1e-6;
            let (mut qp, mut qm, mut vp, mut vm) = (q.clone(), q.clone(), v.clone(), v.clone());
            qp[j] += e;
            qm[j] -= e;
            vp[j] += e;
            vm[j] -= e;
            let (fqp, fqm, fvp, fvm) = (f(&qp, &v), f(&qm, &v), f(&q, &vp), f(&q, &vm));
            for i in 0..n {
                let (dq, dv) = ((fqp[i] - fqm[i]) / (2.0 * e), (fvp[i] - fvm[i]) / (2.0 * e));
                assert!(
                    (jq[i * n + j] - dq).abs() < 1e-6 * (1.0 + dq.abs()),
                    "dq {i} {j}"
                );
                assert!(
                    (jv[i * n + j] - dv).abs() < 1e-6 * (1.0 + dv.abs()),
                    "dv {i} {j}"
                );
            }
        }
    }
}

/// A dissipative law's power is booked as dissipation: the balance closes to the solver's
/// accuracy while the pendulum loses a large part of its energy.
#[test]
fn the_energy_balance_books_a_dissipative_law() {
    let law = Arc::new(RotaryDamper {
        c: 0.3,
        jacobians: AtomicUsize::new(0),
        with_jacobian: true,
    });
    let sys = pendulum_with(law);
    let mut eb = EnergyBalance::new(&sys).unwrap();
    let mut sim = Simulation::new(sys, "symplectic:2").unwrap();
    sim.run_observed(RunConfig::new(2.0, 1e-3), &mut eb)
        .unwrap();
    assert!(eb.dissipated() > 0.1, "{}", eb.dissipated());
    assert_eq!(eb.external_work(), 0.0);
    let rel = eb.max_residual() / eb.max_energy();
    assert!(rel < 1e-8, "{rel:e}");
}

/// Files name laws: without the registry the load fails naming the element and the law; a
/// factory's or a law's parameter error names the element; a law registered twice is refused;
/// a system written back to a file keeps the law and its parameters.
#[test]
fn model_files_name_registered_laws() {
    let (_, user) = slider_crank_files();
    let e = user.build().unwrap_err().to_string();
    assert!(
        e.contains("force 'return_spring'")
            && e.contains("force law 'user_spring' is not registered")
            && e.contains("ModelFile::build_with"),
        "{e}"
    );
    let e = user.build_with(&ForceLaws::new()).unwrap_err().to_string();
    assert!(e.contains("not registered"), "{e}");
    let mut other = ForceLaws::new();
    other
        .register("something_else", UserSpring::from_parameters)
        .unwrap();
    let e = user.build_with(&other).unwrap_err().to_string();
    assert!(e.contains("(registered: something_else)"), "{e}");

    let with_parameters = |p: serde_json::Value| {
        let mut bad = user.clone();
        let ForceSpec::Custom(c) = &mut bad.forces[0] else {
            panic!()
        };
        c.parameters = p;
        bad.build_with(&laws()).unwrap_err().to_string()
    };
    let ForceSpec::Custom(c) = &user.forces[0] else {
        panic!()
    };
    let mut p = c.parameters.clone();
    p["stiffness"] = json!(-1.0);
    let e = with_parameters(p);
    assert!(
        e.contains("return_spring") && e.contains("stiffness -1 must not be negative"),
        "{e}"
    );
    let e = with_parameters(json!({}));
    assert!(e.contains("return_spring") && e.contains("missing"), "{e}");

    let mut twice = laws();
    let e = twice
        .register("user_spring", UserSpring::from_parameters)
        .unwrap_err();
    assert_eq!(e.to_string(), "duplicate force law name 'user_spring'");

    let sys = user.build_with(&laws()).unwrap();
    let back = sys.to_model_file();
    assert_eq!(back.forces, user.forces);
    let toml = back.to_toml().unwrap();
    assert!(toml.contains("law = \"user_spring\""), "{toml}");
}
