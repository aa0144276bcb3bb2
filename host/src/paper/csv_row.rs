//! One CSV row of a paper command's table (`pada paper pendulum`'s and
//! `pada paper wear`'s configurations): cells appended in the header's
//! order, an [`Estimate`] as its two cells (mean, then the 95 % interval's
//! half-width), an absent value as an empty cell. Numbers are written as
//! `to_string` writes them, so a table reads back bit for bit.

use crate::stats::Estimate;

/// A row being built.
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct CsvRow(Vec<String>);

impl CsvRow {
    /// An empty row.
    pub fn new() -> Self {
        Self::default()
    }

    /// One cell.
    pub fn cell(mut self, v: impl ToString) -> Self {
        self.0.push(v.to_string());
        self
    }

    /// One cell, empty for `None`.
    pub fn opt(mut self, v: Option<impl ToString>) -> Self {
        self.0.push(v.map(|v| v.to_string()).unwrap_or_default());
        self
    }

    /// Two cells: the mean, then the 95 % interval's half-width.
    pub fn estimate(self, e: &Estimate) -> Self {
        self.cell(e.mean).cell(e.ci95)
    }

    /// The cells, for `csv::Writer::write_record`.
    pub fn cells(&self) -> &[String] {
        &self.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cells_in_order() {
        let e = Estimate { mean: 1.5, ci95: 0.25, n: 2 };
        let r = CsvRow::new().cell("pada").opt(None::<f64>).opt(Some(0.5)).estimate(&e).cell(3);
        assert_eq!(r.cells(), ["pada", "", "0.5", "1.5", "0.25", "3"]);
    }
}
