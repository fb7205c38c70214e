//! CSV and JSON writers for time series.

use crate::energy_balance::EnergyBalance;
use crate::error::AnalysisError;
use mbd_model::System;
use mbd_solve::{
    Flow, JointReaction, Observer, OutputSolve, ReactionSolver, SensorSolver, SolveError, State,
};
use serde::Serialize;
use std::io::Write;
use std::path::Path;

/// Named columns of equal length.
#[derive(Clone, Debug, Default, PartialEq, Serialize)]
pub struct TimeSeries {
    /// Column names (the first is usually `t`).
    pub names: Vec<String>,
    /// Columns.
    pub columns: Vec<Vec<f64>>,
}

impl TimeSeries {
    /// An empty series with the given column names.
    pub fn new<S: Into<String>>(names: impl IntoIterator<Item = S>) -> Self {
        let names: Vec<String> = names.into_iter().map(Into::into).collect();
        let columns = vec![Vec::new(); names.len()];
        TimeSeries { names, columns }
    }
    /// Appends a row.
    pub fn push(&mut self, row: &[f64]) -> Result<(), AnalysisError> {
        if row.len() != self.names.len() {
            return Err(AnalysisError::Dimension {
                what: "time series row",
                expected: self.names.len(),
                got: row.len(),
            });
        }
        for (c, &x) in self.columns.iter_mut().zip(row) {
            c.push(x);
        }
        Ok(())
    }
    /// Number of rows.
    pub fn len(&self) -> usize {
        self.columns.first().map_or(0, Vec::len)
    }
    /// Whether there are no rows.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }
    /// Writes CSV (header line, then rows; full precision).
    pub fn write_csv<W: Write>(&self, mut w: W) -> std::io::Result<()> {
        writeln!(w, "{}", self.names.join(","))?;
        for r in 0..self.len() {
            let row: Vec<String> = self.columns.iter().map(|c| format!("{:e}", c[r])).collect();
            writeln!(w, "{}", row.join(","))?;
        }
        Ok(())
    }
    /// Writes CSV to a file.
    pub fn save_csv(&self, path: impl AsRef<Path>) -> Result<(), AnalysisError> {
        let p = path.as_ref();
        let io = |e: std::io::Error| AnalysisError::Io {
            path: p.display().to_string(),
            message: e.to_string(),
        };
        let f = std::fs::File::create(p).map_err(io)?;
        self.write_csv(std::io::BufWriter::new(f)).map_err(io)
    }
    /// JSON object `{ name: [values...] }` (non-finite values become null).
    pub fn to_json(&self) -> serde_json::Value {
        let mut m = serde_json::Map::new();
        for (n, c) in self.names.iter().zip(&self.columns) {
            m.insert(n.clone(), serde_json::Value::from(c.clone()));
        }
        serde_json::Value::Object(m)
    }
    /// Writes JSON to a file.
    pub fn save_json(&self, path: impl AsRef<Path>) -> Result<(), AnalysisError> {
        let p = path.as_ref();
        let s = serde_json::to_string_pretty(&self.to_json()).map_err(|e| AnalysisError::Io {
            path: p.display().to_string(),
            message: e.to_string(),
        })?;
        std::fs::write(p, s).map_err(|e| AnalysisError::Io {
            path: p.display().to_string(),
            message: e.to_string(),
        })
    }
}

