//! Figures: every plot function writes a plausible SVG and PNG (size, PNG
//! dimensions, title and axis labels in the SVG); bad input is an error.
//!
//! Set AUTOBAL_PLOT_DIR to keep the figures for looking at them.

use autobal::design::Shape;
use autobal::metrics::{Outcome, RunMetrics};
use autobal::plot::design::plot_design;
use autobal::plot::run::{RunFigure, plot_run};
use autobal::plot::study::{
    StudyData, StudyFigure, plot_settled_fraction, plot_settling_times, plot_settling_vs_unbalance,
    plot_study,
};
use autobal::plot::tradeoff::{TradeoffPoint, plot_work_precision, read_tradeoff};
use autobal::plot::{Format, PlotError};
use autobal::scene_file::SceneFile;
use autobal::study::plan::config::StudyFile;
use autobal::study::results::io::{Provenance, write_parquet};
use autobal::study::results::record::{RunRecord, to_dataframe};
use autobal::study::run::aggregate::summarize;
use polars::prelude::*;
use std::path::{Path, PathBuf};
use std::process::Command;

/// A folder for the figures: AUTOBAL_PLOT_DIR when set (kept), else a temporary one.
struct OutDir {
    path: PathBuf,
    _tmp: Option<tempfile::TempDir>,
}

fn out_dir(name: &str) -> OutDir {
    match std::env::var_os("AUTOBAL_PLOT_DIR") {
        Some(dir) => {
            let path = PathBuf::from(dir).join(name);
            std::fs::create_dir_all(&path).unwrap();
            OutDir { path, _tmp: None }
        }
        None => {
            let tmp = tempfile::tempdir().unwrap();
            OutDir {
                path: tmp.path().to_path_buf(),
                _tmp: Some(tmp),
            }
        }
    }
}

/// Width and height from a PNG's IHDR chunk.
fn png_size(path: &Path) -> (u32, u32) {
    let bytes = std::fs::read(path).unwrap();
    assert_eq!(
        &bytes[..8],
        b"\x89PNG\r\n\x1a\n",
        "{} is not a PNG",
        path.display()
    );
    assert_eq!(&bytes[12..16], b"IHDR");
    let word = |at: usize| u32::from_be_bytes(bytes[at..at + 4].try_into().unwrap());
    (word(16), word(20))
}

fn file_size(path: &Path) -> u64 {
    std::fs::metadata(path).unwrap().len()
}

/// The SVG's text, after checking it is an SVG of plausible size holding every phrase.
fn check_svg(path: &Path, min_bytes: u64, phrases: &[&str]) -> String {
    let text = std::fs::read_to_string(path).unwrap();
    assert!(text.contains("<svg"), "{} is not an SVG", path.display());
    let size = file_size(path);
    assert!(size > min_bytes, "{}: only {size} bytes", path.display());
    assert!(
        size < 3_000_000,
        "{}: {size} bytes is too large",
        path.display()
    );
    for phrase in phrases {
        assert!(text.contains(phrase), "{} lacks '{phrase}'", path.display());
    }
    text
}

fn check_png(path: &Path, min_bytes: u64, min_size: (u32, u32)) {
    let (w, h) = png_size(path);
    assert!(
        w >= min_size.0 && h >= min_size.1,
        "{}: {w}×{h}",
        path.display()
    );
    let size = file_size(path);
    assert!(size > min_bytes, "{}: only {size} bytes", path.display());
}

#[test]
fn design_curves_in_svg_and_png() {
    let dir = out_dir("design");
    let svg = dir.path.join("design.svg");
    plot_design(&Shape::ALL, &[1, 2, 3, 4, 5, 6, 7, 8], &svg).unwrap();
    check_svg(
        &svg,
        20_000,
        &[
            "Design curves",
            "radius ratio ρ = r/R",
            "dimensionless capacity",
            "number of weights n",
            "transient measure ã",
            "max: n = 3",
            "max: n = 5",
        ],
    );
    let png = dir.path.join("design.png");
    plot_design(&[Shape::Roller], &[2, 3, 4, 5], &png).unwrap();
    check_png(&png, 20_000, (1000, 500));
}

