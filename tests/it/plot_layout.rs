//! Layout of every figure kind: rendered to SVG with crowded, realistic data
//! (more than eight series, long labels), every piece of text must lie inside
//! the canvas and no two pieces of text may overlap; within one figure no two
//! different series may share a look (colour, dash, marker).
//!
//! Text boxes are approximated from the SVG alone: width 0.6 × font size per
//! character, height one font size, placed by `text-anchor`, `dy` and any
//! `rotate(…)` transform. The SVG is read by a few lines of string scanning
//! rather than an XML crate: plotters writes one flat `<text …>…</text>` per
//! label with a fixed attribute set, and a parser dependency for that would
//! be heavier than the test.
//!
//! Set AUTOBAL_PLOT_DIR to keep the figures for looking at them.

use autobal::design::Shape;
use autobal::metrics::observer::Series;
use autobal::metrics::{Outcome, RunMetrics};
use autobal::plot::design::plot_design;
use autobal::plot::km::{KmCurve, SecondsAxis, plot_kaplan_meier};
use autobal::plot::map::plot_stability_map;
use autobal::plot::run::{RunFigure, plot_run};
use autobal::plot::study::{DesignStats, StudyData, StudyFigure};
use autobal::plot::style::{SeriesStyle, legend_styles};
use autobal::plot::tradeoff::{TradeoffPoint, plot_work_precision};
use autobal::stats::survival::Observation;
use autobal::study::results::record::RunRecord;
use autobal::study::stability_map::MapPoint;
use std::path::{Path, PathBuf};

/// A piece of text in the SVG with its approximate box (pixels).
#[derive(Debug, Clone)]
struct TextBox {
    text: String,
    x0: f64,
    y0: f64,
    x1: f64,
    y1: f64,
}

/// The value of `name="…"` in a tag's attribute text.
fn attr<'a>(tag: &'a str, name: &str) -> Option<&'a str> {
    let key = format!(" {name}=\"");
    let start = tag.find(&key)? + key.len();
    let len = tag[start..].find('"')?;
    Some(&tag[start..start + len])
}

fn unescape(s: &str) -> String {
    s.replace("&lt;", "<")
        .replace("&gt;", ">")
        .replace("&quot;", "\"")
        .replace("&apos;", "'")
        .replace("&amp;", "&")
}

/// Canvas size and the boxes of every non-empty `<text>` element.
fn text_boxes(svg: &str) -> ((f64, f64), Vec<TextBox>) {
    let head = &svg[svg.find("<svg").expect("no <svg> tag")..];
    let head = &head[..head.find('>').unwrap()];
    let num = |tag: &str, name: &str| -> f64 {
        attr(tag, name)
            .unwrap_or_else(|| panic!("no {name} in {tag}"))
            .trim_end_matches("px")
            .parse()
            .unwrap()
    };
    let canvas = (num(head, "width"), num(head, "height"));
    let mut boxes = Vec::new();
    let mut rest = svg;
    while let Some(at) = rest.find("<text") {
        rest = &rest[at..];
        let tag_end = rest.find('>').unwrap();
        let tag = &rest[..tag_end];
        let close = rest.find("</text>").unwrap();
        let content = unescape(rest[tag_end + 1..close].trim());
        rest = &rest[close..];
        let chars = content.chars().count() as f64;
        if chars == 0.0 {
            continue;
        }
        let (x, y, size) = (num(tag, "x"), num(tag, "y"), num(tag, "font-size"));
        let (w, h) = (0.6 * size * chars, size);
        let x0 = match attr(tag, "text-anchor") {
            Some("middle") => x - w / 2.0,
            Some("end") => x - w,
            _ => x,
        };
        // plotters' dy: 0.76em hangs the text below y, 0.5ex centres it, −0.5ex sits on it.
        let y0 = match attr(tag, "dy") {
            Some("0.76em") => y,
            Some("0.5ex") => y - h / 2.0,
            _ => y - h,
        };
        let mut corners = [(x0, y0), (x0 + w, y0), (x0, y0 + h), (x0 + w, y0 + h)];
        if let Some(t) = attr(tag, "transform") {
            let inner = t
                .strip_prefix("rotate(")
                .and_then(|t| t.strip_suffix(')'))
                .unwrap_or_else(|| panic!("unexpected transform {t}"));
            let v: Vec<f64> = inner
                .split(',')
                .map(|p| p.trim().parse().unwrap())
                .collect();
            let (s, c) = v[0].to_radians().sin_cos();
            for p in &mut corners {
                let (dx, dy) = (p.0 - v[1], p.1 - v[2]);
                *p = (v[1] + dx * c - dy * s, v[2] + dx * s + dy * c);
            }
        }
        let fold = |f: fn(f64, f64) -> f64, pick: fn(&(f64, f64)) -> f64, init| {
            corners.iter().map(pick).fold(init, f)
        };
        boxes.push(TextBox {
            text: content,
            x0: fold(f64::min, |p| p.0, f64::INFINITY),
            y0: fold(f64::min, |p| p.1, f64::INFINITY),
            x1: fold(f64::max, |p| p.0, f64::NEG_INFINITY),
            y1: fold(f64::max, |p| p.1, f64::NEG_INFINITY),
        });
    }
    (canvas, boxes)
}