/// An [`Observer`] that streams `t, q..., v..., H` rows as CSV to a writer, keeping nothing in
/// memory (for long runs).
///
/// Columns: `t`, the coordinates by name (`body.x`, `body.y`, `body.theta`, see
/// [`System::coordinate_names`]), the velocities (`d_body.x`, ...), the energy `H`, and with
/// [`CsvObserver::with_residuals`] the constraint residuals `max_abs_phi` (`||Phi(q, t)||_inf`)
/// and `max_abs_phidot` (`||Phi_q v + Phi_t||_inf`). With [`CsvObserver::with_every`] only
/// every `k`-th step is written; [`CsvObserver::finish`] then adds the final state.
///
/// ```
/// use mbd_analysis::CsvObserver;
/// use mbd_solve::{run, ButcherTableau, Index1Options, Index1Rk, RunConfig, State};
///
/// let sys = mbd_model::models::pendulum(1.0, 1.0, 0.3, 9.81)?;
/// let mut s = State::consistent(&sys, 0.0)?;
/// let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default())?;
/// let mut csv = CsvObserver::new(Vec::new()).with_residuals().with_every(3);
/// run(&mut rk, &sys, &mut s, RunConfig::new(0.1, 0.01), &mut csv)?;
/// csv.finish(&sys, &s)?;
/// let text = String::from_utf8(csv.into_inner()).unwrap();
/// let lines: Vec<&str> = text.lines().collect();
/// assert!(lines[0].ends_with(",H,max_abs_phi,max_abs_phidot"));
/// assert_eq!(lines.len(), 1 + 5); // header, steps 0, 3, 6, 9 and the final step 10
/// # Ok::<(), Box<dyn std::error::Error>>(())
/// ```
pub struct CsvObserver<W: Write> {
    w: W,
    header_written: bool,
    residuals: bool,
    reactions: bool,
    /// The reaction workspace (built at the first row that needs it) and its buffer.
    reaction_solver: Option<(ReactionSolver, Vec<JointReaction>)>,
    /// The spatial joints' reactions of the current row.
    spatial_reactions: Vec<mbd_model::spatial::SpatialJointReaction>,
    sensors: bool,
    /// The sensor workspace (built at the first row that needs it).
    sensor_solver: Option<SensorSolver>,
    energy_balance: bool,
    /// The running energy balance (built at the first state), advanced at every step.
    balance: Option<EnergyBalance>,
    /// The one index-1 solve of a state shared by the balance, the reactions and the sensors
    /// (built when one of them first needs it).
    solve: Option<OutputSolve>,
    every: usize,
    row: Vec<f64>,
    phi: Vec<f64>,
    last_written: Option<(usize, f64)>,
    last_step: Option<usize>,
}

