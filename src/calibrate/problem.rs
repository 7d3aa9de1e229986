//! The calibration problem, apart from how it is solved: for values of the
//! rig's unknowns, the model's prediction of every measured point. A value
//! is set in the scene file through its serialized form (as an uncertain
//! key is), so any float key of the scene can be an unknown or a case's
//! setting with no code of its own; the scene's own checks judge it.

use super::rig_file::{Point, Protocol, Quantity, RigFile, Run};
use crate::invalid_key::InvalidKey;
use crate::scene_file::SceneFile;
use crate::simulation::Simulation;
use crate::simulation::stepped::{Direction, StepPoint, stepped_speeds};
use crate::uncertain::{UncertainDistribution, UncertainValue, apply, read};
use rayon::prelude::*;
use std::collections::HashMap;
use std::f64::consts::PI;
use std::sync::{Arc, Mutex};

/// A point's prediction, or why the model could not make it.
pub type Prediction = Result<f64, String>;

/// The rig's scene, unknowns, cases and points, ready to predict.
#[derive(Debug)]
pub struct RigProblem {
    /// The rig file.
    pub rig: RigFile,
    /// The scene file (its own `[uncertain]` table dropped: the rig's
    /// unknowns take its place).
    scene: SceneFile,
    /// The scene's path as shown in messages.
    scene_shown: String,
    /// Predictions already made, by the unknowns' values (bit patterns):
    /// repeated calibrations on synthetic data revisit the prior draws.
    memo: Mutex<HashMap<Vec<u64>, Arc<Vec<Prediction>>>>,
}

impl RigProblem {
    /// The problem of `rig` over `scene`; refuses (naming the rig file's
    /// key) an unknown or a case setting the scene does not hold as a
    /// float, and an end of an unknown's prior that makes the scene invalid.
    pub fn new(rig: RigFile, mut scene: SceneFile, scene_shown: &str) -> Result<Self, InvalidKey> {
        scene.uncertain.clear();
        scene
            .simulation(scene_shown)
            .map_err(|e| InvalidKey::new("scene", scene_shown, e.to_string()))?;
        let problem = RigProblem {
            rig,
            scene,
            scene_shown: scene_shown.to_string(),
            memo: Mutex::new(HashMap::new()),
        };
        problem.check_keys()?;
        problem.check_light_spots()?;
        Ok(problem)
    }

    /// A ball offset is read from the light spot: refuse a point whose
    /// case has no static unbalance to put one opposite.
    fn check_light_spots(&self) -> Result<(), InvalidKey> {
        for (k, p) in self.rig.points.iter().enumerate() {
            let Some(i) = self.rig.cases.iter().position(|c| c.name == p.case) else {
                continue;
            };
            if p.quantity != Quantity::BallOffsetDeg {
                continue;
            }
            let sim = self
                .case_scene(i, &[])
                .map_err(|why| InvalidKey::new(format!("point[{k}].case"), &p.case, why))?;
            if sim.scene.rotor.as_rotor().static_unbalance().0 <= 0.0 {
                return Err(InvalidKey::new(
                    format!("point[{k}].quantity"),
                    p.quantity.name(),
                    format!(
                        "case \"{}\" has no static unbalance, so no light spot to measure the balls from",
                        p.case
                    ),
                ));
            }
        }
        Ok(())
    }

    fn check_keys(&self) -> Result<(), InvalidKey> {
        for (i, case) in self.rig.cases.iter().enumerate() {
            for (key, value) in &case.set {
                let named = format!("case[{i}].set.\"{key}\"");
                read(&self.scene, key).map_err(|why| InvalidKey::new(&named, key, why))?;
                self.case_scene(i, &[])
                    .map_err(|why| InvalidKey::new(&named, value.to_string(), why))?;
            }
        }
        for (key, d) in &self.rig.unknowns {
            let named = format!("unknowns.\"{key}\"");
            read(&self.scene, key).map_err(|why| InvalidKey::new(&named, key, why))?;
            let (lo, hi) = d.support();
            for (end, value) in [("lowest", lo), ("highest", hi)] {
                let one = [UncertainValue {
                    key: Arc::from(key.as_str()),
                    value,
                }];
                for i in 0..self.rig.cases.len() {
                    self.case_scene(i, &one).map_err(|why| {
                        InvalidKey::new(
                            &named,
                            value.to_string(),
                            format!("the {end} value of the prior is not a valid scene: {why}"),
                        )
                    })?;
                }
            }
        }
        Ok(())
    }

    /// The unknowns' keys, in the order of every value vector.
    pub fn keys(&self) -> Vec<&str> {
        self.rig.unknowns.keys().map(String::as_str).collect()
    }

    /// The unknowns' priors, in key order.
    pub fn priors(&self) -> Vec<&UncertainDistribution> {
        self.rig.unknowns.values().collect()
    }

