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
        col!("pack_slip_rate", |r: &RunRecord| r.metrics.pack_slip_rate),
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
    let columns = Columns { df };
    let core = CoreColumns::read(&columns)?;
    let optional = OptionalColumns::read(&columns)?;
    let mut uncertain = uncertain_from(df)?.into_iter();
    let mut out = Vec::with_capacity(df.height());
    for i in 0..df.height() {
        out.push(RunRecord {
            run_id: core.run_id[i],
            design_id: core.design_id[i],
            sample_id: core.sample_id[i],
            kind: core.kind[i].clone(),
            n: core.n[i],
            rho: core.rho[i],
            race_radius: core.race_radius[i],
            weight_mass: core.weight_mass[i],
            capacity: core.capacity[i],
            drag: core.drag[i],
            unbalance: core.unbalance[i],
            unbalance_fraction: core.fraction[i],
            direction_deg: core.direction[i],
            initial_angles_deg: core.initial[i].clone(),
            metrics: metrics_at(&core, &optional, i)?,
            contact: core.contact[i],
            method: core.method[i].clone(),
            stall_torque: optional.stall[i],
            wall_time_s: core.wall[i],
            weights: optional.weights.as_ref().map(|w| w[i].clone()),
            couple: optional.couple.as_ref().map(|c| c[i]),
            uncertain: uncertain.next().unwrap_or_default(),
        });
    }
    Ok(out)
}

/// Typed reads of one runs table's columns, so every group reads a column
/// the same way and a missing or mistyped column fails with polars' error.
struct Columns<'a> {
    df: &'a DataFrame,
}

impl Columns<'_> {
    /// A float column, nulls kept (a run that never settled has no time).
    fn f64s(&self, name: &str) -> PolarsResult<Vec<Option<f64>>> {
        Ok(self.df.column(name)?.f64()?.iter().collect())
    }

    /// A float column every run fills: a null is a damaged file.
    fn req(&self, name: &str) -> PolarsResult<Vec<f64>> {
        self.f64s(name)?
            .into_iter()
            .map(|v| v.ok_or_else(|| polars_err!(ComputeError: "null in column {name}")))
            .collect()
    }

    /// A u64 column (run ids and solver counts).
    fn u64s(&self, name: &str) -> PolarsResult<Vec<u64>> {
        Ok(self.df.column(name)?.u64()?.into_no_null_iter().collect())
    }

    /// A u32 column (design and sample indices, weight counts).
    fn u32s(&self, name: &str) -> PolarsResult<Vec<u32>> {
        Ok(self.df.column(name)?.u32()?.into_no_null_iter().collect())
    }

    /// A boolean column; a null reads as false, as the writer never emits one.
    fn bools(&self, name: &str) -> PolarsResult<Vec<bool>> {
        Ok(self
            .df
            .column(name)?
            .bool()?
            .iter()
            .map(|v| v.unwrap_or(false))
            .collect())
    }

    /// A string column; a null reads as the empty string.
    fn strs(&self, name: &str) -> PolarsResult<Vec<String>> {
        Ok(self
            .df
            .column(name)?
            .str()?
            .iter()
            .map(|v| v.unwrap_or_default().to_string())
            .collect())
    }

    /// A list-of-float column, one vector per row, nulls inside dropped.
    fn lists(&self, name: &str) -> PolarsResult<Vec<Vec<f64>>> {
        let list = self.df.column(name)?.list()?;
        (0..list.len())
            .map(|i| match list.get_as_series(i) {
                Some(s) => Ok(s.f64()?.no_null_iter().collect()),
                None => Ok(Vec::new()),
            })
            .collect()
    }

    /// A float column absent from tables written before the Sommerfeld
    /// columns existed: all nulls then.
    fn optional(&self, name: &str) -> PolarsResult<Vec<Option<f64>>> {
        match self.df.column(name) {
            Ok(_) => self.f64s(name),
            Err(_) => Ok(vec![None; self.df.height()]),
        }
    }

    /// A list column written only by rotors with several planes.
    fn optional_lists(&self, name: &str) -> PolarsResult<Option<Vec<Vec<f64>>>> {
        match self.df.column(name) {
            Ok(_) => self.lists(name).map(Some),
            Err(_) => Ok(None),
        }
    }

    /// The contact model per run; `None` for tables written before rigid
    /// contact existed, whose runs with contact on were all penalty.
    fn contact_models(&self) -> PolarsResult<Option<Vec<Option<&'static str>>>> {
        match self.df.column("contact_model") {
            Ok(c) => Ok(Some(
                c.str()?
                    .iter()
                    .map(|v| match v {
                        Some("rigid") => Some("rigid"),
                        Some(_) => Some("penalty"),
                        None => None,
                    })
                    .collect(),
            )),
            Err(_) => Ok(None),
        }
    }

    /// Whether each hold was certified; false for tables written before the
    /// certified hold existed.
    fn certified(&self) -> PolarsResult<Vec<bool>> {
        match self.df.column("hold_certified") {
            Ok(_) => self.bools("hold_certified"),
            Err(_) => Ok(vec![false; self.df.height()]),
        }
    }

    /// The weights as built, when the study sampled tolerances.
    fn weights(&self) -> PolarsResult<Option<Vec<SampledWeights>>> {
        if self.df.column(WEIGHT_COLUMNS[0]).is_err() {
            return Ok(None);
        }
        let [masses, radii, tracks] = WEIGHT_COLUMNS;
        let (m, r, l) = (self.lists(masses)?, self.lists(radii)?, self.lists(tracks)?);
        let [offset, angle] = RACE_COLUMNS;
        let (offsets, angles) = (self.f64s(offset)?, self.f64s(angle)?);
        Ok(Some(
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
        ))
    }

    /// The couple part of each unbalance, when the study sampled one.
    fn couples(&self) -> PolarsResult<Option<Vec<SampledCouple>>> {
        if self.df.column(COUPLE_COLUMNS[0]).is_err() {
            return Ok(None);
        }
        let (u, fraction, direction) = (
            self.f64s(COUPLE_COLUMNS[0])?,
            self.f64s(COUPLE_COLUMNS[1])?,
            self.f64s(COUPLE_COLUMNS[2])?,
        );
        Ok(Some(
            (0..self.df.height())
                .map(|i| SampledCouple {
                    unbalance: u[i].unwrap_or(f64::NAN),
                    fraction: fraction[i].unwrap_or(f64::NAN),
                    direction_deg: direction[i].unwrap_or(f64::NAN),
                })
                .collect(),
        ))
    }
}

