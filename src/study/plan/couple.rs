//! Couple unbalance of a rotor on two supports (`[sampling.couple]`): the
//! part of a load's unbalance that tilts the rotor, which a balancer in one
//! plane cannot cancel (seed 003).
//!
//! A study samples, per run, a static part U_s at direction θ_s
//! (`sampling.unbalance`, `sampling.direction`) and, with this table, a
//! couple part U_c at direction θ_c. Both are per-plane unbalances (kg·m):
//! the first balancer plane takes U_s e^{iθ_s} + U_c e^{iθ_c}, the second
//! U_s e^{iθ_s} − U_c e^{iθ_c}. The couple is then a moment U_c (z₁ − z₂)
//! about the centre between the planes, and without this table (U_c = 0)
//! every plane takes U_s, as before. The couple is drawn either on its own
//! (`unbalance`, `phase`) or tied to the static part (`follows_static = c`:
//! U_c = c·U_s at θ_s, what one load at one axial position gives: a load
//! at z splits into the planes as U (z₂ − z)/(z₂ − z₁) and
//! U (z − z₁)/(z₂ − z₁), so c = (z₁ + z₂ − 2z)/(z₂ − z₁), in [−1, 1]
//! between the planes). Its stream is its own ([`Purpose::Couple`]), so the
//! static draws, and every study without the table, are unchanged; common
//! random numbers hold as for the static part.

use crate::invalid_key::InvalidKey;
use crate::model::rotor::RotorModel;
use crate::model::rotor::two_support::PointUnbalance;
use crate::study::plan::design::Design;
use crate::study::plan::distribution::{DirectionSpec, Scale, UnbalanceSpec, draw_value};
use crate::study::plan::stream::{Purpose, RunStreams};
use rand::RngExt;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};
use std::f64::consts::PI;

/// `[sampling.couple]`: how the couple part is drawn.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct CoupleSpec {
    /// Its magnitude U_c per plane, with `relative_to` as for the static part.
    #[serde(default)]
    pub unbalance: Option<UnbalanceSpec>,
    /// Its direction θ_c: "uniform" (default) or `{ fixed = degrees }`.
    #[serde(default)]
    pub phase: DirectionSpec,
    /// Instead of `unbalance` and `phase`: U_c = this × U_s, at θ_s (one load
    /// at one axial position; see the module documentation).
    #[serde(default)]
    pub follows_static: Option<f64>,
    /// Axial positions z₁, z₂ (m) of the two planes the static ± couple
    /// parts sit in; default the rotor's two balancer planes. Given, the
    /// rotor may carry one balancer plane: a single balancer against a
    /// load's static and couple unbalance.
    #[serde(default)]
    pub at: Option<crate::pair::Pair>,
}

/// The balancer planes' axial positions of a rotor on two supports.
fn rotor_planes(rotor: &RotorModel) -> &[f64] {
    match rotor {
        RotorModel::TwoSupport(r) => &r.planes,
        _ => &[],
    }
}

/// Two balancer planes in one axial position, where the couple's parts
/// ±U_c would cancel: the same refusal as `at = [z, z]`.
fn coincident_planes(rotor: &RotorModel) -> bool {
    matches!(rotor_planes(rotor), [a, b] if a == b)
}

/// A couple part as drawn for one run.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampledCouple {
    /// U_c (kg·m per plane; negative only when it follows the static part
    /// with a negative factor, i.e. it points opposite θ_s).
    pub unbalance: f64,
    /// U_c over the design's capacity.
    pub fraction: f64,
    /// θ_c (degrees, as recorded: `couple_direction_deg`).
    pub direction_deg: f64,
}

/// Check the table against the rotor: a key, its value and the reason on failure.
pub fn validate(
    spec: &CoupleSpec,
    rotor: &RotorModel,
    check_distribution: impl Fn(&UnbalanceSpec) -> Result<(), InvalidKey>,
) -> Result<(), InvalidKey> {
    let planes = match rotor {
        RotorModel::TwoSupport(r) => Some(r.planes.len()),
        _ => None,
    };
    match (planes, spec.at) {
        (None, _) => {
            return Err(InvalidKey::new(
                "sampling.couple",
                format!("rotor.model = \"{}\"", rotor.as_rotor().name()),
                "a couple unbalance needs a rotor on two supports (rotor.model = \"two_support\")",
            ));
        }
        (Some(n), None) if n != 2 => {
            return Err(InvalidKey::new(
                "sampling.couple.at",
                "(missing)",
                format!(
                    "the rotor has {n} balancer plane(s): give the axial positions [z1, z2] (m) of the two planes the static and couple parts sit in"
                ),
            ));
        }
        (Some(2), None) if coincident_planes(rotor) => {
            return Err(InvalidKey::new(
                "scene.rotor.planes",
                format!("{:?}", rotor_planes(rotor)),
                "a couple unbalance needs two distinct balancer planes: in one axial position the couple has no moment (or give sampling.couple.at)",
            ));
        }
        (_, Some(crate::pair::Pair([a, b]))) if !(a.is_finite() && b.is_finite() && a != b) => {
            return Err(InvalidKey::new(
                "sampling.couple.at",
                format!("[{a}, {b}]"),
                "two distinct finite axial positions (m)",
            ));
        }
        _ => {}
    }
    match (&spec.unbalance, spec.follows_static) {
        (Some(_), Some(c)) => Err(InvalidKey::new(
            "sampling.couple.follows_static",
            c.to_string(),
            "give either `unbalance` (drawn on its own) or `follows_static` (tied to the static part), not both",
        )),
        (None, None) => Err(InvalidKey::new(
            "sampling.couple",
            "{}",
            "give `unbalance` (a distribution with relative_to, drawn on its own) or `follows_static` (U_c = factor × U_s)",
        )),
        (None, Some(c)) if !c.is_finite() => Err(InvalidKey::new(
            "sampling.couple.follows_static",
            c.to_string(),
            "must be finite (−1 to 1 for a load between the planes)",
        )),
        (None, Some(_)) => match spec.phase {
            DirectionSpec::Uniform => Ok(()),
            DirectionSpec::Fixed(d) => Err(InvalidKey::new(
                "sampling.couple.phase",
                d.to_string(),
                "a couple that follows the static part has its direction; leave phase out",
            )),
        },
        (Some(u), None) => {
            if u.relative_to.is_none() {
                return Err(InvalidKey::new(
                    "sampling.couple.unbalance.relative_to",
                    "(missing)",
                    "required: \"capacity\" (fractions of each plane's design capacity) or \"absolute\" (kg·m per plane)",
                ));
            }
            check_distribution(u)?;
            match spec.phase {
                DirectionSpec::Fixed(d) if !d.is_finite() => Err(InvalidKey::new(
                    "sampling.couple.phase.fixed",
                    d.to_string(),
                    "must be finite",
                )),
                _ => Ok(()),
            }
        }
    }
}

