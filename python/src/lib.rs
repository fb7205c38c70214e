//! The Rust core of the Python package `mbd` (`mbd._mbd`): models read and written through
//! their model files, runs the way `mbd run` does them (the GIL released), many runs at once on
//! threads, the solver registry, and the library's errors as Python exceptions. The Python
//! layer (`python/mbd/`) wraps it in the documented API.

mod errors;
mod run;

use errors::Failure;
use mbd::model::{ModelFile, System};
use numpy::ndarray::Array2;
use numpy::IntoPyArray;
use pyo3::prelude::*;
use pyo3::types::{PyDict, PyList};
use rayon::prelude::*;
use run::{run_model, RunData, RunOptions};

/// A validated model (a `System`), built from a model file's text.
#[pyclass(module = "mbd._mbd", name = "CoreModel", frozen)]
struct CoreModel {
    system: System,
}

fn parse(text: &str, format: &str) -> Result<System, Failure> {
    let file = match format {
        "json" => ModelFile::from_json(text)?,
        "toml" => ModelFile::from_toml(text)?,
        other => {
            return Err(Failure::argument(format!(
                "unknown model format '{other}': use \"toml\" or \"json\""
            )))
        }
    };
    Ok(file.build()?)
}

#[pymethods]
impl CoreModel {
    /// Reads a model file (`.toml` or `.json`; tables named in it relative to its folder).
    #[staticmethod]
    fn from_path(py: Python<'_>, path: std::path::PathBuf) -> PyResult<Self> {
        let system = py
            .detach(|| System::from_path(&path).map_err(Failure::from))
            .map_err(|f| f.to_pyerr(py))?;
        Ok(CoreModel { system })
    }

    /// Parses a model file's text, `format` `"toml"` or `"json"`.
    #[staticmethod]
    fn from_text(py: Python<'_>, text: &str, format: &str) -> PyResult<Self> {
        let system = py
            .detach(|| parse(text, format))
            .map_err(|f| f.to_pyerr(py))?;
        Ok(CoreModel { system })
    }

    /// The model file as JSON.
    fn to_json(&self, py: Python<'_>) -> PyResult<String> {
        self.system
            .to_model_file()
            .to_json()
            .map_err(|e| Failure::from(e).to_pyerr(py))
    }

    /// The model file as TOML.
    fn to_toml(&self, py: Python<'_>) -> PyResult<String> {
        self.system
            .to_model_file()
            .to_toml()
            .map_err(|e| Failure::from(e).to_pyerr(py))
    }

    /// A summary: names of bodies, joints, forces, spatial bodies and joints; coordinate names;
    /// sizes.
    fn describe<'py>(&self, py: Python<'py>) -> PyResult<Bound<'py, PyDict>> {
        let s = &self.system;
        let d = PyDict::new(py);
        let names = |it: Vec<&str>| it.into_iter().map(str::to_string).collect::<Vec<_>>();
        d.set_item(
            "bodies",
            names(s.bodies().iter().map(|b| b.name.as_str()).collect()),
        )?;
        d.set_item(
            "joints",
            names(s.joints().iter().map(|j| j.name.as_str()).collect()),
        )?;
        d.set_item(
            "forces",
            names(s.forces().iter().map(|f| f.name.as_str()).collect()),
        )?;
        d.set_item(
            "spatial_bodies",
            names(s.spatial_bodies().iter().map(|b| b.name.as_str()).collect()),
        )?;
        d.set_item(
            "spatial_point_masses",
            names(
                s.spatial_point_masses()
                    .iter()
                    .map(|p| p.name.as_str())
                    .collect(),
            ),
        )?;
        d.set_item(
            "spatial_joints",
            names(s.spatial_joints().iter().map(|j| j.name.as_str()).collect()),
        )?;
        d.set_item(
            "spatial_forces",
            names(s.spatial_forces().iter().map(|f| f.name.as_str()).collect()),
        )?;
        d.set_item("coordinates", s.coordinate_names())?;
        d.set_item("n_constraints", s.n_constraints())?;
        d.set_item("dof", s.dof())?;
        d.set_item("gravity", s.gravity().to_vec())?;
        Ok(d)
    }

    /// Runs the model; returns `(columns, data, n_coordinates, stats)` or raises.
    #[allow(clippy::too_many_arguments)]
    #[pyo3(signature = (solver, t_end, h=None, tol=None, every=1, reactions=false, drift_tol=None, drift_guard=true, max_steps=1_000_000_000, atol=None))]
    fn run<'py>(
        &self,
        py: Python<'py>,
        solver: String,
        t_end: f64,
        h: Option<f64>,
        tol: Option<f64>,
        every: usize,
        reactions: bool,
        drift_tol: Option<f64>,
        drift_guard: bool,
        max_steps: usize,
        atol: Option<f64>,
    ) -> PyResult<Bound<'py, PyAny>> {
        let opts = RunOptions {
            solver,
            t_end,
            h,
            tol,
            atol,
            every,
            reactions,
            drift_tol,
            drift_guard,
            max_steps,
        };
        let out = py.detach(|| run_model(&self.system, &opts));
        match out {
            Ok(data) => to_python(py, data),
            Err(f) => Err(f.to_pyerr(py)),
        }
    }
}

