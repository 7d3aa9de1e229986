//! A design per balancer plane. On a rotor with several balancer planes,
//! `[[designs.per_plane]]` gives one plane its own kinds, counts, radius
//! ratios and drags; the keys it leaves out follow plane 0's (the
//! `[designs]` table's) value in every design, as every plane did before.
//! The grid is the product: for each of plane 0's combinations, every
//! combination of the other planes' own axes. Each plane's design is checked
//! on its own (fit, capacity); the design's `capacity` is its weakest plane's.
//! runs.parquet and summary.parquet then name every plane's design in
//! columns of their own (`kind_plane0`, `n_plane1`, …).

use crate::invalid_key::InvalidKey;
use crate::model::balancer::Kind;
use crate::model::scene::{DesignSpec, RhoChoice};
use crate::study::plan::design::{Design, MAX_WEIGHTS, OneOrMany};
use polars::prelude::*;
use schemars::JsonSchema;
use serde::{Deserialize, Serialize};

/// The axes one balancer plane varies on its own.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize, JsonSchema)]
#[serde(deny_unknown_fields)]
pub struct PlaneAxes {
    /// The balancer plane (1, 2, …: plane 0 is `[designs]` itself).
    pub plane: usize,
    /// Balancer kinds of this plane (default: plane 0's, design by design).
    #[serde(default)]
    pub kind: Option<OneOrMany<Kind>>,
    /// Weight counts of this plane (default: plane 0's).
    #[serde(default)]
    pub n: Option<OneOrMany<u32>>,
    /// Radius ratios of this plane (default: plane 0's).
    #[serde(default)]
    pub rho: Option<OneOrMany<RhoChoice>>,
    /// Viscous coefficients β (N·s/m) of this plane (default: plane 0's).
    #[serde(default)]
    pub drag: Option<OneOrMany<f64>>,
}

/// A bad `[[designs.per_plane]]` entry: (key, value, reason).
type Refusal = InvalidKey;

/// Check the entries against a rotor with `planes` balancer planes.
pub fn validate(axes: &[PlaneAxes], planes: usize) -> Result<(), Refusal> {
    for (i, a) in axes.iter().enumerate() {
        let key = |k: &str| format!("designs.per_plane[{i}].{k}");
        if planes < 2 {
            return Err(InvalidKey::new(
                "designs.per_plane",
                format!("plane {}", a.plane),
                "the rotor has one balancer plane: a design per plane needs a rotor with several (rotor.model = \"two_support\" or \"flexible\")",
            ));
        }
        if a.plane == 0 || a.plane >= planes {
            return Err(InvalidKey::new(
                key("plane"),
                a.plane.to_string(),
                format!(
                    "must name one of the rotor's other balancer planes, 1 to {} (plane 0 is [designs] itself)",
                    planes - 1
                ),
            ));
        }
        if axes[..i].iter().any(|b| b.plane == a.plane) {
            return Err(InvalidKey::new(
                key("plane"),
                a.plane.to_string(),
                "this plane already has an entry",
            ));
        }
        let empty = [
            (
                "kind",
                a.kind.as_ref().is_some_and(|v| v.values().is_empty()),
            ),
            ("n", a.n.as_ref().is_some_and(|v| v.values().is_empty())),
            ("rho", a.rho.as_ref().is_some_and(|v| v.values().is_empty())),
            (
                "drag",
                a.drag.as_ref().is_some_and(|v| v.values().is_empty()),
            ),
        ];
        if let Some((k, _)) = empty.iter().find(|(_, e)| *e) {
            return Err(InvalidKey::new(key(k), "[]", "needs at least one value"));
        }
        if let Some(n) =
            a.n.as_ref()
                .and_then(|v| v.values().into_iter().find(|&n| n > MAX_WEIGHTS))
        {
            return Err(InvalidKey::new(
                key("n"),
                n.to_string(),
                format!("at most {} weights per balancer", MAX_WEIGHTS),
            ));
        }
    }
    Ok(())
}

