//! Typed access to `summary.parquet`'s columns by name, for the decision
//! (`crate::decide::decision`) and for the tools that render a summary.

use polars::prelude::{DataFrame, PolarsResult};

/// Typed access to a summary's columns.
pub struct SummaryColumns<'a>(pub &'a DataFrame);

impl SummaryColumns<'_> {
    /// Column `name` as f64 values.
    pub fn f(&self, name: &str) -> PolarsResult<Vec<Option<f64>>> {
        Ok(self.0.column(name)?.f64()?.iter().collect())
    }
    /// Column `name` as f64 values, all `None` when the summary lacks it (written before it existed).
    pub fn f_or_none(&self, name: &str) -> PolarsResult<Vec<Option<f64>>> {
        match self.0.column(name) {
            Ok(_) => self.f(name),
            Err(_) => Ok(vec![None; self.0.height()]),
        }
    }
    /// Column `name` as strings.
    pub fn s(&self, name: &str) -> PolarsResult<Vec<Option<String>>> {
        Ok(self
            .0
            .column(name)?
            .str()?
            .iter()
            .map(|s| s.map(str::to_string))
            .collect())
    }
    /// Column `name` as strings, all `None` when the summary lacks it.
    pub fn s_or_none(&self, name: &str) -> PolarsResult<Vec<Option<String>>> {
        match self.0.column(name) {
            Ok(_) => self.s(name),
            Err(_) => Ok(vec![None; self.0.height()]),
        }
    }
    /// Column `name` as booleans (null: false).
    pub fn b(&self, name: &str) -> PolarsResult<Vec<bool>> {
        Ok(self
            .0
            .column(name)?
            .bool()?
            .iter()
            .map(Option::unwrap_or_default)
            .collect())
    }
    /// Column `name` as u32 values.
    pub fn u32s(&self, name: &str) -> PolarsResult<Vec<Option<u32>>> {
        Ok(self.0.column(name)?.u32()?.iter().collect())
    }
    /// Column `name` as u64 counts (null: 0).
    pub fn u(&self, name: &str) -> PolarsResult<Vec<u64>> {
        Ok(self
            .0
            .column(name)?
            .u64()?
            .iter()
            .map(Option::unwrap_or_default)
            .collect())
    }
}
