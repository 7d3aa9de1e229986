//! From a parsed study file to a plan: every value checked against its
//! domain (errors name the dotted key), the design grid resolved, and the
//! scene errors mapped onto the study file's keys.

use super::*;

/// Longest study name in bytes (docs/limits.md): a folder name.
pub const MAX_NAME_BYTES: usize = 128;

impl StudyFile {
    /// Parse TOML text (`path` is used in messages only).
    pub fn parse(text: &str, path: &str) -> Result<Self, StudyError> {
        toml::from_str(text).map_err(|e| StudyError::Parse {
            path: path.to_string(),
            message: crate::input_file::toml_message(text, &e),
        })
    }

    /// Validate every value and resolve the design grid.
    pub fn plan(self, text: &str, path: &str) -> Result<StudyPlan, StudyError> {
        let r = Refusal { path };
        let name = self.checked_name(path, &r)?;
        // Planes and weights first: every later check may walk the planes.
        self.check_size_limits(&r)?;
        self.check_statistics(&r)?;
        self.check_sampling_counts(&r)?;
        self.check_sampling_draws(&r)?;
        self.check_metrics_and_solver(&r)?;
        self.check_plane_designs(&r)?;
        self.check_grid_size(&r)?;
        let designs = self.resolve_designs().map_err(|e| r.refused(e))?;
        self.check_tolerances(&designs, &r)?;
        self.check_effects_balanceable(&designs, &r)?;
        self.check_couple_balanceable(&designs, &r)?;
        self.check_absolute_balanceable(&designs, &r)?;
        unbalance_within_reason(&self.sampling, &designs).map_err(|e| r.refused(e))?;
        self.check_total_runs(&designs, &r)?;
        let plan = StudyPlan {
            name,
            file: self,
            designs,
            text: text.to_string(),
        };
        plan.check_uncertain().map_err(|e| r.refused(e))?;
        Ok(plan)
    }

    /// The study's name (given, or the file's stem). It becomes a folder and
    /// a label: checked here, before any folder is made, so that a refusal
    /// leaves nothing behind.
    fn checked_name(&self, path: &str, r: &Refusal) -> Result<String, StudyError> {
        let name = match &self.name {
            Some(n) => n.clone(),
            None => std::path::Path::new(path)
                .file_stem()
                .and_then(|s| s.to_str())
                .unwrap_or("study")
                .to_string(),
        };
        let bad_name = if name.trim().is_empty() {
            Some("must not be empty or blank")
        } else if name.chars().any(char::is_control) {
            Some("must not hold control characters (a newline, a tab, …)")
        } else if name.trim() != name {
            Some("must not begin or end with a space")
        } else if name.contains(['/', '\\']) || name == ".." || name == "." {
            Some("must be a plain folder name")
        } else if name.len() > MAX_NAME_BYTES {
            Some(
                "at most 128 bytes: it is a folder name, and file systems refuse longer ones (255 bytes, less with the files beside it)",
            )
        } else {
            None
        };
        if let Some(reason) = bad_name {
            let key = if self.name.is_some() {
                "name"
            } else {
                "name (from the study file's name)"
            };
            let shown = if name.len() > 40 {
                format!(
                    "{:?}… ({} bytes)",
                    name.chars().take(20).collect::<String>(),
                    name.len()
                )
            } else {
                format!("{name:?}")
            };
            return Err(r.invalid(key, shown, reason));
        }
        Ok(name)
    }

    /// The planes and weights a machine can carry, checked before anything
    /// walks them.
    fn check_size_limits(&self, r: &Refusal) -> Result<(), StudyError> {
        let planes = self.scene.rotor.as_rotor().planes();
        if planes > MAX_PLANES {
            return Err(r.invalid(
                "scene.rotor.planes",
                format!("{planes} planes"),
                &format!(
                    "at most {MAX_PLANES} balancer planes: each plane adds a balancer's equations, and no machine carries more"
                ),
            ));
        }
        if let Some(n) = self
            .designs
            .n
            .values()
            .into_iter()
            .find(|&n| n > MAX_WEIGHTS)
        {
            return Err(r.invalid(
                "designs.n",
                n.to_string(),
                &format!(
                    "at most {MAX_WEIGHTS} weights per balancer: the state and the implicit method's Jacobian grow with n (n² entries), and no race holds more weights of a useful size"
                ),
            ));
        }
        Ok(())
    }