impl<W: Write> CsvObserver<W> {
    /// Streams to `w` (wrap files in a `BufWriter`): every sample, without residual columns.
    pub fn new(w: W) -> Self {
        CsvObserver {
            w,
            header_written: false,
            residuals: false,
            reactions: false,
            reaction_solver: None,
            spatial_reactions: Vec::new(),
            sensors: false,
            sensor_solver: None,
            energy_balance: false,
            balance: None,
            solve: None,
            every: 1,
            row: Vec::new(),
            phi: Vec::new(),
            last_written: None,
            last_step: None,
        }
    }
    /// Adds the columns `max_abs_phi` and `max_abs_phidot` (constraint residuals at position
    /// and velocity level, max-norm).
    pub fn with_residuals(mut self) -> Self {
        self.residuals = true;
        self
    }
    /// Adds three columns per joint, `<joint>.fx`, `<joint>.fy`, `<joint>.mz`: the force on the
    /// joint's second body in global axes and the moment about the joint's point on it
    /// ([`ReactionSolver`], whose documentation gives the conventions); six per spatial joint,
    /// `.fx`, `.fy`, `.fz`, `.mx`, `.my`, `.mz`
    /// ([`mbd_model::System::spatial_joint_reactions`]).
    pub fn with_reactions(mut self) -> Self {
        self.reactions = true;
        self
    }
    /// Adds the columns of the model's sensors ([`SensorSolver::columns`]: `tip.x`, ...,
    /// `elbow.angle`, ...); none for a model without sensors.
    pub fn with_sensors(mut self) -> Self {
        self.sensors = true;
        self
    }
    /// Adds the energy balance's columns ([`EnergyBalance`]): `W_external` (work of
    /// time-dependent loads and drivers, J), `E_dissipated` (taken by dampers, J) and
    /// `energy_balance` (`H - H0 - W_external + E_dissipated`, J). The balance is advanced at
    /// every step the observer sees ([`CsvObserver::advance`]), written or not.
    pub fn with_energy_balance(mut self) -> Self {
        self.energy_balance = true;
        self
    }
    /// The running energy balance, if [`CsvObserver::with_energy_balance`] asked for it and a
    /// state was seen.
    pub fn energy_balance(&self) -> Option<&EnergyBalance> {
        self.balance.as_ref()
    }
    /// Advances what accumulates along the run (the energy balance) to state `s`: called by
    /// [`Observer::observe`] at every step; a writer that observes through another observer
    /// calls it at every step too.
    pub fn advance(&mut self, sys: &System, s: &State) -> Result<(), SolveError> {
        if self.energy_balance {
            let b = match &mut self.balance {
                Some(b) => b,
                None => self.balance.insert(EnergyBalance::new(sys)?),
            };
            b.advance_with(sys, s, OutputSolve::lazy(&mut self.solve, sys)?)?;
        }
        Ok(())
    }
    /// Writes only the samples of steps `0, k, 2k, ...` (`k = 0` is treated as 1); call
    /// [`CsvObserver::finish`] after the run to add the final state.
    pub fn with_every(mut self, k: usize) -> Self {
        self.every = k.max(1);
        self
    }
    /// The column names for `sys` (the CSV header).
    pub fn columns(&self, sys: &System) -> Vec<String> {
        let mut h = vec!["t".to_string()];
        let names = sys.coordinate_names();
        h.extend(names.iter().cloned());
        h.extend(names.iter().map(|n| format!("d_{n}")));
        h.push("H".into());
        if self.residuals {
            h.push("max_abs_phi".into());
            h.push("max_abs_phidot".into());
        }
        if self.reactions {
            for j in sys.joints() {
                for c in ["fx", "fy", "mz"] {
                    h.push(format!("{}.{c}", j.name));
                }
            }
            for j in sys.spatial_joints() {
                for c in ["fx", "fy", "fz", "mx", "my", "mz"] {
                    h.push(format!("{}.{c}", j.name));
                }
            }
        }
        if self.sensors {
            h.extend(SensorSolver::columns(sys));
        }
        if self.energy_balance {
            h.extend(["W_external", "E_dissipated", "energy_balance"].map(String::from));
        }
        h
    }
    /// The values of one row for state `s` (in the order of [`CsvObserver::columns`]); an
    /// error only from the reactions' index-1 solve (a singular configuration).
    pub fn row(&mut self, sys: &System, s: &State) -> Result<&[f64], SolveError> {
        self.row.clear();
        self.row.push(s.t);
        self.row.extend(s.q.iter().chain(s.v.iter()).copied());
        self.row.push(sys.energy(s.q.as_slice(), s.v.as_slice()));
        if self.residuals {
            self.phi.resize(sys.n_constraints(), 0.0);
            sys.phi(s.q.as_slice(), s.t, &mut self.phi);
            let a = mbd_solve::linalg::max_abs(&self.phi);
            sys.phi_dot(s.q.as_slice(), s.v.as_slice(), s.t, &mut self.phi);
            let b = mbd_solve::linalg::max_abs(&self.phi);
            self.row.push(a);
            self.row.push(b);
        }
        if self.reactions {
            let (rs, out) = match &mut self.reaction_solver {
                Some(x) => x,
                None => self.reaction_solver.insert((
                    ReactionSolver::new(sys)?,
                    vec![JointReaction::default(); sys.joints().len()],
                )),
            };
            let (_, lambda) = OutputSolve::lazy(&mut self.solve, sys)?.at(sys, s)?;
            rs.compute_with(sys, s, lambda, out)?;
            for r in out.iter() {
                self.row.extend([r.force[0], r.force[1], r.moment]);
            }
            if !sys.spatial_joints().is_empty() {
                // sized once: a written row allocates nothing
                self.spatial_reactions
                    .resize(sys.spatial_joints().len(), Default::default());
                sys.spatial_joint_reactions_into(
                    s.q.as_slice(),
                    s.t,
                    lambda,
                    &mut self.spatial_reactions,
                )?;
                for r in &self.spatial_reactions {
                    self.row.extend(r.force.iter().chain(&r.moment));
                }
            }
        }
        if self.sensors && !sys.sensors().is_empty() {
            let ss = match &mut self.sensor_solver {
                Some(x) => x,
                None => self.sensor_solver.insert(SensorSolver::new(sys)?),
            };
            if ss.needs_solve() {
                let (a, lambda) = OutputSolve::lazy(&mut self.solve, sys)?.at(sys, s)?;
                ss.evaluate_with(sys, s, a, lambda, &mut self.row)?;
            } else {
                ss.evaluate(sys, s, &mut self.row)?;
            }
        }
        if self.energy_balance {
            let b = self.balance.as_ref();
            self.row.extend([
                b.map_or(0.0, EnergyBalance::external_work),
                b.map_or(0.0, EnergyBalance::dissipated),
                b.map_or(0.0, EnergyBalance::residual),
            ]);
        }
        Ok(&self.row)
    }
    fn write_state(&mut self, sys: &System, s: &State, step: usize) -> Result<(), SolveError> {
        let io = |e: std::io::Error| SolveError::Observer {
            t: s.t,
            message: e.to_string(),
        };
        if !self.header_written {
            let h = self.columns(sys);
            writeln!(self.w, "{}", h.join(",")).map_err(io)?;
            self.header_written = true;
        }
        self.row(sys, s)?;
        self.write_row(step, s.t).map_err(io)
    }
    fn write_row(&mut self, step: usize, t: f64) -> std::io::Result<()> {
        let mut first = true;
        for x in &self.row {
            if first {
                write!(self.w, "{x:e}")?;
                first = false;
            } else {
                write!(self.w, ",{x:e}")?;
            }
        }
        writeln!(self.w)?;
        self.last_written = Some((step, t));
        Ok(())
    }
    /// Ends a run: writes the final state `s` unless it was the last row written (the run
    /// loop's last step is not a multiple of [`CsvObserver::with_every`]'s `k`), then flushes.
    /// Errors name the time of the row that could not be written.
    pub fn finish(&mut self, sys: &System, s: &State) -> Result<(), SolveError> {
        let err = |e: std::io::Error| SolveError::Observer {
            t: s.t,
            message: e.to_string(),
        };
        let written = matches!(self.last_written, Some((_, t)) if t == s.t);
        if !written {
            let step = self.last_step.map_or(0, |k| k + 1);
            self.write_state(sys, s, step)?;
        }
        self.w.flush().map_err(err)
    }
    /// The writer back.
    pub fn into_inner(self) -> W {
        self.w
    }
}

