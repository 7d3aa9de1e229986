//! Why a design does not balance: when even the first-ranked design settles
//! in too few runs or leaves more vibration than no balancer, the verdict
//! names a cause instead of a winner. The checks run in a fixed order and
//! the first that applies is named (docs/statistics.md, "No crown without
//! a balancer that works"):
//!
//! 1. the dead band of rolling resistance, μ_s·l, against the band δ·A_ref;
//! 2. a capacity below the unbalances drawn;
//! 3. a speed at or below the rotor's critical speed;
//! 4. gravity, g/(l ω²), against δ·U/C;
//! 5. a balanced state unstable at every point of its family tried, or a
//!    horizon too short for the slowest mode where it is stable (the linear
//!    analysis of `study linear`, repeated along the family).

use crate::model::balanced_family::family_stability;
use crate::model::critical_speeds::critical_speeds_in_range;
use crate::study::plan::config::StudyPlan;
use crate::study::plan::design::Design;

/// What the checks measured for one design (every length in m).
#[derive(Debug, Clone, PartialEq)]
pub struct DesignFacts {
    /// Median A_ref over the design's runs.
    pub a_ref_median: f64,
    /// Median sampled unbalance over capacity, U/C.
    pub unbalance_fraction_median: f64,
    /// Share of runs whose sampled unbalance exceeded the capacity.
    pub over_capacity_share: f64,
    /// Median A_ref of each balancer plane, on rotors with several watched
    /// planes (empty otherwise): a run settles only when every plane is
    /// inside its own band δ·A_ref of the plane.
    pub plane_a_ref_medians: Vec<f64>,
    /// Median over the runs of each run's breakaway coefficient μ_s, when
    /// rolling resistance's keys are `[uncertain]` (`None`: the nominal one).
    pub breakaway_median: Option<f64>,
}

/// Rolling resistance's keys whose drawn values set a run's dead band
/// (μ_s = coefficient × static_ratio), as `[uncertain]` names them;
/// runs.parquet holds them under [`crate::uncertain::COLUMN_PREFIX`].
pub const BREAKAWAY_KEYS: [&str; 2] = [
    "effects.rolling_resistance.coefficient",
    "effects.rolling_resistance.static_ratio",
];

/// A run's breakaway coefficient μ_s from its drawn `coefficient` and
/// `static_ratio` (`None` where the key is not uncertain: the nominal
/// value); `None` without rolling resistance.
pub fn breakaway(plan: &StudyPlan, coefficient: Option<f64>, ratio: Option<f64>) -> Option<f64> {
    let rr = plan.file.scene.effects.rolling_resistance.as_ref()?;
    Some(coefficient.unwrap_or(rr.coefficient) * ratio.unwrap_or(rr.static_ratio))
}

/// The dead band of plane `p` at breakaway coefficient `mu_s` (`None`:
/// the nominal one), `None` without rolling resistance.
fn dead_band_at(plan: &StudyPlan, design: &Design, p: usize, mu_s: Option<f64>) -> Option<f64> {
    match mu_s {
        Some(mu) => plan
            .file
            .scene
            .effects
            .rolling_resistance
            .as_ref()
            .map(|_| mu * plane_track_radius(design, p)),
        None => plane_dead_band(plan, design, p),
    }
}

/// Each run's breakaway coefficient μ_s (rows of `runs`), from its drawn
/// rolling-resistance keys; `None` when neither key is `[uncertain]` (or
/// the table lacks their columns) and every run has the nominal one.
pub fn run_breakaways(
    plan: &StudyPlan,
    runs: &polars::prelude::DataFrame,
) -> polars::prelude::PolarsResult<Option<Vec<Option<f64>>>> {
    let column = |key: &str| -> polars::prelude::PolarsResult<Option<Vec<Option<f64>>>> {
        let name = format!("{}{key}", crate::uncertain::COLUMN_PREFIX);
        match runs.column(&name) {
            Ok(c) => Ok(Some(c.f64()?.iter().collect())),
            Err(_) => Ok(None),
        }
    };
    let (coefficient, ratio) = (column(BREAKAWAY_KEYS[0])?, column(BREAKAWAY_KEYS[1])?);
    if coefficient.is_none() && ratio.is_none() {
        return Ok(None);
    }
    let at = |v: &Option<Vec<Option<f64>>>, i: usize| v.as_ref().and_then(|v| v[i]);
    Ok(Some(
        (0..runs.height())
            .map(|i| breakaway(plan, at(&coefficient, i), at(&ratio, i)))
            .collect(),
    ))
}

