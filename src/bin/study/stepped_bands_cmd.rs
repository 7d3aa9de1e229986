//! `study stepped --draws N`: the stepped sweep over draws of the scene's
//! uncertain keys, printed as bands (median, 5–95 %) per speed with the
//! onset speed's distribution.

use crate::UserError;
use crate::output::{say, say_err, text_table};
use autobal::scene_file::SceneFile;
use autobal::simulation::Simulation;
use autobal::simulation::stepped::Direction;
use autobal::study::results::io::{Provenance, write_parquet};
use autobal::study::stepped_bands::{
    BandRow, Quantity, bands, bands_frame, draws_frame, onset_spread, onsets, sweep_draws,
};
use std::f64::consts::PI;
use std::path::Path;

/// Where the bands and the draws go.
pub struct Outputs<'a> {
    /// The bands table (`--out`).
    pub bands: Option<&'a Path>,
    /// Each draw's values and onset (`--draws-out`).
    pub draws: Option<&'a Path>,
    /// The scene file (for the files' provenance).
    pub scene: &'a Path,
    /// Print every draw (its key values, onset and steps) as JSON instead of the table.
    pub json: bool,
}

/// One draw as `--json` prints it.
#[derive(serde::Serialize)]
struct DrawJson<'a> {
    draw: u32,
    values: std::collections::BTreeMap<&'a str, f64>,
    onset_rpm: Option<f64>,
    failure: Option<&'a str>,
    steps: &'a [autobal::simulation::stepped::StepPoint],
}

/// What a verb over the scene's uncertain draws says before it runs.
pub fn draws_header(file: &SceneFile, draws: u32, seed: u64) -> String {
    format!(
        "{draws} draws of {} uncertain key(s) ({}), seed {seed}",
        file.uncertain.len(),
        file.uncertain
            .keys()
            .cloned()
            .collect::<Vec<_>>()
            .join(", ")
    )
}

/// Sweep `draws` draws of the scene's uncertain keys and print the bands.
pub fn run(
    file: &SceneFile,
    simulation: &Simulation,
    sweep: (&[(Direction, f64)], f64, Option<f64>),
    (draws, seed): (u32, u64),
    outputs: Outputs<'_>,
) -> Result<(), UserError> {
    say_err(&format!(
        "{}: {draws} sweeps",
        draws_header(file, draws, seed)
    ));
    let sweeps = sweep_draws(simulation, &file.uncertain, sweep, draws, seed);
    let rows = bands(&sweeps);
    let text = autobal::input_file::read_text(outputs.scene)?;
    let provenance = Provenance::new(&text, seed, "stepped sweep over uncertain draws");
    let internal = |e: polars::prelude::PolarsError| UserError::internal(e.to_string());
    if let Some(path) = outputs.bands {
        write_parquet(
            path,
            &mut bands_frame(&rows).map_err(internal)?,
            &provenance,
        )
        .map_err(|e| UserError::internal(format!("--out {e}")))?;
    }
    if let Some(path) = outputs.draws {
        write_parquet(
            path,
            &mut draws_frame(&sweeps).map_err(internal)?,
            &provenance,
        )
        .map_err(|e| UserError::internal(format!("--draws-out {e}")))?;
    }
    if outputs.json {
        let all: Vec<DrawJson> = sweeps
            .iter()
            .map(|s| DrawJson {
                draw: s.draw,
                values: s.values.iter().map(|v| (&*v.key, v.value)).collect(),
                onset_rpm: autobal::study::stepped_bands::onset(&s.points).map(|w| w * 30.0 / PI),
                failure: s.failure.as_deref(),
                steps: &s.points,
            })
            .collect();
        println!("{}", serde_json::to_string_pretty(&all)?);
        return Ok(());
    }
    print!("{}", table(&rows));
    let (found, none) = onsets(&sweeps);
    let rpm = 30.0 / PI;
    match onset_spread(&found) {
        Some([lo, mid, hi]) => say(&format!(
            "onset of balancing on the run-up (the lowest speed from which the balls lower the bearings' mean peak at every higher step): median {:.0} rpm, 5–95 % {:.0}–{:.0} rpm over {} draws; {none} draw(s) never balance for good",
            mid * rpm,
            lo * rpm,
            hi * rpm,
            found.len()
        )),
        None => say(&format!(
            "onset of balancing: none of the {none} draws balances for good on the run-up"
        )),
    }
    let failed: Vec<String> = sweeps
        .iter()
        .filter_map(|s| Some(format!("draw {}: {}", s.draw, s.failure.as_ref()?)))
        .collect();
    if !failed.is_empty() {
        say(&format!(
            "{} draw(s) stopped early, their later steps left out of the bands: {}",
            failed.len(),
            failed.join("; ")
        ));
    }
    Ok(())
}

/// The bearings' mean peak and ratio per step: median [5 %, 95 %].
fn table(rows: &[BandRow]) -> String {
    let mean: Vec<&BandRow> = rows.iter().filter(|r| r.bearing.is_none()).collect();
    let cell = |r: &BandRow, scale: f64, digits: usize| {
        let [lo, mid, hi] = r.quantiles.map(|q| q * scale);
        format!("{mid:.digits$} [{lo:.digits$}, {hi:.digits$}]")
    };
    let lines: Vec<Vec<String>> = mean
        .chunks(2)
        .filter_map(|pair| {
            let peak = pair.iter().find(|r| r.quantity == Quantity::Peak)?;
            let ratio = pair.iter().find(|r| r.quantity == Quantity::Ratio)?;
            Some(vec![
                peak.direction.name().to_string(),
                format!("{:.0}", peak.omega * 30.0 / PI),
                cell(peak, 1e6, 2),
                cell(ratio, 1.0, 3),
                peak.draws.to_string(),
            ])
        })
        .collect();
    let mut s = text_table(
        &[
            "run",
            "speed\nrpm",
            "mean bearing peak µm\nmedian [5 %, 95 %]",
            "over without\nmedian [5 %, 95 %]",
            "draws",
        ],
        &lines,
    );
    s += "\nEach row: the last revolution of the dwell at that speed over the draws of the uncertain keys, the state carried from the step before; mean bearing peak: the supports' peaks averaged; over without: that mean over the same without the balancer's unbalance (below 1: the balls help). --out writes every bearing's bands.\n";
    s
}