    /// The significance level and the Pareto measures the summary needs.
    fn check_statistics(&self, r: &Refusal) -> Result<(), StudyError> {
        let alpha = self.statistics.alpha;
        if !(alpha > 0.0 && alpha <= 0.5) {
            return Err(r.invalid(
                "statistics.alpha",
                alpha.to_string(),
                "a significance level in (0, 0.5], e.g. 0.05",
            ));
        }
        if self.summary.pareto.is_empty() {
            return Err(r.invalid(
                "summary.pareto",
                "[]".into(),
                "name at least one measure (median, mean, p90, residual_p95, …), or leave the key out for all four",
            ));
        }
        let reruns = self.summary.counterfactual_runs;
        if reruns > super::MAX_COUNTERFACTUAL_RUNS {
            return Err(r.invalid(
                "summary.counterfactual_runs",
                reruns.to_string(),
                &format!(
                    "at most {} samples re-run per effect (each one a whole run per effect); 0 turns the experiment off",
                    super::MAX_COUNTERFACTUAL_RUNS
                ),
            ));
        }
        Ok(())
    }

    /// How many samples are drawn and when sampling stops: the unbalance's
    /// scale, the sample and batch counts (powers of two under Sobol), and
    /// the stopping precision.
    fn check_sampling_counts(&self, r: &Refusal) -> Result<(), StudyError> {
        let s = &self.sampling;
        if s.unbalance.relative_to.is_none() {
            return Err(r.invalid(
                "sampling.unbalance.relative_to",
                "(missing)".into(),
                "required: \"capacity\" (the values are fractions of each design's balancing capacity, no unit) or \"absolute\" (the values are unbalances in kg·m)",
            ));
        }
        if s.samples == 0 {
            return Err(r.invalid(
                "sampling.samples",
                "0".into(),
                "need at least one sample per design",
            ));
        }
        if s.batch == 0 {
            return Err(r.invalid(
                "sampling.batch",
                "0".into(),
                "a batch holds at least one sample per design",
            ));
        }
        if s.sequence == crate::study::plan::stream::Sequence::Sobol {
            let max = crate::study::plan::stream::SOBOL_MAX_SAMPLES;
            if s.samples > max || !s.samples.is_power_of_two() {
                return Err(r.invalid(
                    "sampling.samples",
                    s.samples.to_string(),
                    &format!(
                        "with sequence = \"sobol\" a power of two up to {max} (e.g. {}): a Sobol sequence is even only over 2^m points",
                        s.samples
                            .checked_next_power_of_two()
                            .map_or(max, |p| p.min(max))
                    ),
                ));
            }
            if s.stop_when.is_some() && !s.batch.is_power_of_two() {
                return Err(r.invalid(
                    "sampling.batch",
                    s.batch.to_string(),
                    &format!(
                        "with sequence = \"sobol\" a power of two (e.g. {}), so that every batch ends on an even prefix of the sequence",
                        s.batch.checked_next_power_of_two().unwrap_or(1024)
                    ),
                ));
            }
        }
        if let Some(stop) = &s.stop_when {
            let keys = [
                ("median_halfwidth_rel", stop.median_halfwidth_rel),
                ("win_share_halfwidth", stop.win_share_halfwidth),
            ];
            if keys.iter().all(|(_, v)| v.is_none()) {
                return Err(r.invalid(
                    "sampling.stop_when",
                    "{}".into(),
                    "name a precision: median_halfwidth_rel or win_share_halfwidth",
                ));
            }
            for (key, value) in keys {
                if let Some(v) = value
                    && !(v > 0.0 && v < 1.0)
                {
                    return Err(r.invalid(
                        &format!("sampling.stop_when.{key}"),
                        v.to_string(),
                        "a half-width in (0, 1), e.g. 0.05",
                    ));
                }
            }
        }
        Ok(())
    }

