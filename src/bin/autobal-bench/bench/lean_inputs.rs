//! The inputs of the lean reference (`bench/lean`): every run of the main
//! job (`studies/three_balls.toml`, samples cut down) written as one CSV row
//! with all a hand-written rotating-frame DP5 needs to redo it, and
//! autobal's own answer for that run.
//!
//! The rows are built as [`autobal::study::run::run_design_sample`] and
//! [`Simulation::run`] build a run (same sample, scene, start state, frame
//! change, tolerances, metric constants), so that the lean program solves
//! exactly the problem autobal solved; the unit tests below check that the
//! exported numbers reproduce autobal's right-hand side bit for bit and its
//! settling time.

use super::threads::edited_main_job;
use autobal::metrics::reference::a_ref;
use autobal::model::effect::contact::{Contact, ContactModel, ContactSpec};
use autobal::model::frame::RotatingSystem;
use autobal::simulation::{Fidelity, Simulation, scaled_atol};
use autobal::study::plan::config::{Design, StudyPlan};
use autobal::study::run::{run_design_sample, sample_simulation};
use std::f64::consts::PI;
use std::io::Write;
use std::path::Path;

/// Column names of the CSV, in order; list-valued cells hold one value per
/// weight (or per state component) separated by `;`.
pub const COLUMNS: &[&str] = &[
    "run_id",
    "design_id",
    "sample_id",
    "n",
    "omega",
    "rotor_mass",
    "k",
    "b",
    "unbalance_force_u",
    "unbalance_force_v",
    "mass",
    "track_radius",
    "inertia",
    "drag",
    "contact_half_angle",
    "contact_stiffness",
    "contact_damping",
    "y0",
    "rtol",
    "atol",
    "max_steps",
    "t_end",
    "dt",
    "samples_per_rev",
    "band",
    "window",
    "divergence_limit",
    "autobal_outcome",
    "autobal_settling_revs",
    "autobal_rhs_calls",
    "autobal_steps",
    "autobal_method",
];

/// One run as the lean program redoes it: the rotating-frame equations'
/// constants, the start, the solver's tolerances, the observer's constants,
/// and autobal's answer.
#[derive(Debug, Clone, PartialEq)]
pub struct LeanRow {
    /// Run index in the study.
    pub run_id: u64,
    /// Design index.
    pub design_id: u32,
    /// Sample index within the design.
    pub sample_id: u64,
    /// Spin speed ω (rad/s).
    pub omega: f64,
    /// Rotor mass M without the weights (kg); the equations use M + Σ m_j.
    pub rotor_mass: f64,
    /// Support stiffness k (N/m, isotropic).
    pub k: f64,
    /// Support damping b (N·s/m, isotropic).
    pub b: f64,
    /// The rotor's centrifugal force M e ω² e^{iψ₀} in the rotating frame (N).
    pub unbalance_force: (f64, f64),
    /// Mass m_j of each weight (kg).
    pub mass: Vec<f64>,
    /// Track radius l_j of each weight (m).
    pub track_radius: Vec<f64>,
    /// Inertia κ m l² of each weight about the race centre (kg·m²).
    pub inertia: Vec<f64>,
    /// Drag β_j of each weight (N·s/m); the equations use β l².
    pub drag: Vec<f64>,
    /// Contact half-angle α_j (rad); empty when the scene has no contact.
    pub contact_half_angle: Vec<f64>,
    /// Contact stiffness k_θ of each weight (N·m/rad); empty without contact.
    pub contact_stiffness: Vec<f64>,
    /// Contact damping c_θ of each weight (N·m·s/rad); empty without contact.
    pub contact_damping: Vec<f64>,
    /// Initial state [u, v, ψ…, u̇, v̇, ψ̇…] in the rotating frame.
    pub y0: Vec<f64>,
    /// Relative tolerance.
    pub rtol: f64,
    /// Absolute tolerance per state component.
    pub atol: Vec<f64>,
    /// Step budget (accepted plus rejected).
    pub max_steps: u64,
    /// End of the run (s) if it does not settle.
    pub t_end: f64,
    /// Spacing of the observer's samples (s).
    pub dt: f64,
    /// Samples per revolution (a revolution is dt × this, as the observer counts).
    pub samples_per_rev: u32,
    /// Settling band δ·A_ref (m) on the whirl radius r = |(u, v)|.
    pub band: f64,
    /// Hold window (s): r must stay in the band this long.
    pub window: f64,
    /// r beyond this (m) ends the run as diverged.
    pub divergence_limit: f64,
    /// autobal's outcome (settled, censored, …).
    pub autobal_outcome: String,
    /// autobal's settling time in revolutions (settled runs only).
    pub autobal_settling_revs: Option<f64>,
    /// autobal's RHS calls.
    pub autobal_rhs_calls: u64,
    /// autobal's accepted steps.
    pub autobal_steps: u64,
    /// autobal's method, e.g. "dp5" or "dp5→radau5" when it switched.
    pub autobal_method: String,
}

