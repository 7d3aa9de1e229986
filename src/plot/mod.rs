//! Figures people can look at: one run, one study, the design curves of
//! seed 000, the work–precision diagram of the trade-off study and the
//! Kaplan–Meier curves of `study compare`.
//!
//! Every function takes data and an output path; the format follows the
//! extension (`.svg` or `.png`). Text is set in an embedded subset of DejaVu
//! Sans (`fonts/`), so PNG output needs no system font libraries. Files are
//! written atomically, like every other output of autobal. What each figure
//! shows is described in `docs/plots.md`.

pub mod decimate;
pub mod design;
pub mod km;
pub mod map;
pub mod run;
pub mod study;
pub mod style;
pub mod tradeoff;

use plotters::drawing::DrawingAreaErrorKind;
use std::path::Path;

/// Output format of a figure, chosen by the file extension.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// Scalable vector graphics (text stays text).
    Svg,
    /// A bitmap encoded as PNG.
    Png,
}

impl Format {
    /// The format for `path`'s extension (case-insensitive), or an error naming it.
    pub fn from_path(path: &Path) -> Result<Self, PlotError> {
        let ext = path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase);
        match ext.as_deref() {
            Some("svg") => Ok(Format::Svg),
            Some("png") => Ok(Format::Png),
            _ => Err(PlotError::Format(path.display().to_string())),
        }
    }

    /// The file extension without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Svg => "svg",
            Format::Png => "png",
        }
    }
}

/// Why a figure could not be made.
#[derive(Debug, thiserror::Error)]
pub enum PlotError {
    /// The output path does not end in .svg or .png.
    #[error("{0}: the figure format follows the extension, which must be .svg or .png")]
    Format(String),
    /// The folder the figure should go to does not exist.
    #[error("{0}: folder does not exist")]
    NoFolder(String),
    /// There is nothing to plot.
    #[error("nothing to plot: {0}")]
    NoData(String),
    /// The data are inconsistent or outside their domain.
    #[error("{what}: {reason}")]
    Invalid {
        /// The quantity or column concerned.
        what: String,
        /// Why it is unusable.
        reason: String,
    },
    /// The embedded font could not be registered.
    #[error("the embedded font could not be loaded")]
    Font,
    /// plotters failed while drawing or encoding.
    #[error("drawing failed: {0}")]
    Draw(String),
    /// A file could not be read or written.
    #[error(transparent)]
    Io(#[from] std::io::Error),
    /// A Parquet file could not be read or has the wrong schema.
    #[error(transparent)]
    Polars(#[from] polars::error::PolarsError),
    /// A design curve is outside the theory's domain.
    #[error(transparent)]
    Design(#[from] crate::design::DesignError),
}

impl<E: std::error::Error + Send + Sync> From<DrawingAreaErrorKind<E>> for PlotError {
    fn from(e: DrawingAreaErrorKind<E>) -> Self {
        PlotError::Draw(e.to_string())
    }
}

impl PlotError {
    /// An [`PlotError::Invalid`] from anything printable.
    pub fn invalid(what: impl Into<String>, reason: impl Into<String>) -> Self {
        PlotError::Invalid {
            what: what.into(),
            reason: reason.into(),
        }
    }

    /// A results table at `path` that could not be read, named once
    /// (`read_parquet`'s message already starts with the path).
    pub fn unreadable(path: &std::path::Path, e: polars::error::PolarsError) -> Self {
        let shown = path.display().to_string();
        let text = e.to_string();
        let reason = match text.strip_prefix(&format!("{shown}: ")) {
            Some(rest) => rest.to_string(),
            None => text,
        };
        PlotError::invalid(shown, reason)
    }
}
