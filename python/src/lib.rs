//! `autobal._native`: the Python package's bridge to the library. Each
//! function takes plain values (TOML text, paths, numbers), calls the same
//! library code the `study` binary calls, and returns plain values (JSON
//! text, lists of floats); `autobal/__init__.py` turns them into NumPy
//! arrays, polars frames and exceptions. Bad input raises `InputError`
//! with the CLI's exit-2 message and the dotted key it names.

use autobal::decide::decision::{Crown, Recommendation, StoredVerdict, StudyDecision};
use autobal::design::Shape;
use autobal::design::table::{optimal_row, row_at};
use autobal::model::validate::SceneError;
use autobal::scene_file::{SceneFile, SceneFileError};
use autobal::study::plan::config::{StudyError, StudyFile};
use autobal::study::run::{NoProgress, RunError, RunOptions, run_study as run};
use pyo3::create_exception;
use pyo3::exceptions::{PyRuntimeError, PyValueError};
use pyo3::prelude::*;
use pyo3::types::PyDict;
use serde_json::json;

create_exception!(
    _native,
    InputError,
    PyValueError,
    "Bad input: args are (message, dotted key or None), as the study CLI's exit-2 errors."
);

/// An [`InputError`] with `message` and the `key` it names.
fn input_error(message: String, key: Option<String>) -> PyErr {
    InputError::new_err((message, key))
}

/// The dotted key a scene file's error names, if it names one.
fn scene_key(error: &SceneFileError, text: &str) -> Option<String> {
    match error {
        SceneFileError::Parse { .. } => autobal::input_file::toml_error_key::<SceneFile>(text),
        SceneFileError::Invalid {
            source: SceneError::Invalid { field, .. },
            ..
        } => Some(field.clone()),
        SceneFileError::Invalid {
            source: SceneError::Design(_),
            ..
        } => Some("balancer".into()),
        SceneFileError::Io { .. } => None,
    }
}

/// The dotted key a study file's error names, if it names one.
fn study_key(error: &StudyError, text: &str) -> Option<String> {
    match error {
        StudyError::Parse { .. } => autobal::input_file::toml_error_key::<StudyFile>(text),
        StudyError::Invalid { key, .. } => Some(key.clone()),
        StudyError::Io { .. } => None,
    }
}

/// Simulate the scene in `text` (`name` in messages): the run's metrics as
/// the JSON `study simulate --json` prints, and (with `series`) the sampled
/// time history as lists (t, x, y, r, eps, one list of angles per weight,
/// and each bearing's x and y on rotors with bearings of their own).
#[pyfunction]
#[pyo3(signature = (text, name, series = true))]
fn simulate(py: Python<'_>, text: &str, name: &str, series: bool) -> PyResult<Py<PyAny>> {
    let file = SceneFile::parse(text, name)
        .map_err(|e| input_error(e.to_string(), scene_key(&e, text)))?;
    let simulation = file
        .simulation(name)
        .map_err(|e| input_error(e.to_string(), scene_key(&e, text)))?;
    let result = py.detach(|| simulation.run(series)).map_err(|e| match &e {
        SceneError::Invalid { field, .. } => {
            input_error(format!("{name}: {e}"), Some(field.clone()))
        }
        SceneError::Design(_) => input_error(format!("{name}: {e}"), Some("balancer".into())),
    })?;
    let out = PyDict::new(py);
    let metrics = serde_json::to_string_pretty(&result.metrics)
        .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
    out.set_item("metrics_json", metrics)?;
    if let Some(s) = result.series {
        out.set_item("t", s.t)?;
        out.set_item("x", s.x)?;
        out.set_item("y", s.y)?;
        out.set_item("r", s.r)?;
        out.set_item("eps", s.eps)?;
        out.set_item("psi", s.psi)?;
        out.set_item("bearing_x", s.bearing_x)?;
        out.set_item("bearing_y", s.bearing_y)?;
    }
    Ok(out.into_any().unbind())
}

/// Run the study in `text` (`name` in messages), its folder under `out`
/// when given: the folder written (runs.parquet, summary.parquet), the runs
/// made, and the typed decision as JSON.
#[pyfunction]
#[pyo3(signature = (text, name, threads = None, out = None, overwrite = false))]
fn run_study(
    py: Python<'_>,
    text: &str,
    name: &str,
    threads: Option<usize>,
    out: Option<String>,
    overwrite: bool,
) -> PyResult<(String, u64, String)> {
    let study = |e: StudyError| input_error(e.to_string(), study_key(&e, text));
    let mut plan = StudyFile::parse(text, name)
        .map_err(study)?
        .plan(text, name)
        .map_err(study)?;
    if let Some(dir) = out {
        plan.file.output = dir;
    }
    if threads == Some(0) {
        return Err(input_error(
            "threads = 0: at least one thread".into(),
            Some("threads".into()),
        ));
    }
    let options = RunOptions {
        threads,
        overwrite,
        ..RunOptions::default()
    };
    let output = py
        .detach(|| run(&plan, &options, &NoProgress))
        .map_err(|e| {
            if e.is_user_error() || matches!(e, RunError::AdaptiveSharded) {
                input_error(e.to_string(), None)
            } else {
                PyRuntimeError::new_err(e.to_string())
            }
        })?;
    let decision = match &output.summary {
        Some(summary) => {
            let d = StudyDecision::from_summary(summary)
                .map_err(|e| PyRuntimeError::new_err(e.to_string()))?;
            decision_json(&d)
        }
        None => serde_json::Value::Null,
    };
    Ok((
        output.dir.display().to_string(),
        output.runs,
        decision.to_string(),
    ))
}

