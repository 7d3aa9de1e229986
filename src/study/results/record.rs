//! One row of `runs.parquet`: the design, the sample, every metric, the
//! outcome and the solver's cost; and its conversion to and from polars.

use crate::metrics::{Outcome, RunMetrics};
use crate::study::plan::couple::{SampledCouple, plane_unbalances};
use crate::study::plan::tolerance::SampledWeights;
use crate::uncertain::{COLUMN_PREFIX, UncertainValue};
use polars::prelude::*;
use std::sync::Arc;

/// Everything recorded about one run.
#[derive(Clone, PartialEq)]
pub struct RunRecord {
    /// Global run index: design_id × samples + sample_id.
    pub run_id: u64,
    /// Design index in grid order.
    pub design_id: u32,
    /// Sample index within the design.
    pub sample_id: u32,
    /// Balancer kind.
    pub kind: String,
    /// Number of weights.
    pub n: u32,
    /// Radius ratio ρ.
    pub rho: f64,
    /// Race radius R (m).
    pub race_radius: f64,
    /// Mass of one weight (kg).
    pub weight_mass: f64,
    /// Design capacity (kg·m).
    pub capacity: f64,
    /// Drag coefficient β (N·s/m).
    pub drag: f64,
    /// Sampled unbalance U (kg·m).
    pub unbalance: f64,
    /// U / capacity.
    pub unbalance_fraction: f64,
    /// Unbalance direction (degrees).
    pub direction_deg: f64,
    /// Initial cargo angles relative to the rotor (degrees).
    pub initial_angles_deg: Vec<f64>,
    /// The run's metrics.
    pub metrics: RunMetrics,
    /// Integrator used.
    pub method: String,
    /// Whether contact between the weights was on (it is unless the study
    /// switched it off; off, weights may pass through each other).
    pub contact: bool,
    /// The motor's stall torque M_s (N·m) when the study sweeps it
    /// (`designs.stall_torque`), else empty.
    pub stall_torque: Option<f64>,
    /// Wall-clock time of the run (s); excluded from determinism checks.
    pub wall_time_s: f64,
    /// The weights as built, when the study samples tolerances (columns
    /// `weight_masses`, `weight_radii`, `track_radii`; absent otherwise).
    pub weights: Option<SampledWeights>,
    /// The couple part of the unbalance, when the study samples one
    /// (`[sampling.couple]`; columns [`COUPLE_COLUMNS`], absent otherwise).
    pub couple: Option<SampledCouple>,
    /// The uncertain scene keys' drawn values (`[uncertain]`; a column
    /// `scene.<key>` each, absent when the study has none).
    pub uncertain: Vec<UncertainValue>,
}

/// As derived, but `weights` and `couple` are shown only when the study sampled them: the
/// golden files print records with `{:?}`, and a study without tolerances
/// must print exactly what it printed before they existed.
impl std::fmt::Debug for RunRecord {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let mut s = f.debug_struct("RunRecord");
        s.field("run_id", &self.run_id)
            .field("design_id", &self.design_id)
            .field("sample_id", &self.sample_id)
            .field("kind", &self.kind)
            .field("n", &self.n)
            .field("rho", &self.rho)
            .field("race_radius", &self.race_radius)
            .field("weight_mass", &self.weight_mass)
            .field("capacity", &self.capacity)
            .field("drag", &self.drag)
            .field("unbalance", &self.unbalance)
            .field("unbalance_fraction", &self.unbalance_fraction)
            .field("direction_deg", &self.direction_deg)
            .field("initial_angles_deg", &self.initial_angles_deg)
            .field("metrics", &self.metrics)
            .field("method", &self.method)
            .field("contact", &self.contact)
            .field("stall_torque", &self.stall_torque)
            .field("wall_time_s", &self.wall_time_s);
        if let Some(w) = &self.weights {
            s.field("weights", w);
        }
        if let Some(c) = &self.couple {
            s.field("couple", c);
        }
        if !self.uncertain.is_empty() {
            s.field("uncertain", &self.uncertain);
        }
        s.finish()
    }
}