impl<W: Write> Observer for CsvObserver<W> {
    fn observe(&mut self, sys: &System, s: &State, step: usize) -> Result<Flow, SolveError> {
        self.last_step = Some(step);
        self.advance(sys, s)?;
        if step % self.every == 0 {
            self.write_state(sys, s, step)?;
        }
        Ok(Flow::Continue)
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use mbd_solve::{run, ButcherTableau, Index1Options, Index1Rk, RunConfig};

    fn pendulum() -> System {
        mbd_model::models::pendulum(1.0, 1.0, 0.3, 9.81).unwrap()
    }

    fn parse(text: &str) -> (Vec<String>, Vec<Vec<f64>>) {
        let mut lines = text.lines();
        let head = lines.next().unwrap().split(',').map(String::from).collect();
        let rows = lines
            .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
            .collect();
        (head, rows)
    }

    fn integrate(csv: &mut CsvObserver<Vec<u8>>, t_end: f64) -> (System, State) {
        let sys = pendulum();
        let mut s = State::consistent(&sys, 0.0).unwrap();
        let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default()).unwrap();
        run(&mut rk, &sys, &mut s, RunConfig::new(t_end, 0.01), csv).unwrap();
        (sys, s)
    }

    /// The balance, the reactions and a point sensor share one index-1 solve per state (six
    /// states: six solves, not eighteen), and the row's values equal each consumer's own.
    #[test]
    fn one_index1_solve_per_state_serves_every_output() {
        let mut file = pendulum().to_model_file();
        let body = file.bodies[0].name.clone();
        file.sensors.push(mbd_model::SensorSpec::Point {
            name: "tip".into(),
            body,
            point: [0.5, 0.0],
        });
        let sys = file.build().unwrap();
        let mut csv = CsvObserver::new(Vec::new())
            .with_reactions()
            .with_sensors()
            .with_energy_balance();
        let mut s = State::consistent(&sys, 0.0).unwrap();
        let mut rk = Index1Rk::new(&sys, ButcherTableau::rk4(), Index1Options::default()).unwrap();
        run(&mut rk, &sys, &mut s, RunConfig::new(0.05, 0.01), &mut csv).unwrap();
        assert_eq!(csv.solve.as_ref().map(OutputSolve::solves), Some(6));
        let row = csv.row(&sys, &s).unwrap().to_vec();
        assert_eq!(csv.solve.as_ref().map(OutputSolve::solves), Some(6));
        let mut rs = ReactionSolver::new(&sys).unwrap();
        let mut out = vec![JointReaction::default(); 1];
        rs.compute(&sys, &s, &mut out).unwrap();
        let mut sensors = Vec::new();
        SensorSolver::new(&sys)
            .unwrap()
            .evaluate(&sys, &s, &mut sensors)
            .unwrap();
        let head = csv.columns(&sys);
        let at = |c: &str| head.iter().position(|h| h == c).unwrap();
        let pin = &sys.joints()[0].name;
        assert_eq!(row[at(&format!("{pin}.fx"))], out[0].force[0]);
        assert_eq!(row[at(&format!("{pin}.mz"))], out[0].moment);
        assert_eq!(row[at("tip.ax")..at("tip.ay") + 1], sensors[4..6]);
    }