#[test]
fn one_run_in_three_panels() {
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/three_balls.toml");
    let simulation = SceneFile::read(Path::new(scene))
        .unwrap()
        .simulation(scene)
        .unwrap();
    let result = simulation.run(true).unwrap();
    let figure = RunFigure::new(&simulation, &result, "three balls: one run").unwrap();
    let dir = out_dir("run");
    let svg = dir.path.join("run.svg");
    plot_run(&figure, &svg).unwrap();
    let text = check_svg(
        &svg,
        20_000,
        &[
            "three balls: one run",
            "r / A_ref",
            "time t  (revolutions)",
            "Cargo angles",
            "ψ_j  (degrees)",
            "ε  (–, log scale)",
            "δ = 0.05",
            "t_s (settling time)",
        ],
    );
    // Thinning keeps the file small although the run has tens of thousands of samples.
    assert!(text.len() < 400_000, "{} bytes", text.len());
    let png = dir.path.join("run.PNG");
    plot_run(&figure, &png).unwrap();
    check_png(&png, 30_000, (1000, 1000));

    let unrecorded = simulation.run(false).unwrap();
    assert!(matches!(
        RunFigure::new(&simulation, &unrecorded, "x"),
        Err(PlotError::NoData(_))
    ));
    let empty = autobal::metrics::observer::Series::default();
    let bad = RunFigure {
        series: &empty,
        ..figure
    };
    assert!(matches!(plot_run(&bad, &svg), Err(PlotError::NoData(_))));
}

#[test]
fn unsettled_run_with_circulating_cargo() {
    // Cargoes that keep circulating relative to the rotor and never settle:
    // no t_s marker, angles wrap around 360°.
    let t: Vec<f64> = (0..20_000).map(|i| f64::from(i) * 0.01).collect();
    let series = autobal::metrics::observer::Series {
        x: t.iter().map(|t| 0.5 * t.cos()).collect(),
        y: t.iter().map(|t| 0.5 * t.sin()).collect(),
        r: t.iter().map(|t| 0.5 + 0.2 * (0.3 * t).sin()).collect(),
        eps: t.iter().map(|t| 0.3 + 0.1 * (0.2 * t).cos()).collect(),
        psi: vec![
            t.iter().map(|t| 0.05 * t).collect(),
            t.iter().map(|t| 2.0 - 0.11 * t).collect(),
        ],
        t,
        ..Default::default()
    };
    let metrics: RunMetrics = study_runs(&study_plan(), 1)[3].metrics.clone();
    assert!(!metrics.settled);
    let figure = RunFigure {
        series: &series,
        metrics: &metrics,
        revolution_s: 2.0 * std::f64::consts::PI,
        delta: 0.05,
        hold_revs: 50.0,
        title: "circulating cargo",
    };
    let dir = out_dir("run_unsettled");
    let png = dir.path.join("run.png");
    plot_run(&figure, &png).unwrap();
    check_png(&png, 20_000, (1000, 1000));
    let svg = dir.path.join("run.svg");
    plot_run(&figure, &svg).unwrap();
    check_svg(
        &svg,
        20_000,
        &["did not settle", "never held below δ", "cargo 2"],
    );
}

/// The fixture study's file, as `study run` keeps it beside its results.
const STUDY_TOML: &str = r#"
[scene.rotor]
mass = 10.0
kx = 1.0e5
ky = 1.0e5
bx = 100.0
by = 100.0
[scene.speed]
mode = "constant"
omega = 300.0
[designs]
kind = "ball"
n = 3
rho = ["optimal", 0.25]
race_radius = 0.05
drag = [5.0, 20.0]
[sampling]
samples = 40
unbalance = { distribution = "uniform", min = 0.1, max = 0.9, relative_to = "capacity" }
"#;

fn study_plan() -> autobal::study::plan::config::StudyPlan {
    StudyFile::parse(STUDY_TOML, "fixture.toml")
        .unwrap()
        .plan(STUDY_TOML, "fixture.toml")
        .unwrap()
}