/// Columns of the sampled weights, in order; written only by studies with
/// `[sampling.tolerances]`, so that other studies' files keep their schema.
pub const WEIGHT_COLUMNS: [&str; 3] = ["weight_masses", "weight_radii", "track_radii"];

/// Columns of the couple part U_c (kg·m per plane), U_c/capacity and θ_c
/// (degrees), and of the unbalance each balancer plane takes (magnitude
/// kg·m and direction degrees per plane, in plane order); written only by
/// studies with `[sampling.couple]`.
pub const COUPLE_COLUMNS: [&str; 5] = [
    "couple_unbalance",
    "couple_fraction",
    "couple_direction_deg",
    "plane_unbalances",
    "plane_directions_deg",
];

/// Columns of each watched plane's A_ref and residual (m) and settling time
/// (revolutions, null for a plane that did not settle), for rotors with
/// several planes (balancer planes, then the load's planes), in plane order.
pub const PLANE_COLUMNS: [&str; 4] = [
    "plane_a_ref",
    "plane_residual_abs",
    "plane_settling_revs",
    "plane_balancing_error",
];

/// Columns of each bearing's orbit over the revolution after the run: peak
/// and RMS radial displacement (m), in support order; written only for
/// rotors with bearings of their own (two supports).
pub const BEARING_COLUMNS: [&str; 2] = ["bearing_orbit_peak", "bearing_orbit_rms"];

/// Columns of the race centre's offset (m) and direction (degrees), written
/// with the weight columns; null when neither sampled nor set by the scene.
pub const RACE_COLUMNS: [&str; 2] = ["race_offset", "race_angle_deg"];

fn list_column(name: &str, rows: impl Iterator<Item = Vec<f64>>) -> Column {
    let series: Vec<Series> = rows.map(|v| Series::new(PlSmallStr::EMPTY, v)).collect();
    Column::new(name.into(), series)
}

