//! `study criterion`: seed 003's closed-form criterion for a scene's rotor on
//! two supports: resonances, extra speeds and balancing speed ranges.

use crate::UserError;
use autobal::design::criterion::{
    RotorShape, SpeedRanges, dynamic_ranges, extra_speed, partial_frequencies, resonances,
    static_ranges, z_max,
};
use autobal::scene_file::SceneFile;
use clap::Args;
use serde::Serialize;
use std::path::PathBuf;

/// Examples shown under `study criterion --help`.
pub const EXAMPLES: &str = "Examples:
  study criterion scenes/two_support_long.toml
  study criterion scenes/two_support_single.toml --json";

/// Arguments of `study criterion`.
#[derive(Args)]
pub struct CriterionArgs {
    /// Scene file (TOML) with `[rotor] model = "two_support"`.
    scene: PathBuf,
    /// Print the result as one JSON object.
    #[arg(long)]
    json: bool,
}

/// One correction plane's static-balancing prediction.
#[derive(Serialize)]
struct PlaneReport {
    z: f64,
    extra_speed: f64,
    static_ranges: SpeedRanges,
}

/// The criterion for the whole rotor.
#[derive(Serialize)]
struct Report {
    shape: RotorShape,
    omega1: f64,
    omega2: Option<f64>,
    partial: (f64, Option<f64>),
    z_max: Option<f64>,
    planes: Vec<PlaneReport>,
    dynamic_ranges: SpeedRanges,
}

/// Run `study criterion`.
pub fn run(args: &CriterionArgs) -> Result<(), UserError> {
    let shown = args.scene.display().to_string();
    let file = SceneFile::read(&args.scene)?;
    let criterion = file
        .rotor
        .as_rotor()
        .closed_form_criterion()
        .map_err(|why| {
            UserError(
                format!("{shown}: rotor (model \"{}\"): {why}", file.rotor.name()),
                2,
            )
        })?;
    file.rotor.validate()?;
    let p = criterion.params;
    let res = resonances(&p)?;
    let planes = criterion
        .planes
        .iter()
        .map(|&z| {
            Ok(PlaneReport {
                z,
                extra_speed: extra_speed(&p, z)?,
                static_ranges: static_ranges(&p, z)?,
            })
        })
        .collect::<Result<Vec<_>, autobal::design::criterion::CriterionError>>()?;
    let report = Report {
        shape: res.shape,
        omega1: res.omega1,
        omega2: res.omega2,
        partial: partial_frequencies(&p)?,
        z_max: z_max(&p).ok(),
        planes,
        dynamic_ranges: dynamic_ranges(&p)?,
    };
    if args.json {
        println!("{}", serde_json::to_string_pretty(&report)?);
    } else {
        print!(
            "{}",
            crate::output::wrap(&describe(&report), crate::output::text_width())
        );
    }
    Ok(())
}

fn show(r: &SpeedRanges) -> String {
    if r.is_empty() {
        return "none".into();
    }
    r.0.iter()
        .map(|(a, b)| {
            if b.is_infinite() {
                format!("({a:.4}, ∞)")
            } else {
                format!("({a:.4}, {b:.4})")
            }
        })
        .collect::<Vec<_>>()
        .join(" ∪ ")
}

fn describe(r: &Report) -> String {
    let opt = |v: Option<f64>| v.map_or("–".into(), |x| format!("{x:.4}"));
    let mut s = format!(
        "rotor              {:?}\nresonance ω1       {:.4} rad/s\nresonance ω2       {} rad/s\npartial ω_p1, ω_p2 {:.4}, {} rad/s\nz_max (eq 36)      {}\n",
        r.shape,
        r.omega1,
        opt(r.omega2),
        r.partial.0,
        opt(r.partial.1),
        opt(r.z_max)
    );
    for p in &r.planes {
        s += &format!(
            "plane z = {:<8.4} ω̃ = {:.4}, static balancing for ω ∈ {}\n",
            p.z,
            p.extra_speed,
            show(&p.static_ranges)
        );
    }
    s += &format!(
        "dynamic balancing (two or more planes) for ω ∈ {}\n",
        show(&r.dynamic_ranges)
    );
    s
}