    /// The unknowns' values at unit-cube coordinates `u` (each through its
    /// prior's inverse CDF).
    pub fn values_at(&self, u: &[f64]) -> Vec<f64> {
        self.priors()
            .iter()
            .zip(u)
            .map(|(d, &u)| d.quantile(u.clamp(0.0, 1.0 - f64::EPSILON)))
            .collect()
    }

    /// Case `i`'s simulation with the unknowns at `values`.
    fn case_scene(&self, i: usize, values: &[UncertainValue]) -> Result<Simulation, String> {
        let case = &self.rig.cases[i];
        let set: Vec<UncertainValue> = case
            .set
            .iter()
            .map(|(key, &value)| UncertainValue {
                key: Arc::from(key.as_str()),
                value,
            })
            .chain(values.iter().cloned())
            .collect();
        let file = apply(&self.scene, &set)?;
        file.simulation(&self.scene_shown)
            .map_err(|e| e.to_string())
    }

    /// Every point's prediction with the unknowns at `values` (one run or
    /// sweep per case, the cases in parallel).
    pub fn predict(&self, values: &[f64]) -> Arc<Vec<Prediction>> {
        self.predict_cases(values, false)
    }

    /// The fitted points' predictions only (the cases with no fitted point
    /// are not run: their points read "not run"), for the fit's search.
    pub fn predict_fitted(&self, values: &[f64]) -> Arc<Vec<Prediction>> {
        self.predict_cases(values, true)
    }

    fn predict_cases(&self, values: &[f64], fitted_only: bool) -> Arc<Vec<Prediction>> {
        let bits: Vec<u64> = values.iter().map(|v| v.to_bits()).collect();
        let full_key = [bits.as_slice(), &[0]].concat();
        let memo_key = [bits.as_slice(), &[u64::from(fitted_only)]].concat();
        {
            let memo = self.memo.lock().expect("memo lock");
            // A full prediction serves a fitted-only request as well.
            if let Some(hit) = memo.get(&full_key).or_else(|| memo.get(&memo_key)) {
                return Arc::clone(hit);
            }
        }
        let set: Vec<UncertainValue> = self
            .keys()
            .iter()
            .zip(values)
            .map(|(key, &value)| UncertainValue {
                key: Arc::from(*key),
                value,
            })
            .collect();
        let fitted = |i: usize| {
            let name = &self.rig.cases[i].name;
            self.rig
                .points
                .iter()
                .any(|p| p.role == super::rig_file::Use::Fit && &p.case == name)
        };
        let per_case: Vec<Result<Observed, String>> = (0..self.rig.cases.len())
            .into_par_iter()
            .map(|i| {
                if fitted_only && !fitted(i) {
                    return Err("not run: the case has no fitted point".into());
                }
                self.case_scene(i, &set).and_then(|sim| self.observe(&sim))
            })
            .collect();
        let predictions: Vec<Prediction> = self
            .rig
            .points
            .iter()
            .map(|p| {
                let case = self.rig.cases.iter().position(|c| c.name == p.case);
                match case.map(|i| &per_case[i]) {
                    Some(Ok(observed)) => self.read_point(p, observed),
                    Some(Err(why)) => Err(why.clone()),
                    None => Err(format!("no case {}", p.case)),
                }
            })
            .collect();
        let shared = Arc::new(predictions);
        self.memo
            .lock()
            .expect("memo lock")
            .insert(memo_key, Arc::clone(&shared));
        shared
    }

    /// What the protocol measures on one case's simulation.
    fn observe(&self, sim: &Simulation) -> Result<Observed, String> {
        match self.rig.protocol {
            Protocol::Run => {
                let m = sim.run(false).map_err(|e| e.to_string())?.metrics;
                use crate::metrics::Outcome;
                if matches!(
                    m.outcome,
                    Outcome::Diverged | Outcome::BudgetExceeded | Outcome::SolverFailed
                ) {
                    return Err(format!("the run failed: {}", m.reason));
                }
                Ok(Observed::Run {
                    settling_time: m.settling_time.unwrap_or(m.t_final),
                    residual: m.residual_abs,
                })
            }
            Protocol::Stepped {
                rpm,
                step_rpm,
                dwell,
                window,
                down,
            } => {
                let to_omega = PI / 30.0;
                let speeds = stepped_speeds(
                    rpm[0] * to_omega,
                    rpm[1] * to_omega,
                    step_rpm * to_omega,
                    down,
                );
                let steps = sim
                    .stepped_sweep_windowed(&speeds, dwell, window, None)
                    .map_err(|e| e.to_string())?;
                let (size, angle) = sim.scene.rotor.as_rotor().static_unbalance();
                Ok(Observed::Stepped {
                    steps,
                    top_rpm: rpm[1],
                    light_spot: (size > 0.0).then_some(angle + PI),
                })
            }
        }
    }