/// Synthetic runs for the plan: settling time grows with the unbalance; a few do not settle.
fn study_runs(plan: &autobal::study::plan::config::StudyPlan, samples: u32) -> Vec<RunRecord> {
    let mut runs = Vec::new();
    for design in &plan.designs {
        for s in 0..samples {
            let fraction = 0.1 + 0.8 * f64::from(s) / f64::from(samples);
            let settled = !(design.id == 3 && s % 9 == 0);
            let revs = (5.0 + 10.0 * f64::from(design.id)) * (1.0 + 4.0 * fraction * fraction);
            let outcome = if settled {
                Outcome::Settled
            } else {
                Outcome::NotSettled
            };
            runs.push(RunRecord {
                run_id: u64::from(design.id) * u64::from(samples) + u64::from(s),
                design_id: design.id,
                sample_id: s,
                kind: "ball".into(),
                n: 3,
                rho: design.rho,
                race_radius: 0.05,
                weight_mass: 0.2,
                capacity: design.capacity,
                drag: design.spec.drag,
                unbalance: fraction * design.capacity,
                unbalance_fraction: fraction,
                direction_deg: 0.0,
                initial_angles_deg: vec![0.0, 10.0, 20.0],
                metrics: RunMetrics {
                    settled,
                    settling_time: settled.then_some(revs * 0.02),
                    settling_revs: settled.then_some(revs),
                    settling_time_err: 0.001,
                    settling_time_eps: None,
                    hold_complete: settled,
                    hold_certified: false,
                    residual_abs: 1e-6,
                    residual_rel: 0.01,
                    a_ref: 1e-4,
                    balancing_error: 0.0,
                    peak_r: 1e-3,
                    final_rel_angles_deg: vec![120.0, 180.0, 240.0],
                    p_final: 0.0,
                    outcome,
                    reason: String::new(),
                    t_final: 10.0,
                    steps: 100,
                    rhs_calls: 600,
                    method: "dp5".into(),
                    fidelity: "full".into(),
                    contact_model: None,
                    min_gap_rad: None,
                    final_min_gap_rad: None,
                    censoring_revs: None,
                    operating_time: Some(0.0),
                    final_spin_rate: None,
                    pack_slip_rate: None,
                    balance_angle_error_deg: None,
                    plane_a_ref: None,
                    plane_residual_abs: None,
                    plane_settling_revs: None,
                    plane_balancing_error: None,
                    bearing_orbit_peak: None,
                    bearing_orbit_rms: None,
                },
                method: "dp5".into(),
                contact: true,
                stall_torque: None,
                wall_time_s: 0.001,
                weights: None,
                couple: None,
                uncertain: Vec::new(),
            });
        }
    }
    runs
}

/// A study folder as `study run` leaves it: study.toml, runs.parquet and summary.parquet.
fn write_study(dir: &Path) {
    std::fs::write(dir.join("study.toml"), STUDY_TOML).unwrap();
    let plan = study_plan();
    let runs = study_runs(&plan, 40);
    // The fixture's runs belong to the study.toml beside them, as a run's do.
    let provenance = Provenance::new(
        STUDY_TOML,
        autobal::study::plan::config::DEFAULT_SEED,
        "all",
    );
    let mut summary = summarize(&plan, &runs).unwrap();
    write_parquet(&dir.join("summary.parquet"), &mut summary, &provenance).unwrap();
    write_parquet(
        &dir.join("runs.parquet"),
        &mut to_dataframe(&runs).unwrap(),
        &provenance,
    )
    .unwrap();
}

