//! One self-contained HTML page per study (`study report`): the question,
//! the ranking and its verdicts, the figures as inline SVG, the
//! Kaplan–Meier curves of the leading designs and the provenance. Nothing
//! in the page is fetched: no script, font, style sheet or image comes
//! from elsewhere, so it opens offline and can be mailed as one file.

use crate::decide::compare_designs::Side;
use crate::plot::Format;
use crate::plot::PlotError;
use crate::plot::km::{KmCurve, SecondsAxis, plot_kaplan_meier};
use crate::plot::study::{StudyData, StudyFigure, plot_study};
use std::path::Path;

/// The cause experiment on the page: the finding in words and, per effect
/// removed, how many re-runs settled.
#[derive(Debug, Clone, PartialEq)]
pub struct CausesTable {
    /// The finding, as `study run` prints it.
    pub finding: String,
    /// Per effect: its name, re-runs, settled, failed.
    pub rows: Vec<[String; 4]>,
}

impl CausesTable {
    /// The table of a finding.
    pub fn of(finding: &crate::decide::causes::CauseFinding) -> Self {
        CausesTable {
            finding: finding.to_string(),
            rows: finding
                .tallies
                .iter()
                .map(|t| {
                    [
                        t.counterfactual.label().to_string(),
                        t.reruns.to_string(),
                        t.settled.to_string(),
                        t.failed.to_string(),
                    ]
                })
                .collect(),
        }
    }

    /// Its HTML: a heading, the sentence and the table.
    fn html(&self) -> String {
        let mut out =
            String::from("<h3 id=\"causes\">Why runs do not settle (causes.parquet)</h3>\n");
        out.push_str(&format!("<p>{}</p>\n", prose(&self.finding)));
        out.push_str("<table id=\"causes-table\">\n<thead><tr><th>effect removed</th><th>re-runs</th><th>settled</th><th>failed</th></tr></thead>\n<tbody>\n");
        for row in &self.rows {
            out.push_str("<tr>");
            for cell in row {
                out.push_str(&format!("<td>{}</td>", escape(cell)));
            }
            out.push_str("</tr>\n");
        }
        out.push_str("</tbody>\n</table>\n");
        out
    }
}

/// The cause experiment of the study folder `dir` (`causes.parquet`,
/// with the design's run counts from `summary`); `None` when it did not run.
pub fn causes_table(
    dir: &Path,
    summary: &polars::prelude::DataFrame,
) -> polars::prelude::PolarsResult<Option<CausesTable>> {
    use crate::study::results::causes_file::{CAUSES_FILE, from_dataframe};
    let path = dir.join(CAUSES_FILE);
    if !path.exists() {
        return Ok(None);
    }
    let rows = from_dataframe(&crate::study::results::io::read_parquet(&path)?)?;
    let Some(id) = rows.first().map(|r| r.design_id) else {
        return Ok(None);
    };
    let ids = summary.column("design_id")?.u32()?;
    let Some(i) = (0..summary.height()).find(|&i| ids.get(i) == Some(id)) else {
        return Ok(None);
    };
    let count = |name: &str| -> polars::prelude::PolarsResult<usize> {
        Ok(summary.column(name)?.u64()?.get(i).unwrap_or(0) as usize)
    };
    let unsettled = count("censored")? + count("not_settled")?;
    let finding =
        crate::decide::causes::CauseFinding::from_rows(id, count("runs")?, unsettled, &rows);
    Ok(Some(CausesTable::of(&finding)))
}

/// A figure of the page.
#[derive(Debug, Clone)]
pub struct Figure {
    /// What the figure shows, one sentence (or, when `svg` is empty, why
    /// it could not be drawn).
    pub caption: String,
    /// The SVG document, without its XML prologue; empty for a figure the
    /// study's runs cannot give (nothing settled, say).
    pub svg: String,
}

impl Figure {
    /// A figure that could not be drawn: a sentence in its place.
    pub fn not_drawn(what: &str, why: &str) -> Self {
        Figure {
            caption: format!("{what}: not drawn, because {why}."),
            svg: String::new(),
        }
    }
}

/// Everything the page shows, already in words and numbers.
#[derive(Debug, Clone, Default)]
pub struct Report {
    /// The study's name.
    pub title: String,
    /// The study's question: the comment lines at the top of its file.
    pub question: Vec<String>,
    /// The ranking's column headers (a "\n" stacks a header on two lines).
    pub header: Vec<String>,
    /// The ranking's rows, in rank order.
    pub rows: Vec<Vec<String>>,
    /// What the columns mean, one note each.
    pub legend: Vec<String>,
    /// Verdict, disagreements, recommendation and other findings, one each.
    pub findings: Vec<String>,
    /// Preformatted text shown after the findings (e.g. a passage table).
    pub preformatted: String,
    /// The cause experiment's counts (`causes.parquet`), when it ran.
    pub causes: Option<CausesTable>,
    /// The figures.
    pub figures: Vec<Figure>,
    /// (what, value) pairs: commit, study hash, seed, the command.
    pub provenance: Vec<(String, String)>,
}