/// Every layout defect of one SVG, as readable lines (empty: none).
fn layout_defects(svg: &str) -> Vec<String> {
    let ((w, h), boxes) = text_boxes(svg);
    let mut defects = Vec::new();
    for b in &boxes {
        if b.x0 < 0.0 || b.y0 < 0.0 || b.x1 > w || b.y1 > h {
            defects.push(format!(
                "outside the {w}×{h} canvas: {:?} at ({:.0}, {:.0})–({:.0}, {:.0})",
                b.text, b.x0, b.y0, b.x1, b.y1
            ));
        }
    }
    // A pixel of slack: rounding puts neighbours in a row edge to edge.
    let slack = 1.0;
    for (i, a) in boxes.iter().enumerate() {
        for b in &boxes[i + 1..] {
            let dx = a.x1.min(b.x1) - a.x0.max(b.x0);
            let dy = a.y1.min(b.y1) - a.y0.max(b.y0);
            if dx > slack && dy > slack {
                defects.push(format!(
                    "overlap: {:?} at ({:.0}, {:.0}) and {:?} at ({:.0}, {:.0})",
                    a.text, a.x0, a.y0, b.text, b.x0, b.y0
                ));
            }
        }
    }
    defects
}

/// Pairs of different series of the figure just drawn that look the same.
/// One series may appear in several panels (n = 3 for balls and for
/// rollers), so entries with the same label may, and should, look alike.
fn shared_looks(styles: &[(String, SeriesStyle)]) -> Vec<String> {
    let mut out = Vec::new();
    for (i, (a, sa)) in styles.iter().enumerate() {
        for (b, sb) in &styles[i + 1..] {
            if sa == sb && a != b {
                out.push(format!("{a:?} and {b:?} both drawn as {sa:?}"));
            }
        }
    }
    out
}

/// A folder for the figures: AUTOBAL_PLOT_DIR/layout when set (kept), else a temporary one.
fn figure_dir() -> (PathBuf, Option<tempfile::TempDir>) {
    match std::env::var_os("AUTOBAL_PLOT_DIR") {
        Some(dir) => {
            let path = PathBuf::from(dir).join("layout");
            std::fs::create_dir_all(&path).unwrap();
            (path, None)
        }
        None => {
            let tmp = tempfile::tempdir().unwrap();
            (tmp.path().to_path_buf(), Some(tmp))
        }
    }
}