#[test]
fn study_figures_from_parquet() {
    let input = tempfile::tempdir().unwrap();
    let study_dir = input.path().join("fixture_study");
    std::fs::create_dir(&study_dir).unwrap();
    write_study(&study_dir);
    let data = StudyData::read(&study_dir).unwrap();
    assert_eq!(data.name, "fixture_study");
    assert_eq!(data.designs.len(), 4);
    assert_eq!(data.runs.len(), 160);

    let dir = out_dir("study");
    let paths = plot_study(&data, &dir.path, Format::Svg, &StudyFigure::ALL).unwrap();
    assert_eq!(paths.len(), 3);
    check_svg(
        &paths[0],
        5_000,
        &[
            "fixture_study: settling time per design",
            "settling time t_s  (revolutions, log scale)",
            "ρ = 0.25, β = 5 N·s/m",
        ],
    );
    check_svg(
        &paths[1],
        3_000,
        &[
            "fraction of runs that settled",
            "settled fraction  (–)",
            "Wilson 95 %",
        ],
    );
    check_svg(
        &paths[2],
        10_000,
        &[
            "settling time vs unbalance",
            "unbalance U / capacity S  (–)",
            "settling time t_s  (revolutions)",
            "not settled",
        ],
    );
    for path in plot_study(&data, &dir.path, Format::Png, &StudyFigure::ALL).unwrap() {
        check_png(&path, 10_000, (900, 480));
    }
}

#[test]
fn study_figures_reject_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let empty = StudyData {
        name: "empty".into(),
        runs: Vec::new(),
        designs: Vec::new(),
        operating_speed: None,
        sensitivity: Vec::new(),
    };
    let out = dir.path().join("x.svg");
    assert!(matches!(
        plot_settling_times(&empty, &out),
        Err(PlotError::NoData(_))
    ));
    assert!(matches!(
        plot_settled_fraction(&empty, &out),
        Err(PlotError::NoData(_))
    ));
    assert!(matches!(
        plot_settling_vs_unbalance(&empty, &out),
        Err(PlotError::NoData(_))
    ));
    let missing = StudyData::read(dir.path()).unwrap_err();
    assert!(missing.to_string().contains("runs.parquet"), "{missing}");

    let study_dir = dir.path().join("s");
    std::fs::create_dir(&study_dir).unwrap();
    write_study(&study_dir);
    let mut data = StudyData::read(&study_dir).unwrap();
    data.designs[0].settled_hi = 1.5;
    assert!(matches!(
        plot_settled_fraction(&data, &out),
        Err(PlotError::Invalid { .. })
    ));
    let mut data = StudyData::read(&study_dir).unwrap();
    for r in &mut data.runs {
        r.metrics.settled = false;
    }
    assert!(matches!(
        plot_settling_times(&data, &out),
        Err(PlotError::NoData(_))
    ));
}

#[test]
fn kaplan_meier_curve_is_the_product_limit_estimate() {
    use autobal::plot::km::{settled_band, settled_steps};
    use autobal::stats::survival::{KaplanMeier, Observation};
    let o = |time, settled| Observation { time, settled };
    // Settled at 2, 4 and 4; still unsettled when last seen at 3 and at 10.
    let runs = [
        o(2.0, true),
        o(3.0, false),
        o(4.0, true),
        o(4.0, true),
        o(10.0, false),
    ];
    let km = KaplanMeier::fit(&runs).unwrap();
    // By hand: at 2 one of five settles, S = 4/5; at 4 two of the three
    // still at risk settle, S = 4/5 · 1/3; the curve is 1 − S.
    let f4 = 1.0 - 0.8 / 3.0;
    let want = [
        (0.0, 0.0),
        (2.0, 0.0),
        (2.0, 0.2),
        (4.0, 0.2),
        (4.0, f4),
        (10.0, f4),
    ];
    let same = |got: Vec<(f64, f64)>, want: &[(f64, f64)]| {
        let close = |a: f64, b: f64| (a - b).abs() < 1e-12;
        let ok = got.len() == want.len()
            && got
                .iter()
                .zip(want)
                .all(|(g, w)| close(g.0, w.0) && close(g.1, w.1));
        assert!(ok, "got {got:?}, want {want:?}");
    };
    same(settled_steps(&km, 10.0), &want);
    // Cut at 3, before the second settling: the curve stops there.
    same(
        settled_steps(&km, 3.0),
        &want[..3]
            .iter()
            .copied()
            .chain([(3.0, 0.2)])
            .collect::<Vec<_>>(),
    );
    // The 95 % band, by hand: Greenwood V = Σ d/(n(n−d)) = 1/20 at 2 and
    // 1/20 + 2/3 at 4; S's log-log limits exp(−exp(ln(−ln S) ± z·√V/|ln S|))
    // with z = 1.959964, then 1 − each (Python's math module, 17 digits).
    let band = settled_band(&km, 10.0);
    let want = [
        (2.0, 4.0, 0.030_820_211_133_257_28, 0.796_190_736_732_361),
        (4.0, 10.0, 0.313_863_720_842_987_97, 0.990_322_999_421_118_7),
    ];
    assert_eq!(band.len(), 2, "{band:?}");
    for ((from, to, iv), w) in band.iter().zip(want) {
        assert_eq!((*from, *to), (w.0, w.1));
        assert!(
            (iv.lower - w.2).abs() < 1e-12 && (iv.upper - w.3).abs() < 1e-12,
            "{band:?}"
        );
    }
}

