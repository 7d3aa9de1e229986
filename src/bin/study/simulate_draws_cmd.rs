//! `study simulate --draws N`: one scene run once per draw of its
//! `[uncertain]` keys, printed as the spread of its settling and residual.

use crate::UserError;
use crate::output::{say, say_err};
use autobal::metrics::RunMetrics;
use autobal::scene_file::SceneFile;
use autobal::simulation::Simulation;
use autobal::stats::quantile::{Interpolation, quantile_sorted};
use autobal::study::stepped_bands::drawn_simulation;
use rayon::prelude::*;

/// One draw as `--json` prints it.
#[derive(serde::Serialize)]
struct DrawJson {
    draw: u32,
    values: std::collections::BTreeMap<String, f64>,
    metrics: Option<RunMetrics>,
    failure: Option<String>,
}

/// Run `draws` draws of the scene's uncertain keys and print their spread.
pub fn run(
    file: &SceneFile,
    simulation: &Simulation,
    (draws, seed): (u32, u64),
    json: bool,
) -> Result<(), UserError> {
    say_err(&crate::stepped_bands_cmd::draws_header(file, draws, seed));
    let runs: Vec<DrawJson> = (0..draws)
        .into_par_iter()
        .map(|i| {
            let (values, drawn) = drawn_simulation(simulation, &file.uncertain, seed, i);
            let (metrics, failure) = match drawn.map(|sim| sim.run(false)) {
                Ok(Ok(result)) => (Some(result.metrics), None),
                Ok(Err(e)) => (None, Some(e.to_string())),
                Err(why) => (None, Some(why)),
            };
            DrawJson {
                draw: i,
                values: values
                    .iter()
                    .map(|v| (v.key.to_string(), v.value))
                    .collect(),
                metrics,
                failure,
            }
        })
        .collect();
    if json {
        println!("{}", serde_json::to_string_pretty(&runs)?);
        return Ok(());
    }
    let done: Vec<&RunMetrics> = runs.iter().filter_map(|r| r.metrics.as_ref()).collect();
    let settled = done.iter().filter(|m| m.settled).count();
    let spread = |mut v: Vec<f64>| -> String {
        v.sort_by(f64::total_cmp);
        let at = |q| quantile_sorted(&v, q, Interpolation::Linear);
        match (at(0.05), at(0.5), at(0.95)) {
            (Some(lo), Some(mid), Some(hi)) => {
                format!("median {mid:.4} [5 %: {lo:.4}, 95 %: {hi:.4}]")
            }
            _ => "–".into(),
        }
    };
    let revs = spread(
        done.iter()
            .filter_map(|m| m.settling_revs.filter(|_| m.settled))
            .collect(),
    );
    let residual = spread(
        done.iter()
            .map(|m| m.residual_rel)
            .filter(|r| r.is_finite())
            .collect(),
    );
    say(&format!(
        "settled in {settled} of {} draws; settling time (rev, settled draws): {revs}; residual / A_ref: {residual}",
        runs.len()
    ));
    let failed = runs.iter().filter(|r| r.failure.is_some()).count();
    if failed > 0 {
        say(&format!(
            "{failed} draw(s) could not run (--json shows why)"
        ));
    }
    Ok(())
}
