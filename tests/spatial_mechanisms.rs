//! Three spatial mechanisms through the public run loop: the spatial double pendulum
//! (`models::spatial_double_pendulum`), Haug's spatial slider-crank
//! (`models::spatial_slider_crank`) and the Bricard linkage (`models::bricard`, one redundant
//! equation). Each model file in `examples/models/` builds the model's system; every solver
//! that runs spatial bodies keeps the constraints and the energy; two independent solvers
//! agree at fine settings; the Bricard linkage moves with one degree of freedom.

mod common;
use mbd::model::models::{bricard, spatial_double_pendulum, spatial_slider_crank, sprung_rod};
use mbd::prelude::*;
use nalgebra::{DMatrix, DVector, Vector3};
use std::f64::consts::PI;
use std::path::Path;

type Result<T> = std::result::Result<T, Box<dyn std::error::Error>>;

fn slider_crank() -> std::result::Result<System, mbd::model::ModelError> {
    spatial_slider_crank(-2.0 * PI)
}

/// The three mechanisms and the rod on a spring (`models::sprung_rod`): name, the model in
/// code, its example file.
fn mechanisms() -> Vec<(&'static str, System, &'static str)> {
    vec![
        (
            "double pendulum",
            spatial_double_pendulum().expect("double pendulum"),
            "spatial_double_pendulum.toml",
        ),
        (
            "slider-crank",
            slider_crank().expect("slider-crank"),
            "spatial_slider_crank.toml",
        ),
        ("Bricard", bricard().expect("Bricard"), "bricard.toml"),
        (
            "rod on a spring",
            sprung_rod([0.05, 0.05, 0.002]).expect("rod on a spring"),
            "sprung_rod.toml",
        ),
    ]
}

/// What a run kept: the largest `|Phi|` over its steps, the largest energy change relative to
/// `scale`, and the end state.
struct Kept {
    phi: f64,
    energy: f64,
    end: State,
}

/// Runs `sys` with `spec` to `t_end` (fixed steps `h`, or tolerance `h` for `index1:dopri5`),
/// watching the constraints and the energy at every step.
fn run_watched(sys: &System, spec: &str, t_end: f64, h: f64, scale: f64) -> Result<Kept> {
    let mut sim = Simulation::new(sys.clone(), spec)?;
    let s0 = sim.state().clone();
    let h0 = sys.energy(s0.q.as_slice(), s0.v.as_slice());
    let (mut phi, mut energy) = (common::max_phi(sys, s0.q.as_slice(), 0.0), 0.0f64);
    let mut watch = |sys: &System, s: &State, _: usize| -> std::result::Result<Flow, SolveError> {
        phi = phi.max(common::max_phi(sys, s.q.as_slice(), s.t));
        let e = sys.energy(s.q.as_slice(), s.v.as_slice());
        energy = energy.max((e - h0).abs() / scale);
        Ok(Flow::Continue)
    };
    let plan: Plan = if spec.starts_with("index1") {
        AdaptiveConfig::new(t_end, h).into()
    } else {
        RunConfig::new(t_end, h).into()
    };
    sim.run_observed(plan, &mut watch)?;
    Ok(Kept {
        phi,
        energy,
        end: sim.state().clone(),
    })
}

/// The energy scale of a mechanism: its kinetic energy plus the potential energy of lifting
/// its bodies by `lift` metres (so a drift is measured against the energy that moves).
fn energy_scale(sys: &System, lift: f64) -> f64 {
    let (_, v) = sys.initial_guess();
    let mass: f64 = sys.spatial_bodies().iter().map(|b| b.inertia.mass()).sum();
    sys.kinetic(v.as_slice()) + mass * 9.81 * lift
}