/// One run that did not settle, as the floor checks see it.
#[derive(Debug, Clone, PartialEq)]
pub struct UnsettledRun {
    /// Its A_ref per watched plane (or the rotor's alone).
    pub a_refs: Vec<f64>,
    /// Its own breakaway coefficient μ_s, drawn (`None`: the nominal one).
    pub breakaway: Option<f64>,
}

/// The dead band μ_s·l of a design (m), with rolling resistance on.
pub fn dead_band(plan: &StudyPlan, design: &Design) -> Option<f64> {
    plane_dead_band(plan, design, 0)
}

/// The dead band μ_s·l of balancer plane `p`'s weights (m): planes with a
/// design of their own have their own track radius.
pub fn plane_dead_band(plan: &StudyPlan, design: &Design, p: usize) -> Option<f64> {
    let rr = plan.file.scene.effects.rolling_resistance.as_ref()?;
    Some(rr.coefficient * rr.static_ratio * plane_track_radius(design, p))
}

/// The track radius of balancer plane `p`'s weights (m).
fn plane_track_radius(design: &Design, p: usize) -> f64 {
    match p.checked_sub(1) {
        Some(i) => design
            .plane_designs
            .get(i)
            .map_or(design.track_radius, |d| d.track_radius),
        None => design.track_radius,
    }
}

/// The bands the checks compare floors with: each balancer plane's own
/// (median A_ref of the plane) on rotors with several, else the rotor's.
fn bands(plan: &StudyPlan, facts: &DesignFacts) -> Vec<(Option<usize>, f64)> {
    let planes = plan.file.scene.rotor.as_rotor().planes();
    if facts.plane_a_ref_medians.len() > 1 {
        facts
            .plane_a_ref_medians
            .iter()
            .take(planes)
            .enumerate()
            .map(|(p, &a)| (Some(p), a))
            .collect()
    } else {
        vec![(None, facts.a_ref_median)]
    }
}

/// The settling band δ·A_ref (m) at a given A_ref.
pub fn settling_band(plan: &StudyPlan, a_ref: f64) -> f64 {
    plan.file.metrics.delta * a_ref
}

/// The diagnosis of a design that does not balance: its cause, and the
/// median U/C when it is so small that kg·m were probably meant.
#[derive(Debug, Clone, PartialEq)]
pub struct Diagnosis {
    /// The first check that applies.
    pub cause: Cause,
    /// The median U/C, when under 1 % with `relative_to = "capacity"`.
    pub tiny_fraction: Option<f64>,
}

impl std::fmt::Display for Diagnosis {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}", self.cause)?;
        if let Some(fraction) = self.tiny_fraction {
            write!(
                f,
                " (note: the median unbalance drawn is {fraction:.1e} of the capacity; if the values were meant in kg·m, set relative_to = \"absolute\")"
            )?;
        }
        Ok(())
    }
}

/// The first cause among the checks that applies to `design`, and the
/// kg·m note where the fractions drawn look like kg·m.
pub fn diagnose(plan: &StudyPlan, design: &Design, facts: &DesignFacts) -> Diagnosis {
    // Fractions of capacity this small are usually kg·m read as fractions.
    let tiny = facts.unbalance_fraction_median < 0.01
        && plan.file.sampling.unbalance.scale()
            == crate::study::plan::distribution::Scale::Capacity;
    Diagnosis {
        cause: first_cause(plan, design, facts),
        tiny_fraction: tiny.then_some(facts.unbalance_fraction_median),
    }
}

