//! The figures' CSV files and their number format.

use std::path::Path;

use anyhow::Context;

/// A CSV table: a header and rows of cells.
pub struct Csv {
    pub header: Vec<&'static str>,
    pub rows: Vec<Vec<String>>,
}

impl Csv {
    pub fn new(header: &[&'static str]) -> Self {
        Self {
            header: header.to_vec(),
            rows: Vec::new(),
        }
    }
    pub fn row(&mut self, cells: Vec<String>) {
        debug_assert_eq!(cells.len(), self.header.len());
        self.rows.push(cells);
    }
    pub fn write(&self, path: &Path) -> anyhow::Result<()> {
        let mut s = self.header.join(",");
        s.push('\n');
        for r in &self.rows {
            s.push_str(&csv_line(r));
            s.push('\n');
        }
        std::fs::write(path, s).with_context(|| format!("cannot write {}", path.display()))
    }
}

/// One CSV line: cells with `,` or `"` quoted, quotes doubled.
pub fn csv_line(cells: &[String]) -> String {
    cells
        .iter()
        .map(|c| {
            if c.contains(',') || c.contains('"') {
                format!("\"{}\"", c.replace('"', "\"\""))
            } else {
                c.clone()
            }
        })
        .collect::<Vec<_>>()
        .join(",")
}

/// A number for a CSV cell (full precision, "nan" for missing).
pub fn num(v: f64) -> String {
    if v.is_finite() {
        format!("{v}")
    } else {
        "nan".into()
    }
}