/// A plane's own values, or plane 0's value of the design.
fn pick<T>(given: Option<Vec<T>>, tied: T) -> Vec<T> {
    given.unwrap_or_else(|| vec![tied])
}

/// The other planes' balancers for plane 0's `base`, one list per
/// combination of their own axes (planes 1, 2, … of a rotor with `planes`
/// balancer planes, in order), in grid order: the last plane's axes vary
/// fastest, and within a plane kind, n, ρ, drag as in `[designs]`.
pub fn combinations(axes: &[PlaneAxes], planes: usize, base: &DesignSpec) -> Vec<Vec<DesignSpec>> {
    let mut out: Vec<Vec<DesignSpec>> = vec![Vec::new()];
    for plane in 1..planes {
        let own = axes.iter().find(|a| a.plane == plane);
        let kinds = pick(
            own.and_then(|a| a.kind.as_ref()).map(OneOrMany::values),
            base.kind,
        );
        let ns = pick(
            own.and_then(|a| a.n.as_ref()).map(OneOrMany::values),
            base.n,
        );
        let rhos = pick(
            own.and_then(|a| a.rho.as_ref()).map(OneOrMany::values),
            base.rho.clone(),
        );
        let drags = pick(
            own.and_then(|a| a.drag.as_ref()).map(OneOrMany::values),
            base.drag,
        );
        let mut next = Vec::new();
        for head in &out {
            for &kind in &kinds {
                for &n in &ns {
                    for rho in &rhos {
                        for &drag in &drags {
                            let mut list = head.clone();
                            list.push(DesignSpec {
                                kind,
                                n,
                                rho: rho.clone(),
                                drag,
                                plane,
                                ..base.clone()
                            });
                            next.push(list);
                        }
                    }
                }
            }
        }
        out = next;
    }
    out
}

/// The per-plane design columns, before their `_plane{p}` suffix: enough
/// to name each plane's part (count, size, mass, race, drag).
const PLANE_COLUMNS: [&str; 8] = [
    "kind",
    "n",
    "rho",
    "drag",
    "capacity",
    "race_radius",
    "weight_mass",
    "roller_height",
];

/// Names of the per-plane design columns of `planes` planes, as written.
pub fn column_names(planes: usize) -> Vec<String> {
    (0..planes)
        .flat_map(|p| PLANE_COLUMNS.map(|k| format!("{k}_plane{p}")))
        .collect()
}