/// Records as a DataFrame with one column per field (in the documented order).
pub fn to_dataframe(rows: &[RunRecord]) -> PolarsResult<DataFrame> {
    macro_rules! col {
        ($name:expr, $f:expr) => {
            Column::new($name.into(), rows.iter().map($f).collect::<Vec<_>>())
        };
    }
    let mut columns = vec![
        col!("run_id", |r: &RunRecord| r.run_id),
        col!("design_id", |r: &RunRecord| r.design_id),
        col!("sample_id", |r: &RunRecord| r.sample_id),
        col!("kind", |r: &RunRecord| r.kind.clone()),
        col!("n", |r: &RunRecord| r.n),
        col!("rho", |r: &RunRecord| r.rho),
        col!("race_radius", |r: &RunRecord| r.race_radius),
        col!("weight_mass", |r: &RunRecord| r.weight_mass),
        col!("capacity", |r: &RunRecord| r.capacity),
        col!("drag", |r: &RunRecord| r.drag),
        col!("unbalance", |r: &RunRecord| r.unbalance),
        col!("unbalance_fraction", |r: &RunRecord| r.unbalance_fraction),
        col!("direction_deg", |r: &RunRecord| r.direction_deg),
        list_column(
            "initial_angles_deg",
            rows.iter().map(|r| r.initial_angles_deg.clone()),
        ),
        col!("settled", |r: &RunRecord| r.metrics.settled),
        col!("settling_time", |r: &RunRecord| r.metrics.settling_time),
        col!("settling_revs", |r: &RunRecord| r.metrics.settling_revs),
        col!("settling_time_err", |r: &RunRecord| r
            .metrics
            .settling_time_err),
        col!("settling_time_eps", |r: &RunRecord| r
            .metrics
            .settling_time_eps),
        col!("censoring_revs", |r: &RunRecord| r.metrics.censoring_revs),
        col!("hold_complete", |r: &RunRecord| r.metrics.hold_complete),
        col!("hold_certified", |r: &RunRecord| r.metrics.hold_certified),
        col!("residual_abs", |r: &RunRecord| r.metrics.residual_abs),
        col!("residual_rel", |r: &RunRecord| r.metrics.residual_rel),
        col!("a_ref", |r: &RunRecord| r.metrics.a_ref),
        col!("balancing_error", |r: &RunRecord| r.metrics.balancing_error),
        col!("peak_r", |r: &RunRecord| r.metrics.peak_r),
        list_column(
            "final_rel_angles_deg",
            rows.iter().map(|r| r.metrics.final_rel_angles_deg.clone()),
        ),
        col!("p_final", |r: &RunRecord| r.metrics.p_final),
        col!("outcome", |r: &RunRecord| r
            .metrics
            .outcome
            .name()
            .to_string()),
        col!("reason", |r: &RunRecord| r.metrics.reason.clone()),
        col!("t_final", |r: &RunRecord| r.metrics.t_final),
        col!("steps", |r: &RunRecord| r.metrics.steps),
        col!("rhs_calls", |r: &RunRecord| r.metrics.rhs_calls),
        col!("method", |r: &RunRecord| r.method.clone()),
        col!("fidelity", |r: &RunRecord| r.metrics.fidelity.clone()),
        col!("contact", |r: &RunRecord| r.contact),
        col!("contact_model", |r: &RunRecord| r.metrics.contact_model),
        col!("min_gap_rad", |r: &RunRecord| r.metrics.min_gap_rad),
        col!("final_min_gap_rad", |r: &RunRecord| r
            .metrics
            .final_min_gap_rad),
        // Variable speed (the Sommerfeld effect, docs/realism.md).
        col!("stall_torque", |r: &RunRecord| r.stall_torque),
        col!("operating_time_s", |r: &RunRecord| r.metrics.operating_time),
        col!("final_spin_rate", |r: &RunRecord| r.metrics.final_spin_rate),
        col!("balance_angle_error_deg", |r: &RunRecord| r
            .metrics
            .balance_angle_error_deg),
        col!("wall_time_s", |r: &RunRecord| r.wall_time_s),
    ];
    columns.extend(tolerance_columns(rows));
    columns.extend(plane_columns(rows));
    columns.extend(bearing_columns(rows));
    columns.extend(couple_columns(rows));
    columns.extend(uncertain_columns(rows));
    DataFrame::new(rows.len(), columns)
}

/// The sampled tolerances' columns (each weight's mass, radius and track,
/// the race's offset and angle), when the study samples them.
fn tolerance_columns(rows: &[RunRecord]) -> Vec<Column> {
    // All rows of a study sample tolerances or none do.
    let mut columns = Vec::new();
    if !rows.iter().any(|r| r.weights.is_some()) {
        return columns;
    }
    let weights = |pick: fn(&SampledWeights) -> &Vec<f64>| {
        rows.iter()
            .map(move |r| r.weights.as_ref().map(pick).cloned().unwrap_or_default())
    };
    let [masses, radii, tracks] = WEIGHT_COLUMNS;
    columns.push(list_column(masses, weights(|w| &w.masses)));
    columns.push(list_column(radii, weights(|w| &w.radii)));
    columns.push(list_column(tracks, weights(|w| &w.track_radii)));
    let race = |pick: fn(&(f64, f64)) -> f64| {
        rows.iter()
            .map(move |r| r.weights.as_ref().and_then(|w| w.race.as_ref()).map(pick))
            .collect::<Vec<_>>()
    };
    let [offset, angle] = RACE_COLUMNS;
    columns.push(Column::new(offset.into(), race(|r| r.0)));
    columns.push(Column::new(angle.into(), race(|r| r.1)));
    columns
}