/// The main job with `samples` samples per design (output folder unused),
/// holding every window to its end as the lean program does: autobal's
/// answers in the rows are the full hold's (`metrics.certified_hold` off).
/// With penalty contact, the one contact model the lean program has.
pub fn lean_plan(samples: u32) -> StudyPlan {
    edited_main_job(samples, Path::new("results"), "--lean-inputs", |file| {
        file.metrics.certified_hold = false;
        file.scene.effects.contact = Some(ContactSpec::with_model(ContactModel::Penalty));
    })
}

/// The study in `path` at `samples` per design, held to the lean program's
/// rule (every hold window to its end).
pub fn lean_plan_of(path: &Path, samples: u32) -> Result<StudyPlan, String> {
    let text = std::fs::read_to_string(path).map_err(|e| e.to_string())?;
    let shown = path.display().to_string();
    let mut file =
        autobal::study::plan::config::StudyFile::parse(&text, &shown).map_err(|e| e.to_string())?;
    file.sampling.samples = samples.max(1);
    file.metrics.certified_hold = false;
    file.plan(&text, &shown).map_err(|e| e.to_string())
}

/// Every run of `plan` as a row, in run order (each run is solved by autobal once).
pub fn lean_rows(plan: &StudyPlan) -> Result<Vec<LeanRow>, String> {
    let samples = u64::from(plan.file.sampling.samples);
    let mut rows = Vec::new();
    for design in &plan.designs {
        for sample_id in 0..samples {
            let run_id = u64::from(design.id) * samples + sample_id;
            rows.push(lean_row(plan, design, sample_id, run_id)?);
        }
    }
    Ok(rows)
}

/// The simulation `run_design_sample` builds for this sample.
pub fn simulation_of(plan: &StudyPlan, design: &Design, sample_id: u64) -> Simulation {
    sample_simulation(plan, design, sample_id).1
}