#[test]
fn compare_plot_writes_kaplan_meier_figure() {
    let dir = tempfile::tempdir().unwrap();
    let study_dir = dir.path().join("s");
    std::fs::create_dir(&study_dir).unwrap();
    write_study(&study_dir);
    let compare = |plot: &Path| {
        Command::new(env!("CARGO_BIN_EXE_study"))
            .arg("compare")
            .arg(&study_dir)
            .args(["--designs", "0,3", "--plot"])
            .arg(plot)
            .output()
            .unwrap()
    };
    let figures = out_dir("compare");
    // Design 3 has runs that never settled (every ninth sample).
    let svg = figures.path.join("km.svg");
    let out = compare(&svg);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{stdout}{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        stdout.contains("verdict:") && stdout.contains("wrote"),
        "{stdout}"
    );
    let text = check_svg(
        &svg,
        5_000,
        &[
            // The title names the study folder, the legend gives β its unit.
            "s: fraction of runs settled by t",
            "settling time t  (revolutions, log scale)",
            // The study turns at a constant 300 rad/s: a top axis in seconds.
            "settling time t  (s at the constant speed, log scale)",
            "settled by t, 1 − S(t)",
            "A: ball n=3",
            " N·s/m",
            "(40 runs, 0 not settled)",
            "(40 runs, 5 not settled)",
            "horizon t_end − W",
            "95 % pointwise band",
        ],
    );
    assert!(text.trim_end().ends_with("</svg>"));
    let png = figures.path.join("km.png");
    assert_eq!(compare(&png).status.code(), Some(0));
    check_png(&png, 10_000, (1000, 600));

    // A bad extension, a missing folder, or a path that cannot be written:
    // exit 2 naming --plot; a bad path is refused before any work.
    let blocked = dir.path().join("taken.svg");
    std::fs::create_dir(&blocked).unwrap();
    for bad in [
        dir.path().join("km.jpg"),
        dir.path().join("no/such/km.svg"),
        blocked,
    ] {
        let out = compare(&bad);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{}: {err}", bad.display());
        assert!(err.contains("--plot"), "{}: {err}", bad.display());
    }
    assert!(
        compare(&dir.path().join("km.jpg")).stdout.is_empty(),
        "refused before comparing"
    );
    // The write that failed left no temporary file beside the folder.
    let mut left: Vec<_> = std::fs::read_dir(dir.path())
        .unwrap()
        .map(|e| e.unwrap().file_name())
        .collect();
    left.sort();
    assert_eq!(left, ["s", "taken.svg"]);
    let png = dir.path().join("taken.png");
    std::fs::create_dir(&png).unwrap();
    assert_eq!(compare(&png).status.code(), Some(2));
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 3);
}

fn tradeoff_points() -> Vec<TradeoffPoint> {
    let mut points = Vec::new();
    for (f, (fidelity, scale)) in [("dp5", 1.0), ("dop853", 0.5), ("radau5", 3.0)]
        .into_iter()
        .enumerate()
    {
        for k in 3..=9 {
            let rtol = 10f64.powi(-k);
            let error = if k == 9 && f == 1 {
                0.0
            } else {
                scale * 50.0 * rtol.powf(0.6)
            };
            points.push(TradeoffPoint {
                fidelity: fidelity.into(),
                rtol,
                // One row per setting: its median and its largest are its one error.
                median_error_revs: error,
                max_error_revs: error,
                rhs_calls: (2000.0 * (f + 1) as f64) * 10f64.powf(0.2 * k as f64),
                wall_time_s: 1e-3 * (f + 1) as f64 * 10f64.powf(0.2 * k as f64),
            });
        }
    }
    points
}

