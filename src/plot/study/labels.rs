//! How a study's designs are told apart in its figures: labels naming only
//! the parameters that vary, colours or panels shared by one geometry (or
//! by one drive where the geometry is shared), and
//! the category axis that lists designs top to bottom.

use super::DesignStats;
use crate::plot::style::{TICK, short};

/// How designs are told apart: the parameters that vary, and those that do not.
pub(super) struct Labels {
    /// One label per design, naming what varies.
    pub per_design: Vec<String>,
    /// What every design shares, for the caption.
    pub common: String,
}

/// Per-design labels and the common part, from what varies across `designs`.
pub(super) fn labels(designs: &[DesignStats]) -> Labels {
    let varies = |f: &dyn Fn(&DesignStats) -> String| {
        let first = f(&designs[0]);
        designs.iter().any(|d| f(d) != first)
    };
    let weights = |d: &DesignStats| match per_plane(d, |p| p.n.to_string()) {
        Some(ns) => format!(
            "{ns} {}s",
            per_plane(d, |p| p.kind.clone()).unwrap_or_default()
        ),
        None => weight_count(d.n, &d.kind),
    };
    let rho = |d: &DesignStats| {
        format!(
            "ρ = {}",
            per_plane(d, |p| short(p.rho)).unwrap_or_else(|| short(d.rho))
        )
    };
    let drag = |d: &DesignStats| {
        format!(
            "β = {} N·s/m",
            per_plane(d, |p| short(p.drag)).unwrap_or_else(|| short(d.drag))
        )
    };
    // Empty without a motor, so that designs without one are not labelled.
    let stall = |d: &DesignStats| match d.stall_torque {
        Some(m) => format!("M_s = {} N·m", short(m)),
        None => String::new(),
    };
    let parts: [&dyn Fn(&DesignStats) -> String; 4] = [&weights, &rho, &drag, &stall];
    let (vary, fixed): (Vec<_>, Vec<_>) = parts.iter().partition(|f| varies(**f));
    let per_design = designs
        .iter()
        .map(|d| {
            if vary.is_empty() {
                format!("design {}", d.design_id)
            } else {
                vary.iter()
                    .map(|f: &&dyn Fn(&DesignStats) -> String| f(d))
                    .filter(|s| !s.is_empty())
                    .collect::<Vec<_>>()
                    .join(", ")
            }
        })
        .collect();
    let common = fixed
        .iter()
        .map(|f| f(&designs[0]))
        .filter(|s| !s.is_empty())
        .collect::<Vec<_>>()
        .join(", ");
    Labels { per_design, common }
}

/// A value over a design's balancer planes: one value where every plane
/// has it, else each plane's joined by "/" ("2/3"); `None` without
/// designs per plane.
fn per_plane(d: &DesignStats, f: impl Fn(&super::PlaneDesignStats) -> String) -> Option<String> {
    let values: Vec<String> = d.planes.iter().map(f).collect();
    let first = values.first()?;
    Some(if values.iter().all(|v| v == first) {
        first.clone()
    } else {
        values.join("/")
    })
}

/// "3 balls", "1 roller".
pub(super) fn weight_count(n: u32, kind: &str) -> String {
    if n == 1 {
        format!("1 {kind}")
    } else {
        format!("{n} {kind}s")
    }
}

/// Index of each design's geometry (kind, n, ρ): designs sharing it share a colour or panel.
pub(super) fn geometries(designs: &[DesignStats]) -> (Vec<usize>, Vec<String>) {
    let mut keys: Vec<(String, String, String)> = Vec::new();
    let index = designs
        .iter()
        .map(|d| {
            let key = (
                per_plane(d, |p| p.kind.clone()).unwrap_or_else(|| d.kind.clone()),
                per_plane(d, |p| p.n.to_string()).unwrap_or_else(|| d.n.to_string()),
                per_plane(d, |p| short(p.rho)).unwrap_or_else(|| short(d.rho)),
            );
            match keys.iter().position(|k| *k == key) {
                Some(i) => i,
                None => {
                    keys.push(key);
                    keys.len() - 1
                }
            }
        })
        .collect();
    let names = keys
        .iter()
        .map(|(kind, n, rho)| {
            let weights = match n.parse::<u32>() {
                Ok(n) => weight_count(n, kind),
                Err(_) => format!("{n} {kind}s"),
            };
            format!("{weights}, ρ = {rho}")
        })
        .collect();
    (index, names)
}

/// The colour group of each design's row in a one-row-per-design figure,
/// with a legend name per group: its geometry (kind, n, ρ) where
/// geometries differ, else its drive and damping (β, M_s) where those
/// differ, so that the colours tell apart what varies (in a Sommerfeld
/// study, each stall torque its own colour, as in settling vs unbalance).
pub(super) fn row_colours(designs: &[DesignStats]) -> (Vec<usize>, Vec<String>) {
    let geometry = geometries(designs);
    if geometry.1.len() > 1 {
        return geometry;
    }
    let drive = drives(designs);
    if drive.1.len() > 1 { drive } else { geometry }
}

