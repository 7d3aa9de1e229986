//! A run with one effect taken out: the counterfactuals that test why a
//! design's runs do not settle (issue 70). A floor compared with the band
//! says what *could* stop a run settling; re-running the same sample with
//! the effect removed says whether it *does*.
//!
//! Each counterfactual says whether it applies to a run (the effect is
//! there to remove) and removes it, leaving everything else of the run as
//! drawn. Adding an effect to test is one variant here.

use super::Simulation;
use crate::model::rotor::RotorModel;
use crate::model::speed::SpeedLaw;
use crate::model::start::StartMode;

/// One effect removed from a run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub enum Counterfactual {
    /// The race's centre put on the rotation axis (e_r = 0).
    RaceEccentricity,
    /// No rolling resistance (nor pivot friction).
    RollingResistance,
    /// The rotor's unbalance reduced to its static part at the centre of
    /// mass: the moment (couple) about it removed, the total kept.
    Couple,
    /// No gravity in the rotor's plane.
    Gravity,
    /// Weights that pass through each other.
    Contact,
    /// The operating speed from the start: no run-up, no motor's slip.
    SpeedHeld,
}

impl Counterfactual {
    /// Every counterfactual, in the order they are tried and reported.
    pub const ALL: [Counterfactual; 6] = [
        Counterfactual::RaceEccentricity,
        Counterfactual::RollingResistance,
        Counterfactual::Couple,
        Counterfactual::Gravity,
        Counterfactual::Contact,
        Counterfactual::SpeedHeld,
    ];

    /// Its key in `causes.parquet` and `summary.parquet`.
    pub fn key(self) -> &'static str {
        match self {
            Counterfactual::RaceEccentricity => "race_eccentricity",
            Counterfactual::RollingResistance => "rolling_resistance",
            Counterfactual::Couple => "couple",
            Counterfactual::Gravity => "gravity",
            Counterfactual::Contact => "contact",
            Counterfactual::SpeedHeld => "speed_held",
        }
    }

    /// The effect it removes, in words.
    pub fn label(self) -> &'static str {
        match self {
            Counterfactual::RaceEccentricity => "race eccentricity",
            Counterfactual::RollingResistance => "rolling resistance",
            Counterfactual::Couple => "the couple unbalance",
            Counterfactual::Gravity => "gravity",
            Counterfactual::Contact => "contact between the weights",
            Counterfactual::SpeedHeld => "the speed's run-up",
        }
    }

    /// The counterfactual of a key; `None` for one this build does not know.
    pub fn parse(key: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|c| c.key() == key)
    }

    /// Whether the run has the effect to remove.
    pub fn applies(self, run: &Simulation) -> bool {
        let effects = &run.scene.effects;
        match self {
            Counterfactual::RaceEccentricity => effects
                .race_eccentricity
                .as_ref()
                .is_some_and(|e| e.offset != 0.0),
            Counterfactual::RollingResistance => effects
                .rolling_resistance
                .as_ref()
                .is_some_and(|r| r.coefficient != 0.0),
            Counterfactual::Couple => couple_moment(&run.scene.rotor).is_some_and(|m| m != 0.0),
            Counterfactual::Gravity => effects
                .gravity
                .as_ref()
                .is_some_and(|g| g.in_plane() != 0.0),
            Counterfactual::Contact => effects.contact.as_ref().is_some_and(|c| c.enabled),
            Counterfactual::SpeedHeld => !matches!(run.scene.speed, SpeedLaw::Constant { .. }),
        }
    }

    /// Take the effect out of the run; everything else stays as drawn.
    pub fn remove(self, run: &mut Simulation) {
        let effects = &mut run.scene.effects;
        match self {
            Counterfactual::RaceEccentricity => effects.race_eccentricity = None,
            Counterfactual::RollingResistance => effects.rolling_resistance = None,
            Counterfactual::Couple => remove_couple(&mut run.scene.rotor),
            Counterfactual::Gravity => effects.gravity = None,
            Counterfactual::Contact => {
                if let Some(c) = effects.contact.as_mut() {
                    c.enabled = false;
                }
            }
            Counterfactual::SpeedHeld => {
                run.scene.speed = SpeedLaw::Constant {
                    omega: run.scene.speed.nominal_speed(),
                };
                // A run-up start needs a speed that runs up: at constant
                // speed the run starts as a locked steady one.
                if run.start == StartMode::Runup {
                    run.start = StartMode::LockedSteady;
                }
            }
        }
    }
}

impl std::fmt::Display for Counterfactual {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.label())
    }
}

/// The static unbalance (complex, kg·m) and the moment about the centre of
/// mass (complex, kg·m²) of a rotor on two supports; `None` for other models.
fn unbalance_parts(rotor: &RotorModel) -> Option<((f64, f64), (f64, f64))> {
    let RotorModel::TwoSupport(r) = rotor else {
        return None;
    };
    let polar = |s: f64, a: f64| (s * a.cos(), s * a.sin());
    let (mut s, mut m) = (
        polar(r.static_unbalance, r.static_angle),
        polar(r.moment_unbalance, r.moment_angle),
    );
    for u in &r.unbalances {
        let (x, y) = polar(u.s, u.angle);
        s = (s.0 + x, s.1 + y);
        m = (m.0 + u.z * x, m.1 + u.z * y);
    }
    Some((s, m))
}

/// The size of the couple (kg·m²) of a rotor on two supports.
fn couple_moment(rotor: &RotorModel) -> Option<f64> {
    unbalance_parts(rotor).map(|(_, m)| m.0.hypot(m.1))
}

/// Replace a two-support rotor's unbalances by their static resultant at
/// the centre of mass, which exerts no moment about it.
fn remove_couple(rotor: &mut RotorModel) {
    let Some((s, _)) = unbalance_parts(rotor) else {
        return;
    };
    if let RotorModel::TwoSupport(r) = rotor {
        r.static_unbalance = s.0.hypot(s.1);
        r.static_angle = s.1.atan2(s.0);
        r.moment_unbalance = 0.0;
        r.moment_angle = 0.0;
        r.unbalances.clear();
    }
}