fn write_tradeoff(path: &Path, points: &[TradeoffPoint]) {
    let mut df = df!(
        "fidelity" => points.iter().map(|p| p.fidelity.clone()).collect::<Vec<_>>(),
        "rtol" => points.iter().map(|p| p.rtol).collect::<Vec<_>>(),
        "settling_error_revs" => points.iter().map(|p| p.max_error_revs).collect::<Vec<_>>(),
        "rhs_calls" => points.iter().map(|p| p.rhs_calls as u64).collect::<Vec<_>>(),
        "wall_time_s" => points.iter().map(|p| p.wall_time_s).collect::<Vec<_>>(),
        "extra" => points.iter().map(|_| 1i32).collect::<Vec<_>>(),
    )
    .unwrap();
    write_parquet(
        path,
        &mut df,
        &Provenance::new("tradeoff fixture", 0, "all"),
    )
    .unwrap();
}

#[test]
fn tradeoff_table_round_trips_and_plots() {
    let dir = out_dir("tradeoff");
    let table = dir.path.join("tradeoff.parquet");
    let mut points = tradeoff_points();
    write_tradeoff(&table, &points);
    let read = read_tradeoff(&table).unwrap();
    for p in &mut points {
        p.rhs_calls = p.rhs_calls.trunc();
    }
    assert_eq!(read, points);

    let svg = dir.path.join("wp.svg");
    plot_work_precision(&read, "Work–precision test", &svg).unwrap();
    check_svg(
        &svg,
        10_000,
        &[
            "Work–precision test",
            "RHS calls  (count, log scale)",
            "wall time  (s, log scale)",
            "|Δt_s| over the measured runs  (rev, log scale)",
            "marker: median |Δt_s| over the measured runs",
            "not shown: the analytic and linear rungs",
            "dop853",
            "radau5",
        ],
    );
    let png = dir.path.join("wp.png");
    plot_work_precision(&read, "Work–precision test", &png).unwrap();
    check_png(&png, 20_000, (1200, 600));
}

#[test]
fn tradeoff_points_are_the_median_with_the_largest_of_their_runs() {
    // A per-run table, as `study tradeoff` writes it: three runs at one
    // setting, four at another; the figure shows the upper median (as the
    // trade-off table does) with a whisker up to the largest, at the mean cost.
    let dir = tempfile::tempdir().unwrap();
    let table = dir.path().join("runs.parquet");
    let rows = [
        ("dp5", 1e-6, 0.2, 100u64),
        ("dp5", 1e-6, 5.0, 300),
        ("dp5", 1e-6, 0.1, 200),
        ("dp5", 1e-8, 0.01, 400),
        ("dp5", 1e-8, 0.04, 400),
        ("dp5", 1e-8, 0.03, 400),
        ("dp5", 1e-8, 0.02, 400),
    ];
    let mut df = df!(
        "fidelity" => rows.iter().map(|r| r.0).collect::<Vec<_>>(),
        "rtol" => rows.iter().map(|r| r.1).collect::<Vec<_>>(),
        "settling_error_revs" => rows.iter().map(|r| r.2).collect::<Vec<_>>(),
        "rhs_calls" => rows.iter().map(|r| r.3).collect::<Vec<_>>(),
        "wall_time_s" => rows.iter().map(|r| r.3 as f64 * 1e-5).collect::<Vec<_>>(),
    )
    .unwrap();
    write_parquet(&table, &mut df, &Provenance::new("per run", 0, "all")).unwrap();
    let points = read_tradeoff(&table).unwrap();
    assert_eq!(points.len(), 2);
    let loose = &points[0];
    assert_eq!((loose.median_error_revs, loose.max_error_revs), (0.2, 5.0));
    assert!((loose.rhs_calls - 200.0).abs() < 1e-12);
    let tight = &points[1];
    assert_eq!(
        (tight.median_error_revs, tight.max_error_revs),
        (0.03, 0.04)
    );
    // A median above the largest is a broken table, not a figure.
    let mut broken = points.clone();
    broken[0].median_error_revs = 6.0;
    assert!(matches!(
        plot_work_precision(&broken, "t", &dir.path().join("wp.svg")),
        Err(PlotError::Invalid { .. })
    ));
}

