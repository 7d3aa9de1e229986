//! A stability map: the linear stability of a scene's balanced state over a
//! grid of speeds and rotor unbalances (seed 002's map over (ω/ω0, ε/R)).

use crate::model::forced::supports_isotropic;
use crate::model::linear::analyse;
use crate::model::scene::{Scene, SceneError};
use crate::model::speed::SpeedLaw;
use polars::prelude::*;
use rayon::prelude::*;
use serde::Serialize;

/// One grid point of the map.
#[derive(Debug, Clone, PartialEq, Serialize)]
pub struct MapPoint {
    /// Speed ω (rad/s).
    pub omega: f64,
    /// Rotor unbalance U (kg·m), set with `RotorModel::set_unbalance`.
    pub unbalance: f64,
    /// A fully balanced state exists (the balancers can cancel U).
    pub balanced: bool,
    /// The steady state nearest to balance is linearly stable (None: not analysable).
    pub stable: Option<bool>,
    /// Slowest decay rate σ of its linearisation (1/s).
    pub slowest_decay: Option<f64>,
}

/// Linear stability over every (ω, U) of the grid, in row-major order
/// (unbalance outer, speed inner), computed in parallel.
pub fn stability_map(
    template: &Scene,
    omegas: &[f64],
    unbalances: &[f64],
) -> Result<Vec<MapPoint>, SceneError> {
    template.validate()?;
    refuse_time_dependent(template, omegas)?;
    let grid: Vec<(f64, f64)> = unbalances
        .iter()
        .flat_map(|&u| omegas.iter().map(move |&w| (w, u)))
        .collect();
    grid.par_iter()
        .with_max_len(1) // one analysis per job, as runs (study::run)
        .map(|&(omega, unbalance)| {
            let mut scene = template.clone();
            scene.speed = SpeedLaw::Constant { omega };
            scene.rotor.set_unbalance(unbalance, 0.0);
            let report = analyse(&scene.build()?, None).ok();
            Ok(MapPoint {
                omega,
                unbalance,
                balanced: report.as_ref().is_some_and(|r| r.balancing_error < 1e-6),
                stable: report.as_ref().map(|r| r.stable),
                slowest_decay: report.as_ref().map(|r| r.slowest_decay),
            })
        })
        .collect()
}

/// Refuse a scene whose rotating-frame equations depend on time (gravity,
/// anisotropic supports): it has no steady balanced state to linearise, and
/// every cell would read "beyond capacity" (as `study map` printed with exit
/// 0 before 2026-11-27, where `study linear` refused the same scene).
fn refuse_time_dependent(template: &Scene, omegas: &[f64]) -> Result<(), SceneError> {
    let refuse = |field: &str, value: &str, why: &str| SceneError::Invalid {
        field: field.to_string(),
        value: value.to_string(),
        reason: format!(
            "{why}, so the balanced state has no linear stability to map; `study sweep` simulates this scene"
        ),
    };
    if let Some(why) = template.effects.rotating_frame_obstacle() {
        return Err(refuse("effects", "enabled", why));
    }
    let mut probe = template.clone();
    let omega = omegas.first().copied().unwrap_or(1.0);
    probe.speed = SpeedLaw::Constant { omega };
    if !supports_isotropic(&probe.build()?, omega) {
        return Err(refuse(
            "rotor",
            probe.rotor.name(),
            "anisotropic supports make the equations in the rotating frame depend on time",
        ));
    }
    Ok(())
}

/// The map as a table, one row per grid point.
pub fn to_dataframe(points: &[MapPoint]) -> PolarsResult<DataFrame> {
    df!(
        "omega" => points.iter().map(|p| p.omega).collect::<Vec<f64>>(),
        "unbalance" => points.iter().map(|p| p.unbalance).collect::<Vec<f64>>(),
        "balanced" => points.iter().map(|p| p.balanced).collect::<Vec<bool>>(),
        "stable" => points.iter().map(|p| p.stable).collect::<Vec<Option<bool>>>(),
        "slowest_decay" => points.iter().map(|p| p.slowest_decay).collect::<Vec<Option<f64>>>(),
    )
}

/// A character picture of the map: rows from the largest unbalance down,
/// `#` balanced and stable, `.` balanced and unstable, ` ` not balanceable.
pub fn ascii(points: &[MapPoint], columns: usize) -> String {
    let mut rows: Vec<String> = points
        .chunks(columns.max(1))
        .map(|row| {
            row.iter()
                .map(|p| match (p.balanced, p.stable) {
                    (true, Some(true)) => '#',
                    (true, _) => '.',
                    _ => ' ',
                })
                .collect()
        })
        .collect();
    rows.reverse();
    rows.join("\n") + "\n"
}
