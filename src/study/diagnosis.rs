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
//! 5. a horizon too short for the slowest mode, or an unstable balanced
//!    state (the linear analysis of `study linear`).

use super::config::StudyPlan;
use super::design::Design;
use crate::model::critical_speeds::critical_speeds_in_range;
use crate::model::linear::analyse;

/// What the checks measured for one design (every length in m).
#[derive(Debug, Clone, PartialEq)]
pub struct DesignFacts {
    /// Median A_ref over the design's runs.
    pub a_ref_median: f64,
    /// Median sampled unbalance over capacity, U/C.
    pub unbalance_fraction_median: f64,
    /// Share of runs whose sampled unbalance exceeded the capacity.
    pub over_capacity_share: f64,
}

/// The dead band μ_s·l of a design (m), with rolling resistance on.
pub fn dead_band(plan: &StudyPlan, design: &Design) -> Option<f64> {
    let rr = plan.file.scene.effects.rolling_resistance.as_ref()?;
    Some(rr.coefficient * rr.static_ratio * design.track_radius)
}

/// The settling band δ·A_ref (m) at a given A_ref.
pub fn settling_band(plan: &StudyPlan, a_ref: f64) -> f64 {
    plan.file.metrics.delta * a_ref
}

/// The first cause among the checks that applies to `design`, in words with
/// its numbers; a sentence saying none applied otherwise.
pub fn diagnose(plan: &StudyPlan, design: &Design, facts: &DesignFacts) -> String {
    let cause = first_cause(plan, design, facts);
    // Fractions of capacity this small are usually kg·m read as fractions.
    if facts.unbalance_fraction_median < 0.01
        && plan.file.sampling.unbalance.scale() == super::distribution::Scale::Capacity
    {
        return format!(
            "{cause} (note: the median unbalance drawn is {:.1e} of the capacity; if the values were meant in kg·m, set relative_to = \"absolute\")",
            facts.unbalance_fraction_median
        );
    }
    cause
}

/// The first of the checks that applies.
fn first_cause(plan: &StudyPlan, design: &Design, facts: &DesignFacts) -> String {
    let band = settling_band(plan, facts.a_ref_median);
    if let Some(dead) = dead_band(plan, design).filter(|&d| d >= band) {
        return format!(
            "the dead band of rolling resistance μ_s·l = {:.3} µm (l = {:.2} mm the track radius) is as large as the settling band δ·A_ref = {:.3} µm (median A_ref {:.3} µm): the weights stop anywhere inside it; lower μ_s, or judge against a band wider than the dead band",
            dead * 1e6,
            design.track_radius * 1e3,
            band * 1e6,
            facts.a_ref_median * 1e6
        );
    }
    if let Some((floor, why)) = plan
        .file
        .scene
        .effects
        .whirl_floor()
        .filter(|&(f, _)| f >= band)
    {
        return format!(
            "{why} = {:.3} µm, as large as the settling band δ·A_ref = {:.3} µm (median A_ref {:.3} µm): no balancer gets inside it; true the race, or judge against a band wider than the floor (metrics.delta above {:.3})",
            floor * 1e6,
            band * 1e6,
            facts.a_ref_median * 1e6,
            floor / facts.a_ref_median
        );
    }
    if facts.over_capacity_share >= 0.5 {
        return format!(
            "the capacity C = {:.4e} kg·m is below the unbalance drawn in {:.0} % of runs: use more or heavier weights, or a larger race",
            design.capacity,
            100.0 * facts.over_capacity_share
        );
    }
    let omega = plan.file.scene.speed.nominal_speed();
    if let Some((critical, several)) = critical_speed(plan, design).filter(|&(w, _)| omega <= w) {
        let which = if several {
            "lowest critical speed"
        } else {
            "critical speed"
        };
        return format!(
            "the speed ω = {omega:.1} rad/s is at or below the rotor's {which} {critical:.1} rad/s: a passive balancer only balances above it"
        );
    }
    if let Some(g) = plan.file.scene.effects.gravity.as_ref() {
        let ratio = g.in_plane() / (design.track_radius * omega * omega);
        let limit = plan.file.metrics.delta * facts.unbalance_fraction_median;
        if ratio >= limit {
            return format!(
                "gravity pulls the weights round every revolution: g/(l ω²) = {ratio:.3e} is above δ·U/C = {limit:.3e}, so the weights swing by more than the band allows"
            );
        }
    }
    let scene = plan.scene(
        design,
        facts.unbalance_fraction_median * design.capacity,
        0.0,
    );
    if plan.file.scene.speed.is_prescribed()
        && let Ok(report) = scene
            .build()
            .map_err(|_| ())
            .and_then(|s| analyse(&s, None).map_err(|_| ()))
    {
        if !report.stable {
            return format!(
                "the balanced state is linearly unstable at ω = {omega:.1} rad/s (slowest decay rate σ = {:.3e} 1/s; `study linear` on this design shows the growing mode)",
                report.slowest_decay
            );
        }
        // From the locked start the whirl is up to (U + C)/U times A_ref.
        let from = 1.0 + 1.0 / facts.unbalance_fraction_median.max(f64::MIN_POSITIVE);
        let needed = report.settling_time(from, plan.file.metrics.delta) * omega
            / (2.0 * std::f64::consts::PI);
        let horizon = plan.file.metrics.t_end_revs - plan.file.metrics.hold_revs;
        if needed >= horizon {
            return format!(
                "the horizon is too short for the slowest mode: it decays at σ = {:.3e} 1/s and needs about {needed:.0} rev to reach the band, against t_end_revs − hold_revs = {horizon:.0} rev; raise metrics.t_end_revs",
                report.slowest_decay
            );
        }
    }
    "none of the usual causes applies (dead band, capacity, critical speed, gravity, horizon): look at single runs with `study simulate` or `study plot run`".to_string()
}

/// The rotor's lowest critical speed with the weights' mass carried (any
/// rotor model), and whether it has more than one; `None` when it has none.
fn critical_speed(plan: &StudyPlan, design: &Design) -> Option<(f64, bool)> {
    let system = plan.scene(design, 0.0, 0.0).build().ok()?;
    let speeds = critical_speeds_in_range(&system)?;
    Some((*speeds.first()?, speeds.len() > 1))
}