#[test]
fn tradeoff_rejects_bad_tables() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("wp.svg");
    assert!(matches!(
        plot_work_precision(&[], "t", &out),
        Err(PlotError::NoData(_))
    ));
    let mut points = tradeoff_points();
    points[2].wall_time_s = f64::NAN;
    assert!(matches!(
        plot_work_precision(&points, "t", &out),
        Err(PlotError::Invalid { .. })
    ));

    let table = dir.path().join("bad.parquet");
    let mut df = df!("fidelity" => ["dp5"], "rtol" => [1e-6]).unwrap();
    write_parquet(&table, &mut df, &Provenance::new("bad", 0, "all")).unwrap();
    let e = read_tradeoff(&table).unwrap_err().to_string();
    assert!(e.contains("settling_error_revs"), "{e}");
    assert!(read_tradeoff(&dir.path().join("none.parquet")).is_err());
}

#[test]
fn output_path_is_checked() {
    let dir = tempfile::tempdir().unwrap();
    assert!(matches!(
        plot_design(&[Shape::Ball], &[3], &dir.path().join("d.jpg")),
        Err(PlotError::Format(_))
    ));
    assert!(matches!(
        plot_design(&[Shape::Ball], &[3], &dir.path().join("no/such/d.svg")),
        Err(PlotError::NoFolder(_))
    ));
    assert!(matches!(
        plot_design(&[Shape::Ball], &[], &dir.path().join("d.svg")),
        Err(PlotError::NoData(_))
    ));
    assert!(matches!(
        plot_design(&[Shape::Ball], &[0], &dir.path().join("d.svg")),
        Err(PlotError::Design(_))
    ));
    // Nothing half-written is left behind.
    assert_eq!(std::fs::read_dir(dir.path()).unwrap().count(), 0);
}

