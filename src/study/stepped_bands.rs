//! A stepped sweep over draws of a scene's uncertain keys: per speed and
//! bearing the median and the 5–95 % band of the peak and of the ratio
//! with/without balls, and the distribution of the onset speed (where the
//! balls begin to help and keep helping on the way up).
//!
//! A rig's published curve is one realisation of physics that is partly
//! unknown (rolling resistance, the race's eccentricity and its direction):
//! the band is what the model predicts for it, the measurement is judged
//! against the band rather than one line.

use crate::simulation::Simulation;
use crate::simulation::stepped::{Direction, StepPoint, SteppedError};
use crate::stats::quantile::{Interpolation, quantile_sorted};
use crate::study::plan::stream::{Matrix, RunStreams, Sequence, key_hash};
use crate::uncertain::{UncertainSpec, UncertainValue, apply, draw};
use polars::prelude::*;
use rand::RngExt;
use rayon::prelude::*;

/// Lower and upper probability of the printed band.
pub const BAND: (f64, f64) = (0.05, 0.95);

/// One draw's sweep: the keys' values and the steps it measured (the steps
/// before a failure, and why it stopped, when a dwell failed).
#[derive(Debug, Clone)]
pub struct DrawSweep {
    /// The draw's index (its stream's sample index).
    pub draw: u32,
    /// The uncertain keys' values.
    pub values: Vec<UncertainValue>,
    /// The steps measured.
    pub points: Vec<StepPoint>,
    /// Why the sweep stopped early, if it did.
    pub failure: Option<String>,
}

/// The scene of `simulation` under draw `i` of `spec` (stream `i` of
/// `seed`, every key its own): the keys' values and the simulation, or why
/// the drawn scene cannot be used.
pub fn drawn_simulation(
    simulation: &Simulation,
    spec: &UncertainSpec,
    seed: u64,
    i: u32,
) -> (Vec<UncertainValue>, Result<Simulation, String>) {
    let streams = RunStreams {
        seed,
        shared: None,
        sequence: Sequence::Random,
        matrix: Matrix::A,
    };
    let values = draw(spec, |key| {
        streams
            .key_draws(key_hash(key), u64::from(i))
            .random::<f64>()
    });
    let drawn = apply(&simulation.scene, &values).map(|scene| Simulation {
        scene,
        ..simulation.clone()
    });
    (values, drawn)
}

/// Run the sweep once per draw of `spec` (draw i from stream i of `seed`),
/// in parallel; the results do not depend on the thread count.
pub fn sweep_draws(
    simulation: &Simulation,
    spec: &UncertainSpec,
    (speeds, dwell, window): (&[(Direction, f64)], f64, Option<f64>),
    draws: u32,
    seed: u64,
) -> Vec<DrawSweep> {
    (0..draws)
        .into_par_iter()
        .map(|i| {
            let (values, drawn) = drawn_simulation(simulation, spec, seed, i);
            let (points, failure) =
                match drawn.map(|sim| sim.stepped_sweep_windowed(speeds, dwell, window, None)) {
                    Ok(Ok(points)) => (points, None),
                    Ok(Err(SteppedError::Failed { done, why, .. })) => (done, Some(why)),
                    Ok(Err(SteppedError::Scene(e))) => (Vec::new(), Some(e.to_string())),
                    Err(why) => (Vec::new(), Some(why)),
                };
            DrawSweep {
                draw: i,
                values,
                points,
                failure,
            }
        })
        .collect()
}

/// What a band row measures.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Quantity {
    /// Peak radial displacement (m).
    Peak,
    /// Peak over the same without the balancer's unbalance.
    Ratio,
}

impl Quantity {
    /// Its name in the bands file.
    pub fn name(self) -> &'static str {
        match self {
            Quantity::Peak => "peak",
            Quantity::Ratio => "ratio",
        }
    }
}

/// The spread of one quantity at one step over the draws.
#[derive(Debug, Clone, PartialEq)]
pub struct BandRow {
    /// Run-up or run-down.
    pub direction: Direction,
    /// Speed (rad/s).
    pub omega: f64,
    /// The bearing, or `None` for the mean over the bearings (a rig's
    /// reading of both).
    pub bearing: Option<usize>,
    /// Peak or ratio.
    pub quantity: Quantity,
    /// 5 %, 50 % and 95 % quantiles over the draws that reached the step.
    pub quantiles: [f64; 3],
    /// Draws that reached the step.
    pub draws: u32,
}