/// The columns every runs table has (a few read as defaults from older
/// tables). Fields are read in declaration order of the literal in
/// [`CoreColumns::read`], which fixes which missing column is reported first.
struct CoreColumns {
    run_id: Vec<u64>,
    design_id: Vec<u32>,
    sample_id: Vec<u32>,
    n: Vec<u32>,
    kind: Vec<String>,
    outcome: Vec<String>,
    reason: Vec<String>,
    method: Vec<String>,
    rho: Vec<f64>,
    race_radius: Vec<f64>,
    weight_mass: Vec<f64>,
    capacity: Vec<f64>,
    drag: Vec<f64>,
    unbalance: Vec<f64>,
    fraction: Vec<f64>,
    direction: Vec<f64>,
    initial: Vec<Vec<f64>>,
    finals: Vec<Vec<f64>>,
    settled: Vec<bool>,
    hold: Vec<bool>,
    ts: Vec<Option<f64>>,
    tr: Vec<Option<f64>>,
    te: Vec<f64>,
    teps: Vec<Option<f64>>,
    ra: Vec<f64>,
    rr: Vec<f64>,
    aref: Vec<f64>,
    be: Vec<f64>,
    peak: Vec<f64>,
    pf: Vec<f64>,
    tf: Vec<f64>,
    steps: Vec<u64>,
    rhs: Vec<u64>,
    wall: Vec<f64>,
    fidelity: Vec<String>,
    contact: Vec<bool>,
    contact_model: Option<Vec<Option<&'static str>>>,
    certified: Vec<bool>,
    min_gap: Vec<Option<f64>>,
    final_gap: Vec<Option<f64>>,
    censoring: Vec<Option<f64>>,
}

impl CoreColumns {
    /// Reads the always-present columns first, in the order the table was
    /// always read, so the same damaged file reports the same column.
    fn read(c: &Columns) -> PolarsResult<Self> {
        Ok(Self {
            run_id: c.u64s("run_id")?,
            design_id: c.u32s("design_id")?,
            sample_id: c.u32s("sample_id")?,
            n: c.u32s("n")?,
            kind: c.strs("kind")?,
            outcome: c.strs("outcome")?,
            reason: c.strs("reason")?,
            method: c.strs("method")?,
            rho: c.req("rho")?,
            race_radius: c.req("race_radius")?,
            weight_mass: c.req("weight_mass")?,
            capacity: c.req("capacity")?,
            drag: c.req("drag")?,
            unbalance: c.req("unbalance")?,
            fraction: c.req("unbalance_fraction")?,
            direction: c.req("direction_deg")?,
            initial: c.lists("initial_angles_deg")?,
            finals: c.lists("final_rel_angles_deg")?,
            settled: c.bools("settled")?,
            hold: c.bools("hold_complete")?,
            ts: c.f64s("settling_time")?,
            tr: c.f64s("settling_revs")?,
            te: c.req("settling_time_err")?,
            teps: c.f64s("settling_time_eps")?,
            ra: c.req("residual_abs")?,
            rr: c.req("residual_rel")?,
            aref: c.req("a_ref")?,
            be: c.req("balancing_error")?,
            peak: c.req("peak_r")?,
            pf: c.req("p_final")?,
            tf: c.req("t_final")?,
            steps: c.u64s("steps")?,
            rhs: c.u64s("rhs_calls")?,
            wall: c.req("wall_time_s")?,
            fidelity: c.strs("fidelity")?,
            contact: c.bools("contact")?,
            contact_model: c.contact_models()?,
            certified: c.certified()?,
            min_gap: c.f64s("min_gap_rad")?,
            final_gap: c.f64s("final_min_gap_rad")?,
            censoring: c.f64s("censoring_revs")?,
        })
    }