impl Report {
    /// The page as one HTML document.
    pub fn html(&self) -> String {
        let mut out = String::new();
        out.push_str("<!DOCTYPE html>\n<html lang=\"en\">\n<head>\n<meta charset=\"utf-8\">\n");
        out.push_str("<meta name=\"viewport\" content=\"width=device-width, initial-scale=1\">\n");
        out.push_str(&format!(
            "<title>{} — autobal study report</title>\n",
            escape(&self.title)
        ));
        out.push_str(STYLE);
        out.push_str("</head>\n<body>\n<main>\n");
        out.push_str(&format!(
            "<h1>Study <code>{}</code></h1>\n",
            escape(&self.title)
        ));
        if !self.question.is_empty() {
            out.push_str("<section id=\"question\">\n<h2>The question</h2>\n");
            for line in &self.question {
                out.push_str(&format!("<p>{}</p>\n", prose(line)));
            }
            out.push_str("</section>\n");
        }
        out.push_str("<section id=\"ranking\">\n<h2>Ranking</h2>\n");
        out.push_str("<div class=\"scroll\"><table id=\"ranking-table\">\n<thead><tr>");
        for h in &self.header {
            out.push_str(&format!("<th>{}</th>", escape(h).replace('\n', "<br>")));
        }
        out.push_str("</tr></thead>\n<tbody>\n");
        for row in &self.rows {
            out.push_str("<tr>");
            for cell in row {
                out.push_str(&format!("<td>{}</td>", cell_html(cell)));
            }
            out.push_str("</tr>\n");
        }
        out.push_str("</tbody>\n</table></div>\n");
        for line in &self.legend {
            out.push_str(&format!("<p class=\"legend\">{}</p>\n", prose(line)));
        }
        out.push_str("</section>\n<section id=\"verdicts\">\n<h2>Verdicts</h2>\n");
        for line in &self.findings {
            out.push_str(&format!("<p>{}</p>\n", prose(line)));
        }
        if !self.preformatted.trim().is_empty() {
            out.push_str(&format!("<pre>{}</pre>\n", escape(&self.preformatted)));
        }
        if let Some(causes) = &self.causes {
            out.push_str(&causes.html());
        }
        out.push_str("</section>\n<section id=\"figures\">\n<h2>Figures</h2>\n");
        for (i, figure) in self.figures.iter().enumerate() {
            if figure.svg.is_empty() {
                out.push_str(&format!(
                    "<figure id=\"figure-{i}\" class=\"not-drawn\">\n<p>{}</p>\n</figure>\n",
                    escape(&figure.caption)
                ));
                continue;
            }
            out.push_str(&format!(
                "<figure id=\"figure-{i}\">\n{}\n<figcaption>{}</figcaption>\n</figure>\n",
                figure.svg,
                prose(&figure.caption)
            ));
        }
        out.push_str("</section>\n<section id=\"provenance\">\n<h2>Provenance</h2>\n<dl>\n");
        for (what, value) in &self.provenance {
            out.push_str(&format!(
                "<dt>{}</dt><dd><code>{}</code></dd>\n",
                escape(what),
                escape(value)
            ));
        }
        out.push_str("</dl>\n</section>\n</main>\n</body>\n</html>\n");
        out
    }
}