/// Draw one figure with `draw`, then collect its defects under its name.
fn check(
    name: &str,
    dir: &Path,
    defects: &mut Vec<String>,
    draw: impl Fn(&Path) -> Result<(), autobal::plot::PlotError>,
) {
    if std::env::var_os("AUTOBAL_PLOT_DIR").is_some() {
        // A bitmap as well, for looking at the figure.
        draw(&dir.join(format!("{name}.png"))).unwrap_or_else(|e| panic!("{name}: {e}"));
    }
    let path = dir.join(format!("{name}.svg"));
    draw(&path).unwrap_or_else(|e| panic!("{name}: {e}"));
    let svg = std::fs::read_to_string(&path).unwrap();
    let styles = legend_styles();
    for d in layout_defects(&svg)
        .into_iter()
        .chain(shared_looks(&styles))
    {
        defects.push(format!("{name}: {d}"));
    }
}

fn metrics(settled: bool, revs: f64) -> RunMetrics {
    RunMetrics {
        settled,
        settling_time: settled.then_some(revs * 0.02),
        settling_revs: settled.then_some(revs),
        settling_time_err: 0.001,
        settling_time_eps: settled.then_some(revs * 0.025),
        hold_complete: settled,
        hold_certified: false,
        residual_abs: 1e-6,
        residual_rel: 0.01,
        a_ref: 1e-4,
        balancing_error: 0.0,
        peak_r: 1e-3,
        final_rel_angles_deg: vec![120.0, 180.0, 240.0],
        p_final: 0.0,
        outcome: if settled {
            Outcome::Settled
        } else {
            Outcome::NotSettled
        },
        reason: String::new(),
        t_final: 10.0,
        steps: 100,
        rhs_calls: 600,
        method: "dp5".into(),
        fidelity: "full".into(),
        contact_model: None,
        min_gap_rad: None,
        final_min_gap_rad: None,
        censoring_revs: None,
        operating_time: Some(0.0),
        final_spin_rate: None,
        pack_slip_rate: None,
        balance_angle_error_deg: None,
        plane_a_ref: None,
        plane_residual_abs: None,
        plane_settling_revs: None,
        plane_balancing_error: None,
        bearing_orbit_peak: None,
        bearing_orbit_rms: None,
    }
}

/// A study of `geometries` × `drags` designs, `samples` runs each; some never settle.
fn crowded_study(geometries: usize, drags: usize, samples: u32) -> StudyData {
    let mut designs = Vec::new();
    let mut runs = Vec::new();
    for g in 0..geometries {
        let (n, rho) = (2 + (g / 2) as u32, if g % 2 == 0 { 0.18 } else { 0.2875 });
        for k in 0..drags {
            let id = designs.len() as u32;
            let drag = 2.0 * 1.6f64.powi(k as i32);
            let mut settled_count = 0;
            for s in 0..samples {
                let fraction = 0.05 + 0.9 * f64::from(s) / f64::from(samples);
                let settled = !(s + id).is_multiple_of(7);
                settled_count += u64::from(settled);
                let revs = (4.0 + 3.0 * id as f64) * (1.0 + 6.0 * fraction * fraction);
                runs.push(RunRecord {
                    run_id: u64::from(id) * u64::from(samples) + u64::from(s),
                    design_id: id,
                    sample_id: s,
                    kind: "ball".into(),
                    n,
                    rho,
                    race_radius: 0.05,
                    weight_mass: 0.2,
                    capacity: 0.01,
                    drag,
                    unbalance: fraction * 0.01,
                    unbalance_fraction: fraction,
                    direction_deg: 0.0,
                    initial_angles_deg: vec![0.0; n as usize],
                    metrics: metrics(settled, revs),
                    method: "dp5".into(),
                    contact: true,
                    stall_torque: None,
                    wall_time_s: 0.001,
                    weights: None,
                    couple: None,
                    uncertain: Vec::new(),
                });
            }
            let p = settled_count as f64 / f64::from(samples);
            designs.push(DesignStats {
                design_id: id,
                kind: "ball".into(),
                n,
                rho,
                drag,
                runs: u64::from(samples),
                settled_fraction: p,
                settled_lo: (p - 0.12).max(0.0),
                settled_hi: (p + 0.06).min(1.0),
                planes: Vec::new(),
                stall_torque: None,
            });
        }
    }
    StudyData {
        name: "a_study_with_a_rather_long_folder_name".into(),
        runs,
        designs,
        operating_speed: None,
        sensitivity: Vec::new(),
    }
}

