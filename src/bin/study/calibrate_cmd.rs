//! `study calibrate`: fit a rig's unknowns to its measured points, give
//! their intervals and predict the held-out points; or, with
//! `--synthetic`, check on data the model generates at a known truth that
//! the points can pin the unknowns at all.

use crate::UserError;
use crate::output::{say, text_table};
use autobal::calibrate::calibration::{Calibration, Coverage, Settings};
use autobal::calibrate::problem::RigProblem;
use autobal::calibrate::rig_file::{RigFile, RigFileError, Use};
use autobal::calibrate::tables::{coverage_frame, draws_frame, estimates_frame, points_frame};
use autobal::output_file::{WhenExists, prepare, prepare_folder};
use autobal::scene_file::SceneFile;
use autobal::study::results::io::{Provenance, write_parquet};
use clap::Args;
use polars::prelude::DataFrame;
use std::path::{Path, PathBuf};

/// Examples shown under `study calibrate --help`.
pub const EXAMPLES: &str = "Examples:
  study calibrate rigs/synthetic_three_balls.toml
  study calibrate rigs/bristol_fig12.toml --threads 2 --out results/calibrate/bristol
  study calibrate rigs/synthetic_three_balls.toml --synthetic balancer.drag=0.01,effects.rolling_resistance.coefficient=2e-3 --repeats 20";

/// Arguments of `study calibrate`.
#[derive(Args)]
pub struct CalibrateArgs {
    /// Rig file (TOML): the scene, its unknowns, the cases, the protocol and the measured points.
    rig: PathBuf,
    /// Draws from the unknowns' priors (the posterior's first stage and the restarts' starts).
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(2..=100_000))]
    draws: u32,
    /// Draws from the proposal around the fit (default: as many as --draws).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=100_000))]
    proposal_draws: Option<u32>,
    /// Nelder–Mead restarts, each from one of the best prior draws.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=64))]
    restarts: u32,
    /// Most model evaluations per restart.
    #[arg(long, default_value_t = 60, value_parser = clap::value_parser!(u64).range(4..=100_000))]
    budget: u64,
    /// Seed of the draws (default: the rig file's).
    #[arg(long)]
    seed: Option<u64>,
    /// Worker threads (default: all cores, or RAYON_NUM_THREADS); the results do not depend on it.
    #[arg(long, value_parser = crate::limits::threads)]
    threads: Option<usize>,
    /// Write calibration.parquet, points.parquet and draws.parquet (and
    /// coverage.parquet with --repeats) into this folder.
    #[arg(long)]
    out: Option<PathBuf>,
    /// Replace files of the same names in --out.
    #[arg(long)]
    overwrite: bool,
    /// Replace the measured values by the model's at these values of the
    /// unknowns plus noise of each point's sd: `key=value,…`, every unknown.
    #[arg(long)]
    synthetic: Option<String>,
    /// With --synthetic: calibrate this many times on fresh noise and
    /// report how often each interval covered the truth.
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u64).range(1..=1000))]
    repeats: u64,
}

/// The files --out writes.
const FILES: [&str; 4] = [
    "calibration.parquet",
    "points.parquet",
    "draws.parquet",
    "coverage.parquet",
];

