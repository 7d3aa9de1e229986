//! `study sensitivity`: which sampled input explains the spread of each
//! design's settling time, residual and settled share (Sobol indices).

use crate::UserError;
use crate::output::{dropped_note, fitted_table, say, say_err, text_width};
use autobal::output_file::WhenExists;
use autobal::study::plan::config::load;
use autobal::study::plan::stream::{SOBOL_MAX_SAMPLES, Sequence};
use autobal::study::run::study_folder::claim;
use autobal::study::sensitivity::{
    FILE, InputKind, Measure, SensitivityRow, SensitivitySettings, estimate, inputs,
    run_pick_freeze, runs_needed, write,
};
use clap::Args;
use std::path::PathBuf;

/// Examples shown under `study sensitivity --help`.
pub const EXAMPLES: &str = "Examples:
  study sensitivity studies/bristol_uncertain.toml
  study sensitivity studies/three_balls.toml --rows 128 --designs 0,7
  study sensitivity studies/tolerances.toml --random   # plain random draws, to compare";

/// Most runs one analysis may make (as a study: about 80 bytes each in memory).
const MAX_RUNS: u64 = 10_000_000;

/// Arguments of `study sensitivity`.
#[derive(Args)]
pub struct SensitivityArgs {
    /// Study file.
    study: PathBuf,
    /// Rows N of each pick-freeze matrix: N·(k + 2) runs per design for k
    /// inputs (a power of two, as the Sobol sequence is even only over 2^m points).
    #[arg(long, default_value_t = 64)]
    rows: u32,
    /// Only these designs (the ids of the ranking's `id` column), comma-separated.
    #[arg(long, value_delimiter = ',')]
    designs: Vec<u32>,
    /// Draw the matrices pseudo-randomly instead of from the scrambled Sobol
    /// sequence (wider intervals at the same cost: for comparison).
    #[arg(long)]
    random: bool,
    /// Worker threads (default: all cores, or RAYON_NUM_THREADS).
    #[arg(long, value_parser = crate::limits::threads)]
    threads: Option<usize>,
    /// Replace the study folder's sensitivity.parquet if it exists.
    #[arg(long)]
    overwrite: bool,
}

/// Run `study sensitivity`.
pub fn run(args: &SensitivityArgs) -> Result<(), UserError> {
    let mut plan = load(&args.study)?;
    let sequence = if args.random {
        Sequence::Random
    } else {
        Sequence::Sobol
    };
    check_rows(args.rows, sequence)?;
    if !args.designs.is_empty() {
        if let Some(id) = args
            .designs
            .iter()
            .find(|id| **id as usize >= plan.designs.len())
        {
            return Err(UserError(
                format!(
                    "--designs {id}: the study has designs 0..={} only",
                    plan.designs.len() - 1
                ),
                2,
            ));
        }
        plan.designs.retain(|d| args.designs.contains(&d.id));
    }
    let settings = SensitivitySettings {
        rows: args.rows,
        sequence,
        threads: crate::limits::capped_threads(args.threads),
    };
    let inputs = inputs(&plan);
    if inputs.is_empty() {
        return Err(UserError(
            "the study samples nothing (fixed unbalance and direction, a balanced start, no tolerances, no [uncertain] keys): there is no variance to apportion".into(),
            2,
        ));
    }
    let total = runs_needed(&plan, &settings);
    if total > MAX_RUNS {
        return Err(UserError(
            format!(
                "--rows {}: {total} runs, more than the {MAX_RUNS} one analysis may make; use fewer rows or --designs",
                args.rows
            ),
            2,
        ));
    }
    let _folder = claim(
        &plan,
        "sensitivity",
        &[FILE],
        WhenExists::from_overwrite(args.overwrite),
    )?;
    say_err(&format!(
        "cost: N·(k + 2) = {}·({} + 2) = {} runs per design, {total} runs for {} design(s); inputs: {}",
        args.rows,
        inputs.len(),
        total / plan.designs.len() as u64,
        plan.designs.len(),
        inputs
            .iter()
            .map(|i| i.name.as_str())
            .collect::<Vec<_>>()
            .join(", ")
    ));
    let step = (total / 10).max(1);
    let runs = run_pick_freeze(&plan, &settings, &|done| {
        if done % step == 0 {
            eprintln!("{done}/{total} runs");
        }
    });
    let rows = estimate(&plan, &settings, &runs);
    let path = write(&plan, &rows).map_err(|e| UserError::internal(e.to_string()))?;
    for design in &plan.designs {
        print_design(
            design.id,
            &autobal::study::plan::plane_designs::describe(design),
            &rows,
        );
    }
    say(&format!(
        "(S_T: the total index, the share of the measure's variance that goes when the input is known, interactions included; S_1: the first-order index, the input alone; [95 % bootstrap interval]; shares shown within [0, 1], estimates beyond are noise and sensitivity.parquet keeps them; settling ≤ τ: the settling time capped at the horizon τ = {} rev, as the restricted mean counts it; {} draws)",
        autobal::study::results::design_runs::settling_horizon(&plan),
        if args.random {
            "pseudo-random"
        } else {
            "scrambled Sobol"
        }
    ));
    say_err(&format!("wrote {}", path.display()));
    Ok(())
}

