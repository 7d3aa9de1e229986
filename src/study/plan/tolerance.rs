//! Manufacturing tolerances of the weights, sampled per run (issue 19, item 3).
//!
//! `[sampling.tolerances]` gives each weight's mass and radius a normal
//! spread about the design's nominal value, truncated at ±`limit`·σ (draws
//! beyond are redrawn, as a supplier's sorting would reject them). Every
//! weight of every run gets its own draw, from streams of their own
//! ([`Purpose::MassTolerance`], [`Purpose::RadiusTolerance`]): the unbalance,
//! direction and start draws are untouched, so a study without the table
//! gives bit-identical results, and with common random numbers sample k of
//! every design meets the same standardised deviations (weight j of a design
//! with fewer weights takes the j-th draw).
//!
//! Physically, what matters is each weight's unbalance m_j l_j: mismatched
//! weights can still cancel an unbalance that lies inside the set of sums
//! Σ m_j l_j e^{iψ_j} they can form, but not one outside it (two weights
//! cannot cancel an unbalance below |m₁l₁ − m₂l₂|, and pressed-together
//! weights reach a capacity that shifts with the draws). A weight's radius r
//! moves both: rolling in a common race of radius R its centre runs at
//! l = R − r and its mass grows as r³ (balls) or r² (rollers), so a radius
//! tolerance rebuilds the weight from its kind's model at r_j; a mass
//! tolerance (density, bores, inclusions) scales the mass at fixed geometry.
//!
//! Race eccentricity (issue 19, item 2) is a property of the race, not of a
//! weight: `eccentricity = { sigma }` draws the race centre's offset as two
//! independent truncated normals (x, y in the rotor frame, σ each, so the
//! offset's size is Rayleigh-distributed) from a stream of its own
//! ([`Purpose::EccentricityTolerance`]), adds it to the scene's nominal
//! `[effects.race_eccentricity]` if any, and records it in the columns
//! `race_offset` (m) and `race_angle_deg`. The effect models the plane rotor
//! at a prescribed speed; other studies are refused when validated.

use crate::invalid_key::InvalidKey;
use crate::model::balancer::Geometry;
use crate::model::cargo::Cargo;
use crate::model::effect::SceneFacts;
use crate::model::effect::race_eccentricity::RaceEccentricity;
use crate::model::scene::Scene;
use crate::study::plan::design::Design;
use crate::study::plan::stream::{Purpose, RunStreams};
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// `[sampling.tolerances]`: which properties of the weights are sampled.
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Tolerances {
    /// Spread of each weight's mass at fixed geometry (kg; a fraction of the
    /// nominal mass with `relative = true`).
    #[serde(default)]
    pub mass: Option<Tolerance>,
    /// Spread of each weight's radius r (m; a fraction of the nominal r with
    /// `relative = true`): the weight is rebuilt at r_j, so its track radius
    /// l = R − r_j, its mass and its contact size follow.
    #[serde(default)]
    pub radius: Option<Tolerance>,
    /// Spread of the race centre's offset from the rotation axis, per axis
    /// of the rotor frame (m; absolute only): see
    /// [`crate::model::effect::race_eccentricity`].
    #[serde(default)]
    pub eccentricity: Option<Tolerance>,
}

/// A normal spread truncated at ±`limit`·σ.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct Tolerance {
    /// Standard deviation σ (kg for masses, m for radii; a fraction of the
    /// nominal value with `relative = true`), ≥ 0.
    pub sigma: f64,
    /// True: `sigma` is a fraction of the nominal value; false (default): in
    /// the quantity's unit.
    #[serde(default)]
    pub relative: bool,
    /// Truncation in standard deviations: draws beyond ±limit·σ are redrawn
    /// (default 3, in [0.01, 10]).
    #[serde(default = "default_limit")]
    pub limit: f64,
}

fn default_limit() -> f64 {
    3.0
}

impl Tolerance {
    /// The value `nominal` moved by `z` standard deviations.
    fn apply(&self, nominal: f64, z: f64) -> f64 {
        if self.relative {
            nominal * (1.0 + self.sigma * z)
        } else {
            nominal + self.sigma * z
        }
    }

    /// The largest deviation it allows from `nominal` (limit·σ, in its unit).
    fn reach(&self, nominal: f64) -> f64 {
        let spread = self.limit * self.sigma;
        if self.relative {
            spread * nominal
        } else {
            spread
        }
    }
}