    /// One point's value from its case's observation.
    fn read_point(&self, p: &Point, observed: &Observed) -> Prediction {
        match (observed, p.quantity) {
            (Observed::Run { settling_time, .. }, Quantity::SettlingTime) => Ok(*settling_time),
            (Observed::Run { residual, .. }, Quantity::Residual) => Ok(*residual),
            (Observed::Stepped { steps, top_rpm, .. }, Quantity::OnsetRpm) => {
                Ok(crate::study::stepped_bands::onset(steps).map_or(*top_rpm, |w| w * 30.0 / PI))
            }
            (
                Observed::Stepped {
                    steps, light_spot, ..
                },
                q,
            ) => {
                if q == Quantity::BallOffsetDeg && light_spot.is_none() {
                    return Err(
                        "the case has no static unbalance: no light spot to measure the balls from"
                            .into(),
                    );
                }
                let [lo, hi] = p.rpm.unwrap_or([0.0, f64::INFINITY]);
                let tol = 1e-6 * hi.abs().max(1.0);
                let in_band: Vec<f64> = steps
                    .iter()
                    .filter(|s| match p.run {
                        Run::Up => s.direction == Direction::Up,
                        Run::Down => s.direction == Direction::Down,
                        Run::Both => true,
                    })
                    .filter(|s| {
                        let r = s.omega * 30.0 / PI;
                        r >= lo - tol && r <= hi + tol
                    })
                    .filter_map(|s| step_value(s, q, *light_spot))
                    .collect();
                if in_band.is_empty() {
                    return Err(format!(
                        "no {} step of the sweep lies in {lo}..{hi} rpm",
                        match p.run {
                            Run::Up => "run-up",
                            Run::Down => "run-down",
                            Run::Both => "",
                        }
                    ));
                }
                Ok(in_band.iter().sum::<f64>() / in_band.len() as f64)
            }
            (Observed::Run { .. }, q) => Err(format!("{} needs a stepped sweep", q.name())),
        }
    }
}

/// A step's bearing peak (the bearings' mean), its ratio to the same
/// without the balls' unbalance, or the balls' offset from the light spot.
fn step_value(s: &StepPoint, q: Quantity, light_spot: Option<f64>) -> Option<f64> {
    if q == Quantity::BallOffsetDeg {
        return ball_offset_deg(&s.angles_deg, light_spot?);
    }
    let mean = |v: &[f64]| v.iter().sum::<f64>() / v.len().max(1) as f64;
    let with = mean(s.bearing_peak.as_deref()?);
    let without = mean(s.bearing_peak_without.as_deref()?);
    let v = match q {
        Quantity::BearingPeak => with,
        _ => with / without,
    };
    v.is_finite().then_some(v)
}

/// How far (degrees, 0–180, either way) the weights' mean direction sits
/// from the light spot (radians, rotor frame): a rig photographing its
/// balls reads this, since balanced balls straddle the light spot
/// symmetrically. None when the weights' directions cancel (no mean).
fn ball_offset_deg(angles_deg: &[f64], light_spot: f64) -> Option<f64> {
    let (sin, cos) = angles_deg
        .iter()
        .map(|a| a.to_radians().sin_cos())
        .fold((0.0, 0.0), |(s, c), (si, ci)| (s + si, c + ci));
    if sin.hypot(cos) < 1e-9 * angles_deg.len() as f64 {
        return None;
    }
    let offset = (sin.atan2(cos) - light_spot).rem_euclid(2.0 * PI);
    Some(offset.min(2.0 * PI - offset).to_degrees())
}

/// What one case's run or sweep measured.
#[derive(Debug)]
enum Observed {
    Run {
        settling_time: f64,
        residual: f64,
    },
    Stepped {
        steps: Vec<StepPoint>,
        top_rpm: f64,
        /// The static unbalance's opposite (rotor frame, radians); None
        /// without a static unbalance.
        light_spot: Option<f64>,
    },
}

#[cfg(test)]
mod tests {
    use super::ball_offset_deg;
    use std::f64::consts::PI;

    #[test]
    fn balls_straddling_the_light_spot_have_no_offset_and_a_turned_pair_has_its_turn() {
        // Light spot at 90°: balls at 90 ± 40° are balanced, at 90 − 18 ± 40°
        // turned clockwise by 18°, the same size read either way.
        let spot = PI / 2.0;
        assert!(ball_offset_deg(&[50.0, 130.0], spot).unwrap() < 1e-12);
        let turned = ball_offset_deg(&[32.0, 112.0], spot).unwrap();
        assert!((turned - 18.0).abs() < 1e-9, "{turned}");
        let other_way = ball_offset_deg(&[68.0, 148.0], spot).unwrap();
        assert!((other_way - 18.0).abs() < 1e-9, "{other_way}");
        // Across 0°/360° and at the far side: 180°, never more.
        let wrapped = ball_offset_deg(&[350.0, 30.0], 0.0).unwrap();
        assert!((wrapped - 10.0).abs() < 1e-9, "{wrapped}");
        assert!((ball_offset_deg(&[250.0, 290.0], spot).unwrap() - 180.0).abs() < 1e-9);
    }

    #[test]
    fn opposite_balls_have_no_mean_direction() {
        assert_eq!(ball_offset_deg(&[10.0, 190.0], 0.0), None);
    }
}