/// The rows N allowed for the sequence.
fn check_rows(rows: u32, sequence: Sequence) -> Result<(), UserError> {
    let fine = match sequence {
        Sequence::Sobol => rows.is_power_of_two() && (4..=SOBOL_MAX_SAMPLES).contains(&rows),
        Sequence::Random => (4..=SOBOL_MAX_SAMPLES).contains(&rows),
    };
    if fine {
        Ok(())
    } else {
        Err(UserError(
            format!(
                "--rows {rows}: a power of two from 4 to {SOBOL_MAX_SAMPLES} (e.g. 64): the Sobol sequence is even only over 2^m points, and the bootstrap needs a few rows"
            ),
            2,
        ))
    }
}

/// One design's table: S_T of each measure, then S_1 (dropped first when narrow).
fn print_design(id: u32, describe: &str, rows: &[SensitivityRow]) {
    let mine: Vec<&SensitivityRow> = rows.iter().filter(|r| r.design_id == id).collect();
    let of = |input: &str, m: Measure| mine.iter().find(|r| r.input == input && r.measure == m);
    let cell = |r: Option<&&SensitivityRow>, total: bool| match r.and_then(|r| r.index.as_ref()) {
        Some(i) if total => shown(i.total, i.total_ci),
        Some(i) => shown(i.first, i.first_ci),
        None => "–".into(),
    };
    let mut inputs: Vec<&str> = Vec::new();
    for r in &mine {
        if !inputs.contains(&r.input.as_str()) {
            inputs.push(&r.input);
        }
    }
    let table: Vec<Vec<String>> = inputs
        .iter()
        .map(|input| {
            let mut row = vec![input.to_string()];
            row.extend(Measure::ALL.map(|m| cell(of(input, m), true)));
            row.extend(Measure::ALL.map(|m| cell(of(input, m), false)));
            row
        })
        .collect();
    let used = mine.first().map_or(0, |r| r.rows);
    say(&format!("design {id} ({describe}), {used} rows:"));
    let (text, dropped) = fitted_table(
        &[
            "input",
            "S_T settling ≤ τ",
            "S_T residual",
            "S_T settled",
            "S_1 settling ≤ τ",
            "S_1 residual",
            "S_1 settled",
        ],
        &table,
        &[0, 0, 2, 3, 4, 5, 6],
        text_width(),
    );
    print!("{text}{}", dropped_note(&dropped));
    for m in Measure::ALL {
        if let Some(note) = mine
            .iter()
            .find(|r| r.measure == m)
            .and_then(|r| r.note.as_ref())
        {
            say(&format!("{}: no index ({note})", m.name()));
        }
    }
    let settling: Vec<Total> = mine
        .iter()
        .filter(|r| r.measure == Measure::RestrictedSettling)
        .filter_map(|r| {
            let i = r.index.as_ref()?;
            Some(Total {
                input: &r.input,
                kind: r.kind,
                total: i.total,
                interval: i.total_ci,
            })
        })
        .collect();
    if let Some(line) = headline(&format!("design {id}'s settling time"), &settling) {
        say(&line);
    }
}

/// One input's total index as a headline names it.
pub struct Total<'a> {
    /// The input's name.
    pub input: &'a str,
    /// What kind of input it is.
    pub kind: InputKind,
    /// Its total index (raw estimate).
    pub total: f64,
    /// Its interval.
    pub interval: (f64, f64),
}

/// Which input matters for `what`: the largest total index among the
/// machine unknowns (the `[uncertain]` keys, what an engineer can measure
/// or specify), then the sampled inputs apart ([`sampled_apart`]); `None`
/// without indices.
fn headline(what: &str, totals: &[Total]) -> Option<String> {
    if totals.is_empty() {
        return None;
    }
    let unknown = totals
        .iter()
        .filter(|t| t.kind == InputKind::MachineUnknown)
        .max_by(|a, b| a.total.total_cmp(&b.total));
    let first = match unknown {
        Some(top) => format!(
            "largest total index on {what} among the machine unknowns ([uncertain] keys): {}, S_T = {}",
            top.input,
            shown(top.total, top.interval)
        ),
        None => "no machine unknowns ([uncertain] keys) to name".to_string(),
    };
    Some(match sampled_apart(totals) {
        Some(rest) => format!("{first}; {rest}"),
        None => first,
    })
}

/// The sampled inputs that are not machine unknowns, each kind apart and
/// largest total index first: "operating conditions (sampled, not machine
/// unknowns): unbalance (size, direction) S_T = …"; `None` when there are none.
pub fn sampled_apart(totals: &[Total]) -> Option<String> {
    let group = |kind: InputKind, label: &str| {
        let mut mine: Vec<&Total> = totals.iter().filter(|t| t.kind == kind).collect();
        mine.sort_by(|a, b| b.total.total_cmp(&a.total));
        (!mine.is_empty()).then(|| {
            let each: Vec<String> = mine
                .iter()
                .map(|t| format!("{} S_T = {}", t.input, shown(t.total, t.interval)))
                .collect();
            format!("{label}: {}", each.join(", "))
        })
    };
    let parts: Vec<String> = [
        group(
            InputKind::OperatingCondition,
            "operating conditions (sampled, not machine unknowns)",
        ),
        group(
            InputKind::Tolerance,
            "manufacturing tolerances (sampled, not machine unknowns)",
        ),
    ]
    .into_iter()
    .flatten()
    .collect();
    (!parts.is_empty()).then(|| parts.join("; "))
}

/// An index and its interval as printed: a share, so clipped to [0, 1]
/// (beyond is the estimator's noise; sensitivity.parquet keeps the raw
/// estimates).
pub fn shown(value: f64, (lo, hi): (f64, f64)) -> String {
    let c = |x: f64| x.clamp(0.0, 1.0);
    format!("{:.2} [{:.2}, {:.2}]", c(value), c(lo), c(hi))
}
