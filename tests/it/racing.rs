//! Racing the designs: the error rate of dropping a design no worse than
//! the leader, the same decision as the full study with fewer runs, and
//! the same results whatever the threads or shards.

use autobal::decide::decision::{Crown, Recommendation, StudyDecision};
use autobal::decide::verdict::ranking;
use autobal::stats::survival::Observation;
use autobal::study::plan::config::{StudyFile, StudyPlan};
use autobal::study::results::io::read_parquet;
use autobal::study::results::measured_runs::DesignRuns;
use autobal::study::results::record::deterministic_columns;
use autobal::study::run::merge::merge;
use autobal::study::run::racing::{LOOKS, SPENDING, significantly_worse};
use autobal::study::run::{NoProgress, RunOptions, Shard, run_study};
use rand::{RngExt, SeedableRng};
use rand_xoshiro::Xoshiro256PlusPlus;
use std::path::Path;

fn plan(text: &str) -> StudyPlan {
    StudyFile::parse(text, "race.toml")
        .unwrap()
        .plan(text, "race.toml")
        .unwrap()
}

/// The main job's study text, writing under `output`, with `extra` keys
/// appended to `[sampling]`.
fn main_job(output: &Path, extra: &str) -> String {
    let text = std::fs::read_to_string("studies/three_balls.toml").unwrap();
    let text = text.replace("[sampling]\n", &format!("[sampling]\n{extra}\n"));
    format!("name = \"race\"\noutput = \"{}\"\n{text}", output.display())
}

/// What a study decides, as sets: the recommendation, the Pareto set, the
/// verdicts on #1 (better than, not distinguishable from, other better) and
/// every "better than #1 on another measure" as (design, measure).
type Decided = (Option<u32>, Vec<u32>, [Vec<u32>; 3], Vec<(u32, String)>);

/// What the study in `dir` decides ([`Decided`]).
fn decision(dir: &Path) -> Decided {
    let summary = read_parquet(&dir.join("summary.parquet")).unwrap();
    let d = StudyDecision::from_summary(&summary).unwrap();
    let sorted = |v: &[u32]| {
        let mut v = v.to_vec();
        v.sort_unstable();
        v
    };
    let (build, pareto) = match &d.recommendation {
        Recommendation::Build { design, pareto, .. } => (Some(*design), sorted(pareto)),
        _ => (None, Vec::new()),
    };
    let verdicts = match &d.crown {
        Crown::Best {
            better_than,
            not_distinguishable,
            other_better,
            ..
        } => [
            sorted(better_than),
            sorted(not_distinguishable),
            sorted(other_better),
        ],
        _ => [Vec::new(), Vec::new(), Vec::new()],
    };
    let mut disagree: Vec<(u32, String)> = d
        .disagreements
        .iter()
        .map(|x| (x.design, x.measure.to_string()))
        .collect();
    disagree.sort();
    (build, pareto, verdicts, disagree)
}

/// The main job raced and run in full: the same recommendation, Pareto set,
/// verdicts and other-measure findings, from fewer runs.
#[test]
fn the_raced_main_job_decides_as_the_full_study_with_fewer_runs() {
    let dir = tempfile::tempdir().unwrap();
    let raced = plan(&main_job(&dir.path().join("raced"), ""));
    let full = plan(&main_job(&dir.path().join("full"), "racing = false"));
    let options = RunOptions::default();
    let a = run_study(&raced, &options, &NoProgress).unwrap();
    let b = run_study(&full, &options, &NoProgress).unwrap();
    assert_eq!(b.runs, 10_000);
    assert!(b.race.is_none());
    let departures = a.race.as_ref().unwrap();
    assert!(!departures.is_empty());
    // Measured: 6 400 runs.
    assert!(a.runs <= 7_000, "raced runs: {}", a.runs);
    assert_eq!(
        a.runs,
        10_000
            - departures
                .iter()
                .map(|d| u64::from(500 - d.samples))
                .sum::<u64>()
    );
    let (raced, full) = (decision(&a.dir), decision(&b.dir));
    // #1 is design 2; designs 7 and 16 tie with it and 16 is the lightest.
    assert_eq!(raced.0, Some(16));
    assert_eq!(raced, full);
    // Every design that left is one the full study calls worse than #1.
    for d in departures {
        assert!(full.2[0].contains(&d.design_id), "design {}", d.design_id);
    }
}