fn study(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_study"))
        .arg("plot")
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn cli_writes_figures_and_rejects_bad_input() {
    let dir = tempfile::tempdir().unwrap();
    let out = dir.path().join("design.svg");
    let ok = study(&[
        "design",
        "--kind",
        "ball",
        "--n",
        "2..5",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    assert!(String::from_utf8_lossy(&ok.stdout).contains("wrote"));
    assert!(file_size(&out) > 10_000);

    let study_dir = dir.path().join("s");
    std::fs::create_dir(&study_dir).unwrap();
    write_study(&study_dir);
    let figures = dir.path().join("figures");
    let ok = study(&[
        "study",
        study_dir.to_str().unwrap(),
        "--out",
        figures.to_str().unwrap(),
        "--format",
        "png",
    ]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    for figure in StudyFigure::ALL {
        check_png(
            &figures.join(format!("{}.png", figure.file_stem())),
            10_000,
            (900, 480),
        );
    }
    let only = dir.path().join("only");
    let ok = study(&[
        "study",
        study_dir.to_str().unwrap(),
        "--out",
        only.to_str().unwrap(),
        "--only",
        "settling-time",
    ]);
    assert!(
        ok.status.success(),
        "{}",
        String::from_utf8_lossy(&ok.stderr)
    );
    let written: Vec<_> = std::fs::read_dir(&only).unwrap().collect();
    assert_eq!(written.len(), 1);
    assert!(only.join("settling_time.svg").is_file());

    let bad = |args: &[&str], needle: &str| {
        let out = study(args);
        assert_eq!(out.status.code(), Some(2), "{args:?}");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(needle), "{args:?}: {err}");
    };
    let jpg = dir.path().join("d.jpg");
    bad(&["design", "--out", jpg.to_str().unwrap()], ".svg or .png");
    bad(
        &["design", "--n", "0", "--out", out.to_str().unwrap()],
        "n = 0",
    );
    bad(
        &[
            "design",
            "--out",
            dir.path().join("no/d.svg").to_str().unwrap(),
        ],
        "does not exist",
    );
    bad(
        &[
            "study",
            dir.path().join("missing").to_str().unwrap(),
            "--out",
            "x",
        ],
        "not a folder",
    );
    bad(
        &[
            "tradeoff",
            dir.path().join("t.parquet").to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        "not found",
    );
    let scene = dir.path().join("bad.toml");
    std::fs::write(&scene, "[rotor]\nmass = -1\n").unwrap();
    bad(
        &[
            "run",
            scene.to_str().unwrap(),
            "--out",
            out.to_str().unwrap(),
        ],
        "bad.toml",
    );
}

#[test]
fn stability_map_is_drawn_from_the_map_table() {
    use autobal::plot::map::{plot_stability_map, read_map};
    use autobal::study::stability_map::{MapPoint, to_dataframe};
    let tmp = tempfile::tempdir().unwrap();
    let mut points = Vec::new();
    for j in 0..4 {
        for i in 0..5 {
            let omega = 0.5 + f64::from(i);
            points.push(MapPoint {
                omega,
                unbalance: 0.005 * f64::from(j + 1),
                balanced: j < 3,
                stable: Some(omega > 1.0),
                slowest_decay: Some(0.1),
            });
        }
    }
    let table = tmp.path().join("map.parquet");
    let mut df = to_dataframe(&points).unwrap();
    autobal::study::results::io::write_parquet(
        &table,
        &mut df,
        &autobal::study::results::io::Provenance::new("", 0, "test"),
    )
    .unwrap();
    let back = read_map(&table).unwrap();
    assert_eq!(back.len(), 20);
    let png = tmp.path().join("map.png");
    plot_stability_map(&back, "map test", &png).unwrap();
    let bytes = std::fs::read(&png).unwrap();
    assert_eq!(&bytes[1..4], b"PNG");
    let (w, h) = (
        u32::from_be_bytes(bytes[16..20].try_into().unwrap()),
        u32::from_be_bytes(bytes[20..24].try_into().unwrap()),
    );
    assert_eq!((w, h), (1000, 760));
    let svg = tmp.path().join("map.svg");
    plot_stability_map(&back, "map test", &svg).unwrap();
    let text = std::fs::read_to_string(&svg).unwrap();
    assert!(
        text.contains("map test") && text.contains("speed ω") && text.contains("rotor unbalance U")
    );
    assert!(plot_stability_map(&[], "empty", &svg).is_err());
}

#[test]
fn passage_figure_needs_a_stall_torque_sweep_and_draws_held_runs_as_crosses() {
    let plan = study_plan();
    let mut runs = study_runs(&plan, 10);
    let without = StudyData {
        name: "no_sweep".into(),
        runs: runs.clone(),
        designs: vec![],
        operating_speed: None,
        sensitivity: Vec::new(),
    };
    let dir = out_dir("passage");
    let path = dir.path.join("passage.svg");
    assert!(StudyFigure::Passage.plot(&without, &path).is_err());
    for (i, r) in runs.iter_mut().enumerate() {
        r.stall_torque = Some(2.0 + (i % 3) as f64 * 4.0);
        let held = i % 3 == 0;
        r.metrics.final_spin_rate = Some(if held { 150.0 } else { 299.0 });
        r.metrics.operating_time = (!held).then_some(3.0);
    }
    let summary = summarize(&plan, &runs).unwrap();
    let data = StudyData {
        name: "sweep".into(),
        runs,
        designs: autobal::plot::study::design_stats(&summary).unwrap(),
        operating_speed: Some(300.0),
        sensitivity: Vec::new(),
    };
    StudyFigure::Passage.plot(&data, &path).unwrap();
    check_svg(
        &path,
        3_000,
        &[
            "spin rate at the end of the run-up vs motor stall torque",
            "motor stall torque M_s  (N·m)",
            "held below the operating speed",
            "operating speed ω_op = 300 rad/s",
        ],
    );
}