/// The page's own style: plain, printable, no external font. Nothing may
/// be wider than its box: the table scrolls inside its own (an interval
/// first drops under its value), figures shrink to the column, long words
/// and code break.
const STYLE: &str = "<style>
*, *::before, *::after { box-sizing: border-box; }
body { font-family: system-ui, sans-serif; margin: 0; color: #1a1a1a; background: #fff; }
main { max-width: 1240px; margin: 0 auto; padding: 1rem 1.5rem 3rem; overflow-wrap: anywhere; }
h1 { font-size: 1.6rem; } h2 { font-size: 1.25rem; border-bottom: 1px solid #ccc; padding-bottom: .2rem; }
.scroll { overflow-x: auto; max-width: 100%; }
table { border-collapse: collapse; font-variant-numeric: tabular-nums; font-size: .9rem; overflow-wrap: normal; }
th, td { padding: .2rem .5rem; text-align: right; border-bottom: 1px solid #e4e4e4; }
td span { white-space: nowrap; }
th { background: #f4f4f4; vertical-align: bottom; }
code { font-size: .95em; background: #f4f4f4; padding: 0 .15em; }
tbody tr:first-child { background: #eef6ee; }
p.legend { font-size: .85rem; color: #444; }
figure { margin: 1.5rem 0; }
figure svg, img { max-width: 100%; height: auto; display: block; }
figcaption { font-size: .9rem; color: #444; }
pre { background: #f7f7f7; padding: .5rem; overflow-x: auto; max-width: 100%; }
dt { font-weight: bold; margin-top: .4rem; } dd { margin-left: 1rem; }
</style>
";

/// `text` safe inside HTML.
pub fn escape(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
        .replace('"', "&quot;")
}

/// A line of prose safe inside HTML, its `code` spans (Markdown's
/// backticks, as the CLI prints them) set as code rather than shown as
/// backticks; an unpaired backtick stays as it is.
pub fn prose(text: &str) -> String {
    let parts: Vec<&str> = text.split('`').collect();
    if parts.len().is_multiple_of(2) {
        return escape(text);
    }
    parts
        .iter()
        .enumerate()
        .map(|(i, part)| {
            if i % 2 == 1 {
                format!("<code>{}</code>", escape(part))
            } else {
                escape(part)
            }
        })
        .collect()
}

/// A ranking cell: a value with its interval ("+12.4 [+7.6, +17.2]") as
/// two unbreakable pieces, so that a narrow table wraps the interval under
/// its value instead of cutting it.
fn cell_html(cell: &str) -> String {
    match cell.split_once(" [") {
        Some((value, interval)) => format!(
            "<span>{}</span> <span>[{}</span>",
            escape(value),
            escape(interval)
        ),
        None => format!("<span>{}</span>", escape(cell)),
    }
}

/// An SVG file's text ready to sit inside HTML: without its XML prologue,
/// scaled by its box (a `viewBox` from its width and height), labelled.
pub fn inline_svg(svg: &str, label: &str) -> String {
    let start = svg.find("<svg").unwrap_or(0);
    let mut body = svg[start..].to_string();
    let attribute = |name: &str| -> Option<String> {
        let head = &body[..body.find('>')?];
        let at = head.find(&format!(" {name}=\""))? + name.len() + 3;
        let end = head[at..].find('"')? + at;
        Some(head[at..end].to_string())
    };
    if attribute("viewBox").is_none()
        && let (Some(w), Some(h)) = (attribute("width"), attribute("height"))
    {
        body = body.replacen("<svg", &format!("<svg viewBox=\"0 0 {w} {h}\""), 1);
    }
    body.replacen(
        "<svg",
        &format!("<svg role=\"img\" aria-label=\"{}\"", escape(label)),
        1,
    )
}

/// The comment at the top of a study file, as paragraphs: its question in
/// its author's words (the `#:schema` line is for editors, not readers).
pub fn question(study_text: &str) -> Vec<String> {
    // A byte-order mark would hide the first comment line from the test below.
    let study_text = study_text.strip_prefix('\u{feff}').unwrap_or(study_text);
    let mut paragraphs = vec![String::new()];
    for line in study_text
        .lines()
        .take_while(|l| l.trim_start().starts_with('#'))
        .map(|l| l.trim_start().trim_start_matches('#').trim())
        .filter(|l| !l.starts_with(":schema"))
    {
        let last = paragraphs.last_mut().expect("never empty");
        if line.is_empty() {
            if !last.is_empty() {
                paragraphs.push(String::new());
            }
        } else {
            if !last.is_empty() {
                last.push(' ');
            }
            last.push_str(line);
        }
    }
    paragraphs.retain(|p| !p.is_empty());
    paragraphs
}

/// The study figures of `dir` (as `study plot study` draws them) and the
/// Kaplan–Meier curves of the designs `leading`, as inline SVG. They are
/// drawn into a private folder under the system's temporary folder, which
/// is removed afterwards.
pub fn study_figures(dir: &Path, leading: &[u32]) -> Result<Vec<Figure>, PlotError> {
    let scratch = std::env::temp_dir().join(format!("autobal-report-{}", std::process::id()));
    let result = draw_figures(dir, leading, &scratch);
    let _ = std::fs::remove_dir_all(&scratch);
    result
}

fn draw_figures(dir: &Path, leading: &[u32], scratch: &Path) -> Result<Vec<Figure>, PlotError> {
    std::fs::create_dir_all(scratch)?;
    let data = StudyData::read(dir)?;
    let mut which = StudyFigure::ALL.to_vec();
    if data.runs.iter().any(|r| r.stall_torque.is_some()) {
        which.push(StudyFigure::Passage);
    }
    if !data.sensitivity.is_empty() {
        which.push(StudyFigure::Sensitivity);
    }
    // A figure the runs cannot give (nothing settled: no settling time to
    // draw) leaves a sentence in its place; the verdict is still worth sharing.
    let mut figures = Vec::new();
    for figure in which {
        let name = figure.file_stem().replace('_', " ");
        figures.push(match plot_study(&data, scratch, Format::Svg, &[figure]) {
            Ok(drawn) => inline_figure(caption(figure), &drawn[0])?,
            Err(e) => Figure::not_drawn(&name, &undrawable(e)?),
        });
    }
    if !leading.is_empty() {
        let sides = leading
            .iter()
            .map(|&id| Side::load(dir, Some(id)).map_err(|e| PlotError::NoData(e.to_string())))
            .collect::<Result<Vec<_>, PlotError>>()?;
        let curves: Vec<KmCurve> = sides
            .iter()
            .zip(leading)
            .enumerate()
            .map(|(rank, (side, id))| KmCurve {
                label: format!("#{} (design {id}): {}", rank + 1, side.label),
                observations: side.runs.settling.clone(),
                horizon: side.horizon,
            })
            .collect();
        let path = scratch.join("kaplan_meier.svg");
        let drawn = plot_kaplan_meier(
            &curves,
            "Fraction of runs settled by t: the leading designs",
            Some(SecondsAxis::for_clock(
                sides[0].clock,
                sides[0].scale.rev_seconds,
            )),
            &path,
        );
        figures.push(match drawn {
            Ok(()) => inline_figure(
                format!(
                    "Kaplan–Meier curves of the {} leading designs: the share of runs settled by each time, with 95 % bands.",
                    leading.len()
                ),
                &path,
            )?,
            Err(e) => Figure::not_drawn(
                "Kaplan–Meier curves of the leading designs",
                &undrawable(e)?,
            ),
        });
    }
    Ok(figures)
}

/// The SVG file at `path` as a figure of the page.
fn inline_figure(caption: String, path: &Path) -> Result<Figure, PlotError> {
    let svg = std::fs::read_to_string(path)?;
    Ok(Figure {
        svg: inline_svg(&svg, &caption),
        caption,
    })
}

/// Why a figure cannot be drawn from the study's data, in words; an error
/// that is not about the data (a full disk, a font) is passed on.
fn undrawable(e: PlotError) -> Result<String, PlotError> {
    match e {
        PlotError::NoData(why) => Ok(format!("there is nothing to plot ({why})")),
        PlotError::Invalid { what, reason } => Ok(format!("{what}: {reason}")),
        other => Err(other),
    }
}

/// One sentence on what a study figure shows.
fn caption(figure: StudyFigure) -> String {
    match figure {
        StudyFigure::Passage => {
            "Passage through resonance: each run's final spin rate against the motor's stall torque."
                .into()
        }
        StudyFigure::Sensitivity => {
            "Which input matters: each input's total Sobol index on the settling time capped at the horizon, per design `study sensitivity` analysed, with its 95 % interval."
                .into()
        }
        other => format!("{} (as `study plot study` draws it).", other.file_stem().replace('_', " ")),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn text_is_escaped_and_svg_gets_a_box_and_a_label() {
        assert_eq!(escape("a < b & \"c\""), "a &lt; b &amp; &quot;c&quot;");
        let svg = "<?xml version=\"1.0\"?>\n<svg width=\"900\" height=\"560\" xmlns=\"http://www.w3.org/2000/svg\"></svg>";
        let inline = inline_svg(svg, "a <figure>");
        assert!(
            inline.starts_with(
                "<svg role=\"img\" aria-label=\"a &lt;figure&gt;\" viewBox=\"0 0 900 560\""
            ),
            "{inline}"
        );
        assert!(!inline.contains("<?xml"));
        let page = Report {
            title: "t<1>".into(),
            header: vec!["a\nb".into()],
            rows: vec![vec!["<x>".into()]],
            ..Report::default()
        }
        .html();
        assert!(
            page.contains("<th>a<br>b</th>") && page.contains("<td><span>&lt;x&gt;</span></td>")
        );
        for external in ["http://", "https://", "src=", "<script", "<link"] {
            assert!(!page.contains(external), "{external}");
        }
    }

    #[test]
    fn backticks_become_code_and_intervals_stay_whole() {
        assert_eq!(
            prose("as `study plot study` draws <it>"),
            "as <code>study plot study</code> draws &lt;it&gt;"
        );
        assert_eq!(prose("an odd ` stays"), "an odd ` stays");
        assert_eq!(
            cell_html("+12.4 [+7.6, +17.2]"),
            "<span>+12.4</span> <span>[+7.6, +17.2]</span>"
        );
    }

    #[test]
    fn the_question_is_the_files_leading_comment() {
        let text = "#:schema ../schema/study.schema.json\n# Which count?\n#   And which radius?\n#\n# Second.\nname = \"x\"\n# not this";
        assert_eq!(
            question(text),
            ["Which count? And which radius?", "Second."]
        );
    }
}