#[test]
fn every_figure_keeps_its_text_inside_and_apart() {
    let (dir, _keep) = figure_dir();
    let mut defects = Vec::new();

    check("design", &dir, &mut defects, |p| {
        plot_design(&Shape::ALL, &(1..=10).collect::<Vec<_>>(), p)
    });

    // Ten cargoes circulating at different rates, and a settled amplitude.
    let t: Vec<f64> = (0..20_000).map(|i| f64::from(i) * 0.01).collect();
    let series = Series {
        x: t.iter().map(|t| 0.5 * t.cos()).collect(),
        y: t.iter().map(|t| 0.5 * t.sin()).collect(),
        r: t.iter()
            .map(|t| 1e-4 * (0.01 + (-t / 20.0).exp()))
            .collect(),
        eps: t.iter().map(|t| 0.01 + (-t / 30.0).exp()).collect(),
        psi: (0..10)
            .map(|j| t.iter().map(|t| f64::from(j) * 0.6 + 0.01 * t).collect())
            .collect(),
        t,
        ..Default::default()
    };
    let settled = metrics(true, 40.0);
    let run = RunFigure {
        series: &series,
        metrics: &settled,
        revolution_s: 0.05,
        delta: 0.05,
        hold_revs: 50.0,
        title: "ten pendulums on a flexible rotor: one run with a long title to test the layout",
    };
    check("run", &dir, &mut defects, |p| plot_run(&run, p));

    let crowded = crowded_study(10, 9, 24);
    let small = crowded_study(2, 2, 40);
    for (tag, data) in [("crowded", &crowded), ("small", &small)] {
        for figure in StudyFigure::ALL {
            let name = format!("{tag}_{}", figure.file_stem());
            check(&name, &dir, &mut defects, |p| figure.plot(data, p));
        }
    }

    let mut points = Vec::new();
    for f in 0..10 {
        for k in 3..=9 {
            let rtol = 10f64.powi(-k);
            points.push(TradeoffPoint {
                fidelity: format!("fidelity_{f}/method_with_a_long_name"),
                rtol,
                median_error_revs: (1.0 + f as f64) * 20.0 * rtol.powf(0.6),
                max_error_revs: (1.0 + f as f64) * 50.0 * rtol.powf(0.6),
                rhs_calls: 2000.0 * (1.0 + 0.1 * f as f64) * 10f64.powf(0.2 * k as f64),
                wall_time_s: 1e-3 * (1.0 + 0.1 * f as f64) * 10f64.powf(0.2 * k as f64),
            });
        }
    }
    check("tradeoff", &dir, &mut defects, |p| {
        plot_work_precision(&points, "Work–precision of ten fidelities", p)
    });

    let mut map = Vec::new();
    for j in 0..30 {
        for i in 0..40 {
            let omega = 10.0 + 12.5 * f64::from(i);
            map.push(MapPoint {
                omega,
                unbalance: 1e-4 * f64::from(j + 1),
                balanced: j < 22,
                stable: Some(omega > 120.0),
                slowest_decay: Some(0.1),
            });
        }
    }
    check("map", &dir, &mut defects, |p| {
        plot_stability_map(&map, "Stability map of the balanced state", p)
    });

    let curves: Vec<KmCurve> = (0..10)
        .map(|d| KmCurve {
            label: format!(
                "{}: ball n={} ρ=0.250 β={}",
                char::from(b'A' + d as u8),
                2 + d,
                10 * (d + 1)
            ),
            observations: (0..40u32)
                .map(|s| Observation {
                    time: (5.0 + 4.0 * f64::from(d)) * (1.0 + 0.1 * f64::from(s)),
                    settled: !s.is_multiple_of(9),
                })
                .collect(),
            horizon: 400.0 + 50.0 * f64::from(d % 3),
        })
        .collect();
    check("km", &dir, &mut defects, |p| {
        // A constant speed: the top axis in seconds must fit as well.
        plot_kaplan_meier(
            &curves,
            "Kaplan–Meier: fraction of runs settled by t",
            Some(SecondsAxis {
                per_rev: 0.0209,
                from_operating_speed: true,
            }),
            p,
        )
    });

    // A label longer than the figure is wide, and the smaller variants.
    let long = vec![
        KmCurve {
            label: format!("A: {}", "a design with a very long description, ".repeat(6)),
            ..curves[0].clone()
        },
        curves[1].clone(),
    ];
    check("km_long_label", &dir, &mut defects, |p| {
        plot_kaplan_meier(&long, "two designs", None, p)
    });
    check("design_rollers", &dir, &mut defects, |p| {
        plot_design(&[Shape::Roller], &[2, 3, 4, 5], p)
    });
    let unsettled = metrics(false, 0.0);
    let run_unsettled = RunFigure {
        metrics: &unsettled,
        title: "did not settle",
        ..run
    };
    check("run_unsettled", &dir, &mut defects, |p| {
        plot_run(&run_unsettled, p)
    });

    assert!(
        defects.is_empty(),
        "{} layout defects:\n{}",
        defects.len(),
        defects.join("\n")
    );
}