/// Twenty looks at five designs whose runs come from one distribution (so
/// none is worse than the leader): over 400 races, any design is called
/// worse in at most α of them (plus three standard errors), where testing
/// every look at α itself calls one worse far more often.
#[test]
fn racing_drops_a_design_no_worse_than_the_leader_at_most_alpha_of_the_time() {
    let dir = tempfile::tempdir().unwrap();
    let plan = plan(&main_job(dir.path(), ""));
    let alpha = plan.file.statistics.alpha;
    let (designs, batch, reps) = (5u32, 10usize, 400usize);
    let fractions: Vec<f64> = (1..=LOOKS)
        .map(|k| f64::from(k) / f64::from(LOOKS))
        .collect();
    let levels = SPENDING.look_levels(alpha, &fractions);
    let mut rng = Xoshiro256PlusPlus::seed_from_u64(20_261_127);
    let (mut spent, mut naive) = (0usize, 0usize);
    for _ in 0..reps {
        let samples = batch * LOOKS as usize;
        let all: Vec<DesignRuns> = (0..designs)
            .map(|id| {
                let times: Vec<f64> = (0..samples)
                    .map(|_| -20.0 * (1.0 - rng.random::<f64>()).ln())
                    .collect();
                DesignRuns {
                    design_id: id,
                    sample_ids: (0..samples as u32).collect(),
                    settling: times
                        .iter()
                        .map(|&t| Observation {
                            time: t,
                            settled: true,
                        })
                        .collect(),
                    residual: (0..samples).map(|_| Some(rng.random::<f64>())).collect(),
                    residual_abs: vec![Some(1e-6); samples],
                }
            })
            .collect();
        let (mut spent_hit, mut naive_hit) = (false, false);
        for (k, level) in levels.iter().enumerate().take(LOOKS as usize - 1) {
            let so_far: Vec<DesignRuns> = all.iter().map(|d| d.first((k + 1) * batch)).collect();
            let scale = autobal::study::results::design_runs::measure_scale(&plan);
            let leader = &so_far[ranking(&so_far, plan.file.summary.rank_by, &scale)[0]];
            spent_hit |= !significantly_worse(&plan, &so_far, leader, *level, k).is_empty();
            naive_hit |= !significantly_worse(&plan, &so_far, leader, alpha, k).is_empty();
        }
        spent += usize::from(spent_hit);
        naive += usize::from(naive_hit);
    }
    let rate = spent as f64 / reps as f64;
    let se = (alpha * (1.0 - alpha) / reps as f64).sqrt();
    assert!(rate <= alpha + 3.0 * se, "spent levels: {rate}");
    let naive = naive as f64 / reps as f64;
    assert!(naive > 2.0 * alpha, "every look at α: {naive}");
}

/// A raced study is the same for one and two threads, and for two shards
/// merged (the merge replays the race on every run).
#[test]
fn a_raced_study_is_identical_for_threads_and_shards() {
    let dir = tempfile::tempdir().unwrap();
    let text = main_job(dir.path(), "").replace("samples = 500", "samples = 100");
    let p = plan(&text);
    let stable = |path: &Path| {
        let df = read_parquet(path).unwrap();
        let cols = deterministic_columns(&df);
        df.select(cols).unwrap()
    };
    let run = |threads, shard: Option<Shard>, out: &str| {
        let mut p = p.clone();
        p.file.output = dir.path().join(out).display().to_string();
        let options = RunOptions {
            threads: Some(threads),
            shard,
            ..RunOptions::default()
        };
        run_study(&p, &options, &NoProgress).unwrap()
    };
    let one = run(1, None, "one");
    assert!(
        !one.race.as_ref().unwrap().is_empty(),
        "nobody left the race"
    );
    let two = run(2, None, "two");
    let shards: Vec<_> = (1..=2)
        .map(|k| run(2, Some(Shard { index: k, count: 2 }), "sharded").dir)
        .collect();
    let merged = merge(&shards, Some(&dir.path().join("merged")), false).unwrap();
    for other in [&two.dir, &merged.dir] {
        assert!(
            stable(&one.dir.join("runs.parquet"))
                .equals_missing(&stable(&other.join("runs.parquet"))),
            "{}",
            other.display()
        );
        assert!(
            read_parquet(&one.dir.join("summary.parquet"))
                .unwrap()
                .equals_missing(&read_parquet(&other.join("summary.parquet")).unwrap())
        );
    }
    let summary = read_parquet(&one.dir.join("summary.parquet")).unwrap();
    let left: Vec<Option<u32>> = summary
        .column("left_race_after")
        .unwrap()
        .u32()
        .unwrap()
        .iter()
        .collect();
    assert_eq!(
        left.iter().flatten().count(),
        one.race.as_ref().unwrap().len()
    );
}

/// Racing beside a precision to stop at: the race looks after every batch,
/// the precision is judged on the designs still running, and the result is
/// the same for one and two threads.
#[test]
fn a_race_with_a_precision_to_stop_at_is_the_same_for_any_thread_count() {
    let dir = tempfile::tempdir().unwrap();
    let text = main_job(
        dir.path(),
        "batch = 20\nstop_when = { median_halfwidth_rel = 0.1 }",
    )
    .replace("samples = 500", "samples = 200");
    let p = plan(&text);
    let run = |threads, out: &str| {
        let mut p = p.clone();
        p.file.output = dir.path().join(out).display().to_string();
        let options = RunOptions {
            threads: Some(threads),
            ..RunOptions::default()
        };
        run_study(&p, &options, &NoProgress).unwrap()
    };
    let (one, two) = (run(1, "one"), run(2, "two"));
    let adaptive = one.adaptive.clone().expect("where it stopped");
    let departures = one.race.clone().expect("a race");
    assert!(!departures.is_empty(), "nobody left the race");
    // Every design that left did so at a batch's end, at the latest at the
    // look that stopped the study (whose precision no longer counts it).
    for d in &departures {
        assert_eq!(d.samples % 20, 0, "{d:?}");
        assert!(
            d.samples <= adaptive.samples_per_design,
            "{d:?} {adaptive:?}"
        );
    }
    assert_eq!(two.adaptive, one.adaptive);
    assert_eq!(two.race, one.race);
    let stable = |dir: &Path| {
        let df = read_parquet(&dir.join("runs.parquet")).unwrap();
        let cols = deterministic_columns(&df);
        df.select(cols).unwrap()
    };
    assert!(stable(&one.dir).equals_missing(&stable(&two.dir)));
}