/// The decision as plain data: criterion, the designs in rank order with
/// their verdicts, the crown, and the recommendation with its part and the
/// sentence `study run` prints.
fn decision_json(d: &StudyDecision) -> serde_json::Value {
    let verdict = |v: Option<StoredVerdict>| {
        v.map(|v| match v {
            StoredVerdict::Best => "best",
            StoredVerdict::BestBetter => "best_better",
            StoredVerdict::NotDistinguishable => "not_distinguishable",
            StoredVerdict::OtherBetter => "other_better",
            StoredVerdict::NoDesignBalances => "no_design_balances",
            StoredVerdict::OnlyDesign => "only_design",
        })
    };
    let ranked: Vec<_> = d
        .ranked
        .iter()
        .map(|r| {
            json!({
                "design_id": r.id,
                "verdict": verdict(r.verdict),
                "balances": r.balances,
                "pareto": r.pareto,
                "left_race": r.left_race,
            })
        })
        .collect();
    let crown = match &d.crown {
        Crown::Best {
            best,
            better_than,
            not_distinguishable,
            other_better,
        } => json!({
            "kind": "best", "best": best, "better_than": better_than,
            "not_distinguishable": not_distinguishable, "other_better": other_better,
        }),
        Crown::NoneBalances { best, cause, .. } => {
            json!({"kind": "none_balances", "best": best, "cause": cause})
        }
        Crown::Alone => json!({"kind": "alone"}),
    };
    let recommendation = match &d.recommendation {
        Recommendation::Build {
            design,
            first,
            indistinguishable,
            tie_break,
            part,
            pareto,
            ..
        } => json!({
            "kind": "build",
            "design_id": design,
            "first": first,
            "indistinguishable": indistinguishable,
            "tie_break": tie_break.name(),
            "part": part,
            "pareto": pareto,
        }),
        Recommendation::NoneBalances => json!({"kind": "none_balances"}),
        Recommendation::NoDesigns => json!({"kind": "no_designs"}),
    };
    json!({
        "criterion": d.criterion.label(),
        "alpha": d.alpha,
        "ranked": ranked,
        "crown": crown,
        "recommendation": recommendation,
        "text": autobal::text::ranking::decision_text(d),
    })
}

/// The seed tables' rows (capacity, optimal or given radius ratio) for
/// `kind` ("ball", "roller" or None for both) and each count in `counts`, as JSON.
#[pyfunction]
#[pyo3(signature = (counts, kind = None, rho = None))]
fn design(counts: Vec<u32>, kind: Option<&str>, rho: Option<f64>) -> PyResult<String> {
    let shapes = match kind {
        None => Shape::ALL.to_vec(),
        Some("ball") => vec![Shape::Ball],
        Some("roller") => vec![Shape::Roller],
        Some(other) => {
            return Err(input_error(
                format!("kind = {other:?}: one of \"ball\", \"roller\""),
                Some("kind".into()),
            ));
        }
    };
    let mut rows = Vec::new();
    for shape in shapes {
        for &n in &counts {
            let row = match rho {
                Some(rho) => row_at(shape, n, rho),
                None => optimal_row(shape, n),
            };
            rows.push(row.map_err(|e| input_error(e.to_string(), None))?);
        }
    }
    serde_json::to_string(&rows).map_err(|e| PyRuntimeError::new_err(e.to_string()))
}

/// The build's version line (crate version and commit), as `study --version` prints it.
#[pyfunction]
fn version() -> &'static str {
    autobal::build_info::VERSION_LINE
}

/// The native module.
#[pymodule]
fn _native(m: &Bound<'_, PyModule>) -> PyResult<()> {
    m.add_function(wrap_pyfunction!(simulate, m)?)?;
    m.add_function(wrap_pyfunction!(run_study, m)?)?;
    m.add_function(wrap_pyfunction!(design, m)?)?;
    m.add_function(wrap_pyfunction!(version, m)?)?;
    m.add("InputError", m.py().get_type::<InputError>())?;
    Ok(())
}