#[test]
fn the_box_approximation_is_honest() {
    // A box that crosses the edge and two that overlap are reported; two side by side are not.
    let svg = r#"<svg width="200" height="100" viewBox="0 0 200 100">
<text x="190" y="10" dy="0.76em" text-anchor="start" font-size="10">wide</text>
<text x="10" y="50" dy="0.5ex" text-anchor="start" font-size="10">abc</text>
<text x="20" y="52" dy="0.5ex" text-anchor="start" font-size="10">def</text>
<text x="100" y="80" dy="0.5ex" text-anchor="end" font-size="10">left</text>
<text x="100" y="80" dy="0.5ex" text-anchor="start" font-size="10">right</text>
<text x="50" y="50" dy="0.5ex" text-anchor="middle" font-size="10" transform="rotate(270, 50, 50)">up</text>
</svg>"#;
    let defects = layout_defects(svg);
    assert_eq!(defects.len(), 2, "{defects:#?}");
    assert!(defects[0].contains("\"wide\""), "{defects:#?}");
    assert!(defects[1].contains("\"abc\"") && defects[1].contains("\"def\""));
    // Rotated a quarter turn the box stands upright: 10 wide, 12 high.
    let (_, boxes) = text_boxes(svg);
    let up = boxes.iter().find(|b| b.text == "up").unwrap();
    assert!((up.x1 - up.x0 - 10.0).abs() < 1e-9 && (up.y1 - up.y0 - 12.0).abs() < 1e-9);
}