/// Why a design does not balance: the first check that applies, with the
/// numbers it measured (lengths in m, rates in 1/s, speeds in rad/s).
#[derive(Debug, Clone, PartialEq)]
pub enum Cause {
    /// Rolling resistance stops the weights anywhere inside μ_s·l ≥ δ·A_ref.
    DeadBand {
        /// μ_s·l.
        dead: f64,
        /// The track radius l.
        track_radius: f64,
        /// δ·A_ref at the median A_ref.
        band: f64,
        /// Median A_ref.
        a_ref: f64,
        /// The balancer plane whose own band it reaches (rotors with several).
        plane: Option<usize>,
    },
    /// An effect leaves a whirl no balancer removes, at least the band.
    WhirlFloor {
        /// The floor's size.
        floor: f64,
        /// What makes it (the effect's own words).
        what: &'static str,
        /// δ·A_ref at the median A_ref.
        band: f64,
        /// Median A_ref.
        a_ref: f64,
        /// The balancer plane whose own band it reaches (rotors with several).
        plane: Option<usize>,
    },
    /// Half the runs or more drew an unbalance above the capacity.
    OverCapacity {
        /// The capacity C (kg·m).
        capacity: f64,
        /// Share of runs over it.
        share: f64,
    },
    /// The speed is at or below the rotor's (lowest) critical speed.
    BelowCritical {
        /// ω.
        omega: f64,
        /// The critical speed.
        critical: f64,
        /// Whether the rotor has more than one.
        several: bool,
    },
    /// Gravity swings the weights by more than the band allows.
    Gravity {
        /// g/(l ω²), each weight's swing (rad).
        swing: f64,
        /// The most whirl the swing leaves, relative to A_ref (`gravity_whirl`).
        whirl_over_a_ref: f64,
        /// δ, the band relative to A_ref.
        delta: f64,
    },
    /// Unstable at every balanced position tried along the family.
    Unstable {
        /// ω.
        omega: f64,
        /// Balanced positions reached.
        points: usize,
        /// The slowest decay rate at the symmetric fan (negative: growing).
        sigma_fan: f64,
    },
    /// Stable somewhere on the family, but too slow for the horizon.
    HorizonTooShort {
        /// Decay rate at the fastest stable position found.
        sigma: f64,
        /// Revolutions the linear estimate needs to reach the band.
        needed_revs: f64,
        /// t_end − hold, in revolutions.
        horizon_revs: f64,
        /// When the symmetric fan is unstable: stable positions of those reached.
        fan_unstable: Option<(usize, usize)>,
    },
    /// None of the checks applies.
    NoneFound,
}

impl Cause {
    /// A stable key for the cause, written to `summary.parquet` (`diagnosis_cause`).
    pub fn key(&self) -> &'static str {
        match self {
            Cause::DeadBand { .. } => "dead_band",
            Cause::WhirlFloor { .. } => "whirl_floor",
            Cause::OverCapacity { .. } => "over_capacity",
            Cause::BelowCritical { .. } => "below_critical_speed",
            Cause::Gravity { .. } => "gravity",
            Cause::Unstable { .. } => "unstable",
            Cause::HorizonTooShort { .. } => "horizon_too_short",
            Cause::NoneFound => "none_found",
        }
    }
}