/// A step's value of `quantity` at `bearing` (None: the bearings' mean).
fn value(p: &StepPoint, bearing: Option<usize>, quantity: Quantity) -> Option<f64> {
    let peaks = p.bearing_peak.as_ref()?;
    let without = p.bearing_peak_without.as_ref()?;
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let (with, base) = match bearing {
        Some(b) => (*peaks.get(b)?, *without.get(b)?),
        None => (mean(peaks), mean(without)),
    };
    Some(match quantity {
        Quantity::Peak => with,
        Quantity::Ratio => with / base,
    })
}

/// The 5 %, 50 % and 95 % quantiles (linear interpolation) of `values`.
fn spread(mut values: Vec<f64>) -> Option<[f64; 3]> {
    values.sort_by(f64::total_cmp);
    let at = |q| quantile_sorted(&values, q, Interpolation::Linear);
    Some([at(BAND.0)?, at(0.5)?, at(BAND.1)?])
}

/// Every step's band over the draws, for the bearings' mean and each bearing.
pub fn bands(sweeps: &[DrawSweep]) -> Vec<BandRow> {
    let Some(longest) = sweeps.iter().max_by_key(|s| s.points.len()) else {
        return Vec::new();
    };
    let bearings = longest
        .points
        .first()
        .and_then(|p| p.bearing_peak.as_ref())
        .map_or(0, Vec::len);
    let mut out = Vec::new();
    for (step, p) in longest.points.iter().enumerate() {
        let at: Vec<&StepPoint> = sweeps.iter().filter_map(|s| s.points.get(step)).collect();
        for bearing in std::iter::once(None).chain((0..bearings).map(Some)) {
            for quantity in [Quantity::Peak, Quantity::Ratio] {
                let values: Vec<f64> = at
                    .iter()
                    .filter_map(|p| value(p, bearing, quantity))
                    .filter(|v| v.is_finite())
                    .collect();
                let draws = values.len() as u32;
                if let Some(quantiles) = spread(values) {
                    out.push(BandRow {
                        direction: p.direction,
                        omega: p.omega,
                        bearing,
                        quantity,
                        quantiles,
                        draws,
                    });
                }
            }
        }
    }
    out
}

/// The onset of balancing on the run-up (rad/s): the lowest up-step from
/// which the bearings' mean peak stays below its value without the
/// balancer's unbalance at every higher up-step; `None` when the balls
/// never help for good (or the rotor has no bearings).
pub fn onset(points: &[StepPoint]) -> Option<f64> {
    let up: Vec<&StepPoint> = points
        .iter()
        .filter(|p| p.direction == Direction::Up)
        .collect();
    let helps = |p: &&StepPoint| value(p, None, Quantity::Ratio).is_some_and(|r| r < 1.0);
    let last_bad = up.iter().rposition(|p| !helps(p));
    let first_good = last_bad.map_or(0, |i| i + 1);
    up.get(first_good).map(|p| p.omega)
}

/// The onsets of every draw that has one, and how many have none.
pub fn onsets(sweeps: &[DrawSweep]) -> (Vec<f64>, usize) {
    let found: Vec<f64> = sweeps.iter().filter_map(|s| onset(&s.points)).collect();
    let none = sweeps.len() - found.len();
    (found, none)
}

/// The onsets' 5 %, 50 % and 95 % quantiles (rad/s).
pub fn onset_spread(onsets: &[f64]) -> Option<[f64; 3]> {
    spread(onsets.to_vec())
}

/// The band rows as a table (one row per step, bearing and quantity; the
/// bearing null for the bearings' mean).
pub fn bands_frame(rows: &[BandRow]) -> PolarsResult<DataFrame> {
    let q = |k: usize| rows.iter().map(|r| r.quantiles[k]).collect::<Vec<_>>();
    df!(
        "run" => rows.iter().map(|r| r.direction.name()).collect::<Vec<_>>(),
        "omega" => rows.iter().map(|r| r.omega).collect::<Vec<_>>(),
        "rpm" => rows.iter().map(|r| r.omega * 30.0 / std::f64::consts::PI).collect::<Vec<_>>(),
        "bearing" => rows.iter().map(|r| r.bearing.map(|b| b as u32)).collect::<Vec<_>>(),
        "quantity" => rows.iter().map(|r| r.quantity.name()).collect::<Vec<_>>(),
        "p05" => q(0),
        "median" => q(1),
        "p95" => q(2),
        "draws" => rows.iter().map(|r| r.draws).collect::<Vec<_>>(),
    )
}