#[test]
fn study_figures_name_every_varying_parameter_and_colour_each_drive() {
    // Three geometries (n and ρ vary) × two drags, each design with its own
    // stall torque: every one of them must be named, and no two (β, M_s)
    // may share a colour.
    let mut data = crowded_study(3, 2, 14);
    let torque = |id: u32| 0.5 * f64::from(id + 1);
    for d in &mut data.designs {
        d.stall_torque = Some(torque(d.design_id));
    }
    for r in &mut data.runs {
        r.stall_torque = Some(torque(r.design_id));
    }
    let dir = tempfile::tempdir().unwrap();
    for figure in [StudyFigure::SettlingTime, StudyFigure::SettledFraction] {
        let path = dir.path().join(format!("{}.svg", figure.file_stem()));
        figure.plot(&data, &path).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        for d in &data.designs {
            let ms = format!("M_s = {} N·m", torque(d.design_id));
            assert!(svg.contains(&ms), "{}: no {ms}", figure.file_stem());
        }
        for part in ["2 balls", "3 balls", "ρ = 0.18", "ρ = 0.287", "β = 2 N·s/m"] {
            assert!(svg.contains(part), "{}: no {part}", figure.file_stem());
        }
    }
    let path = dir.path().join("scatter.svg");
    StudyFigure::SettlingVsUnbalance.plot(&data, &path).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    let styles = legend_styles();
    for d in &data.designs {
        let ms = format!("M_s = {} N·m", torque(d.design_id));
        assert!(svg.contains(&ms), "settling vs unbalance: no {ms}");
    }
    let drives: Vec<&(String, SeriesStyle)> =
        styles.iter().filter(|(l, _)| l.contains("M_s")).collect();
    assert_eq!(drives.len(), data.designs.len(), "{styles:?}");
    for (i, a) in drives.iter().enumerate() {
        assert!(
            drives[i + 1..].iter().all(|b| b.1.colour != a.1.colour),
            "{a:?} shares its colour"
        );
    }
}

#[test]
fn one_geometry_rows_take_a_colour_per_stall_torque() {
    // A Sommerfeld study: five designs alike but for the motor's stall
    // torque. Each row of the per-design figures has its own colour, named
    // by its torque, as its band in settling vs unbalance.
    let mut data = crowded_study(1, 5, 14);
    let torque = |id: u32| 0.2 * f64::from(id + 1);
    for d in &mut data.designs {
        d.drag = 2.0;
        d.stall_torque = Some(torque(d.design_id));
    }
    for r in &mut data.runs {
        r.drag = 2.0;
        r.stall_torque = Some(torque(r.design_id));
    }
    let dir = tempfile::tempdir().unwrap();
    for figure in [
        StudyFigure::SettlingTime,
        StudyFigure::SettledFraction,
        StudyFigure::SettlingVsUnbalance,
    ] {
        let path = dir.path().join(format!("{}.svg", figure.file_stem()));
        figure.plot(&data, &path).unwrap();
        let looks = legend_styles();
        let names: Vec<&str> = looks.iter().map(|(l, _)| l.as_str()).collect();
        let expected: Vec<String> = (0..5)
            .map(|id| format!("M_s = {} N·m", short_number(torque(id))))
            .collect();
        for e in &expected {
            assert!(
                names.contains(&e.as_str()),
                "{}: {names:?}",
                figure.file_stem()
            );
        }
        let torques: Vec<&(String, SeriesStyle)> =
            looks.iter().filter(|(l, _)| l.starts_with("M_s")).collect();
        for (i, (label, a)) in torques.iter().enumerate() {
            assert!(
                torques[i + 1..].iter().all(|(_, b)| b.colour != a.colour),
                "{}: {label} shares its colour",
                figure.file_stem()
            );
        }
    }
}

/// A number as the figures print it (three significant digits, no trailing zeros).
fn short_number(v: f64) -> String {
    autobal::plot::style::short(v)
}

#[test]
fn design_curves_for_twelve_counts_look_different() {
    let dir = tempfile::tempdir().unwrap();
    let ns: Vec<u32> = (1..=12).collect();
    plot_design(&[Shape::Ball], &ns, &dir.path().join("design.svg")).unwrap();
    let looks: Vec<(String, SeriesStyle)> = legend_styles()
        .into_iter()
        .filter(|(l, _)| l.starts_with("n = "))
        .collect();
    assert_eq!(looks.len(), 12, "{looks:?}");
    for (i, (label, a)) in looks.iter().enumerate() {
        assert!(
            looks[i + 1..]
                .iter()
                .all(|(_, b)| (b.colour, b.marker) != (a.colour, a.marker)),
            "{label} shares its colour and marker"
        );
    }
}