/// The weights one run was built with, one entry per weight (every plane, in
/// cargo order): the columns `weight_masses`, `weight_radii`, `track_radii`.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct SampledWeights {
    /// Mass m_j (kg).
    pub masses: Vec<f64>,
    /// Radius r_j (m); 0 for weights without a size.
    pub radii: Vec<f64>,
    /// Track radius l_j of the centre of mass (m).
    pub track_radii: Vec<f64>,
    /// The race centre's offset (m) and its direction (degrees) when the
    /// study samples it or the scene sets one.
    pub race: Option<(f64, f64)>,
}

/// A bad tolerance: (key under `sampling.tolerances`, value, reason).
pub type ToleranceError = InvalidKey;

/// Check the table against its domain and against every design (masses
/// and radii stay positive, the largest weights still fit, every radius in
/// reach builds a weight of the design's kind) and the scene (`facts`: race
/// eccentricity needs the plane rotor at a prescribed speed).
pub fn validate(
    t: &Tolerances,
    designs: &[Design],
    facts: &SceneFacts,
) -> Result<(), ToleranceError> {
    if let Some(tol) = &t.eccentricity {
        let key = |k: &str| format!("eccentricity.{k}");
        check_spread("eccentricity", tol)?;
        if tol.relative {
            return Err(InvalidKey::new(
                key("relative"),
                "true",
                "an offset has no nominal size to be relative to: give sigma in m",
            ));
        }
        if !facts.prescribed_speed {
            return Err(InvalidKey::new(
                key("sigma"),
                tol.sigma.to_string(),
                "race eccentricity is modelled at a prescribed speed (constant or ramp) only",
            ));
        }
    }
    // Radius first: it sets the lightest nominal mass the mass tolerance meets.
    for (name, tol) in [("radius", &t.radius), ("mass", &t.mass)] {
        let Some(tol) = tol else { continue };
        let key = |k: &str| format!("{name}.{k}");
        check_spread(name, tol)?;
        if tol.relative && tol.limit * tol.sigma >= 1.0 {
            return Err(InvalidKey::new(
                key("sigma"),
                tol.sigma.to_string(),
                format!(
                    "limit × sigma = {} reaches −100 % of the nominal value; keep it below 1",
                    tol.limit * tol.sigma
                ),
            ));
        }
        // Every plane's balancer, where planes have designs of their own.
        for d in designs
            .iter()
            .flat_map(|d| std::iter::once(d).chain(&d.plane_designs))
        {
            let nominal = match name {
                "mass" => lightest_mass(t, d),
                _ => d.spec.race_radius * d.rho,
            };
            let reach = tol.reach(nominal);
            if reach >= nominal {
                return Err(InvalidKey::new(
                    key("sigma"),
                    tol.sigma.to_string(),
                    format!(
                        "limit × sigma = {reach:.4e} reaches the nominal {name} {nominal:.4e} of design {} ({} n = {} ρ = {:.4}): it must stay positive",
                        d.id, d.spec.kind, d.spec.n, d.rho
                    ),
                ));
            }
            if name == "radius" {
                let extreme = (nominal + reach) / d.spec.race_radius;
                let fits = crate::design::geometry::check_fits(d.spec.n, extreme)
                    .map_err(|e| e.to_string())
                    .and_then(|()| {
                        let g = nominal_geometry(d)?;
                        d.spec
                            .kind
                            .model()
                            .cargo(&Geometry { rho: extreme, ..g })
                            .map(|_| ())
                            .map_err(|e| e.to_string())
                    });
                if let Err(why) = fits {
                    return Err(InvalidKey::new(
                        key("sigma"),
                        tol.sigma.to_string(),
                        format!(
                            "the largest weights (r = {:.4e} m) of design {} ({} n = {} ρ = {:.4}) do not fit: {why}",
                            nominal + reach,
                            d.id,
                            d.spec.kind,
                            d.spec.n,
                            d.rho
                        ),
                    ));
                }
            }
        }
    }
    Ok(())
}

/// σ finite and ≥ 0, the truncation in [0.01, 10] standard deviations (at
/// 0.01 σ, 0.8 % of draws are kept: narrower would leave the redraws
/// under the floor of `truncated::MIN_ACCEPTED_MASS`'s order).
fn check_spread(name: &str, tol: &Tolerance) -> Result<(), ToleranceError> {
    if !(tol.sigma.is_finite() && tol.sigma >= 0.0) {
        return Err(InvalidKey::new(
            format!("{name}.sigma"),
            tol.sigma.to_string(),
            "a standard deviation: finite and ≥ 0",
        ));
    }
    if !(tol.limit >= 0.01 && tol.limit <= 10.0) {
        return Err(InvalidKey::new(
            format!("{name}.limit"),
            tol.limit.to_string(),
            "a truncation in standard deviations, in [0.01, 10] (narrower keeps too few draws to end)",
        ));
    }
    Ok(())
}