    /// What each sample draws: the unbalance's and the couple's
    /// distributions, and a fixed direction or shift that must be finite.
    fn check_sampling_draws(&self, r: &Refusal) -> Result<(), StudyError> {
        let s = &self.sampling;
        crate::study::plan::distribution::check(&s.unbalance.distribution)
            .map_err(|e| r.refused(e.under("sampling.unbalance")))?;
        if let Some(couple) = &s.couple {
            crate::study::plan::couple::validate(couple, &self.scene.rotor, |u| {
                crate::study::plan::distribution::check(&u.distribution)
                    .map_err(|e| e.under("sampling.couple.unbalance"))
            })
            .map_err(|e| r.refused(e))?;
        }
        if let DirectionSpec::Fixed(d) = s.direction
            && !d.is_finite()
        {
            return Err(r.invalid("sampling.direction.fixed", d.to_string(), "must be finite"));
        }
        if let InitialSpec::BalancedForShift(d) = s.initial
            && !d.is_finite()
        {
            return Err(r.invalid(
                "sampling.initial.balanced_for_shift",
                d.to_string(),
                "must be finite",
            ));
        }
        Ok(())
    }

    /// The metrics' and solver's own keys, then the horizon against the
    /// scene's speed.
    fn check_metrics_and_solver(&self, r: &Refusal) -> Result<(), StudyError> {
        self.metrics.validate().map_err(|e| r.refused(e))?;
        self.solver.validate().map_err(|e| r.refused(e))?;
        if let Err(crate::model::validate::SceneError::Invalid {
            field,
            value,
            reason,
        }) = self.metrics.check_horizon(&self.scene.speed)
        {
            return Err(r.invalid(&field, value, &reason));
        }
        Ok(())
    }

    /// The planes' own designs, the weights over every plane, and the two
    /// planes the optimiser can search.
    fn check_plane_designs(&self, r: &Refusal) -> Result<(), StudyError> {
        crate::study::plan::plane_designs::validate(
            &self.designs.per_plane,
            self.scene.rotor.as_rotor().planes(),
        )
        .map_err(|e| r.refused(e))?;
        let planes = self.scene.rotor.as_rotor().planes();
        let most_weights = self
            .designs
            .n
            .values()
            .into_iter()
            .chain(
                self.designs
                    .per_plane
                    .iter()
                    .flat_map(|a| a.n.as_ref().map(|n| n.values()).unwrap_or_default()),
            )
            .max()
            .unwrap_or(0);
        if planes as u64 * u64::from(most_weights) > MAX_TOTAL_WEIGHTS as u64 {
            return Err(r.invalid(
                "scene.rotor.planes",
                format!("{planes} planes × {most_weights} weights"),
                &format!(
                    "at most {MAX_TOTAL_WEIGHTS} weights over every plane (planes × designs.n): the state and the implicit method's Jacobian grow with their number"
                ),
            ));
        }
        if !self.designs.per_plane.is_empty() && self.optimize.is_some() && planes != 2 {
            // The optimiser searches plane 0's and plane 1's radius ratios.
            return Err(r.invalid(
                "optimize",
                format!("{planes} balancer planes"),
                "with designs.per_plane the optimiser searches two balancer planes' radius ratios; this rotor has another number: run the planes' designs as a grid",
            ));
        }
        Ok(())
    }