impl std::fmt::Display for Cause {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match *self {
            Cause::DeadBand {
                dead,
                track_radius,
                band,
                a_ref,
                plane,
            } => write!(
                f,
                "the dead band of rolling resistance μ_s·l = {:.3} µm (l = {:.2} mm the track radius) is as large as {} δ·A_ref = {:.3} µm (median A_ref {:.3} µm): the weights stop anywhere inside it; lower μ_s, or judge against a band wider than the dead band",
                dead * 1e6,
                track_radius * 1e3,
                whose_band(plane),
                band * 1e6,
                a_ref * 1e6
            ),
            Cause::WhirlFloor {
                floor,
                what,
                band,
                a_ref,
                plane,
            } => write!(
                f,
                "{what} = {:.3} µm, as large as {} δ·A_ref = {:.3} µm (median A_ref {:.3} µm): no balancer gets inside it; true the race, or judge against a band wider than the floor (metrics.delta above {:.3})",
                floor * 1e6,
                whose_band(plane),
                band * 1e6,
                a_ref * 1e6,
                floor / a_ref
            ),
            Cause::OverCapacity { capacity, share } => write!(
                f,
                "the capacity C = {capacity:.4e} kg·m is below the unbalance drawn in {:.0} % of runs: use more or heavier weights, or a larger race",
                100.0 * share
            ),
            Cause::BelowCritical {
                omega,
                critical,
                several,
            } => write!(
                f,
                "the speed ω = {omega:.1} rad/s is at or below the rotor's {} {critical:.1} rad/s: a passive balancer only balances above it",
                if several {
                    "lowest critical speed"
                } else {
                    "critical speed"
                }
            ),
            Cause::Gravity {
                swing,
                whirl_over_a_ref,
                delta,
            } => write!(
                f,
                "gravity swings the weights every revolution by g/(l ω²) = {swing:.3e} rad, which can leave a whirl at twice the speed of up to {whirl_over_a_ref:.3} A_ref, as large as the settling band δ = {delta}: run faster, or on a vertical axis"
            ),
            Cause::Unstable {
                omega,
                points,
                sigma_fan,
            } => write!(
                f,
                "the balanced state is linearly unstable at ω = {omega:.1} rad/s at each of the {points} balanced positions reached (slowest decay rate σ = {sigma_fan:.3e} 1/s at the symmetric fan, negative: growing; `study linear` on this design shows the growing mode)"
            ),
            Cause::HorizonTooShort {
                sigma,
                needed_revs,
                horizon_revs,
                fan_unstable,
            } => {
                write!(
                    f,
                    "the horizon is too short for the slowest mode: at the fastest stable balanced position found it decays at σ = {sigma:.3e} 1/s and needs about {needed_revs:.0} rev to reach the band, against t_end_revs − hold_revs = {horizon_revs:.0} rev"
                )?;
                if let Some((stable, reached)) = fan_unstable {
                    write!(
                        f,
                        " (the symmetric fan is unstable, but {stable} of the {reached} balanced positions reached are stable, and the weights can settle there)"
                    )?;
                }
                write!(f, "; raise metrics.t_end_revs")
            }
            Cause::NoneFound => write!(
                f,
                "none of the usual causes applies (dead band, capacity, critical speed, gravity, horizon): look at single runs with `study simulate` or `study plot run`"
            ),
        }
    }
}

/// A floor at or above the own band of most runs that did not settle:
/// why a crowned design falls short when those runs' bands (in some plane)
/// lie below a whirl no balancer removes.
#[derive(Debug, Clone, PartialEq)]
pub struct FloorReach {
    /// What makes the floor.
    pub what: String,
    /// Its size (m): the largest over the runs it reaches.
    pub floor: f64,
    /// The smallest and largest over the runs it reaches (m): a dead band
    /// differs from run to run when μ is uncertain.
    pub floors: (f64, f64),
    /// The balancer plane whose own band it reaches (rotors with several).
    pub plane: Option<usize>,
    /// Runs that did not settle whose band it reaches.
    pub runs: usize,
    /// Runs that did not settle (censored or not settled; failures aside).
    pub unsettled: usize,
    /// The smallest and largest band it reaches (m).
    pub bands: (f64, f64),
}

impl std::fmt::Display for FloorReach {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let (has, bands) = if self.runs == 1 {
            ("has", format!("{:.3} µm in that run", self.bands.0 * 1e6))
        } else {
            (
                "have",
                format!(
                    "{:.3}–{:.3} µm in those runs",
                    self.bands.0 * 1e6,
                    self.bands.1 * 1e6
                ),
            )
        };
        let floor = if self.floors.0 < self.floors.1 {
            format!(
                "{:.3}–{:.3} µm (each run's own, from its drawn μ)",
                self.floors.0 * 1e6,
                self.floors.1 * 1e6
            )
        } else {
            format!("{:.3} µm", self.floor * 1e6)
        };
        write!(
            f,
            "{} of the {} runs that did not settle {has} {} δ·A_ref ({bands}) at or below a whirl no balancer removes, {floor}: {}",
            self.runs,
            self.unsettled,
            whose_band(self.plane),
            self.what,
        )
    }
}