/// `(columns, data, n_coordinates, stats)` for Python.
fn to_python(py: Python<'_>, r: RunData) -> PyResult<Bound<'_, PyAny>> {
    let stats = PyDict::new(py);
    stats.set_item("steps", r.stats.steps)?;
    stats.set_item("rejected", r.stats.rejected_steps)?;
    stats.set_item("stop", r.stop())?;
    stats.set_item("wall_time", r.wall_time)?;
    stats.set_item("rows", r.rows)?;
    stats.set_item("newton_iterations", r.stats.newton_iterations)?;
    stats.set_item("rhs_evals", r.stats.rhs_evals)?;
    stats.set_item("near_singular_steps", r.stats.near_singular_steps)?;
    stats.set_item("stepped_over", r.stats.stepped_over)?;
    stats.set_item("skipped_outputs", r.stats.skipped_outputs)?;
    stats.set_item("min_step", r.stats.min_step)?;
    stats.set_item("max_step", r.stats.max_step)?;
    stats.set_item("e_h", r.measures.e_h)?;
    stats.set_item("e_phi", r.measures.e_phi)?;
    stats.set_item("e_phidot", r.measures.e_phidot)?;
    stats.set_item("not_conserved", r.not_conserved)?;
    stats.set_item("energy_balance", r.balance)?;
    stats.set_item("warnings", r.warnings)?;
    let ncols = r.columns.len();
    let data = Array2::from_shape_vec((r.rows, ncols), r.data)
        .map_err(|e| pyo3::exceptions::PyRuntimeError::new_err(e.to_string()))?;
    let tuple = (r.columns, data.into_pyarray(py), r.n_coordinates, stats);
    Ok(tuple.into_pyobject(py)?.into_any())
}

/// Runs each model with its options on the threads of a pool (the GIL released); returns one
/// entry per member in order: the run's `(columns, data, n_coordinates, stats)` or the
/// exception object of its failure.
#[pyfunction]
#[pyo3(signature = (members, threads=None))]
fn run_many<'py>(
    py: Python<'py>,
    members: Vec<(Py<CoreModel>, Bound<'py, PyDict>)>,
    threads: Option<usize>,
) -> PyResult<Bound<'py, PyList>> {
    let mut jobs = Vec::with_capacity(members.len());
    for (model, opts) in &members {
        let get = |k: &str| opts.get_item(k);
        let opts = RunOptions {
            solver: get("solver")?.map_or(Ok(String::new()), |v| v.extract())?,
            t_end: get("t_end")?.map_or(Ok(f64::NAN), |v| v.extract())?,
            h: get("h")?.map_or(Ok(None), |v| v.extract())?,
            tol: get("tol")?.map_or(Ok(None), |v| v.extract())?,
            atol: get("atol")?.map_or(Ok(None), |v| v.extract())?,
            every: get("every")?.map_or(Ok(1), |v| v.extract())?,
            reactions: get("reactions")?.map_or(Ok(false), |v| v.extract())?,
            drift_tol: get("drift_tol")?.map_or(Ok(None), |v| v.extract())?,
            drift_guard: get("drift_guard")?.map_or(Ok(true), |v| v.extract())?,
            max_steps: get("max_steps")?.map_or(Ok(1_000_000_000), |v| v.extract())?,
        };
        jobs.push((model.get().system.clone(), opts));
    }
    let work = || -> Vec<Result<RunData, Failure>> {
        jobs.par_iter()
            .map(|(sys, opts)| run_model(sys, opts))
            .collect()
    };
    let results = py.detach(|| match threads {
        Some(n) => rayon::ThreadPoolBuilder::new()
            .num_threads(n)
            .build()
            .map(|pool| pool.install(work))
            .map_err(|e| e.to_string()),
        None => Ok(work()),
    });
    let results = results.map_err(pyo3::exceptions::PyRuntimeError::new_err)?;
    let out = PyList::empty(py);
    for r in results {
        match r {
            Ok(data) => out.append(to_python(py, data)?)?,
            Err(f) => out.append(f.instance(py)?)?,
        }
    }
    Ok(out)
}

/// The solver registry: one dict per variant (`spec`, `order`, `adaptive`, `description`,
/// `label`, `refuses`, `syntax` of its family).
#[pyfunction]
fn solvers(py: Python<'_>) -> PyResult<Bound<'_, PyList>> {
    let out = PyList::empty(py);
    for (family, v) in mbd::registry().variants() {
        let d = PyDict::new(py);
        d.set_item("spec", v.spec)?;
        d.set_item("order", v.order)?;
        d.set_item("adaptive", v.adaptive)?;
        d.set_item("description", v.description)?;
        d.set_item("label", v.label)?;
        d.set_item("refuses", v.refuses)?;
        d.set_item("family", family.crate_name)?;
        d.set_item("syntax", family.syntax)?;
        out.append(d)?;
    }
    Ok(out)
}

/// Checks a solver spec string; raises `InvalidSolverSpec` naming the known solvers if bad.
/// Returns `(spec, adaptive)`.
#[pyfunction]
fn parse_solver(py: Python<'_>, spec: &str) -> PyResult<(String, bool)> {
    let s = mbd::registry()
        .parse(spec)
        .map_err(|e| Failure::from(e).to_pyerr(py))?;
    Ok((s.spec().to_string(), s.adaptive()))
}

/// The module `mbd._mbd`.
#[pymodule]
fn _mbd(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_class::<CoreModel>()?;
    m.add_function(wrap_pyfunction!(run_many, m)?)?;
    m.add_function(wrap_pyfunction!(solvers, m)?)?;
    m.add_function(wrap_pyfunction!(parse_solver, m)?)?;
    Ok(())
}