    /// Run `i`'s contact model: the column's value, or penalty wherever
    /// contact was on in a table older than the column.
    fn contact_model(&self, i: usize) -> Option<&'static str> {
        match &self.contact_model {
            Some(models) => models[i],
            None => self.contact[i].then_some("penalty"),
        }
    }
}

/// The columns only some studies write (tolerances, couples, several planes,
/// a swept motor); absent ones read as empty.
struct OptionalColumns {
    weights: Option<Vec<SampledWeights>>,
    stall: Vec<Option<f64>>,
    t_op: Vec<Option<f64>>,
    spin: Vec<Option<f64>>,
    slip: Vec<Option<f64>>,
    angle_error: Vec<Option<f64>>,
    plane_a_ref: Option<Vec<Vec<f64>>>,
    plane_residual: Option<Vec<Vec<f64>>>,
    plane_eps: Option<Vec<Vec<f64>>>,
    bearing_peak: Option<Vec<Vec<f64>>>,
    bearing_rms: Option<Vec<Vec<f64>>>,
    plane_settling: Option<Vec<Vec<Option<f64>>>>,
    couple: Option<Vec<SampledCouple>>,
}

impl OptionalColumns {
    /// Reads the optional columns after the core ones, in their old order.
    fn read(c: &Columns) -> PolarsResult<Self> {
        Ok(Self {
            weights: c.weights()?,
            stall: c.optional("stall_torque")?,
            t_op: c.optional("operating_time_s")?,
            spin: c.optional("final_spin_rate")?,
            slip: c.optional("pack_slip_rate")?,
            angle_error: c.optional("balance_angle_error_deg")?,
            plane_a_ref: c.optional_lists(PLANE_COLUMNS[0])?,
            plane_residual: c.optional_lists(PLANE_COLUMNS[1])?,
            plane_eps: c.optional_lists(PLANE_COLUMNS[3])?,
            bearing_peak: c.optional_lists(BEARING_COLUMNS[0])?,
            bearing_rms: c.optional_lists(BEARING_COLUMNS[1])?,
            // Nulls inside: a plane that did not settle.
            plane_settling: nullable_lists(c.df, PLANE_COLUMNS[2])?,
            couple: c.couples()?,
        })
    }
}

/// Row `i` of a per-plane list column; an empty list is a run with no
/// per-plane values (not integrated).
fn plane_row<T: Clone>(column: &Option<Vec<Vec<T>>>, i: usize) -> Option<Vec<T>> {
    column
        .as_ref()
        .map(|v| v[i].clone())
        .filter(|v| !v.is_empty())
}

/// Run `i`'s metrics, the one step of a row that can fail (an unknown
/// outcome name).
fn metrics_at(
    core: &CoreColumns,
    optional: &OptionalColumns,
    i: usize,
) -> PolarsResult<RunMetrics> {
    Ok(RunMetrics {
        settled: core.settled[i],
        settling_time: core.ts[i],
        settling_revs: core.tr[i],
        settling_time_err: core.te[i],
        settling_time_eps: core.teps[i],
        hold_complete: core.hold[i],
        hold_certified: core.certified[i],
        residual_abs: core.ra[i],
        residual_rel: core.rr[i],
        a_ref: core.aref[i],
        balancing_error: core.be[i],
        peak_r: core.peak[i],
        final_rel_angles_deg: core.finals[i].clone(),
        p_final: core.pf[i],
        outcome: outcome_from(&core.outcome[i])?,
        reason: core.reason[i].clone(),
        t_final: core.tf[i],
        steps: core.steps[i],
        rhs_calls: core.rhs[i],
        method: core.method[i].clone(),
        fidelity: core.fidelity[i].clone(),
        contact_model: core.contact_model(i),
        min_gap_rad: core.min_gap[i],
        final_min_gap_rad: core.final_gap[i],
        censoring_revs: core.censoring[i],
        operating_time: optional.t_op[i],
        final_spin_rate: optional.spin[i],
        pack_slip_rate: optional.slip[i],
        balance_angle_error_deg: optional.angle_error[i],
        plane_a_ref: plane_row(&optional.plane_a_ref, i),
        plane_residual_abs: plane_row(&optional.plane_residual, i),
        plane_settling_revs: plane_row(&optional.plane_settling, i),
        plane_balancing_error: plane_row(&optional.plane_eps, i),
        bearing_orbit_peak: plane_row(&optional.bearing_peak, i),
        bearing_orbit_rms: plane_row(&optional.bearing_rms, i),
    })
}
