//! The loads spatial joints exert on their bodies, from the index-1 multipliers.

use super::point_mass::as_side;
use super::system::SW;
use mbd_jet::Scalar;

/// The load a spatial joint exerts on its second body (on the ground by action and reaction
/// when the second side is ground), from its multipliers: see
/// [`crate::System::spatial_joint_reactions`].
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct SpatialJointReaction {
    /// Force, global axes (N).
    pub force: [f64; 3],
    /// Moment about [`SpatialJointReaction::point`], global axes (N m).
    pub moment: [f64; 3],
    /// The joint's marker point on that body, global (m).
    pub point: [f64; 3],
}

impl crate::System {
    /// The load each spatial joint (in the order of [`crate::System::spatial_joints`]) exerts
    /// on its second body at `q` and time `t` (an angle driver's rows turn with its angle),
    /// from the multipliers `lambda` of the index-1 equations
    /// (`M a = Q - Phi_q^T lambda`; for example `mbd_solve::OutputSolve`). The joint's share of
    /// the constraint force on body `b`'s natural coordinates is `g = -Phi_q,j^T lambda_j`
    /// (12 entries): its centre-of-mass entries are the force `F`, and its director entries
    /// give the moment about the centre of mass `tau = sum_i d_i x g_i` (the virtual work of a
    /// rotation `dtheta` is `sum_i g_i . (dtheta x d_i) = dtheta . tau`); about the marker point
    /// `P` the moment is `tau + (x_b - P) x F`. A joint whose second side is ground reports
    /// the negative of its load on the first body, about the first marker's point. Errors:
    /// `q` or `lambda` of the wrong length.
    pub fn spatial_joint_reactions(
        &self,
        q: &[f64],
        t: f64,
        lambda: &[f64],
    ) -> Result<Vec<SpatialJointReaction>, crate::ModelError> {
        let mut out = vec![SpatialJointReaction::default(); self.spatial.joints.len()];
        self.spatial_joint_reactions_into(q, t, lambda, &mut out)?;
        Ok(out)
    }

    /// [`crate::System::spatial_joint_reactions`] into `out` (one entry per spatial joint),
    /// allocating nothing: what an output loop calls at every row. Errors: `q`, `lambda` or
    /// `out` of the wrong length.
    pub fn spatial_joint_reactions_into(
        &self,
        q: &[f64],
        t: f64,
        lambda: &[f64],
        out: &mut [SpatialJointReaction],
    ) -> Result<(), crate::ModelError> {
        self.check_len("q", q, self.n)?;
        self.check_len("lambda", lambda, self.m)?;
        let sp = &self.spatial;
        if out.len() != sp.joints.len() {
            return Err(crate::ModelError::Dimension {
                what: "reactions",
                expected: sp.joints.len(),
                got: out.len(),
            });
        }
        // a side's centre and directors (a point mass: its position, the constant global axes,
        // on which the joint's rows have no gradient, so its moment is zero)
        let frame = |k: usize| {
            let (ql, _) = sp.local_state(k, q, None);
            let v = |i: usize| nalgebra::Vector3::new(ql[i], ql[i + 1], ql[i + 2]);
            (v(0), [v(3), v(6), v(9)])
        };
        for (j, slot) in out.iter_mut().enumerate() {
            // the joint's share of the constraint force: g = -Phi_q,j^T lambda_j
            let [la, lb] = sp.attach[j].map(|k| k.map(|k| sp.local_state(k, q, None)));
            let mut e = [mbd_jet::DirJetN::<SW>::cst(0.0); 6];
            sp.lowered[j].eval_jets(as_side(&la), as_side(&lb), &mut e);
            sp.combine_angle(j, t, &mut e);
            let mut g = [0.0; SW];
            let row0 = sp.joint_row[j];
            for (k, ek) in e.iter().enumerate().take(sp.lowered[j].n_equations()) {
                for (gl, d) in g.iter_mut().zip(&ek.g) {
                    *gl -= lambda[row0 + k] * d;
                }
            }
            let (ma, mb) = sp.lowered[j].markers();
            // the second side, or the first with the sign of action and reaction
            let (side, marker, off, sign) = match (sp.attach[j][1], sp.attach[j][0]) {
                (Some(k), _) => (Some(k), mb, 12, 1.0),
                (None, Some(k)) => (Some(k), ma, 0, -1.0),
                (None, None) => (None, mb, 12, 1.0),
            };
            let Some(k) = side else {
                *slot = SpatialJointReaction::default();
                continue;
            };
            let (x, d) = frame(k);
            let f = nalgebra::Vector3::new(g[off], g[off + 1], g[off + 2]);
            let mut tau = nalgebra::Vector3::zeros();
            for (i, di) in d.iter().enumerate() {
                let gi = nalgebra::Vector3::new(
                    g[off + 3 + 3 * i],
                    g[off + 4 + 3 * i],
                    g[off + 5 + 3 * i],
                );
                tau += di.cross(&gi);
            }
            let p = x + d[0] * marker.point[0] + d[1] * marker.point[1] + d[2] * marker.point[2];
            let m = tau + (x - p).cross(&f);
            *slot = SpatialJointReaction {
                force: (f * sign).into(),
                moment: (m * sign).into(),
                point: p.into(),
            };
        }
        Ok(())
    }
}
