//! How designs with different weight counts are made comparable. The answer
//! to "which n is fastest" depends on it, so every claim is tested under all three.

use crate::design::capacity::{capacity, weight_mass};
use crate::design::geometry::rho_max;
use crate::design::optimum::optimal_rho;
use crate::model::balancer::Kind;
use crate::study::plan::config::DesignGrid;
use serde::Serialize;

/// A way of comparing designs with different n.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Normalisation {
    /// The paper's: same race, each n at its Table-1 radius (capacity optimum);
    /// unbalances as fractions of each design's own capacity.
    Paper,
    /// Same total weight mass as three weights at their Table-1 radius;
    /// unbalances absolute (fractions of the weakest design's capacity).
    EqualMass,
    /// Same capacity for every n (the smaller radius reaching it); unbalances absolute.
    EqualCapacity,
}

impl Normalisation {
    /// All three.
    pub const ALL: [Normalisation; 3] = [
        Normalisation::Paper,
        Normalisation::EqualMass,
        Normalisation::EqualCapacity,
    ];

    /// snake_case name.
    pub fn name(self) -> &'static str {
        match self {
            Normalisation::Paper => "paper",
            Normalisation::EqualMass => "equal_mass",
            Normalisation::EqualCapacity => "equal_capacity",
        }
    }

    /// One sentence for reports.
    pub fn describe(self) -> &'static str {
        match self {
            Normalisation::Paper => {
                "same race, each n at its Table-1 radius, unbalance as a fraction of each design's capacity (the paper's own normalisation)"
            }
            Normalisation::EqualMass => {
                "same total weight mass as three weights at their Table-1 radius, same absolute unbalances"
            }
            Normalisation::EqualCapacity => {
                "same capacity for every n (smaller radius reaching it), same absolute unbalances"
            }
        }
    }
}

/// Capacity (kg·m) of n weights of `kind` at ρ in the grid's race.
pub fn design_capacity(grid: &DesignGrid, kind: Kind, n: u32, rho: f64) -> Option<f64> {
    let shape = kind.model().shape();
    match kind {
        Kind::Pendulum => {
            let m = weight_mass(
                shape,
                grid.density,
                grid.race_radius,
                rho,
                grid.roller_height,
            )
            .ok()?;
            Some(f64::from(n) * m * grid.race_radius * (1.0 - rho))
        }
        _ => capacity(
            shape,
            n,
            rho,
            grid.density,
            grid.race_radius,
            grid.roller_height,
        )
        .ok(),
    }
}

/// ρ for (kind, n) under a normalisation, given every n compared (for the
/// shared reference); `None` when the design cannot meet it (e.g. does not fit).
pub fn rho_for(
    norm: Normalisation,
    grid: &DesignGrid,
    kind: Kind,
    n: u32,
    all_n: &[u32],
) -> Option<f64> {
    let shape = kind.model().shape();
    match norm {
        Normalisation::Paper => optimal_rho(shape, n).ok().map(|o| o.rho),
        Normalisation::EqualMass => {
            // m ∝ ρ^k, so n m(ρ) = 3 m(ρ₃) gives ρ = ρ₃ (3/n)^(1/k).
            let rho3 = optimal_rho(shape, 3).ok()?.rho;
            let rho = rho3 * (3.0 / f64::from(n)).powf(1.0 / f64::from(shape.mass_exponent()));
            (rho < rho_max(n).ok()? && rho < 1.0).then_some(rho)
        }
        Normalisation::EqualCapacity => {
            let target = reference_capacity(grid, kind, all_n)?;
            // Capacity rises with ρ up to the Table-1 optimum: bisect below it.
            let top = optimal_rho(shape, n).ok()?.rho;
            let (mut lo, mut hi) = (1e-6, top);
            for _ in 0..200 {
                let mid = 0.5 * (lo + hi);
                if design_capacity(grid, kind, n, mid)? < target {
                    lo = mid
                } else {
                    hi = mid
                }
            }
            Some(0.5 * (lo + hi))
        }
    }
}

/// The capacity every design can reach: 90 % of the weakest Table-1 capacity.
pub fn reference_capacity(grid: &DesignGrid, kind: Kind, all_n: &[u32]) -> Option<f64> {
    let shape = kind.model().shape();
    all_n
        .iter()
        .filter_map(|&n| design_capacity(grid, kind, n, optimal_rho(shape, n).ok()?.rho))
        .fold(None, |acc: Option<f64>, c| {
            Some(acc.map_or(c, |a| a.min(c)))
        })
        .map(|c| 0.9 * c)
}