/// Each balancer plane's A_ref, residual, settling and ε, on rotors with
/// several planes.
fn plane_columns(rows: &[RunRecord]) -> Vec<Column> {
    // Every row of a study has the same rotor: per-plane values or none.
    let mut columns = Vec::new();
    if !rows.iter().any(|r| r.metrics.plane_a_ref.is_some()) {
        return columns;
    }
    let [a, res, settling, eps] = PLANE_COLUMNS;
    columns.push(list_column(
        a,
        rows.iter()
            .map(|r| r.metrics.plane_a_ref.clone().unwrap_or_default()),
    ));
    columns.push(list_column(
        res,
        rows.iter()
            .map(|r| r.metrics.plane_residual_abs.clone().unwrap_or_default()),
    ));
    let per_run: Vec<Series> = rows
        .iter()
        .map(|r| {
            let v = r.metrics.plane_settling_revs.clone().unwrap_or_default();
            Series::new(PlSmallStr::EMPTY, v)
        })
        .collect();
    columns.push(Column::new(settling.into(), per_run));
    // Empty where the model defines no per-plane ε (one balancer plane).
    columns.push(list_column(
        eps,
        rows.iter()
            .map(|r| r.metrics.plane_balancing_error.clone().unwrap_or_default()),
    ));
    columns
}

/// Each bearing's orbit peak and RMS, on rotors with bearings.
fn bearing_columns(rows: &[RunRecord]) -> Vec<Column> {
    // Every row of a study has the same rotor: bearings for all or none.
    let mut columns = Vec::new();
    if !rows.iter().any(|r| r.metrics.bearing_orbit_peak.is_some()) {
        return columns;
    }
    let [peak, rms] = BEARING_COLUMNS;
    columns.push(list_column(
        peak,
        rows.iter()
            .map(|r| r.metrics.bearing_orbit_peak.clone().unwrap_or_default()),
    ));
    columns.push(list_column(
        rms,
        rows.iter()
            .map(|r| r.metrics.bearing_orbit_rms.clone().unwrap_or_default()),
    ));
    columns
}

/// The sampled couple's columns and each plane's unbalance, when the
/// study samples a couple.
fn couple_columns(rows: &[RunRecord]) -> Vec<Column> {
    // All rows of a study sample a couple or none do.
    let mut columns = Vec::new();
    if !rows.iter().any(|r| r.couple.is_some()) {
        return columns;
    }
    let [u, fraction, direction, planes, plane_dirs] = COUPLE_COLUMNS;
    let pick = |f: fn(&SampledCouple) -> f64| {
        rows.iter()
            .map(|r| r.couple.as_ref().map(f))
            .collect::<Vec<_>>()
    };
    columns.push(Column::new(u.into(), pick(|c| c.unbalance)));
    columns.push(Column::new(fraction.into(), pick(|c| c.fraction)));
    columns.push(Column::new(direction.into(), pick(|c| c.direction_deg)));
    let per_plane = |r: &RunRecord| {
        r.couple.as_ref().map_or_else(Vec::new, |c| {
            plane_unbalances((r.unbalance, r.direction_deg.to_radians()), c).to_vec()
        })
    };
    columns.push(list_column(
        planes,
        rows.iter()
            .map(|r| per_plane(r).iter().map(|p| p.0).collect()),
    ));
    columns.push(list_column(
        plane_dirs,
        rows.iter()
            .map(|r| per_plane(r).iter().map(|p| p.1.to_degrees()).collect()),
    ));
    columns
}

/// One column `scene.<key>` per uncertain key, in the study's key order
/// (every row of a study draws the same keys).
fn uncertain_columns(rows: &[RunRecord]) -> Vec<Column> {
    let Some(first) = rows.first() else {
        return Vec::new();
    };
    first
        .uncertain
        .iter()
        .enumerate()
        .map(|(k, v)| {
            let values: Vec<Option<f64>> = rows
                .iter()
                .map(|r| r.uncertain.get(k).map(|u| u.value))
                .collect();
            Column::new(format!("{COLUMN_PREFIX}{}", v.key).into(), values)
        })
        .collect()
}

