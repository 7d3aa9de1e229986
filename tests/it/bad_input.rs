//! The bad-input corpus: every case is a study file, a scene file or a
//! command line that must be refused with exit code 2, a message naming the
//! key (or flag) at fault, and no output folder.

use std::path::Path;
use std::process::Command;

pub(crate) fn study(results: &Path) -> String {
    format!(
        r#"name = "corpus"
seed = 5
output = "{}"
[scene]
start = "locked_steady"
[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
inertia = 0.05
[scene.speed]
mode = "constant"
omega = 300.0
[designs]
kind = "ball"
n = 3
rho = "optimal"
race_radius = 0.05
density = 7850.0
drag = 10.0
[sampling]
samples = 2
unbalance = {{ distribution = "uniform", min = 0.2, max = 0.8, relative_to = "capacity" }}
direction = "uniform"
initial = "clustered"
[solver]
rtol = 1e-6
[metrics]
delta = 0.05
hold_revs = 50
t_end_revs = 100
"#,
        results.display()
    )
}

pub(crate) fn scene() -> String {
    crate::fixtures::point_weights_scene(2)
        + "[speed]\nmode = \"constant\"\nomega = 4.0\n[start]\nangles_deg = [90, 100]\n[metrics]\nt_end_revs = 100\n"
}

/// (what to replace, with what, a text the message must contain).
pub(crate) const STUDY_CASES: &[(&str, &str, &str)] = &[
    // Units are never guessed: both choices and their units are named.
    (
        ", relative_to = \"capacity\" }",
        " }",
        "relative_to = (missing): required: \"capacity\" (the values are fractions of each design's balancing capacity, no unit) or \"absolute\" (the values are unbalances in kg·m)",
    ),
    (
        "[sampling]",
        "[summary]\nrank_by = \"fastest\"\n[sampling]",
        "\"fastest\" is not a criterion; one of: median, mean",
    ),
    (
        "[sampling]",
        "[summary]\nrank_by = \"settled_by:30\"\n[sampling]",
        "give the unit",
    ),
    (
        "[sampling]",
        "[summary]\npareto = []\n[sampling]",
        "summary.pareto",
    ),
    // Out of any machine's range: every run would fail (issue 33).
    (
        "omega = 300.0",
        "omega = 5e-324",
        "scene.speed.omega = 5e-324",
    ),
    (
        "omega = 300.0",
        "omega = 1e308",
        "scene.speed.omega = 1e308",
    ),
    // Sizes checked from the input alone, before anything is allocated.
    (
        "t_end_revs = 100",
        "t_end_revs = 1e308",
        "metrics.t_end_revs = 1e308",
    ),
    (
        "hold_revs = 50\nt_end_revs = 100",
        "samples_per_rev = 100000\nhold_revs = 1e5\nt_end_revs = 2e5",
        "metrics.hold_revs",
    ),
    // Rejection sampling that would never end (issue 33): a point interval,
    // and a spread that leaves almost nothing inside.
    (
        "distribution = \"uniform\", min = 0.2, max = 0.8",
        "distribution = \"normal_truncated\", mean = 0.5, std = 0.1, min = 0.4, max = 0.4",
        "sampling.unbalance.max = 0.4: must be above min",
    ),
    (
        "distribution = \"uniform\", min = 0.2, max = 0.8",
        "distribution = \"normal_truncated\", mean = 0.5, std = 1e300, min = 0.4, max = 0.6",
        "sampling.unbalance.std = 1e300: leaves less than 0.1 %",
    ),
    (
        "[sampling]",
        "[sampling.tolerances]\nmass = { sigma = 0.01, relative = true, limit = 1e-300 }\n[sampling]",
        "sampling.tolerances.mass.limit",
    ),
    // An off-centre race asks the weights for e_r·|M − k/ω² − ibω/ω²| more:
    // 1 mm here needs 8.9e-3 kg·m, beyond 20 % of the capacity left.
    (
        "[sampling]",
        "[scene.effects.race_eccentricity]\noffset = 1e-3\n[sampling]",
        "to centre the off-centre race",
    ),
    // The same refusal names the key a `fixed` draw has (`value`), not `max`.
    (
        "[sampling]\nsamples = 2\nunbalance = { distribution = \"uniform\", min = 0.2, max = 0.8",
        "[scene.effects.race_eccentricity]\noffset = 1e-3\n[sampling]\nsamples = 2\nunbalance = { distribution = \"fixed\", value = 0.95",
        "sampling.unbalance.value = 0.95",
    ),
    // The rotor's angles are degrees: a retired radian key names its successor.
    (
        "bx = 100.0",
        "bx = 100.0\nunbalance_angle = 1.5",
        "rotor.unbalance_angle: this key (radians) is now `unbalance_angle_deg`",
    ),
    ("mass = 10.0", "mass = -1.0", "mass"),
    ("mass = 10.0", "mass = 0.0", "mass"),
    ("mass = 10.0", "mass = \"heavy\"", "rotor.mass"),
    ("kx = 1.0e5", "kx = -5.0", "kx"),
    ("bx = 100.0", "bx = -1.0", "bx"),
    ("inertia = 0.05", "inertia = -0.05", "inertia"),
    ("omega = 300.0", "omega = -300.0", "omega"),
    ("omega = 300.0", "omega = 0.0", "omega"),
    ("mode = \"constant\"", "mode = \"spinning\"", "spinning"),
    ("kind = \"ball\"", "kind = \"bal\"", "bal"),
    ("kind = \"ball\"", "kind = 3", "kind"),
    ("n = 3", "n = -3", "-3"),
    ("n = 3", "n = 3.5", "3.5"),
    ("n = 3", "n = 0", "n"),
    ("n = 3", "n = 1000000", "designs.n"),
    ("n = 3", "n = [3, -1]", "entry 2"),
    ("rho = \"optimal\"", "rho = 0.9", "rho"),
    ("rho = \"optimal\"", "rho = -0.1", "rho"),
    ("rho = \"optimal\"", "rho = \"biggest\"", "biggest"),
    ("race_radius = 0.05", "race_radius = -0.05", "race_radius"),
    ("density = 7850.0", "density = 0.0", "density"),
    ("drag = 10.0", "drag = true", "boolean"),
    ("drag = 10.0", "drag = -1.0", "drag"),
    ("samples = 2", "samples = 0", "sampling.samples"),
    ("samples = 2", "samples = 4000000000", "sampling.samples"),
    ("samples = 2", "samples = -2", "samples"),
    ("min = 0.2", "min = 0.9", "min"),
    ("min = 0.2", "min = -0.2", "min"),
    (
        "distribution = \"uniform\"",
        "distribution = \"gaussian\"",
        "gaussian",
    ),
    ("direction = \"uniform\"", "direction = \"north\"", "north"),
    (
        "initial = \"clustered\"",
        "initial = \"scattered\"",
        "scattered",
    ),
    (
        "start = \"locked_steady\"",
        "start = \"sideways\"",
        "sideways",
    ),
    ("rtol = 1e-6", "rtol = 1e-20", "solver.rtol"),
    ("rtol = 1e-6", "rtol = 1.0", "solver.rtol"),
    ("rtol = 1e-6", "rtol = 1e-6\natol = 0.0", "solver.atol"),
    ("rtol = 1e-6", "rtol = 1e-6\nmethod = \"rk45\"", "rk45"),
    ("rtol = 1e-6", "rtol = 1e-6\nfidelity = \"exact\"", "exact"),
    (
        "rtol = 1e-6",
        "rtol = 1e-6\nmax_steps = 0",
        "solver.max_steps",
    ),
    (
        "rtol = 1e-6",
        "rtol = 1e-6\nmax_wall_seconds = 0.0",
        "solver.max_wall_seconds",
    ),
    ("delta = 0.05", "delta = 2", "metrics.delta"),
    ("delta = 0.05", "delta = 0.0", "metrics.delta"),
    ("hold_revs = 50", "hold_revs = -5", "metrics.hold_revs"),
    ("t_end_revs = 100", "t_end_revs = 20", "metrics.t_end_revs"),
    (
        "t_end_revs = 100",
        "t_end_revs = 100\nsamples_per_rev = 4",
        "metrics.samples_per_rev",
    ),
    (
        "t_end_revs = 100",
        "t_end_revs = 100\ndivergence_factor = 0.5",
        "metrics.divergence_factor",
    ),
    ("t_end_revs = 100", "t_end_revs = 100\nbogus = 1", "bogus"),
    ("seed = 5", "seed = -5", "seed"),
    ("name = \"corpus\"", "name = \"../escape\"", "name"),
    ("mass = 10.0", "mass = = 10.0", "line"),
    ("[designs]", "[designz]", "designz"),
    (
        "initial = \"clustered\"",
        "initial = \"clustered\"\ntolerances = { mass = { sigma = -0.01, relative = true } }",
        "sampling.tolerances.mass.sigma",
    ),
    (
        "initial = \"clustered\"",
        "initial = \"clustered\"\ntolerances = { masss = { sigma = 0.01 } }",
        "masss",
    ),
    // A couple unbalance needs two balancer planes on two supports.
    (
        "initial = \"clustered\"",
        "initial = \"clustered\"\ncouple = { follows_static = 0.5 }",
        "sampling.couple",
    ),
    (
        "initial = \"clustered\"",
        "initial = \"clustered\"\ncouple = { follows_static = 0.5, phasee = \"uniform\" }",
        "phasee",
    ),
    (
        "initial = \"clustered\"",
        "initial = \"clustered\"\ntolerances = { mass = { sigma = 0.01, sd = 0.1 } }",
        "sd",
    ),
    (
        "initial = \"clustered\"",
        "initial = \"clustered\"\ntolerances = { mass = { sigma = 1e-3, limit = 0.0 } }",
        "sampling.tolerances.mass.limit",
    ),
    (
        "initial = \"clustered\"",
        "initial = \"clustered\"\ntolerances = { radius = { sigma = 0.5, relative = true } }",
        "sampling.tolerances.radius.sigma",
    ),
    (
        "initial = \"clustered\"",
        "initial = \"clustered\"\ntolerances = { radius = { sigma = 2e-3 } }",
        "sampling.tolerances.radius.sigma",
    ),
];

/// (what to replace in the scene, with what, a text the message must contain).
pub(crate) const SCENE_CASES: &[(&str, &str, &str)] = &[
    ("mass = 1.0", "mass = -1.0", "mass"),
    (
        "eccentricity = 0.01",
        "eccentricity = -0.01",
        "eccentricity",
    ),
    ("kx = 1.0", "kx = \"stiff\"", "stiff"),
    (
        "angles_deg = [90, 100]",
        "angles_deg = [90, 90]",
        "start.angles_deg",
    ),
    (
        "angles_deg = [90, 100]",
        "angles_deg = [90]",
        "start.angles_deg",
    ),
    (
        "track_radius = 1.0\ndrag = 0.01\nkappa = 1.4\n[[cargo]]",
        "track_radius = -1.0\ndrag = 0.01\nkappa = 1.4\n[[cargo]]",
        "track_radius",
    ),
    ("kappa = 1.4\n[speed]", "kappa = 0.5\n[speed]", "kappa"),
    ("omega = 4.0", "omega = 4.0\nbogus = 2", "bogus"),
    ("t_end_revs = 100", "t_end_revs = 10", "metrics.t_end_revs"),
    (
        "t_end_revs = 100",
        "t_end_revs = 100\ndelta = 1.5",
        "metrics.delta",
    ),
    ("[start]", "[solver]\nrtol = 0.5\n[start]", "solver.rtol"),
    ("[start]", "[solver]\nmethod = \"euler\"\n[start]", "euler"),
    (
        "mode = \"constant\"\nomega = 4.0",
        "mode = \"ramp\"\nomega_start = 0.0\nomega_end = 4.0\nduration = 2000.0",
        "metrics.t_end_revs",
    ),
    ("[rotor]", "[rotor]\nmodel = \"wobbly\"", "wobbly"),
    (
        "[start]",
        "[effects.contact]\nfrequency_ratio = 10.0\nstiff = true\n[start]",
        "stiff",
    ),
    // Issue 33: a negative contact frequency burnt every run's step budget.
    (
        "[start]",
        "[effects.contact]\nfrequency_ratio = -1.0\n[start]",
        "effects.contact.frequency_ratio",
    ),
    (
        "[start]",
        "[effects.contact]\ndamping_ratio = nan\n[start]",
        "effects.contact.damping_ratio",
    ),
];

/// Study-file cases of issue 33's messages: a value that made an infinite
/// mass, and serde's words for Rust types (struct, untagged and tagged enum).
pub(crate) const MESSAGE_CASES: &[(&str, &str, &str)] = &[
    (
        "race_radius = 0.05",
        "race_radius = 1e308",
        "designs.race_radius = 1e308: must be in [0.0001, 100] m",
    ),
    (
        "density = 7850.0",
        "density = 1e306",
        "designs.density = 1e306: must be in [1, 100000] kg/m³",
    ),
    (
        "rho = \"optimal\"",
        "rho = [0.3, true]",
        "expected a radius ratio: a number in (0, 1), \"optimal\" or \"half_race\"",
    ),
    (
        "unbalance = {",
        "unbalance = 5\n# {",
        "expected a table of keys",
    ),
    (
        "mode = \"constant\"",
        "mode = 3",
        "expected a name in quotes",
    ),
    (
        "mode = \"constant\"",
        "mode = \"warp\"",
        "unknown variant `warp`, expected one of `constant`, `ramp`, `motor`, `free`",
    ),
    ("omega = 300.0", "omega = \"fast\"", "expected a number"),
];

/// Command lines (after `study`) that must be refused with exit code 2.
fn flag_cases(study_path: &str, scene_path: &str) -> Vec<(Vec<String>, &'static str)> {
    let s = |v: &[&str]| v.iter().map(|x| x.to_string()).collect::<Vec<_>>();
    vec![
        (s(&["run", study_path, "--threads", "0"]), "--threads"),
        (s(&["run", study_path, "--threads", "many"]), "--threads"),
        (s(&["run", study_path, "--rank-by", "fastest"]), "--rank-by"),
        (
            s(&["run", study_path, "--rank-by", "p_residual_below:-1m"]),
            "--rank-by",
        ),
        (s(&["run", study_path, "--shard", "3/2"]), "shard"),
        (s(&["run", study_path, "--shard", "0/4"]), "shard"),
        (
            s(&["run", study_path, "--resume", "--overwrite"]),
            "--overwrite",
        ),
        (s(&["run", "no/such/study.toml"]), "no/such/study.toml"),
        (s(&["simulate", scene_path, "--series"]), "--series"),
        (s(&["frobnicate"]), "frobnicate"),
        (s(&["design", "--kind", "cube", "--n", "3"]), "cube"),
        (s(&["run", study_path, "--chunk-runs", "0"]), "--chunk-runs"),
        // Issue 33: numbers beyond any sensible range panicked, aborted or
        // were accepted; every verb now checks them while parsing, before
        // anything is read or written.
        (
            s(&["run", study_path, "--progress-every", "1e300"]),
            "--progress-every",
        ),
        (
            s(&["run", study_path, "--chunk-runs", "18446744073709551615"]),
            "--chunk-runs",
        ),
        (s(&["check", study_path, "--threads", "0"]), "--threads"),
        (s(&["baseline", study_path, "--threads", "0"]), "--threads"),
        (s(&["check", study_path, "--alpha", "0"]), "--alpha"),
        (s(&["check", study_path, "--alpha", "nan"]), "--alpha"),
        (
            s(&[
                "sweep",
                scene_path,
                "--omega",
                "1..8",
                "--points",
                "18446744073709551615",
            ]),
            "--points",
        ),
        (
            s(&[
                "map",
                scene_path,
                "--omega",
                "1..8",
                "--unbalance",
                "0.1..0.2",
                "--points",
                "100000x100000",
            ]),
            "--points",
        ),
        (s(&["design", "--n", "1..4294967295"]), "--n"),
        (
            s(&["plot", "design", "--n", "1..4294967295", "--out", "x.svg"]),
            "--n",
        ),
        // A FIFO or a folder as the study file: refused at once, not read.
        (s(&["run", "/"]), "not a text file"),
        // A sweep that would never end, and a file named for another format.
        (
            s(&[
                "stepped",
                scene_path,
                "--rpm",
                "8e6..9e6",
                "--step-rpm",
                "1e5",
                "--dwell",
                "86400",
            ]),
            "--dwell",
        ),
        (
            s(&[
                "stepped",
                scene_path,
                "--rpm",
                "38..40",
                "--step-rpm",
                "1",
                "--dwell",
                "5",
                "--out",
                "steps.csv",
            ]),
            "--out",
        ),
        // A design against itself.
        (s(&["compare", study_path, "--designs", "0,0"]), "itself"),
    ]
}

/// Every entry under `dir` with its bytes (folders as such), sorted: two
/// equal snapshots mean nothing under `dir` was made, changed or removed.
pub(crate) fn tree_snapshot(dir: &Path) -> Vec<(std::path::PathBuf, Option<Vec<u8>>)> {
    let mut out = Vec::new();
    let mut stack = vec![dir.to_path_buf()];
    while let Some(d) = stack.pop() {
        for e in std::fs::read_dir(&d).unwrap().flatten() {
            let p = e.path();
            if p.is_dir() {
                stack.push(p.clone());
                out.push((p, None));
            } else {
                out.push((p.clone(), Some(std::fs::read(&p).unwrap())));
            }
        }
    }
    out.sort();
    out
}

/// Run the study `text` from `dir`: exit code, stderr, and whether the
/// run changed anything under `dir` (beyond the study file it was given).
fn run_study(dir: &Path, text: &str) -> (Option<i32>, String, bool) {
    let path = dir.join("case.toml");
    std::fs::write(&path, text).unwrap();
    let before = tree_snapshot(dir);
    let out = Command::new(env!("CARGO_BIN_EXE_study"))
        .args(["run", path.to_str().unwrap(), "--quiet"])
        .output()
        .unwrap();
    (
        out.status.code(),
        String::from_utf8_lossy(&out.stderr).to_string(),
        tree_snapshot(dir) != before,
    )
}

#[test]
fn every_bad_study_file_is_refused_naming_the_key_with_nothing_written() {
    let mut failures = Vec::new();
    for (from, to, needle) in STUDY_CASES.iter().chain(MESSAGE_CASES) {
        let tmp = tempfile::tempdir().unwrap();
        let base = study(&tmp.path().join("results"));
        assert!(base.contains(from), "fixture lacks {from:?}");
        let text = base.replacen(from, to, 1);
        let (code, err, wrote) = run_study(tmp.path(), &text);
        let rust_words = ["struct ", "enum ", "f64", "u32", "variant identifier"];
        if code != Some(2)
            || !err.contains(needle)
            || wrote
            || rust_words.iter().any(|w| err.contains(w))
        {
            failures.push(format!(
                "{to:?}: exit {code:?}, wrote {wrote}, expected {needle:?} in: {err}"
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_bad_scene_file_is_refused_naming_the_key() {
    let mut failures = Vec::new();
    for (from, to, needle) in SCENE_CASES {
        let base = scene();
        assert!(base.contains(from), "fixture lacks {from:?}");
        let tmp = tempfile::tempdir().unwrap();
        let path = tmp.path().join("scene.toml");
        std::fs::write(&path, base.replacen(from, to, 1)).unwrap();
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(["simulate", path.to_str().unwrap()])
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        if out.status.code() != Some(2) || !err.contains(needle) {
            failures.push(format!(
                "{to:?}: exit {:?}, expected {needle:?} in: {err}",
                out.status.code()
            ));
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn every_bad_command_line_is_refused_naming_the_flag() {
    let tmp = tempfile::tempdir().unwrap();
    let results = tmp.path().join("results");
    let study_path = tmp.path().join("ok.toml");
    std::fs::write(&study_path, study(&results)).unwrap();
    let scene_path = tmp.path().join("ok_scene.toml");
    std::fs::write(&scene_path, scene()).unwrap();
    let mut failures = Vec::new();
    let cases = flag_cases(study_path.to_str().unwrap(), scene_path.to_str().unwrap());
    assert!(STUDY_CASES.len() + SCENE_CASES.len() + cases.len() >= 60);
    for (args, needle) in cases {
        // Every refusal leaves the whole tree as it was, not only results/.
        let before = tree_snapshot(tmp.path());
        let out = Command::new(env!("CARGO_BIN_EXE_study"))
            .args(&args)
            .output()
            .unwrap();
        let err = String::from_utf8_lossy(&out.stderr);
        let changed = tree_snapshot(tmp.path()) != before;
        if out.status.code() != Some(2) || !err.contains(needle) || changed {
            failures.push(format!(
                "{args:?}: exit {:?}, changed the tree: {changed}, expected {needle:?} in: {err}",
                out.status.code()
            ));
        }
    }
    assert!(!results.exists(), "a refused command wrote results");
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