/// The nominal mass of design `d`'s lightest weight under the radius
/// tolerance (validated before the mass tolerance is).
fn lightest_mass(t: &Tolerances, d: &Design) -> f64 {
    let Some(tol) = &t.radius else {
        return d.weight_mass;
    };
    let r = d.spec.race_radius * d.rho;
    nominal_geometry(d)
        .ok()
        .and_then(|g| {
            let rho = (r - tol.reach(r)) / d.spec.race_radius;
            d.spec.kind.model().cargo(&Geometry { rho, ..g }).ok()
        })
        .map_or(d.weight_mass, |c| c.mass)
}

fn nominal_geometry(d: &Design) -> Result<Geometry, String> {
    d.spec.geometry().map_err(|e| e.to_string())
}

/// A standard normal draw truncated to [−limit, limit] (redrawn beyond).
fn truncated<R: rand::Rng + ?Sized>(rng: &mut R, limit: f64) -> f64 {
    // Normal(0, 1) draws the same bits as the standard normal (0 + 1·z).
    crate::study::plan::truncated::draw(rng, 0.0, 1.0, -limit, limit)
}

/// Draw the weights of sample `sample` of `design` under the tolerances `t`
/// and put them into `scene` as explicit cargoes (every plane; the plan's
/// scene holds the nominal design). Returns what was drawn.
///
/// The run's streams are passed rather than the plan (as for the couple
/// part) because the study file that holds the tolerances imports this
/// file; [`crate::study::plan::sample::draw_weights`] reads them from the plan.
pub fn apply(
    t: &Tolerances,
    streams: &RunStreams,
    design: &Design,
    sample: u64,
    scene: &mut Scene,
) -> SampledWeights {
    // Plan validation built these for every design and every reachable radius.
    let nominal = scene.cargoes().expect("the plan validated the design");
    // The design of the plane a weight runs in (plane 0's unless planes
    // have designs of their own).
    let design_of = |plane: usize| match plane {
        0 => design,
        p => design.plane_designs.get(p - 1).unwrap_or(design),
    };
    let mut mass_rng = streams.draws(sample, Purpose::MassTolerance);
    let mut radius_rng = streams.draws(sample, Purpose::RadiusTolerance);
    let mut cargo: Vec<Cargo> = Vec::with_capacity(nominal.len());
    for c in nominal {
        let mut c = match &t.radius {
            Some(tol) => {
                let own = design_of(c.plane);
                let geometry = nominal_geometry(own).expect("the plan validated the design");
                let z = truncated(&mut radius_rng, tol.limit);
                let r = tol.apply(geometry.weight_radius(), z);
                let rebuilt = Geometry {
                    rho: r / geometry.race_radius,
                    ..geometry
                };
                let mut w = own
                    .spec
                    .kind
                    .model()
                    .cargo(&rebuilt)
                    .expect("the plan validated every reachable radius");
                w.plane = c.plane;
                w
            }
            None => c,
        };
        if let Some(tol) = &t.mass {
            let z = truncated(&mut mass_rng, tol.limit);
            let m = tol.apply(c.mass, z);
            // Everything that is proportional to the mass at fixed geometry
            // (rolling terms J_C ∝ m; κ is a ratio and stays).
            let f = m / c.mass;
            c.mass = m;
            c.rolling_coupling *= f;
            c.rolling_inertia *= f;
        }
        cargo.push(c);
    }
    if let Some(tol) = &t.eccentricity {
        let mut rng = streams.draws(sample, Purpose::EccentricityTolerance);
        let (dx, dy) = (
            tol.sigma * truncated(&mut rng, tol.limit),
            tol.sigma * truncated(&mut rng, tol.limit),
        );
        let nominal = scene.effects.race_eccentricity.as_ref();
        let (x0, y0) = nominal.map_or((0.0, 0.0), |e| {
            let a = e.angle_deg.to_radians();
            (e.offset * a.cos(), e.offset * a.sin())
        });
        let plane = nominal.and_then(|e| e.plane);
        let (x, y) = (x0 + dx, y0 + dy);
        scene.effects.race_eccentricity = Some(RaceEccentricity {
            offset: x.hypot(y),
            angle_deg: y.atan2(x).to_degrees(),
            plane,
        });
    }
    let weights = SampledWeights {
        masses: cargo.iter().map(|c| c.mass).collect(),
        radii: cargo.iter().map(|c| c.radius).collect(),
        track_radii: cargo.iter().map(|c| c.track_radius).collect(),
        race: scene
            .effects
            .race_eccentricity
            .as_ref()
            .map(|e| (e.offset, e.angle_deg)),
    };
    scene.balancer = None;
    scene.balancers.clear();
    scene.cargo = cargo;
    weights
}