    /// The grid's size from its axes alone, before a design is built, so a
    /// grid too large to hold is refused before it is made.
    fn check_grid_size(&self, r: &Refusal) -> Result<(), StudyError> {
        let s = &self.sampling;
        let g = &self.designs;
        let mut grid = [
            g.kind.values().len(),
            g.n.values().len(),
            g.rho.values().len(),
            g.drag.values().len(),
            g.stall_torque.as_ref().map_or(1, |t| t.values().len()),
        ]
        .iter()
        .fold(1u64, |acc, &k| acc.saturating_mul(k as u64));
        for a in &g.per_plane {
            let axis = |len: Option<usize>| len.unwrap_or(1) as u64;
            grid = grid
                .saturating_mul(axis(a.kind.as_ref().map(|v| v.values().len())))
                .saturating_mul(axis(a.n.as_ref().map(|v| v.values().len())))
                .saturating_mul(axis(a.rho.as_ref().map(|v| v.values().len())))
                .saturating_mul(axis(a.drag.as_ref().map(|v| v.values().len())));
        }
        if grid.saturating_mul(u64::from(s.samples)) > MAX_TOTAL_RUNS {
            // The grid alone too large, or the samples on top of it.
            let (key, value) = if grid > MAX_TOTAL_RUNS {
                ("designs", format!("{grid} designs"))
            } else {
                ("sampling.samples", s.samples.to_string())
            };
            return Err(r.invalid(
                key,
                value,
                &format!(
                    "{grid} designs × {} samples is more than the {MAX_TOTAL_RUNS} runs one study may hold; split the grid into several studies or use fewer samples",
                    s.samples
                ),
            ));
        }
        Ok(())
    }

    /// The sampled tolerances against the built designs and the scene's
    /// facts (planes, prescribed speed).
    fn check_tolerances(&self, designs: &[Design], r: &Refusal) -> Result<(), StudyError> {
        if let Some(t) = &self.sampling.tolerances {
            let facts = crate::model::effect::SceneFacts {
                planes: self.scene.rotor.as_rotor().planes(),
                prescribed_speed: self.scene.speed.is_prescribed(),
            };
            crate::study::plan::tolerance::validate(t, designs, &facts).map_err(
                |InvalidKey {
                     key: k,
                     value: v,
                     reason: reason_text,
                 }| r.invalid(&format!("sampling.tolerances.{k}"), v, &reason_text),
            )?;
        }
        Ok(())
    }