/// The floor that reaches the own band (δ·A_ref, per balancer plane on
/// rotors with several) of at least half the runs that did not settle,
/// each given by its A_ref per watched plane (or the rotor's alone) and
/// its own breakaway coefficient: a run's dead band is its drawn μ_s·l.
pub fn floor_reach(
    plan: &StudyPlan,
    design: &Design,
    unsettled: &[UnsettledRun],
) -> Option<FloorReach> {
    let planes = plan.file.scene.rotor.as_rotor().planes();
    let several = unsettled.iter().any(|r| r.a_refs.len() > 1);
    // (what, plane, the floor of each run).
    let mut candidates: Vec<(String, usize, Vec<Option<f64>>)> = Vec::new();
    for p in 0..if several { planes } else { 1 } {
        if let Some((floor, what)) = plan.file.scene.effects.whirl_floor() {
            candidates.push((what.to_string(), p, vec![Some(floor); unsettled.len()]));
        }
        if plane_dead_band(plan, design, p).is_some() {
            candidates.push((
                "the dead band of rolling resistance μ_s·l, inside which the weights stop anywhere"
                    .into(),
                p,
                unsettled
                    .iter()
                    .map(|r| dead_band_at(plan, design, p, r.breakaway))
                    .collect(),
            ));
        }
    }
    candidates
        .into_iter()
        .filter_map(|(what, p, floors)| {
            let (reached, floors): (Vec<f64>, Vec<f64>) = unsettled
                .iter()
                .zip(&floors)
                .filter_map(|(r, &floor)| Some((settling_band(plan, *r.a_refs.get(p)?), floor?)))
                .filter(|&(band, floor)| floor >= band)
                .unzip();
            let lo = reached.iter().copied().reduce(f64::min)?;
            let hi = reached.iter().copied().reduce(f64::max)?;
            let fl = floors.iter().copied().reduce(f64::min)?;
            let fh = floors.iter().copied().reduce(f64::max)?;
            Some(FloorReach {
                what,
                floor: fh,
                floors: (fl, fh),
                plane: several.then_some(p),
                runs: reached.len(),
                unsettled: unsettled.len(),
                bands: (lo, hi),
            })
        })
        .filter(|r| 2 * r.runs >= r.unsettled)
        // The first of equally reaching floors: the whirl floor before the dead band.
        .min_by_key(|r| std::cmp::Reverse(r.runs))
}

/// "the settling band", or "plane p's own settling band" on a rotor whose
/// planes each settle into their own.
fn whose_band(plane: Option<usize>) -> String {
    match plane {
        Some(p) => format!("plane {p}'s own settling band"),
        None => "the settling band".to_string(),
    }
}

/// The whirl, relative to A_ref, that gravity leaves through the weights'
/// swing, at U/C = `fraction`: an upper bound.
///
/// In the rotating frame gravity pushes weight j along the race with
/// m g sin(ωt + ψ_j); the weight answers by inertia, δψ_j = (g/(l ω²))
/// sin(ωt + ψ_j). The unbalance this moves, Σ m l i δψ_j e^{iψ_j}, has a
/// part that turns at −ω in the rotating frame (fixed in the ground frame:
/// it throws nothing) and one of size (m g/(2ω²))|Σ e^{2iψ_j}|, at most
/// (C/2)·g/(l ω²), that turns at 2ω in the ground frame, where the rotor
/// answers with |H(2ω)| instead of |H(ω)|. The bound takes every weight's
/// swing in phase, because gravity moves the weights off the fan that
/// would spread them. (Before 2026-11-27 the test compared g/(l ω²) with
/// δ·U/C directly, twice this bound.)
pub fn gravity_whirl(swing: f64, fraction: f64, response_ratio: f64) -> f64 {
    0.5 * swing * response_ratio / fraction
}

/// |H(2ω)|/|H(ω)| of a mass on isotropic supports, H(Ω) = Ω²/(k − MΩ² + ibΩ)
/// the whirl per unit unbalance turning at Ω.
fn response_ratio(mass: f64, stiffness: f64, damping: f64, omega: f64) -> f64 {
    let h = |w: f64| w * w / (stiffness - mass * w * w).hypot(damping * w);
    h(2.0 * omega) / h(omega)
}