/// One run as a row; errors when the run does not use the rotating frame
/// or the scene has more than one balancer plane (the lean program has one).
pub fn lean_row(
    plan: &StudyPlan,
    design: &Design,
    sample_id: u64,
    run_id: u64,
) -> Result<LeanRow, String> {
    let sim = simulation_of(plan, design, sample_id);
    if sim.resolved_fidelity() != Fidelity::Rotating {
        return Err(format!("run {run_id}: not a rotating-frame run"));
    }
    let scene = &sim.scene;
    let err = |e: autobal::model::scene::SceneError| format!("run {run_id}: {e}");
    let system = scene.build().map_err(err)?;
    let rotating = RotatingSystem::new(scene).map_err(err)?;
    let rotor = scene.rotor.as_rotor().isotropic_plane()?;
    let cargo = scene.cargoes().map_err(err)?;
    let omega = rotating.omega();

    // The start as Simulation::run makes it: the inertial state turned into the rotating frame.
    let nq = system.layout().nq();
    let mut y0 = autobal::model::start::initial_state(&system, sim.start, &sim.initial_angles);
    let [u, ud, v, vd] = rotating.from_inertial(0.0, y0[0], y0[nq], y0[1], y0[nq + 1]);
    (y0[0], y0[1], y0[nq], y0[nq + 1]) = (u, v, ud, vd);

    // As RotatingSystem::new forms it.
    let me = rotor.unbalance;
    let (s, c) = autobal::model::trig::sin_cos(rotor.unbalance_angle);
    let unbalance_force = (me * omega * omega * c, me * omega * omega * s);

    let rigid = scene
        .effects
        .contact
        .as_ref()
        .is_some_and(|spec| spec.enabled && spec.model() == ContactModel::Rigid);
    if rigid && cargo.iter().any(|c| c.radius > 0.0) {
        return Err(format!(
            "run {run_id}: rigid contact; the lean program has penalty contact only (set [scene.effects.contact] model = \"penalty\" or enabled = false)"
        ));
    }
    let contact = scene
        .effects
        .contact
        .as_ref()
        .and_then(|spec| Contact::new(spec, &cargo, omega));
    let (mut half_angle, mut stiffness, mut damping) = (Vec::new(), Vec::new(), Vec::new());
    if let Some(contact) = &contact {
        for j in 0..cargo.len() {
            let (a, k, c, plane) = contact.cargo_coefficients(j);
            if plane != 0 {
                return Err(format!("run {run_id}: weights in more than one plane"));
            }
            half_angle.push(a);
            stiffness.push(k);
            damping.push(c);
        }
    }

    // The observer's and the solver's constants, as SettlingObserver::new and
    // Simulation::integrate form them.
    let m = &sim.metrics;
    let a = a_ref(&system, omega);
    let rev = 2.0 * PI / omega;
    let samples_per_rev = m.samples_per_rev.max(32);
    let record = run_design_sample(plan, design, sample_id, run_id);
    let metrics = &record.metrics;
    Ok(LeanRow {
        run_id,
        design_id: design.id,
        sample_id,
        omega,
        rotor_mass: rotor.mass,
        k: rotor.stiffness,
        b: rotor.damping,
        unbalance_force,
        mass: cargo.iter().map(|c| c.mass).collect(),
        track_radius: cargo.iter().map(|c| c.track_radius).collect(),
        inertia: cargo.iter().map(|c| c.inertia()).collect(),
        drag: cargo.iter().map(|c| c.drag).collect(),
        contact_half_angle: half_angle,
        contact_stiffness: stiffness,
        contact_damping: damping,
        y0,
        rtol: sim.solver.rtol,
        atol: scaled_atol(&system, sim.solver.atol(), a, omega),
        max_steps: sim.solver.max_steps,
        t_end: m.t_end_revs * 2.0 * PI / omega,
        dt: rev / f64::from(samples_per_rev),
        samples_per_rev,
        band: m.delta * a,
        window: m.hold_revs * rev,
        divergence_limit: m.divergence_factor * a,
        autobal_outcome: metrics.outcome.name().to_string(),
        autobal_settling_revs: metrics.settling_revs,
        autobal_rhs_calls: metrics.rhs_calls,
        autobal_steps: metrics.steps,
        autobal_method: record.method,
    })
}

/// `{:?}` prints the shortest decimal that parses back to the same f64.
fn list(values: &[f64]) -> String {
    values
        .iter()
        .map(|v| format!("{v:?}"))
        .collect::<Vec<_>>()
        .join(";")
}

impl LeanRow {
    /// The row's cells in [`COLUMNS`] order (floats round-trip exactly).
    pub fn cells(&self) -> Vec<String> {
        vec![
            self.run_id.to_string(),
            self.design_id.to_string(),
            self.sample_id.to_string(),
            self.mass.len().to_string(),
            format!("{:?}", self.omega),
            format!("{:?}", self.rotor_mass),
            format!("{:?}", self.k),
            format!("{:?}", self.b),
            format!("{:?}", self.unbalance_force.0),
            format!("{:?}", self.unbalance_force.1),
            list(&self.mass),
            list(&self.track_radius),
            list(&self.inertia),
            list(&self.drag),
            list(&self.contact_half_angle),
            list(&self.contact_stiffness),
            list(&self.contact_damping),
            list(&self.y0),
            format!("{:?}", self.rtol),
            list(&self.atol),
            self.max_steps.to_string(),
            format!("{:?}", self.t_end),
            format!("{:?}", self.dt),
            self.samples_per_rev.to_string(),
            format!("{:?}", self.band),
            format!("{:?}", self.window),
            format!("{:?}", self.divergence_limit),
            self.autobal_outcome.clone(),
            self.autobal_settling_revs
                .map_or(String::new(), |t| format!("{t:?}")),
            self.autobal_rhs_calls.to_string(),
            self.autobal_steps.to_string(),
            self.autobal_method.clone(),
        ]
    }
}

