//! `study design`: print the analytic design table for a range of weight counts.

use crate::UserError;
use crate::output::{Format, csv, json, text_table};
use autobal::design::Shape;
use autobal::design::table::{DesignRow, optimal_row, row_at};
use clap::{Args, ValueEnum};

/// Examples shown under `study design --help`.
pub const EXAMPLES: &str = "Examples:
  study design --kind ball --n 1..8          Table 1 of seed 000 for balls
  study design --kind roller --n 1..12 --json
  study design --kind ball --n 3 --rho 0.3   one design at a given radius ratio";

/// Arguments of `study design`.
#[derive(Args)]
pub struct DesignArgs {
    /// Weight shape; both when omitted.
    #[arg(long, value_enum)]
    kind: Option<KindArg>,
    /// Weight counts: a single value (3), an inclusive range (1..8) or a list (2,3,5).
    #[arg(long, default_value = "1..8", value_parser = parse_counts)]
    n: Counts,
    /// Evaluate at this radius ratio ρ = r/R instead of the capacity optimum.
    #[arg(long)]
    rho: Option<f64>,
    /// Print a JSON array of objects.
    #[arg(long, conflicts_with = "csv")]
    json: bool,
    /// Print CSV with a header line.
    #[arg(long)]
    csv: bool,
}

#[derive(Clone, Copy, ValueEnum)]
pub(crate) enum KindArg {
    Ball,
    Roller,
}

impl From<KindArg> for Shape {
    fn from(k: KindArg) -> Self {
        match k {
            KindArg::Ball => Shape::Ball,
            KindArg::Roller => Shape::Roller,
        }
    }
}

/// The weight counts requested on the command line.
#[derive(Clone)]
pub(crate) struct Counts(pub(crate) Vec<u32>);

pub(crate) fn parse_counts(text: &str) -> Result<Counts, String> {
    let number = |s: &str| {
        let n: u32 = s
            .trim()
            .parse()
            .map_err(|_| format!("'{s}' is not a whole number of weights"))?;
        if n == 0 {
            Err("n = 0: an auto-balancer needs at least one weight (n ≥ 1)".to_string())
        } else if n > autobal::study::plan::config::MAX_WEIGHTS {
            Err(format!(
                "n = {n}: at most {} weights per balancer",
                autobal::study::plan::config::MAX_WEIGHTS
            ))
        } else {
            Ok(n)
        }
    };
    let counts = if let Some((a, b)) = text.split_once("..") {
        let (a, b) = (number(a)?, number(b.trim_start_matches('='))?);
        if a > b {
            return Err(format!("range {text}: start {a} is above end {b}"));
        }
        (a..=b).collect()
    } else {
        text.split(',').map(number).collect::<Result<Vec<_>, _>>()?
    };
    Ok(Counts(counts))
}

/// Run `study design`.
pub fn run(args: &DesignArgs) -> Result<(), UserError> {
    let shapes: Vec<Shape> = match args.kind {
        Some(k) => vec![k.into()],
        None => Shape::ALL.to_vec(),
    };
    let mut rows = Vec::new();
    for shape in shapes {
        for &n in &args.n.0 {
            rows.push(match args.rho {
                Some(rho) => row_at(shape, n, rho)?,
                None => optimal_row(shape, n)?,
            });
        }
    }
    let text = match Format::from_flags(args.json, args.csv) {
        Format::Json => json(&rows)?,
        Format::Csv => csv(&rows)?,
        Format::Table => table(&rows, args.rho.is_some()),
    };
    print!("{text}");
    if !text.ends_with('\n') {
        println!();
    }
    Ok(())
}

fn table(rows: &[DesignRow], given_rho: bool) -> String {
    let rho_header = if given_rho { "ρ" } else { "ρ_opt" };
    let header = [
        "kind", "n", rho_header, "sector°", "s", "ρ_max", "p_max", "ã", "excess",
    ];
    let cells: Vec<Vec<String>> = rows
        .iter()
        .map(|r| {
            vec![
                r.kind.to_string(),
                r.n.to_string(),
                format!("{:.4}", r.rho_opt),
                r.sector_deg.map_or("–".to_string(), |d| format!("{d:.1}")),
                format!("{:.4}", r.s),
                format!("{:.4}", r.rho_max),
                format!("{:.4}", r.p_max),
                format!("{:.5}", r.a_tilde),
                r.excess.to_string(),
            ]
        })
        .collect();
    text_table(&header, &cells)
}