    #[test]
    fn default_columns_and_rows_match_the_states() {
        let mut csv = CsvObserver::new(Vec::new());
        let (sys, s) = integrate(&mut csv, 0.05);
        csv.finish(&sys, &s).unwrap();
        let (head, rows) = parse(std::str::from_utf8(&csv.into_inner()).unwrap());
        let b = &sys.bodies()[0].name;
        let want: Vec<String> = [
            "t",
            "B.x",
            "B.y",
            "B.theta",
            "d_B.x",
            "d_B.y",
            "d_B.theta",
            "H",
        ]
        .iter()
        .map(|c| c.replace('B', b))
        .collect();
        assert_eq!(head, want);
        // steps 0..=5, and finish() does not repeat the final state
        assert_eq!(rows.len(), 6);
        let last = &rows[5];
        assert_eq!(last[0], s.t);
        assert_eq!(&last[1..4], s.q.as_slice());
        assert_eq!(&last[4..7], s.v.as_slice());
        assert_eq!(last[7], sys.energy(s.q.as_slice(), s.v.as_slice()));
        for (k, r) in rows.iter().enumerate() {
            assert!((r[0] - 0.01 * k as f64).abs() < 1e-14);
        }
    }

    #[test]
    fn every_and_finish_sample_the_run_and_its_end() {
        let mut csv = CsvObserver::new(Vec::new()).with_every(4).with_residuals();
        let (sys, s) = integrate(&mut csv, 0.1);
        csv.finish(&sys, &s).unwrap();
        let (head, rows) = parse(std::str::from_utf8(&csv.into_inner()).unwrap());
        assert_eq!(head[head.len() - 2..], ["max_abs_phi", "max_abs_phidot"]);
        let ts: Vec<f64> = rows.iter().map(|r| r[0]).collect();
        let want = [0.0, 0.04, 0.08, 0.1];
        assert_eq!(ts.len(), want.len(), "{ts:?}");
        for (a, b) in ts.iter().zip(want) {
            assert!((a - b).abs() < 1e-14, "{ts:?}");
        }
        // the residuals are those of the states: RK4 on the index-1 form drifts a little
        let mut phi = vec![0.0; sys.n_constraints()];
        sys.phi(s.q.as_slice(), s.t, &mut phi);
        let want_phi = mbd_solve::linalg::max_abs(&phi);
        let last = rows.last().unwrap();
        assert_eq!(last[last.len() - 2], want_phi);
        assert!(rows[0][head.len() - 2] < 1e-12);
    }

    #[test]
    fn columns_and_row_agree_with_the_header() {
        let sys = pendulum();
        let s = State::consistent(&sys, 0.0).unwrap();
        let mut csv = CsvObserver::new(std::io::sink()).with_residuals();
        let cols = csv.columns(&sys);
        let row = csv.row(&sys, &s).unwrap().to_vec();
        assert_eq!(cols.len(), row.len());
        assert_eq!(cols.len(), 1 + 2 * sys.n_coords() + 3);
    }

    struct Broken;
    impl Write for Broken {
        fn write(&mut self, _: &[u8]) -> std::io::Result<usize> {
            Err(std::io::Error::other("disk full"))
        }
        fn flush(&mut self) -> std::io::Result<()> {
            Ok(())
        }
    }

    #[test]
    fn a_failing_writer_is_an_observer_error_with_the_time() {
        let sys = pendulum();
        let s = State::consistent(&sys, 0.0).unwrap();
        let mut csv = CsvObserver::new(Broken);
        match csv.observe(&sys, &s, 0) {
            Err(SolveError::Observer { t, message }) => {
                assert_eq!(t, 0.0);
                assert!(message.contains("disk full"), "{message}");
            }
            other => panic!("expected an observer error, got {other:?}"),
        }
    }
}