/// The first of the checks that applies.
pub fn first_cause(plan: &StudyPlan, design: &Design, facts: &DesignFacts) -> Cause {
    let bands = bands(plan, facts);
    for &(plane, a_ref) in &bands {
        let band = settling_band(plan, a_ref);
        let p = plane.unwrap_or(0);
        // The runs' own dead bands, at their median drawn μ_s when uncertain.
        if let Some(dead) =
            dead_band_at(plan, design, p, facts.breakaway_median).filter(|&d| d >= band)
        {
            return Cause::DeadBand {
                dead,
                track_radius: plane_track_radius(design, p),
                band,
                a_ref,
                plane,
            };
        }
    }
    if let Some((floor, what)) = plan.file.scene.effects.whirl_floor() {
        for &(plane, a_ref) in &bands {
            let band = settling_band(plan, a_ref);
            if floor >= band {
                return Cause::WhirlFloor {
                    floor,
                    what,
                    band,
                    a_ref,
                    plane,
                };
            }
        }
    }
    if facts.over_capacity_share >= 0.5 {
        return Cause::OverCapacity {
            capacity: design.capacity,
            share: facts.over_capacity_share,
        };
    }
    let omega = plan.file.scene.speed.nominal_speed();
    if let Some((critical, several)) = critical_speed(plan, design).filter(|&(w, _)| omega <= w) {
        return Cause::BelowCritical {
            omega,
            critical,
            several,
        };
    }
    let scene = plan.scene(
        design,
        facts.unbalance_fraction_median * design.capacity,
        0.0,
    );
    if let Some(g) = plan.file.scene.effects.gravity.as_ref() {
        let swing = g.in_plane() / (design.track_radius * omega * omega);
        // Off the plane rotor the response ratio is taken as 1 (well above
        // resonance both are about 1/M).
        let ratio = scene.rotor.as_rotor().isotropic_plane().map_or(1.0, |r| {
            let weights = design.weight_mass * f64::from(design.spec.n);
            response_ratio(r.mass + weights, r.stiffness, r.damping, omega)
        });
        let delta = plan.file.metrics.delta;
        let whirl = gravity_whirl(swing, facts.unbalance_fraction_median, ratio);
        if whirl >= delta {
            return Cause::Gravity {
                swing,
                whirl_over_a_ref: whirl,
                delta,
            };
        }
    }
    // Gravity below the band and friction (whose regularised sign no
    // finite-difference Jacobian resolves) are left out of the linear
    // analysis: the equations would not be autonomous in the rotating frame.
    let mut scene = scene;
    scene.effects.gravity = None;
    scene.effects.rolling_resistance = None;
    if plan.file.scene.speed.is_prescribed()
        && let Ok(family) = scene
            .build()
            .map_err(|_| ())
            .and_then(|s| family_stability(&s).map_err(|_| ()))
    {
        // Unstable only where every point of the balanced family tried is:
        // a run may settle anywhere on it, not only at the symmetric fan.
        let Some(stable) = family.fastest_stable() else {
            return Cause::Unstable {
                omega,
                points: family.points.len(),
                sigma_fan: family
                    .at_fan()
                    .or(family.points.first())
                    .map_or(f64::NAN, |r| r.slowest_decay),
            };
        };
        // From the locked start the whirl is up to (U + C)/U times A_ref.
        let from = 1.0 + 1.0 / facts.unbalance_fraction_median.max(f64::MIN_POSITIVE);
        let needed_revs = stable.settling_time(from, plan.file.metrics.delta) * omega
            / (2.0 * std::f64::consts::PI);
        let horizon_revs = plan.file.metrics.t_end_revs - plan.file.metrics.hold_revs;
        if needed_revs >= horizon_revs {
            return Cause::HorizonTooShort {
                sigma: stable.slowest_decay,
                needed_revs,
                horizon_revs,
                fan_unstable: family
                    .at_fan()
                    .filter(|r| !r.stable)
                    .map(|_| (family.stable_count(), family.points.len())),
            };
        }
    }
    Cause::NoneFound
}

/// The rotor's lowest critical speed with the weights' mass carried (any
/// rotor model), and whether it has more than one; `None` when it has none.
fn critical_speed(plan: &StudyPlan, design: &Design) -> Option<(f64, bool)> {
    let system = plan.scene(design, 0.0, 0.0).build().ok()?;
    let speeds = critical_speeds_in_range(&system)?;
    Some((*speeds.first()?, speeds.len() > 1))
}