/// Run `study calibrate`.
pub fn run(args: &CalibrateArgs) -> Result<(), UserError> {
    let shown = args.rig.display().to_string();
    let rig = RigFile::read(&args.rig).map_err(|e| match e {
        RigFileError::Io { .. } | RigFileError::Parse { .. } => UserError(e.to_string(), 2),
        RigFileError::Invalid { path, key } => UserError(format!("{path}: {key}"), 2),
    })?;
    let scene_path = rig.scene_path(&args.rig);
    let scene = SceneFile::read(&scene_path)?;
    let seed = args.seed.unwrap_or(rig.seed);
    let problem = RigProblem::new(rig, scene, &scene_path.display().to_string())
        .map_err(|key| UserError(format!("{shown}: {key}"), 2))?;
    let truth = args
        .synthetic
        .as_deref()
        .map(|text| parse_truth(&problem, text))
        .transpose()?;
    if args.repeats > 1 && truth.is_none() {
        return Err(UserError(
            format!(
                "--repeats {}: repeats calibrations on synthetic data; give --synthetic",
                args.repeats
            ),
            2,
        ));
    }
    if let Some(dir) = &args.out {
        prepare_folder("--out", dir)?;
        // A folder made later, when the results are in: a refusal or a
        // failure leaves nothing behind.
        if dir.is_dir() {
            for name in FILES {
                prepare(
                    "--out",
                    &dir.join(name),
                    WhenExists::from_overwrite(args.overwrite),
                )?;
            }
        }
    }
    let settings = Settings {
        prior_draws: args.draws as usize,
        proposal_draws: args.proposal_draws.unwrap_or(args.draws) as usize,
        restarts: args.restarts as usize,
        budget: args.budget,
        seed,
    };
    let pool = rayon::ThreadPoolBuilder::new()
        .num_threads(crate::limits::capped_threads(args.threads).unwrap_or(0))
        .build()
        .map_err(|e| UserError::internal(e.to_string()))?;
    say(&header(&problem, &settings));
    let measured = match &truth {
        Some(t) => pool
            .install(|| problem.synthetic(t, 0, seed))
            .map_err(|why| UserError(format!("--synthetic: {why}"), 2))?,
        None => problem.measured(),
    };
    let calibration = pool.install(|| problem.calibrate(&measured, &settings));
    let coverage = match (&truth, args.repeats) {
        (Some(t), r) if r > 1 => Some(
            pool.install(|| problem.coverage(t, r, &settings))
                .map_err(|why| UserError(format!("--synthetic: {why}"), 2))?,
        ),
        _ => None,
    };
    if let Some(dir) = &args.out {
        write_all(
            dir,
            &args.rig,
            seed,
            &problem,
            &calibration,
            coverage.as_ref(),
        )?;
    }
    print!("{}", describe(&problem, &calibration, truth.as_deref()));
    if let Some(c) = &coverage {
        print!("{}", describe_coverage(&problem, c));
    }
    Ok(())
}

/// `key=value,…` naming every unknown once.
fn parse_truth(problem: &RigProblem, text: &str) -> Result<Vec<f64>, UserError> {
    let keys = problem.keys();
    let mut truth = vec![None; keys.len()];
    for part in text.split(',').map(str::trim).filter(|p| !p.is_empty()) {
        let bad = |why: String| UserError(format!("--synthetic {part}: {why}"), 2);
        let (key, value) = part
            .split_once('=')
            .ok_or_else(|| bad("give key=value".into()))?;
        let j = keys.iter().position(|k| *k == key.trim()).ok_or_else(|| {
            bad(format!(
                "not an unknown of the rig (they are: {})",
                keys.join(", ")
            ))
        })?;
        let v: f64 = value
            .trim()
            .parse()
            .map_err(|_| bad("the value is not a number".into()))?;
        let (lo, hi) = problem.priors()[j].support();
        if !(lo..=hi).contains(&v) {
            return Err(bad(format!("outside the prior's range {lo}..{hi}")));
        }
        truth[j] = Some(v);
    }
    truth
        .iter()
        .zip(&keys)
        .map(|(t, k)| t.ok_or_else(|| UserError(format!("--synthetic: give a value for {k}"), 2)))
        .collect()
}

fn header(problem: &RigProblem, s: &Settings) -> String {
    let pts = &problem.rig.points;
    let fitted = pts.iter().filter(|p| p.role == Use::Fit).count();
    format!(
        "Rig {}: {} unknowns, {} points ({fitted} fitted, {} held out) over {} cases. Cost: {} prior + {} proposal draws and {} restarts of at most {} evaluations, each one run or sweep per case.\n",
        problem.rig.name,
        problem.keys().len(),
        pts.len(),
        pts.len() - fitted,
        problem.rig.cases.len(),
        s.prior_draws,
        s.proposal_draws,
        s.restarts,
        s.budget
    )
}

fn write_all(
    dir: &Path,
    rig_path: &Path,
    seed: u64,
    problem: &RigProblem,
    c: &Calibration,
    coverage: Option<&Coverage>,
) -> Result<(), UserError> {
    let text = autobal::input_file::read_text(rig_path)?;
    std::fs::create_dir_all(dir)
        .map_err(|e| UserError::internal(format!("--out {}: {e}", dir.display())))?;
    let provenance = Provenance::new(&text, seed, "calibration");
    let internal = |e: polars::prelude::PolarsError| UserError::internal(e.to_string());
    let mut frames: Vec<(&str, DataFrame)> = vec![
        (FILES[0], estimates_frame(c).map_err(internal)?),
        (FILES[1], points_frame(problem, c).map_err(internal)?),
        (FILES[2], draws_frame(problem, c).map_err(internal)?),
    ];
    if let Some(cov) = coverage {
        frames.push((FILES[3], coverage_frame(problem, cov).map_err(internal)?));
    }
    for (name, df) in &mut frames {
        let path = dir.join(*name);
        write_parquet(&path, df, &provenance)
            .map_err(|e| UserError::internal(format!("--out {}: {e}", path.display())))?;
    }
    Ok(())
}