/// Each row's uncertain keys, read back from the `scene.<key>` columns.
fn uncertain_from(df: &DataFrame) -> PolarsResult<Vec<Vec<UncertainValue>>> {
    let mut out = vec![Vec::new(); df.height()];
    for column in df.columns() {
        let Some(key) = column.name().as_str().strip_prefix(COLUMN_PREFIX) else {
            continue;
        };
        let key: Arc<str> = Arc::from(key);
        for (row, value) in out.iter_mut().zip(column.f64()?.iter()) {
            row.push(UncertainValue {
                key: key.clone(),
                value: value.unwrap_or(f64::NAN),
            });
        }
    }
    Ok(out)
}

/// A list column of f64 as one vector per row, nulls kept (a plane that did
/// not settle); `None` when `df` has no such column.
pub fn nullable_lists(df: &DataFrame, name: &str) -> PolarsResult<Option<Vec<Vec<Option<f64>>>>> {
    let Ok(column) = df.column(name) else {
        return Ok(None);
    };
    let list = column.list()?;
    (0..list.len())
        .map(|i| match list.get_as_series(i) {
            Some(s) => Ok(s.f64()?.iter().collect()),
            None => Ok(Vec::new()),
        })
        .collect::<PolarsResult<_>>()
        .map(Some)
}

/// Column names that hold nothing machine- or schedule-dependent (all but wall time).
pub fn deterministic_columns(df: &DataFrame) -> Vec<String> {
    df.get_column_names()
        .into_iter()
        .filter(|c| c.as_str() != "wall_time_s")
        .map(|c| c.to_string())
        .collect()
}

fn outcome_from(name: &str) -> PolarsResult<Outcome> {
    match Outcome::parse(name) {
        Some(o) => Ok(o),
        None => polars_bail!(ComputeError: "unknown outcome '{name}' in runs file"),
    }
}