/// Every draw's steps as a long table: one row per draw and step with the
/// bearings' mean peak and ratio, the draw's onset and a column
/// `scene.<key>` per uncertain key (a draw that failed before its first
/// step keeps one row with its failure and null measures).
pub fn draws_frame(sweeps: &[DrawSweep]) -> PolarsResult<DataFrame> {
    let rows: Vec<(&DrawSweep, Option<&StepPoint>)> = sweeps
        .iter()
        .flat_map(|s| {
            let steps: Vec<Option<&StepPoint>> = if s.points.is_empty() {
                vec![None]
            } else {
                s.points.iter().map(Some).collect()
            };
            steps.into_iter().map(move |p| (s, p))
        })
        .collect();
    let rpm = 30.0 / std::f64::consts::PI;
    let of = |quantity| -> Vec<Option<f64>> {
        rows.iter()
            .map(|(_, p)| p.and_then(|p| value(p, None, quantity)))
            .collect()
    };
    let mut columns = vec![
        Column::new(
            "draw".into(),
            rows.iter().map(|(s, _)| s.draw).collect::<Vec<_>>(),
        ),
        Column::new(
            "run".into(),
            rows.iter()
                .map(|(_, p)| p.map(|p| p.direction.name()))
                .collect::<Vec<_>>(),
        ),
        Column::new(
            "rpm".into(),
            rows.iter()
                .map(|(_, p)| p.map(|p| p.omega * rpm))
                .collect::<Vec<_>>(),
        ),
        Column::new("mean_bearing_peak".into(), of(Quantity::Peak)),
        Column::new("ratio".into(), of(Quantity::Ratio)),
        Column::new(
            "onset_rpm".into(),
            rows.iter()
                .map(|(s, _)| onset(&s.points).map(|w| w * rpm))
                .collect::<Vec<_>>(),
        ),
        Column::new(
            "failure".into(),
            rows.iter()
                .map(|(s, _)| s.failure.clone())
                .collect::<Vec<_>>(),
        ),
    ];
    if let Some(first) = sweeps.first() {
        for (k, v) in first.values.iter().enumerate() {
            columns.push(Column::new(
                format!("{}{}", crate::uncertain::COLUMN_PREFIX, v.key).into(),
                rows.iter()
                    .map(|(s, _)| s.values[k].value)
                    .collect::<Vec<_>>(),
            ));
        }
    }
    DataFrame::new(rows.len(), columns)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn step(direction: Direction, omega: f64, ratio: f64) -> StepPoint {
        StepPoint {
            direction,
            omega,
            whirl_peak: 0.0,
            whirl_rms: 0.0,
            bearing_peak: Some(vec![ratio, ratio]),
            bearing_rms: None,
            bearing_peak_without: Some(vec![1.0, 1.0]),
            balancing_error: 0.0,
            angles_deg: Vec::new(),
        }
    }

    /// The onset is where the ratio drops below 1 for good on the way up: a
    /// dip that comes back above 1 is not it, the run-down is ignored.
    #[test]
    fn onset_is_where_the_balls_help_for_good() {
        use Direction::{Down, Up};
        let sweep = [
            step(Up, 1.0, 1.2),
            step(Up, 2.0, 0.9),
            step(Up, 3.0, 1.1),
            step(Up, 4.0, 0.8),
            step(Up, 5.0, 0.5),
            step(Down, 4.0, 1.5),
        ];
        assert_eq!(onset(&sweep), Some(4.0));
        assert_eq!(onset(&sweep[..3]), None);
        assert_eq!(onset(&[step(Up, 1.0, 0.5)]), Some(1.0));
    }

    /// The band's quantiles are the order statistics' (linear), per step.
    #[test]
    fn bands_are_quantiles_over_the_draws() {
        let sweeps: Vec<DrawSweep> = (0..21)
            .map(|i| DrawSweep {
                draw: i,
                values: Vec::new(),
                points: vec![step(Direction::Up, 1.0, f64::from(i) / 10.0)],
                failure: None,
            })
            .collect();
        let rows = bands(&sweeps);
        let ratio = rows
            .iter()
            .find(|r| r.bearing.is_none() && r.quantity == Quantity::Ratio)
            .unwrap();
        assert_eq!(ratio.draws, 21);
        for (got, want) in ratio.quantiles.iter().zip([0.1, 1.0, 1.9]) {
            assert!((got - want).abs() < 1e-12, "{got} vs {want}");
        }
    }
}