/// Write the header and one line per row (no cell holds a comma or quote).
pub fn write_csv(rows: &[LeanRow], out: &mut impl Write) -> std::io::Result<()> {
    writeln!(out, "{}", COLUMNS.join(","))?;
    for row in rows {
        writeln!(out, "{}", row.cells().join(","))?;
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;
    use autobal::integrate::{OdeSystem, SolverOptions, Stiffness, solve};
    use autobal::metrics::observer::SettlingObserver;
    use autobal::model::effect::contact::wrapped;

    /// The lean program's right-hand side (`bench/lean/src/main.rs`), written
    /// from the row alone: it must agree with autobal's bit for bit.
    fn lean_rhs(r: &LeanRow, y: &[f64], f: &mut [f64]) {
        let n = r.mass.len();
        let nq = 2 + n;
        let m_total = r.rotor_mass + r.mass.iter().sum::<f64>();
        let (q, qd) = y.split_at(nq);
        f[..nq].copy_from_slice(qd);
        let (u, v, ud, vd) = (q[0], q[1], qd[0], qd[1]);
        let w = r.omega;
        let (fr, fi) = (-2.0 * w * vd - w * w * u, 2.0 * w * ud - w * w * v);
        let mut gr = -m_total * fr - r.b * (ud - w * v) - r.k * u + r.unbalance_force.0;
        let mut gi = -m_total * fi - r.b * (vd + w * u) - r.k * v + r.unbalance_force.1;
        let (psi, rate) = (&q[2..], &qd[2..]);
        let cf = &mut f[nq + 2..];
        cf.fill(-0.0);
        if r.drag.iter().any(|&d| d != 0.0) {
            for j in 0..n {
                let l = r.track_radius[j];
                cf[j] -= r.drag[j] * l * l * rate[j];
            }
        }
        if !r.contact_half_angle.is_empty() {
            for j in 0..n {
                if r.contact_half_angle[j] == 0.0 {
                    continue;
                }
                for k in j + 1..n {
                    if r.contact_half_angle[k] == 0.0 {
                        continue;
                    }
                    let gap = r.contact_half_angle[j] + r.contact_half_angle[k];
                    let d = wrapped(psi[k] - psi[j]);
                    let overlap = gap - d.abs();
                    if overlap <= 0.0 {
                        continue;
                    }
                    let dir = if d >= 0.0 { 1.0 } else { -1.0 };
                    let overlap_rate = -dir * (rate[k] - rate[j]);
                    let kp = r.contact_stiffness[j].min(r.contact_stiffness[k]);
                    let cp = r.contact_damping[j].min(r.contact_damping[k]);
                    let torque = (kp * overlap + cp * overlap_rate).max(0.0);
                    cf[k] += dir * torque;
                    cf[j] -= dir * torque;
                }
            }
        }
        let (mut a11, mut a12, mut a22) = (m_total, 0.0, m_total);
        let mut trig = vec![(0.0, 0.0); n];
        for j in 0..n {
            let (s, co) = autobal::model::trig::sin_cos(psi[j]);
            trig[j] = (s, co);
            let ml = r.mass[j] * r.track_radius[j];
            let rt = w + rate[j];
            gr += ml * rt * rt * co;
            gi += ml * rt * rt * s;
            let qj = cf[j] - ml * (fi * co - fr * s);
            cf[j] = qj;
            let (wr, wi) = (-ml * s, ml * co);
            let inv = 1.0 / r.inertia[j];
            a11 -= wr * wr * inv;
            a12 -= wr * wi * inv;
            a22 -= wi * wi * inv;
            gr -= wr * qj * inv;
            gi -= wi * qj * inv;
        }
        let det = a11 * a22 - a12 * a12;
        let ar = (gr * a22 - gi * a12) / det;
        let ai = (gi * a11 - gr * a12) / det;
        for j in 0..n {
            let (s, co) = trig[j];
            let ml = r.mass[j] * r.track_radius[j];
            cf[j] = (cf[j] - ml * (co * ai - s * ar)) / r.inertia[j];
        }
        f[nq] = ar;
        f[nq + 1] = ai;
    }

    /// One sample per design: 20 runs, a fraction of a second.
    fn rows() -> (StudyPlan, Vec<LeanRow>) {
        let plan = lean_plan(1);
        let rows = lean_rows(&plan).unwrap();
        (plan, rows)
    }

    #[test]
    fn one_row_per_run_with_every_column() {
        let (plan, rows) = rows();
        assert_eq!(rows.len(), plan.designs.len());
        let mut csv = Vec::new();
        write_csv(&rows, &mut csv).unwrap();
        let text = String::from_utf8(csv).unwrap();
        let lines: Vec<&str> = text.lines().collect();
        assert_eq!(lines.len(), 1 + rows.len());
        assert_eq!(lines[0].split(',').collect::<Vec<_>>(), COLUMNS);
        for (line, row) in lines[1..].iter().zip(&rows) {
            let cells: Vec<&str> = line.split(',').collect();
            assert_eq!(cells.len(), COLUMNS.len(), "{line}");
            let n = row.mass.len();
            assert_eq!(cells[3], n.to_string());
            // Lists have one entry per weight, the state and atol one per component.
            let y0: Vec<f64> = cells[17].split(';').map(|c| c.parse().unwrap()).collect();
            assert_eq!(y0, row.y0, "floats round-trip exactly");
            assert_eq!(y0.len(), 2 * (2 + n));
            assert_eq!(cells[19].split(';').count(), 2 * (2 + n));
            for col in 10..=16 {
                assert_eq!(cells[col].split(';').count(), n, "{}", COLUMNS[col]);
            }
            assert!(row.autobal_rhs_calls > 0);
        }
        assert!(rows.iter().any(|r| r.autobal_settling_revs.is_some()));
    }

    #[test]
    fn rows_reproduce_autobal_rhs_and_settling_time() {
        let (plan, rows) = rows();
        for row in &rows {
            let design = &plan.designs[row.design_id as usize];
            let sim = simulation_of(&plan, design, row.sample_id);
            let system = sim.scene.build().unwrap();
            let rotating = RotatingSystem::new(&sim.scene).unwrap();
            // The exported constants give autobal's right-hand side exactly,
            // at the start and at a state with overlapping, moving weights.
            let dim = row.y0.len();
            let mut probe = row.y0.clone();
            let n = row.mass.len();
            probe[2 + n..].iter_mut().enumerate().for_each(|(i, v)| {
                *v += 0.3 * (i as f64 + 1.0);
            });
            probe[3] = probe[2] + 0.01;
            for y in [&row.y0, &probe] {
                let (mut lean, mut ours) = (vec![0.0; dim], vec![0.0; dim]);
                lean_rhs(row, y, &mut lean);
                rotating.rhs(0.0, y, &mut ours);
                assert_eq!(
                    lean.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    ours.iter().map(|v| v.to_bits()).collect::<Vec<_>>(),
                    "run {}",
                    row.run_id
                );
            }
            // The exported start, tolerances and horizon give autobal's settling time.
            let omega = row.omega;
            let mut observer = SettlingObserver::new(&system, omega, sim.metrics.clone(), false)
                .in_rotating_frame(omega);
            let options = SolverOptions {
                rtol: row.rtol,
                atol: row.atol.clone(),
                max_steps: row.max_steps,
                stiffness: Stiffness::SwitchToImplicit,
                ..SolverOptions::default()
            };
            let method = sim.solver.method.resolve(row.rtol, false);
            let report = solve(
                method,
                &rotating,
                0.0,
                &row.y0,
                row.t_end,
                &options,
                &mut observer,
            );
            let (metrics, _) = observer.finish(&report);
            assert_eq!(
                metrics.settling_revs, row.autobal_settling_revs,
                "run {}",
                row.run_id
            );
            assert_eq!(
                metrics.rhs_calls, row.autobal_rhs_calls,
                "run {}",
                row.run_id
            );
            // The observer's constants as the lean program uses them.
            assert_eq!(row.dt * f64::from(row.samples_per_rev), 2.0 * PI / omega);
            assert_eq!(metrics.settling_time_err, row.dt);
            assert_eq!(metrics.a_ref * sim.metrics.delta, row.band);
        }
    }
}