    /// With require_balanceable, every design must hold the largest
    /// unbalance drawn plus what the scene's effects ask of the weights.
    fn check_effects_balanceable(&self, designs: &[Design], r: &Refusal) -> Result<(), StudyError> {
        let s = &self.sampling;
        let demand = self.effects_capacity_demand();
        if demand > 0.0 && s.require_balanceable {
            // The weights must also hold the race centred: the unbalance they
            // supply grows by up to e_r·|M − (k + ibω)/ω²| (docs/model.md).
            let upper = s.unbalance.distribution.upper();
            let drawn = |d: &Design| match s.unbalance.scale() {
                Scale::Absolute => upper,
                Scale::Capacity => upper * d.capacity,
            };
            if let Some(d) = designs.iter().find(|d| d.capacity < drawn(d) + demand) {
                return Err(r.invalid(
                    &format!(
                        "sampling.unbalance.{}",
                        s.unbalance.distribution.upper_key()
                    ),
                    upper.to_string(),
                    &format!(
                        "the largest unbalance drawn, {:.4e} kg·m, plus the {demand:.4e} kg·m the weights must add to centre the off-centre race (effects.race_eccentricity: e_r over the plane's compliance, e_r·|M − (k + ibω)/ω²| on the plane rotor) exceeds the capacity {:.4e} kg·m of design {} ({}); lower it or set require_balanceable = false",
                        drawn(d),
                        d.capacity,
                        d.id,
                        crate::study::plan::plane_designs::describe(d)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// With require_balanceable and a couple in kg·m, every design must hold
    /// the static and couple parts together in its worse plane.
    fn check_couple_balanceable(&self, designs: &[Design], r: &Refusal) -> Result<(), StudyError> {
        let s = &self.sampling;
        if let Some(couple) = &s.couple
            && s.require_balanceable
        {
            // Either part in kg·m: the worst plane takes both at full size.
            let static_upper = s.unbalance.distribution.upper();
            let absolute = s.unbalance.scale() == Scale::Absolute
                || couple
                    .unbalance
                    .as_ref()
                    .is_some_and(|u| u.scale() == Scale::Absolute);
            let in_kgm = |v: f64, scale: Scale, d: &Design| match scale {
                Scale::Absolute => v,
                Scale::Capacity => v * d.capacity,
            };
            let worst = |d: &Design| {
                let u_s = in_kgm(static_upper, s.unbalance.scale(), d);
                match (&couple.unbalance, couple.follows_static) {
                    (Some(u), _) => u_s + in_kgm(u.distribution.upper(), u.scale(), d),
                    (None, Some(c)) => u_s * (1.0 + c.abs()),
                    (None, None) => u_s,
                }
            };
            if absolute && let Some(d) = designs.iter().find(|d| d.capacity < worst(d)) {
                let key = match &couple.unbalance {
                    Some(u) => format!("sampling.couple.unbalance.{}", u.distribution.upper_key()),
                    None => "sampling.couple.follows_static".to_string(),
                };
                return Err(r.invalid(
                    &key,
                    format!("{:.4e} kg·m in the worse plane", worst(d)),
                    &format!(
                        "the largest static plus couple unbalance a plane can take exceeds the capacity {:.4e} kg·m of design {} ({}); lower them or set require_balanceable = false",
                        d.capacity,
                        d.id,
                        crate::study::plan::plane_designs::describe(d)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// With require_balanceable and an unbalance in kg·m, every design must
    /// hold the largest one drawn.
    fn check_absolute_balanceable(
        &self,
        designs: &[Design],
        r: &Refusal,
    ) -> Result<(), StudyError> {
        let s = &self.sampling;
        if s.unbalance.scale() == Scale::Absolute && s.require_balanceable {
            let upper = s.unbalance.distribution.upper();
            if let Some(d) = designs.iter().find(|d| d.capacity < upper) {
                return Err(r.invalid(
                    &format!(
                        "sampling.unbalance.{}",
                        s.unbalance.distribution.upper_key()
                    ),
                    upper.to_string(),
                    &format!(
                        "exceeds the capacity {:.4e} kg·m of design {} ({}); lower it or set require_balanceable = false",
                        d.capacity,
                        d.id,
                        crate::study::plan::plane_designs::describe(d)
                    ),
                ));
            }
        }
        Ok(())
    }

    /// The runs the built designs make with the samples, against what one
    /// study may hold in memory and on disk.
    fn check_total_runs(&self, designs: &[Design], r: &Refusal) -> Result<(), StudyError> {
        let s = &self.sampling;
        let total = designs.len() as u64 * u64::from(s.samples);
        if total > MAX_TOTAL_RUNS {
            return Err(r.invalid(
                "sampling.samples",
                s.samples.to_string(),
                &format!(
                    "{} designs × {} samples = {total} runs, more than the {MAX_TOTAL_RUNS} one study may hold (the runner keeps about 80 bytes of each run in memory, and runs.parquet takes about as much on disk); split the grid into several studies or use fewer samples",
                    designs.len(),
                    s.samples
                ),
            ));
        }
        Ok(())
    }

    /// The unbalance (kg·m) the weights must add, besides cancelling the
    /// rotor's, for the scene's effects (an off-centre race held on the
    /// axis) at the nominal speed, on any rotor: each effect says what it
    /// asks, given the planes' compliance ([`crate::model::forced::plane_compliance`]).
    pub fn effects_capacity_demand(&self) -> f64 {
        let system = crate::model::system::RotorSystem::new(
            self.scene.rotor.build(),
            Vec::new(),
            self.scene.speed.clone(),
            Vec::new(),
        );
        let omega = self.scene.speed.nominal_speed();
        let compliance = |p: usize| crate::model::forced::plane_compliance(&system, p, omega);
        self.scene
            .effects
            .capacity_demand(system.rotor().planes(), &compliance)
    }

    /// Validate one design of this study's scene and compute its mass and capacity.
    ///
    /// Errors are (key, value, reason) in the study file's terms.
    pub fn resolve_design(&self, id: u32, spec: DesignSpec) -> Result<Design, InvalidKey> {
        let (kind, n) = (spec.kind, spec.n);
        let scene = Scene {
            rotor: self.scene.rotor.without_unbalance(),
            balancer: Some(spec.clone()),
            balancers: Vec::new(),
            cargo: Vec::new(),
            speed: self.scene.speed.clone(),
            effects: self.scene.effects.clone(),
        };
        scene.validate().map_err(|e| scene_error_key(e, kind, n))?;
        let geometry = spec.geometry().map_err(|e| {
            InvalidKey::new(
                "designs.rho".to_string(),
                format!("{:?}", spec.rho),
                e.to_string(),
            )
        })?;
        check_fits(n, geometry.rho).map_err(|e| {
            InvalidKey::new(
                "designs.rho".to_string(),
                geometry.rho.to_string(),
                e.to_string(),
            )
        })?;
        let cargo = kind
            .model()
            .cargo(&geometry)
            .map_err(|e| InvalidKey::new("designs", kind.to_string(), e.to_string()))?;
        let capacity = match kind {
            Kind::Pendulum => f64::from(n) * cargo.unbalance(),
            _ => crate::design::capacity::capacity_from_mass(
                n,
                geometry.rho,
                cargo.mass,
                spec.race_radius,
            )
            .map_err(|e| InvalidKey::new("designs", kind.to_string(), e.to_string()))?,
        };
        Ok(Design {
            id,
            spec,
            rho: geometry.rho,
            weight_mass: cargo.mass,
            track_radius: cargo.track_radius,
            capacity,
            plane_zero_capacity: capacity,
            plane_designs: Vec::new(),
            stall_torque: None,
        })
    }

    /// A balancer of plane 1, 2, … checked as plane 0's are, its errors named
    /// by its `[[designs.per_plane]]` entry.
    fn resolve_plane_design(&self, spec: DesignSpec) -> Result<Design, InvalidKey> {
        let plane = spec.plane;
        self.resolve_design(0, spec)
            .map_err(|InvalidKey { key, value, reason }| {
                let entry = self.designs.per_plane.iter().position(|a| a.plane == plane);
                let key = match (entry, key.strip_prefix("designs.")) {
                    (Some(i), Some(rest)) if ["n", "rho", "kind", "drag"].contains(&rest) => {
                        format!("designs.per_plane[{i}].{rest}")
                    }
                    _ => key,
                };
                InvalidKey::new(key, value, format!("{reason} (plane {plane})"))
            })
    }

    fn resolve_designs(&self) -> Result<Vec<Design>, InvalidKey> {
        let g = &self.designs;
        let mut designs = Vec::new();
        let (kinds, ns, rhos, drags) = (
            g.kind.values(),
            g.n.values(),
            g.rho.values(),
            g.drag.values(),
        );
        let torques = self.stall_torques()?;
        for (key, empty) in [
            ("designs.kind", kinds.is_empty()),
            ("designs.n", ns.is_empty()),
            ("designs.rho", rhos.is_empty()),
            ("designs.drag", drags.is_empty()),
        ] {
            if empty {
                return Err(InvalidKey::new(key, "[]", "needs at least one value"));
            }
        }
        for kind in &kinds {
            for &n in &ns {
                for rho in &rhos {
                    for &drag in &drags {
                        for &stall_torque in &torques {
                            let spec = DesignSpec {
                                kind: *kind,
                                n,
                                rho: rho.clone(),
                                race_radius: g.race_radius,
                                density: g.density,
                                roller_height: g.roller_height,
                                drag,
                                plane: 0,
                            };
                            let planes = self.scene.rotor.as_rotor().planes();
                            let others = if g.per_plane.is_empty() {
                                vec![Vec::new()]
                            } else {
                                crate::study::plan::plane_designs::combinations(
                                    &g.per_plane,
                                    planes,
                                    &spec,
                                )
                            };
                            for other in others {
                                let design =
                                    self.resolve_design(designs.len() as u32, spec.clone())?;
                                let plane_designs = other
                                    .into_iter()
                                    .map(|s| {
                                        self.resolve_plane_design(s)
                                            .map(|p| Design { id: design.id, ..p })
                                    })
                                    .collect::<Result<Vec<_>, _>>()?;
                                let capacity = plane_designs
                                    .iter()
                                    .map(|p| p.capacity)
                                    .fold(design.capacity, f64::min);
                                designs.push(Design {
                                    stall_torque,
                                    capacity,
                                    plane_designs,
                                    ..design
                                });
                            }
                        }
                    }
                }
            }
        }
        Ok(designs)
    }
}

impl StudyFile {
    /// The grid's stall torques: `[None]` when it sweeps none, else each
    /// value checked (positive, finite, a motor to apply it to).
    fn stall_torques(&self) -> Result<Vec<Option<f64>>, InvalidKey> {
        let Some(list) = &self.designs.stall_torque else {
            return Ok(vec![None]);
        };
        let key = "designs.stall_torque".to_string();
        let values = list.values();
        if !matches!(self.scene.speed, SpeedLaw::Motor { .. }) {
            return Err(InvalidKey::new(
                key,
                format!("{values:?}"),
                "a stall torque needs a motor: set scene.speed.mode = \"motor\"",
            ));
        }
        if values.is_empty() {
            return Err(InvalidKey::new(key, "[]", "needs at least one value"));
        }
        if let Some(bad) = values.iter().find(|v| !(v.is_finite() && **v > 0.0)) {
            return Err(InvalidKey::new(
                key,
                bad.to_string(),
                "a stall torque (N·m) must be positive and finite",
            ));
        }
        Ok(values.into_iter().map(Some).collect())
    }
}

/// Map a scene validation error onto the study file's keys.
impl StudyPlan {
    /// The `[uncertain]` keys against every design's scene: each key set by
    /// the scene and by nothing the study draws per run, and both ends of
    /// its distribution valid (scene checks and the metrics' horizon).
    fn check_uncertain(&self) -> Result<(), InvalidKey> {
        use crate::uncertain::{read, validate};
        let spec = &self.file.uncertain;
        if let (Some(_), Some(key)) = (
            self.file
                .sampling
                .tolerances
                .as_ref()
                .and_then(|t| t.eccentricity.as_ref()),
            spec.keys()
                .find(|k| k.starts_with("effects.race_eccentricity")),
        ) {
            return Err(InvalidKey::new(
                format!("uncertain.\"{key}\""),
                key.clone(),
                "sampling.tolerances.eccentricity already draws the race's offset per run: give the race eccentricity one of the two",
            ));
        }
        for design in &self.designs {
            // Two runs' scenes: a key whose value moves between them, or
            // away from the file's, is one the study sets itself.
            let runs = [(0.5, 0.3), (0.8, 2.1)].map(|(fraction, direction)| {
                self.scene(design, fraction * design.capacity, direction)
            });
            for key in spec.keys() {
                let file = read(&self.file.scene, key).ok();
                let ran = runs.each_ref().map(|s| read(s, key).ok());
                if ran[0] != ran[1] || (file.is_some() && ran[0] != file) {
                    return Err(InvalidKey::new(
                        format!("uncertain.\"{key}\""),
                        key.clone(),
                        "the study sets this key itself in every run (the sampled unbalance is drawn in [sampling], a design's values in [designs]): it cannot also be uncertain",
                    ));
                }
            }
            let (kind, n) = (design.spec.kind, design.spec.n);
            validate(spec, &runs[0], |scene| {
                scene.validate().map_err(|e| scene_error_key(e, kind, n))?;
                self.file
                    .metrics
                    .check_horizon(&scene.speed)
                    .map_err(|e| scene_error_key(e, kind, n))
            })?;
        }
        Ok(())
    }
}

fn scene_error_key(e: SceneError, kind: Kind, n: u32) -> InvalidKey {
    match e {
        SceneError::Invalid {
            field,
            value,
            reason,
        } => {
            let key = if let Some(rest) = field.strip_prefix("balancer.") {
                format!("designs.{rest}")
            } else {
                format!("scene.{field}")
            };
            InvalidKey::new(key, value, reason)
        }
        SceneError::Design(d) => {
            let key = match d.key() {
                "" => "designs".to_string(),
                k => format!("designs.{k}"),
            };
            // "rho = \"opt\": expected …" reads as the key's value and the
            // reason, with the design it was met in after them.
            let message = d.to_string();
            match message.split_once(": ") {
                Some((lhs, reason)) if lhs.contains(" = ") => {
                    let value = lhs.split_once(" = ").map_or(lhs, |(_, v)| v).to_string();
                    InvalidKey::new(
                        key,
                        value,
                        format!("{reason} (in the design {kind} n = {n})"),
                    )
                }
                _ => InvalidKey::new(key, format!("{kind} n = {n}"), message),
            }
        }
    }
}

/// Most unbalance, per plane, over a design's capacity that a study may
/// draw, whatever `require_balanceable` says.
const MOST_OVER_CAPACITY: f64 = 1e3;

/// Refuse unbalances beyond [`MOST_OVER_CAPACITY`] times a design's
/// capacity, naming the key: the runs would measure nothing but the plain
/// rotor, and at 1e300 their numbers overflow and every run fails.
fn unbalance_within_reason(s: &Sampling, designs: &[Design]) -> Result<(), InvalidKey> {
    let in_kgm = |v: f64, scale: Scale, d: &Design| match scale {
        Scale::Absolute => v,
        Scale::Capacity => v * d.capacity,
    };
    let static_key = format!(
        "sampling.unbalance.{}",
        s.unbalance.distribution.upper_key()
    );
    for d in designs {
        let most = MOST_OVER_CAPACITY * d.capacity;
        let u_s = in_kgm(s.unbalance.distribution.upper(), s.unbalance.scale(), d);
        let (key, worst) = match s.couple.as_ref().map(|c| (&c.unbalance, c.follows_static)) {
            Some((Some(u), _)) => (
                format!("sampling.couple.unbalance.{}", u.distribution.upper_key()),
                u_s + in_kgm(u.distribution.upper(), u.scale(), d),
            ),
            Some((None, Some(c))) => (
                "sampling.couple.follows_static".into(),
                u_s * (1.0 + c.abs()),
            ),
            _ => (static_key.clone(), u_s),
        };
        let key = if u_s > most { static_key.clone() } else { key };
        // NaN included: a value that is not a number means nothing either.
        if !matches!(
            worst.partial_cmp(&most),
            Some(std::cmp::Ordering::Less | std::cmp::Ordering::Equal)
        ) {
            return Err(InvalidKey::new(
                &key,
                format!("{worst:.4e} kg·m in a plane"),
                format!(
                    "more than {MOST_OVER_CAPACITY} times the capacity {:.4e} kg·m of design {} ({}): the weights could not move the whirl, and the runs would measure the plain rotor; lower it",
                    d.capacity,
                    d.id,
                    crate::study::plan::plane_designs::describe(d)
                ),
            ));
        }
    }
    Ok(())
}

/// Builds the study file's refusals, each naming the file it came from and
/// the dotted key a user edits.
struct Refusal<'a> {
    path: &'a str,
}

impl Refusal<'_> {
    /// A value outside its domain.
    fn invalid(&self, key: &str, value: String, reason: &str) -> StudyError {
        StudyError::Invalid {
            path: self.path.to_string(),
            key: key.to_string(),
            value,
            reason: reason.to_string(),
        }
    }

    /// A refusal already keyed by the check that made it.
    fn refused(&self, e: InvalidKey) -> StudyError {
        StudyError::Invalid {
            path: self.path.to_string(),
            key: e.key,
            value: e.value,
            reason: e.reason,
        }
    }
}