/// Each example file builds the model's system: the same coordinates, equations, redundancy,
/// joints, force elements, initial guess (to 1e-12) and constraint values at a configuration
/// off the constraints (to 1e-12).
#[test]
fn the_example_files_are_the_models() -> Result<()> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models");
    for (name, code, file) in mechanisms() {
        let from_file = System::from_path(dir.join(file))?;
        assert_eq!(from_file.n_coords(), code.n_coords(), "{name}");
        assert_eq!(from_file.n_constraints(), code.n_constraints(), "{name}");
        assert_eq!(from_file.n_redundant(), code.n_redundant(), "{name}");
        assert_eq!(from_file.dof(), code.dof(), "{name}");
        assert_eq!(
            from_file.coordinate_names(),
            code.coordinate_names(),
            "{name}"
        );
        assert_eq!(from_file.spatial_joints(), code.spatial_joints(), "{name}");
        assert_eq!(
            from_file.spatial_gravity(),
            code.spatial_gravity(),
            "{name}"
        );
        assert_eq!(from_file.spatial_forces(), code.spatial_forces(), "{name}");
        let (qf, vf) = from_file.initial_guess();
        let (qc, vc) = code.initial_guess();
        let (dq, dv) = ((&qf - &qc).amax(), (&vf - &vc).amax());
        assert!(dq < 1e-12 && dv < 1e-12, "{name}: q {dq:e}, v {dv:e}");
        let off = qc.map_with_location(|i, _, x| x + 0.01 * ((i as f64) * 0.7).sin());
        let (mut pf, mut pc) = (
            vec![0.0; code.n_constraints()],
            vec![0.0; code.n_constraints()],
        );
        from_file.phi(off.as_slice(), 0.0, &mut pf);
        code.phi(off.as_slice(), 0.0, &mut pc);
        let d = pf
            .iter()
            .zip(&pc)
            .fold(0.0f64, |m, (a, b)| m.max((a - b).abs()));
        assert!(d < 1e-12, "{name}: Phi differs by {d:e}");
        let dm = (from_file.mass_diag() - code.mass_diag()).amax();
        assert!(dm < 1e-15, "{name}: mass diagonals differ by {dm:e}");
    }
    Ok(())
}