/// The couple part of sample `sample` of `design`, given the static part
/// (U_s, θ_s) drawn for it.
pub fn draw(
    spec: &CoupleSpec,
    streams: &RunStreams,
    design: &Design,
    sample: u64,
    static_part: (f64, f64),
) -> SampledCouple {
    let (u_s, theta_s) = static_part;
    if let Some(c) = spec.follows_static {
        let unbalance = c * u_s;
        return SampledCouple {
            unbalance,
            fraction: unbalance / design.capacity,
            direction_deg: theta_s.to_degrees(),
        };
    }
    let spec_u = spec
        .unbalance
        .as_ref()
        .expect("validated: unbalance or follows_static");
    let mut rng = streams.draws(sample, Purpose::Couple);
    let value = draw_value(&spec_u.distribution, &mut rng);
    let (unbalance, fraction) = match spec_u.scale() {
        Scale::Capacity => (value * design.capacity, value),
        Scale::Absolute => (value, value / design.capacity),
    };
    let direction = match spec.phase {
        DirectionSpec::Uniform => 2.0 * PI * rng.random::<f64>(),
        DirectionSpec::Fixed(deg) => deg.to_radians(),
    };
    SampledCouple {
        unbalance,
        fraction,
        direction_deg: direction.to_degrees(),
    }
}

/// The per-plane unbalances (magnitude kg·m, direction rad) of a static
/// part and a couple part: U_s e^{iθ_s} ± U_c e^{iθ_c}.
pub fn plane_unbalances(static_part: (f64, f64), couple: &SampledCouple) -> [(f64, f64); 2] {
    let s = num_complex::Complex64::from_polar(static_part.0, static_part.1);
    let c = num_complex::Complex64::from_polar(couple.unbalance, couple.direction_deg.to_radians());
    [s + c, s - c].map(|u| (u.norm(), u.arg()))
}

/// Put the per-plane unbalances on the rotor at `at` (default its two
/// balancer planes, in order), replacing the static part it was given.
pub fn apply(rotor: &mut RotorModel, at: Option<[f64; 2]>, planes: &[(f64, f64); 2]) {
    if let RotorModel::TwoSupport(r) = rotor {
        let z = at.unwrap_or_else(|| [r.planes[0], r.planes[1]]);
        r.static_unbalance = 0.0;
        r.moment_unbalance = 0.0;
        r.unbalances = z
            .iter()
            .zip(planes)
            .map(|(&z, &(s, angle))| PointUnbalance { s, z, angle })
            .collect();
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn plane_unbalances_are_static_plus_and_minus_couple() {
        let couple = SampledCouple {
            unbalance: 0.5,
            fraction: 0.0,
            direction_deg: 90.0,
        };
        let [a, b] = plane_unbalances((1.0, 0.0), &couple);
        let expect = (1.0f64 + 0.25).sqrt();
        assert!((a.0 - expect).abs() < 1e-15 && (b.0 - expect).abs() < 1e-15);
        assert!((a.1 - 0.5f64.atan()).abs() < 1e-15);
        assert!((b.1 + 0.5f64.atan()).abs() < 1e-15);
        // A couple that follows the static part with factor c: (1 ± c) U_s at θ_s.
        let tied = SampledCouple {
            unbalance: -0.25,
            fraction: 0.0,
            direction_deg: 1f64.to_degrees(),
        };
        let [a, b] = plane_unbalances((2.0, 1.0), &tied);
        // (θ_c goes through degrees and back: a few ulps.)
        assert!((a.0 - 1.75).abs() < 1e-14 && (b.0 - 2.25).abs() < 1e-14);
        assert!((a.1 - 1.0).abs() < 1e-14 && (b.1 - 1.0).abs() < 1e-14);
    }
}