/// A number with four significant digits.
fn g(x: f64) -> String {
    autobal::number_text::significant(x, 4)
}

fn describe(problem: &RigProblem, c: &Calibration, truth: Option<&[f64]>) -> String {
    let mut header = vec!["unknown", "prior", "fit", "2.5 %", "median", "97.5 %"];
    if truth.is_some() {
        header.push("truth");
    }
    let rows: Vec<Vec<String>> = c
        .estimates
        .iter()
        .enumerate()
        .map(|(j, e)| {
            let mut row = vec![
                e.key.clone(),
                format!("{}..{}", g(e.prior.0), g(e.prior.1)),
                g(e.fit),
                g(e.interval[0]),
                g(e.interval[1]),
                g(e.interval[2]),
            ];
            if let Some(t) = truth {
                row.push(g(t[j]));
            }
            row
        })
        .collect();
    let mut s = format!("\n{}", text_table(&header, &rows));
    let losses: Vec<String> = c.restarts.iter().map(|r| g(r.loss)).collect();
    s += &format!(
        "Fit: robust loss {} over the fitted points (restarts ended at {}); posterior on {} draws, effective size {:.0}.{}\n",
        g(c.loss),
        losses.join(", "),
        c.draws.len(),
        c.effective_size,
        if c.effective_size < 20.0 {
            " Fewer than 20 effective draws: the intervals are rough; give more --draws."
        } else {
            ""
        }
    );
    let rows: Vec<Vec<String>> = problem
        .rig
        .points
        .iter()
        .zip(&c.points)
        .enumerate()
        .map(|(i, (p, o))| {
            let band = o
                .band
                .map_or("–".into(), |b| format!("{}..{}", g(b[0]), g(b[2])));
            let pred = o
                .predictive
                .map_or("–".into(), |b| format!("{}..{}", g(b[0]), g(b[1])));
            vec![
                i.to_string(),
                p.case.clone(),
                match p.rpm {
                    Some([lo, hi]) => format!("{} {lo}–{hi} rpm", p.quantity.name()),
                    None => p.quantity.name().to_string(),
                },
                p.role.name().into(),
                format!("{} ± {}", g(o.measured), g(p.sd)),
                o.at_fit
                    .as_ref()
                    .map_or_else(|e| format!("failed: {e}"), |x| g(*x)),
                o.z.map_or("–".into(), |z| format!("{z:+.2}")),
                band,
                pred,
                match o.inside() {
                    Some(true) => "yes".into(),
                    Some(false) => "NO".into(),
                    None => "–".into(),
                },
            ]
        })
        .collect();
    s += "\n";
    s += &text_table(
        &[
            "#",
            "case",
            "quantity",
            "use",
            "measured",
            "at fit",
            "z",
            "model 95 %",
            "predictive 95 %",
            "inside",
        ],
        &rows,
    );
    let held: Vec<&autobal::calibrate::calibration::PointOutcome> = problem
        .rig
        .points
        .iter()
        .zip(&c.points)
        .filter(|(p, _)| p.role == Use::Predict)
        .map(|(_, o)| o)
        .collect();
    if !held.is_empty() {
        let inside = held.iter().filter(|o| o.inside() == Some(true)).count();
        s += &format!(
            "Held out: {inside} of {} measured points lie in their predictive 95 % band.\n",
            held.len()
        );
    }
    s += "z: (model at the fit − measured)/sd. Model 95 %: the posterior's spread of the model; predictive 95 %: the same widened by the measurement's sd, where a new reading should fall.\n";
    s
}

fn describe_coverage(problem: &RigProblem, c: &Coverage) -> String {
    let rows: Vec<Vec<String>> = problem
        .keys()
        .iter()
        .enumerate()
        .map(|(j, key)| {
            let hits = c.covered.iter().filter(|v| v[j]).count();
            vec![
                key.to_string(),
                g(c.truth[j]),
                format!("{hits} of {}", c.covered.len()),
                format!("{:.0} %", 100.0 * c.share(j)),
            ]
        })
        .collect();
    let min_ess = c
        .effective_sizes
        .iter()
        .copied()
        .fold(f64::INFINITY, f64::min);
    format!(
        "\nSynthetic check, {} repetitions on fresh noise:\n{}Smallest effective size {min_ess:.0}. A 95 % interval should cover the truth in about 95 % of repetitions; far fewer means the points cannot pin that unknown or the draws are too few.\n",
        c.covered.len(),
        text_table(&["unknown", "truth", "covered", "share"], &rows)
    )
}