/// Append each plane's design (kind, n, ρ, drag, capacity) to `df`, whose
/// `design_id` column names rows of `designs`; nothing when no design has a
/// plane of its own.
pub fn append_columns(df: &mut DataFrame, designs: &[Design]) -> PolarsResult<()> {
    let Some(planes) = designs
        .iter()
        .map(|d| d.plane_designs.len())
        .max()
        .filter(|&p| p > 0)
    else {
        return Ok(());
    };
    let ids: Vec<u32> = df.column("design_id")?.u32()?.into_no_null_iter().collect();
    let design = |id: u32| {
        designs
            .iter()
            .find(|d| d.id == id)
            .ok_or_else(|| polars_err!(ComputeError: "design {id} is not in the study"))
    };
    let rows: Vec<&Design> = ids
        .iter()
        .map(|&id| design(id))
        .collect::<PolarsResult<_>>()?;
    // Plane 0 is the design's own spec; planes 1.. its plane designs.
    type Plane = (String, u32, f64, f64, f64, f64, f64, Option<f64>);
    let plane_of = |d: &Design, p: usize| -> Plane {
        let (pd, capacity) = if p == 0 {
            (d, d.plane_zero_capacity)
        } else {
            (&d.plane_designs[p - 1], d.plane_designs[p - 1].capacity)
        };
        let s = &pd.spec;
        let (race, mass) = (s.race_radius, pd.weight_mass);
        (
            s.kind.name().into(),
            s.n,
            pd.rho,
            s.drag,
            capacity,
            race,
            mass,
            pd.roller_length(),
        )
    };
    let names = column_names(planes + 1);
    for (p, names) in names.chunks(PLANE_COLUMNS.len()).enumerate() {
        let values: Vec<Plane> = rows.iter().map(|d| plane_of(d, p)).collect();
        let columns = [
            Column::new(
                names[0].as_str().into(),
                values.iter().map(|v| v.0.clone()).collect::<Vec<_>>(),
            ),
            Column::new(
                names[1].as_str().into(),
                values.iter().map(|v| v.1).collect::<Vec<_>>(),
            ),
            Column::new(
                names[2].as_str().into(),
                values.iter().map(|v| v.2).collect::<Vec<_>>(),
            ),
            Column::new(
                names[3].as_str().into(),
                values.iter().map(|v| v.3).collect::<Vec<_>>(),
            ),
            Column::new(
                names[4].as_str().into(),
                values.iter().map(|v| v.4).collect::<Vec<_>>(),
            ),
            Column::new(
                names[5].as_str().into(),
                values.iter().map(|v| v.5).collect::<Vec<_>>(),
            ),
            Column::new(
                names[6].as_str().into(),
                values.iter().map(|v| v.6).collect::<Vec<_>>(),
            ),
            Column::new(
                names[7].as_str().into(),
                values.iter().map(|v| v.7).collect::<Vec<_>>(),
            ),
        ];
        for c in columns {
            df.with_column(c)?;
        }
    }
    Ok(())
}

/// A design's balancers in a few words: "ball n = 8 ρ = 0.0400" when every
/// plane has the same, "plane 0: …; plane 1: …" when planes have their own.
pub fn describe(d: &Design) -> String {
    let one = |s: &DesignSpec, rho: f64| format!("{} n = {} ρ = {:.4}", s.kind, s.n, rho);
    if d.plane_designs.is_empty() {
        return one(&d.spec, d.rho);
    }
    std::iter::once(format!("plane 0: {}", one(&d.spec, d.rho)))
        .chain(
            d.plane_designs
                .iter()
                .map(|p| format!("plane {}: {}", p.spec.plane, one(&p.spec, p.rho))),
        )
        .collect::<Vec<_>>()
        .join("; ")
}

/// A design in one short line, "ball n=8 ρ=0.040 β=0.05", each value
/// joined by "/" over the planes where they differ ("n=2/3"), and
/// "M_s=2" at the end when the design has a stall torque.
pub fn short_label(d: &Design) -> String {
    label(d, false)
}

/// [`short_label`] with units, "ball n=8 ρ=0.040 β=0.05 N·s/m", for a
/// figure's legend, where no table header gives them.
pub fn figure_label(d: &Design) -> String {
    label(d, true)
}

/// The short label, with or without units.
fn label(d: &Design, units: bool) -> String {
    let planes: Vec<&Design> = std::iter::once(d).chain(&d.plane_designs).collect();
    let joined = |f: &dyn Fn(&Design) -> String| {
        let values: Vec<String> = planes.iter().map(|p| f(p)).collect();
        if values.iter().all(|v| *v == values[0]) {
            values[0].clone()
        } else {
            values.join("/")
        }
    };
    let unit = |u: &'static str| if units { u } else { "" };
    let stall = d
        .stall_torque
        .map(|m| format!(" M_s={m}{}", unit(" N·m")))
        .unwrap_or_default();
    format!(
        "{} n={} ρ={} β={}{}{stall}",
        joined(&|p| p.spec.kind.name().to_string()),
        joined(&|p| p.spec.n.to_string()),
        joined(&|p| format!("{:.3}", p.rho)),
        joined(&|p| crate::number_text::significant(p.spec.drag, 4)),
        unit(" N·s/m")
    )
}
