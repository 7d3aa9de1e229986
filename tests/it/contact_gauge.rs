//! Shipped studies with contact forced on or off, and the deepest overlap
//! of their weights: shared by the contact tests (`contact.rs`) and the
//! table of docs/model.md (`cargo run --example contact_cost_table`, which
//! includes this file by path).

use autobal::model::gap::GapGauge;
use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::run::run_one;
use std::path::PathBuf;

/// A shipped study at `samples` per design, with contact forced on or
/// off (`None`: as shipped).
pub fn plan(name: &str, samples: u32, contact: Option<bool>) -> StudyPlan {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("studies")
        .join(name);
    let text = std::fs::read_to_string(&path).expect("study file");
    let text: String = text
        .lines()
        .map(|l| {
            if l.trim_start().starts_with("samples =") {
                format!("samples = {samples}")
            } else {
                l.to_string()
            }
        })
        .collect::<Vec<_>>()
        .join("\n");
    let mut plan = StudyFile::parse(&text, name)
        .and_then(|f| f.plan(&text, name))
        .expect("shipped study");
    if let Some(on) = contact {
        let spec = plan
            .file
            .scene
            .effects
            .contact
            .get_or_insert_with(Default::default);
        spec.enabled = on;
    }
    plan
}

/// Largest overlap over the runs as a fraction of the pair's touching angle,
/// and the number of runs that end overlapped by more than that tolerance.
pub fn worst_overlap(plan: &StudyPlan) -> (f64, usize, usize) {
    let samples = u64::from(plan.file.sampling.samples);
    let (mut worst, mut ended_overlapped, mut runs) = (0.0_f64, 0, 0);
    for id in 0..plan.total_runs() {
        let record = run_one(plan, id);
        let design = &plan.designs[(id / samples) as usize];
        let scene = plan.scene(design, record.unbalance, record.direction_deg.to_radians());
        let Some(gauge) = GapGauge::new(&scene.cargoes().expect("cargoes")) else {
            continue;
        };
        let scale = gauge.contact_angle();
        let (Some(min_gap), Some(final_gap)) =
            (record.metrics.min_gap_rad, record.metrics.final_min_gap_rad)
        else {
            panic!("run {id} of sized weights has no gap: {:?}", record.metrics);
        };
        runs += 1;
        worst = worst.max(-min_gap / scale);
        if -final_gap / scale > 0.02 {
            ended_overlapped += 1;
        }
    }
    (worst, ended_overlapped, runs)
}

/// Every study shipped in studies/.
pub const STUDIES: [&str; 9] = [
    "three_balls.toml",
    "five_rollers.toml",
    "balls_vs_rollers.toml",
    "gravity_horizontal.toml",
    "runup.toml",
    "regression.toml",
    "paper_claims.toml",
    "optimize_settling.toml",
    "optimize_capacity.toml",
];