/// Index of each design's drive and damping (β, M_s), the parameters a
/// geometry's panel does not name, with a label for each naming those of
/// them that vary (β alone when neither does): designs in one panel that
/// differ in either get different colours.
pub(super) fn drives(designs: &[DesignStats]) -> (Vec<usize>, Vec<String>) {
    let drag = |d: &DesignStats| format!("β = {} N·s/m", short(d.drag));
    let stall = |d: &DesignStats| {
        d.stall_torque
            .map(|m| format!("M_s = {} N·m", short(m)))
            .unwrap_or_default()
    };
    let mut keys: Vec<(f64, Option<f64>, usize)> = Vec::new();
    for (i, d) in designs.iter().enumerate() {
        if !keys.iter().any(|k| k.0 == d.drag && k.1 == d.stall_torque) {
            keys.push((d.drag, d.stall_torque, i));
        }
    }
    // In order of β then M_s, so the legend reads as a sweep.
    keys.sort_by(|a, b| {
        a.0.total_cmp(&b.0)
            .then(a.1.unwrap_or(f64::NAN).total_cmp(&b.1.unwrap_or(f64::NAN)))
    });
    let index = designs
        .iter()
        .map(|d| {
            keys.iter()
                .position(|k| k.0 == d.drag && k.1 == d.stall_torque)
                .unwrap_or(0)
        })
        .collect();
    let first = &designs[keys[0].2];
    let drag_varies = keys.iter().any(|k| k.0 != first.drag);
    let stall_varies = keys.iter().any(|k| k.1 != first.stall_torque);
    let names = keys
        .iter()
        .map(|k| {
            let d = &designs[k.2];
            match (drag_varies, stall_varies) {
                (true, true) => format!("{}, {}", drag(d), stall(d)),
                (false, true) => stall(d),
                _ => drag(d),
            }
        })
        .collect();
    (index, names)
}

/// Width in pixels to reserve for category labels of this many characters.
pub(super) fn label_width(labels: &[String]) -> u32 {
    let longest = labels.iter().map(|l| l.chars().count()).max().unwrap_or(4) as u32;
    (longest * TICK * 58 / 100 + 24).max(60)
}

/// Figure height that gives every design a row.
pub(super) fn category_height(count: usize) -> u32 {
    (180 + 34 * count as u32).max(480)
}

/// Category axis: design i sits at y = count − 1 − i, so the first design is on top.
pub(super) fn category_y(i: usize, count: usize) -> f64 {
    (count - 1 - i) as f64
}

/// Tick labels of the category axis: the design's label at whole positions.
pub(super) fn category_label(labels: &[String]) -> impl Fn(&f64) -> String + '_ {
    move |v: &f64| {
        let count = labels.len();
        let k = v.round();
        if (v - k).abs() > 1e-6 || k < 0.0 || k as usize >= count {
            return String::new();
        }
        labels[count - 1 - k as usize].clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_name_only_what_varies() {
        let d = |id, rho, drag| DesignStats {
            design_id: id,
            kind: "ball".into(),
            n: 3,
            rho,
            drag,
            runs: 10,
            settled_fraction: 1.0,
            settled_lo: 0.7,
            settled_hi: 1.0,
            planes: Vec::new(),
            stall_torque: None,
        };
        let l = labels(&[d(0, 0.25, 2.0), d(1, 0.25, 5.0)]);
        assert_eq!(l.per_design, vec!["β = 2 N·s/m", "β = 5 N·s/m"]);
        assert_eq!(l.common, "3 balls, ρ = 0.25");
    }

    #[test]
    fn stall_torque_is_named_where_it_varies() {
        let d = |id, drag, m| DesignStats {
            design_id: id,
            kind: "ball".into(),
            n: 3,
            rho: 0.25,
            drag,
            runs: 10,
            settled_fraction: 1.0,
            settled_lo: 0.7,
            settled_hi: 1.0,
            planes: Vec::new(),
            stall_torque: Some(m),
        };
        let designs = [d(0, 2.0, 0.5), d(1, 2.0, 1.0), d(2, 5.0, 0.5)];
        let l = labels(&designs);
        assert_eq!(
            l.per_design,
            vec![
                "β = 2 N·s/m, M_s = 0.5 N·m",
                "β = 2 N·s/m, M_s = 1 N·m",
                "β = 5 N·s/m, M_s = 0.5 N·m"
            ]
        );
        let (index, names) = drives(&designs);
        assert_eq!(index, vec![0, 1, 2]);
        assert_eq!(names[1], "β = 2 N·s/m, M_s = 1 N·m");
        let (index, names) = drives(&designs[..2]);
        assert_eq!((index, names[0].as_str()), (vec![0, 1], "M_s = 0.5 N·m"));
        // One geometry: the rows' colours follow the drive, one per design.
        let (index, names) = row_colours(&designs);
        assert_eq!(index, vec![0, 1, 2]);
        assert_eq!(names[2], "β = 5 N·s/m, M_s = 0.5 N·m");
    }

    #[test]
    fn designs_per_plane_name_each_planes_count() {
        let plane = |n| super::super::PlaneDesignStats {
            kind: "ball".into(),
            n,
            rho: 0.1,
            drag: 0.5,
        };
        let d = |id, n1| DesignStats {
            design_id: id,
            kind: "ball".into(),
            n: 2,
            rho: 0.1,
            drag: 0.5,
            runs: 10,
            settled_fraction: 1.0,
            settled_lo: 0.7,
            settled_hi: 1.0,
            planes: vec![plane(2), plane(n1)],
            stall_torque: None,
        };
        let designs = [d(0, 3), d(1, 4)];
        let l = labels(&designs);
        assert_eq!(l.per_design, vec!["2/3 balls", "2/4 balls"]);
        assert_eq!(l.common, "ρ = 0.1, β = 0.5 N·s/m");
        let (index, names) = geometries(&designs);
        assert_eq!(index, vec![0, 1]);
        assert_eq!(names, vec!["2/3 balls, ρ = 0.1", "2/4 balls, ρ = 0.1"]);
        // Geometries differ: the rows' colours follow them.
        assert_eq!(row_colours(&designs), (index, names));
    }
}