/// Read records back from a DataFrame written by [`to_dataframe`].
pub fn from_dataframe(df: &DataFrame) -> PolarsResult<Vec<RunRecord>> {
    let f64s = |name: &str| -> PolarsResult<Vec<Option<f64>>> {
        Ok(df.column(name)?.f64()?.iter().collect())
    };
    let req = |name: &str| -> PolarsResult<Vec<f64>> {
        f64s(name)?
            .into_iter()
            .map(|v| v.ok_or_else(|| polars_err!(ComputeError: "null in column {name}")))
            .collect()
    };
    let u64s = |name: &str| -> PolarsResult<Vec<u64>> {
        Ok(df.column(name)?.u64()?.into_no_null_iter().collect())
    };
    let u32s = |name: &str| -> PolarsResult<Vec<u32>> {
        Ok(df.column(name)?.u32()?.into_no_null_iter().collect())
    };
    let bools = |name: &str| -> PolarsResult<Vec<bool>> {
        Ok(df
            .column(name)?
            .bool()?
            .iter()
            .map(|v| v.unwrap_or(false))
            .collect())
    };
    let strs = |name: &str| -> PolarsResult<Vec<String>> {
        Ok(df
            .column(name)?
            .str()?
            .iter()
            .map(|v| v.unwrap_or_default().to_string())
            .collect())
    };
    let lists = |name: &str| -> PolarsResult<Vec<Vec<f64>>> {
        let list = df.column(name)?.list()?;
        (0..list.len())
            .map(|i| match list.get_as_series(i) {
                Some(s) => Ok(s.f64()?.no_null_iter().collect()),
                None => Ok(Vec::new()),
            })
            .collect()
    };
    let (run_id, design_id, sample_id, n) = (
        u64s("run_id")?,
        u32s("design_id")?,
        u32s("sample_id")?,
        u32s("n")?,
    );
    let (kind, outcome, reason, method) = (
        strs("kind")?,
        strs("outcome")?,
        strs("reason")?,
        strs("method")?,
    );
    let (rho, race_radius, weight_mass, capacity, drag) = (
        req("rho")?,
        req("race_radius")?,
        req("weight_mass")?,
        req("capacity")?,
        req("drag")?,
    );
    let (unbalance, fraction, direction) = (
        req("unbalance")?,
        req("unbalance_fraction")?,
        req("direction_deg")?,
    );
    let (initial, finals) = (lists("initial_angles_deg")?, lists("final_rel_angles_deg")?);
    let (settled, hold) = (bools("settled")?, bools("hold_complete")?);
    let (ts, tr, te, teps) = (
        f64s("settling_time")?,
        f64s("settling_revs")?,
        req("settling_time_err")?,
        f64s("settling_time_eps")?,
    );
    let (ra, rr, aref, be, peak, pf, tf) = (
        req("residual_abs")?,
        req("residual_rel")?,
        req("a_ref")?,
        req("balancing_error")?,
        req("peak_r")?,
        req("p_final")?,
        req("t_final")?,
    );
    let (steps, rhs, wall) = (u64s("steps")?, u64s("rhs_calls")?, req("wall_time_s")?);
    let fidelity = strs("fidelity")?;
    let contact = bools("contact")?;
    // Absent from tables written before rigid contact existed (all penalty).
    let contact_model: Vec<Option<&'static str>> = match df.column("contact_model") {
        Ok(c) => c
            .str()?
            .iter()
            .map(|v| match v {
                Some("rigid") => Some("rigid"),
                Some(_) => Some("penalty"),
                None => None,
            })
            .collect(),
        Err(_) => contact.iter().map(|&on| on.then_some("penalty")).collect(),
    };
    // Absent from tables written before the certified hold existed.
    let certified = match df.column("hold_certified") {
        Ok(_) => bools("hold_certified")?,
        Err(_) => vec![false; df.height()],
    };
    let (min_gap, final_gap) = (f64s("min_gap_rad")?, f64s("final_min_gap_rad")?);
    let censoring = f64s("censoring_revs")?;
    let weights: Option<Vec<SampledWeights>> = if df.column(WEIGHT_COLUMNS[0]).is_ok() {
        let [masses, radii, tracks] = WEIGHT_COLUMNS;
        let (m, r, l) = (lists(masses)?, lists(radii)?, lists(tracks)?);
        let [offset, angle] = RACE_COLUMNS;
        let (offsets, angles) = (f64s(offset)?, f64s(angle)?);
        Some(
            m.into_iter()
                .zip(r)
                .zip(l)
                .zip(offsets.into_iter().zip(angles))
                .map(|(((masses, radii), track_radii), race)| SampledWeights {
                    masses,
                    radii,
                    track_radii,
                    race: race.0.zip(race.1),
                })
                .collect(),
        )
    } else {
        None
    };
    // Absent from tables written before the Sommerfeld columns existed.
    let optional = |name: &str| -> PolarsResult<Vec<Option<f64>>> {
        match df.column(name) {
            Ok(_) => f64s(name),
            Err(_) => Ok(vec![None; df.height()]),
        }
    };
    let (stall, t_op, spin) = (
        optional("stall_torque")?,
        optional("operating_time_s")?,
        optional("final_spin_rate")?,
    );
    let angle_error = optional("balance_angle_error_deg")?;
    // Written only by rotors with several planes.
    let optional_lists = |name: &str| -> PolarsResult<Option<Vec<Vec<f64>>>> {
        match df.column(name) {
            Ok(_) => lists(name).map(Some),
            Err(_) => Ok(None),
        }
    };
    let plane_a_ref = optional_lists(PLANE_COLUMNS[0])?;
    let plane_residual = optional_lists(PLANE_COLUMNS[1])?;
    let plane_eps = optional_lists(PLANE_COLUMNS[3])?;
    let bearing_peak = optional_lists(BEARING_COLUMNS[0])?;
    let bearing_rms = optional_lists(BEARING_COLUMNS[1])?;
    // Nulls inside: a plane that did not settle.
    let plane_settling = nullable_lists(df, PLANE_COLUMNS[2])?;
    let couple: Option<Vec<SampledCouple>> = if df.column(COUPLE_COLUMNS[0]).is_ok() {
        let (u, fraction, direction) = (
            f64s(COUPLE_COLUMNS[0])?,
            f64s(COUPLE_COLUMNS[1])?,
            f64s(COUPLE_COLUMNS[2])?,
        );
        Some(
            (0..df.height())
                .map(|i| SampledCouple {
                    unbalance: u[i].unwrap_or(f64::NAN),
                    fraction: fraction[i].unwrap_or(f64::NAN),
                    direction_deg: direction[i].unwrap_or(f64::NAN),
                })
                .collect(),
        )
    } else {
        None
    };
    let mut uncertain = uncertain_from(df)?.into_iter();
    let mut out = Vec::with_capacity(df.height());
    for i in 0..df.height() {
        out.push(RunRecord {
            run_id: run_id[i],
            design_id: design_id[i],
            sample_id: sample_id[i],
            kind: kind[i].clone(),
            n: n[i],
            rho: rho[i],
            race_radius: race_radius[i],
            weight_mass: weight_mass[i],
            capacity: capacity[i],
            drag: drag[i],
            unbalance: unbalance[i],
            unbalance_fraction: fraction[i],
            direction_deg: direction[i],
            initial_angles_deg: initial[i].clone(),
            metrics: RunMetrics {
                settled: settled[i],
                settling_time: ts[i],
                settling_revs: tr[i],
                settling_time_err: te[i],
                settling_time_eps: teps[i],
                hold_complete: hold[i],
                hold_certified: certified[i],
                residual_abs: ra[i],
                residual_rel: rr[i],
                a_ref: aref[i],
                balancing_error: be[i],
                peak_r: peak[i],
                final_rel_angles_deg: finals[i].clone(),
                p_final: pf[i],
                outcome: outcome_from(&outcome[i])?,
                reason: reason[i].clone(),
                t_final: tf[i],
                steps: steps[i],
                rhs_calls: rhs[i],
                method: method[i].clone(),
                fidelity: fidelity[i].clone(),
                contact_model: contact_model[i],
                min_gap_rad: min_gap[i],
                final_min_gap_rad: final_gap[i],
                censoring_revs: censoring[i],
                operating_time: t_op[i],
                final_spin_rate: spin[i],
                balance_angle_error_deg: angle_error[i],
                // An empty list: a run with no per-plane values (not integrated).
                plane_a_ref: plane_a_ref
                    .as_ref()
                    .map(|v| v[i].clone())
                    .filter(|v| !v.is_empty()),
                plane_residual_abs: plane_residual
                    .as_ref()
                    .map(|v| v[i].clone())
                    .filter(|v| !v.is_empty()),
                plane_settling_revs: plane_settling
                    .as_ref()
                    .map(|v| v[i].clone())
                    .filter(|v| !v.is_empty()),
                plane_balancing_error: plane_eps
                    .as_ref()
                    .map(|v| v[i].clone())
                    .filter(|v| !v.is_empty()),
                bearing_orbit_peak: bearing_peak
                    .as_ref()
                    .map(|v| v[i].clone())
                    .filter(|v| !v.is_empty()),
                bearing_orbit_rms: bearing_rms
                    .as_ref()
                    .map(|v| v[i].clone())
                    .filter(|v| !v.is_empty()),
            },
            contact: contact[i],
            method: method[i].clone(),
            stall_torque: stall[i],
            wall_time_s: wall[i],
            weights: weights.as_ref().map(|w| w[i].clone()),
            couple: couple.as_ref().map(|c| c[i]),
            uncertain: uncertain.next().unwrap_or_default(),
        });
    }
    Ok(out)
}