/// A solver's settings and the bounds it must keep on a mechanism: spec, step `h` (tolerance
/// for `index1:dopri5`), end time, the largest `|Phi|` and the largest energy change relative
/// to the mechanism's energy scale.
type Check = (&'static str, f64, f64, f64, f64);

/// Runs every solver of `checks` on `sys`: each either refuses the model at construction
/// naming its spatial bodies, or runs to the end keeping its bounds; the ones in `must_run`
/// run.
fn solvers_keep_their_bounds(
    name: &str,
    sys: &System,
    scale: f64,
    checks: &[Check],
    must_run: &[&str],
) -> Result<()> {
    let mut ran = Vec::new();
    for &(spec, h, t_end, phi_max, energy_max) in checks {
        if let Err(e) = Simulation::new(sys.clone(), spec) {
            let e = e.to_string();
            assert!(e.contains("spatial"), "{name}, {spec}: {e}");
            eprintln!("{name}: {spec} refuses: {e}");
            continue;
        }
        let k = run_watched(sys, spec, t_end, h, scale)?;
        eprintln!(
            "{name}: {spec} (h/tol {h:e}, {t_end} s): max |Phi| {:.1e}, energy {:.1e} of {scale:.3} J",
            k.phi, k.energy
        );
        assert!(
            (k.end.t - t_end).abs() < 1e-12,
            "{name}, {spec}: stopped at {}",
            k.end.t
        );
        assert!(k.phi < phi_max, "{name}, {spec}: |Phi| {:e}", k.phi);
        assert!(
            k.energy < energy_max,
            "{name}, {spec}: energy {:e}",
            k.energy
        );
        ran.push(spec);
    }
    for spec in must_run {
        assert!(ran.contains(spec), "{name}: {spec} did not run ({ran:?})");
    }
    Ok(())
}

/// The end states of two runs, compared: the largest difference of the positions and of the
/// velocities.
fn end_difference(sys: &System, a: (&str, Plan), b: (&str, Plan)) -> Result<(f64, f64)> {
    let end = |(spec, plan): (&str, Plan)| -> Result<State> {
        let mut sim = Simulation::new(sys.clone(), spec)?;
        sim.run(plan)?;
        Ok(sim.state().clone())
    };
    let (sa, sb) = (end(a)?, end(b)?);
    assert_eq!(sa.t, sb.t);
    Ok(((&sa.q - &sb.q).amax(), (&sa.v - &sb.v).amax()))
}

/// The angular momentum about the vertical through the origin.
fn vertical_momentum(sys: &System, s: &State) -> f64 {
    sys.spatial_angular_momentum(s.q.as_slice(), s.v.as_slice())[2]
}

/// The spatial double pendulum: every spatial solver over 2 s at h = 1e-3 (index-1 DOPRI5 at
/// tolerance 1e-8; firefly-Gauss over 0.3 s only, its steps cost ~30 ms here) keeps the
/// constraints and the energy (relative to `T + m g L` = 21.9 J). Measured: max |Phi| 4.0e-11
/// (plain RK4, which does not project), 6.4e-9 (index-1 DOPRI5), at most 7.8e-14 for the
/// others; energy 1.9e-11 (RK4), 6.1e-13 (projected RK4), 2.0e-9 (DOPRI5), 2.3e-12 / 1.9e-14
/// (tangent RK4 / DOPRI5), 4.4e-7 / 1.1e-13 (symplectic (1,1) / (2,2)), 2.9e-11
/// (firefly-Gauss).
#[test]
fn the_double_pendulum_keeps_constraints_and_energy_with_every_solver() -> Result<()> {
    let sys = spatial_double_pendulum()?;
    let scale = energy_scale(&sys, 1.0);
    let checks: [Check; 8] = [
        ("rk4", 1e-3, 2.0, 1e-9, 1e-9),
        ("rk4-projected", 1e-3, 2.0, 1e-12, 1e-11),
        ("index1:dopri5", 1e-8, 2.0, 1e-7, 1e-7),
        ("tangent:rk4", 1e-3, 2.0, 1e-12, 1e-10),
        ("tangent:dopri5", 1e-3, 2.0, 1e-12, 1e-12),
        ("symplectic:1", 1e-3, 2.0, 1e-13, 5e-6),
        ("symplectic:2", 1e-3, 2.0, 1e-13, 1e-11),
        ("firefly-gauss", 1e-3, 0.3, 1e-12, 1e-9),
    ];
    let all: Vec<&str> = checks.iter().map(|c| c.0).collect();
    solvers_keep_their_bounds("double pendulum", &sys, scale, &checks, &all)
}

/// The spatial slider-crank: every spatial solver over 2 s at h = 1e-3 (index-1 DOPRI5 at
/// tolerance 1e-8, firefly-Gauss at h = 2e-3) keeps the constraints and the energy (relative
/// to `T + m g 0.1 m` = 2.67 J). Measured: max |Phi| 6.7e-6 (plain RK4), 1.6e-6 (index-1
/// DOPRI5), at most 5.1e-14 for the projecting solvers; energy 1.4e-6 (RK4), 1.9e-8
/// (projected RK4), 3.8e-7 (DOPRI5), 2.4e-8 / 5.7e-10 (tangent RK4 / DOPRI5), 5.5e-5 / 2.0e-9
/// (symplectic (1,1) / (2,2)), 5.3e-7 (firefly-Gauss).
#[test]
fn the_slider_crank_keeps_constraints_and_energy_with_every_solver() -> Result<()> {
    let sys = slider_crank()?;
    let scale = energy_scale(&sys, 0.1);
    let checks: [Check; 8] = [
        ("rk4", 1e-3, 2.0, 1e-4, 1e-5),
        ("rk4-projected", 1e-3, 2.0, 1e-12, 1e-7),
        ("index1:dopri5", 1e-8, 2.0, 1e-5, 5e-6),
        ("tangent:rk4", 1e-3, 2.0, 1e-12, 1e-7),
        ("tangent:dopri5", 1e-3, 2.0, 1e-12, 1e-8),
        ("symplectic:1", 1e-3, 2.0, 1e-13, 1e-4),
        ("symplectic:2", 1e-3, 2.0, 1e-13, 1e-8),
        ("firefly-gauss", 2e-3, 2.0, 1e-12, 1e-6),
    ];
    let all: Vec<&str> = checks.iter().map(|c| c.0).collect();
    solvers_keep_their_bounds("slider-crank", &sys, scale, &checks, &all)
}

/// The Bricard linkage with every spatial solver: all 60 equations, the redundant one
/// included, and the energy (relative to `m g L` for the five bars, 49 J) kept over 3 s.
/// Measured: max |Phi| 5.6e-12 (RK4), 1.0e-14 (projected RK4), 1.6e-8 (index-1 DOPRI5 at
/// tolerance 1e-8), 7.1e-14 / 2.1e-13 (tangent RK4 / DOPRI5), 1.6e-15 / 1.6e-15 (symplectic
/// (1,1) / (2,2), on the sparse path, whose stage Jacobian leaves out the equation the
/// body-eliminated Schur complement finds dependent; 6.7e-16 / 6.7e-16 on the dense path),
/// 5.2e-16 (FA-DAE); energy 1.6e-12, 2.3e-14, 2.5e-9, 2.0e-14 / 2.5e-14, 7.9e-8 / 3.0e-15,
/// 1.3e-11. (On the dense path symplectic (2,2) needs the stage LU's pivoting fallback to drop
/// the redundant multiplier: without it the run stopped at t = 0.173.)
#[test]
fn the_bricard_linkage_keeps_constraints_and_energy() -> Result<()> {
    let sys = bricard()?;
    let scale = energy_scale(&sys, 1.0);
    let checks: [Check; 8] = [
        ("rk4", 1e-3, 3.0, 1e-10, 1e-10),
        ("rk4-projected", 1e-3, 3.0, 1e-12, 1e-12),
        ("index1:dopri5", 1e-8, 3.0, 1e-6, 1e-7),
        ("tangent:rk4", 1e-3, 3.0, 1e-12, 1e-9),
        ("tangent:dopri5", 1e-3, 3.0, 1e-12, 1e-9),
        ("symplectic:1", 1e-3, 3.0, 1e-13, 1e-5),
        ("symplectic:2", 1e-3, 3.0, 1e-13, 1e-12),
        ("firefly-gauss", 5e-3, 3.0, 1e-12, 1e-5),
    ];
    solvers_keep_their_bounds(
        "Bricard",
        &sys,
        scale,
        &checks,
        &[
            "rk4",
            "rk4-projected",
            "index1:dopri5",
            "tangent:rk4",
            "tangent:dopri5",
            "symplectic:1",
            "symplectic:2",
            "firefly-gauss",
        ],
    )
}

/// Cross-solver agreement at fine settings: index-1 DOPRI5 at tolerance 1e-12 against a
/// second, independent integrator, the largest differences of the end positions and
/// velocities: the double pendulum at t = 1 s against tangent DOPRI5 at h = 1e-3 (measured
/// 4.3e-13 and 2.6e-12), the slider-crank at t = 2 s against symplectic (2,2) at h = 5e-4
/// (4.0e-9 and 1.4e-7, the symplectic scheme's error), the Bricard linkage at t = 2 s against
/// projected RK4 at h = 2.5e-4 (1.2e-12 and 1.8e-12).
#[test]
fn two_independent_solvers_agree_on_each_mechanism() -> Result<()> {
    type Case = (&'static str, System, f64, &'static str, f64, [f64; 2]);
    let cases: [Case; 3] = [
        (
            "double pendulum",
            spatial_double_pendulum()?,
            1.0,
            "tangent:dopri5",
            1e-3,
            [1e-11, 1e-10],
        ),
        (
            "slider-crank",
            slider_crank()?,
            2.0,
            "symplectic:2",
            5e-4,
            [2e-8, 1e-6],
        ),
        (
            "Bricard",
            bricard()?,
            2.0,
            "rk4-projected",
            2.5e-4,
            [1e-10, 1e-10],
        ),
    ];
    for (name, sys, t_end, other, h, [q_max, v_max]) in cases {
        let (dq, dv) = end_difference(
            &sys,
            ("index1:dopri5", AdaptiveConfig::new(t_end, 1e-12).into()),
            (other, RunConfig::new(t_end, h).into()),
        )?;
        eprintln!("{name}: index1:dopri5 vs {other} at t = {t_end}: q {dq:.1e}, v {dv:.1e}");
        assert!(dq < q_max && dv < v_max, "{name}: q {dq:e}, v {dv:e}");
    }
    Ok(())
}

/// The Bricard linkage has one redundant equation (60 equations of rank 59 on 60 coordinates:
/// one degree of freedom), named with the hinges it combines; the double pendulum and the
/// slider-crank have none; `redundant_constraints = "reject"` turns it into an error.
#[test]
fn the_bricard_linkage_has_exactly_one_redundant_equation() -> Result<()> {
    let sys = bricard()?;
    assert_eq!((sys.n_coords(), sys.n_constraints()), (60, 60));
    assert_eq!((sys.n_redundant(), sys.dof()), (1, 1));
    let red = &sys.redundant_equations()[0];
    eprintln!("Bricard: redundant {} ({:?})", red.equation, red.joints);
    assert!(red.equation.starts_with("hinge"), "{red:?}");
    assert!(red.joints.len() >= 2, "{red:?}");
    assert!(red
        .joints
        .iter()
        .all(|j| j.starts_with("hinge") || j.starts_with("link")));
    assert_eq!(spatial_double_pendulum()?.n_redundant(), 0);
    assert_eq!(slider_crank()?.n_redundant(), 0);
    let text = std::fs::read_to_string(
        Path::new(env!("CARGO_MANIFEST_DIR")).join("examples/models/bricard.toml"),
    )?;
    let e = System::from_toml(&format!("redundant_constraints = \"reject\"\n{text}"))
        .expect_err("a redundant equation rejected")
        .to_string();
    assert!(e.contains(&red.equation), "{e}");
    Ok(())
}

/// The corner between links 3 and 4 of the Bricard linkage (global `(1, -1, -1)` at the start;
/// link 3's first principal axis is its bar, pointing from that corner to the previous one).
fn bricard_corner(sys: &System, q: &DVector<f64>) -> Vector3<f64> {
    let o = sys.spatial_offset() + 12 * 2;
    let link3: [f64; 12] = std::array::from_fn(|i| q[o + i]);
    mbd::model::spatial::point_position(&link3, Vector3::new(-0.5, 0.0, 0.0))
}

/// The Bricard linkage moves with one degree of freedom: along a projected RK4 run
/// (h = 1e-3, 3 s) the rank test finds exactly one dependent equation at every 0.1 s, `Phi_q`
/// keeps one zero singular value (below 1e-12 of the largest) and its next one away from zero
/// (above 1e-2: no bifurcation is crossed), the velocity lies in its kernel, and the corner
/// between links 3 and 4 swings on a path that index-1 DOPRI5 (tolerance 1e-10) retraces to
/// 1e-8 at every 0.1 s (measured: next singular value 7.3e-2, `|Phi_q v|` 9.7e-15 of `|v|`,
/// paths 2.3e-11 apart). The linkage and gravity are symmetric under the reflection `x -> -x`
/// (the ground bar and its hinge lines lie in or across the plane `x = 0`), so released at
/// rest it swings to rest at the mirror image of its start: the corner, from `(1, -1, -1)`,
/// comes within 1e-4 of `(-1, -1, -1)` (2.9e-8, near t = 2.5 s).
#[test]
fn the_bricard_linkage_moves_with_one_degree_of_freedom() -> Result<()> {
    let sys = bricard()?;
    let n = sys.n_coords();
    let mut a = Simulation::new(sys.clone(), "rk4-projected")?;
    let mut b = Simulation::new(sys.clone(), "index1:dopri5")?;
    let start = bricard_corner(&sys, &a.state().q);
    assert!(
        (start - Vector3::new(1.0, -1.0, -1.0)).amax() < 1e-12,
        "{start:?}"
    );
    let mirror = Vector3::new(-1.0, -1.0, -1.0);
    let (mut worst_path, mut to_mirror) = (0.0f64, f64::INFINITY);
    let (mut zero, mut second, mut kernel) = (0.0f64, f64::INFINITY, 0.0f64);
    let mut jac = DMatrix::zeros(sys.n_constraints(), n);
    for k in 1..=30 {
        let t = 0.1 * k as f64;
        let mut watch =
            |sys: &System, s: &State, _: usize| -> std::result::Result<Flow, SolveError> {
                to_mirror = to_mirror.min((bricard_corner(sys, &s.q) - mirror).norm());
                Ok(Flow::Continue)
            };
        a.run_observed(RunConfig::new(t, 1e-3), &mut watch)?;
        b.run(AdaptiveConfig::new(t, 1e-10))?;
        let (sa, sb) = (a.state(), b.state());
        let pa = bricard_corner(&sys, &sa.q);
        worst_path = worst_path.max((pa - bricard_corner(&sys, &sb.q)).amax());
        assert_eq!(sys.redundant_at(sa.q.as_slice(), sa.t)?.len(), 1, "t = {t}");
        sys.phi_q(sa.q.as_slice(), 0.0, &mut jac);
        let mut sv: Vec<f64> = jac.clone().singular_values().iter().copied().collect();
        sv.sort_by(f64::total_cmp);
        let top = sv[n - 1];
        zero = zero.max(sv[0] / top);
        second = second.min(sv[1] / top);
        kernel = kernel.max((&jac * &sa.v).amax() / sa.v.amax());
    }
    eprintln!(
        "Bricard over 3 s: singular values of Phi_q: smallest {zero:.1e}, next {second:.1e} \
         (of the largest); |Phi_q v| {kernel:.1e} of |v|; the corner {to_mirror:.1e} m from \
         its mirror image at the closest, paths {worst_path:.1e} apart"
    );
    assert!(zero < 1e-12, "{zero:e}");
    assert!(second > 1e-2, "{second:e}");
    assert!(kernel < 1e-10, "{kernel:e}");
    assert!(to_mirror < 1e-4, "{to_mirror:e}");
    assert!(worst_path < 1e-8, "{worst_path:e}");
    Ok(())
}

/// The double pendulum's motion is spatial and keeps its angular momentum about the vertical
/// through the pivot (gravity has no moment about it, the ball joints transmit none): kept to
/// 1e-12 relative by symplectic (2,2) (its discrete Noether theorem; measured 2.6e-14) and
/// 1e-11 by projected RK4 (8.0e-13) over 2 s at h = 1e-3, from 2.31 kg m^2/s, while the elbow
/// swings out of the starting plane by more than 0.2 m (0.52 m).
#[test]
fn the_double_pendulum_keeps_its_vertical_angular_momentum() -> Result<()> {
    let sys = spatial_double_pendulum()?;
    let o = sys.spatial_offset();
    for (spec, bound) in [("symplectic:2", 1e-12), ("rk4-projected", 1e-11)] {
        let mut sim = Simulation::new(sys.clone(), spec)?;
        let l0 = vertical_momentum(&sys, sim.state());
        let (mut drift, mut out_of_plane) = (0.0f64, 0.0f64);
        let mut watch =
            |sys: &System, s: &State, _: usize| -> std::result::Result<Flow, SolveError> {
                drift = drift.max((vertical_momentum(sys, s) - l0).abs() / l0.abs());
                // the elbow: rod 1's lower end, x - L/2 d_1 (its first principal axis is the
                // bar, up), its y component
                out_of_plane = out_of_plane.max((s.q[o + 1] - 0.5 * s.q[o + 4]).abs());
                Ok(Flow::Continue)
            };
        sim.run_observed(RunConfig::new(2.0, 1e-3), &mut watch)?;
        eprintln!(
            "double pendulum, {spec}: L_z = {l0:.4} kept to {drift:.1e}; the elbow \
             {out_of_plane:.3} m out of the plane"
        );
        assert!(l0.abs() > 0.1, "{l0}");
        assert!(drift < bound, "{spec}: {drift:e}");
        assert!(out_of_plane > 0.2, "{spec}: {out_of_plane}");
    }
    Ok(())
}

/// The slider-crank's slider sits where the crank angle puts it: with the crank pin at
/// `(0, 0.1 + 0.08 cos a, 0.12 + 0.08 sin a)` and the rod 0.3 m long, the slider's `x` is
/// `sqrt(0.09 - (0.1 + 0.08 cos a)^2 - (0.12 + 0.08 sin a)^2)`; along a symplectic (2,2) run
/// (h = 1e-3, 2 s) it is, to 1e-12 (measured 1.1e-16), while the crank turns more than two
/// revolutions (3.7).
#[test]
fn the_slider_follows_the_crank() -> Result<()> {
    let sys = slider_crank()?;
    let o = sys.spatial_offset();
    let mut sim = Simulation::new(sys.clone(), "symplectic:2")?;
    let (mut worst, mut turned, mut last) = (0.0f64, 0.0f64, PI / 2.0);
    let mut watch = |_: &System, s: &State, _: usize| -> std::result::Result<Flow, SolveError> {
        // the crank's body y (its second director) points from the pivot to the pin
        let a = s.q[o + 8].atan2(s.q[o + 7]);
        let mut da = a - last;
        if da > PI {
            da -= 2.0 * PI;
        } else if da < -PI {
            da += 2.0 * PI;
        }
        turned += da;
        last = a;
        let (y, z) = (0.1 + 0.08 * a.cos(), 0.12 + 0.08 * a.sin());
        let want = (0.09 - y * y - z * z).sqrt();
        worst = worst.max((s.q[o + 24] - want).abs());
        Ok(Flow::Continue)
    };
    sim.run_observed(RunConfig::new(2.0, 1e-3), &mut watch)?;
    eprintln!(
        "slider-crank: crank turned {turned:.2} rad, slider off its closed form by {worst:.1e}"
    );
    assert!(worst < 1e-12, "{worst:e}");
    assert!(turned.abs() > 4.0 * PI, "{turned}");
    Ok(())
}
