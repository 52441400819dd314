//! The sweep table, `sweep.csv`: a row per case (`case`, `status`, one column per axis,
//! then what the case found), written and read by the `csv` crate, and merged over shards.

use super::error::SweepError;
use super::plan::Axis;
use crate::simulation::normal_form::{koiter_fit, KoiterFit};

/// The columns after `case`, `status` and the axes.
pub const RESULT_COLUMNS: [&str; 22] = [
    "model",
    "order",
    "elements",
    "unknowns",
    "target",
    "eps_reached",
    "fz",
    "energy",
    "stable",
    "unstable_dirs",
    "lowest_eig",
    "critical_eps",
    "critical_kind",
    "critical_change",
    "critical_fz",
    "critical_points",
    "limit_parameter",
    "drop",
    "steps",
    "iterations",
    "wall_s",
    "reason",
];

/// The columns of [`RESULT_COLUMNS`] that hold numbers (or nothing).
pub const NUMBER_COLUMNS: [&str; 17] = [
    "elements",
    "unknowns",
    "target",
    "eps_reached",
    "fz",
    "energy",
    "stable",
    "unstable_dirs",
    "lowest_eig",
    "critical_eps",
    "critical_fz",
    "critical_points",
    "limit_parameter",
    "drop",
    "steps",
    "iterations",
    "wall_s",
];

/// A table: its header and rows of cells, the rows sorted by case.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct SweepTable {
    pub headers: Vec<String>,
    pub rows: Vec<Vec<String>>,
}

impl SweepTable {
    /// Koiter's law over a sweep of flaws (an axis `imperfection.amplitude`): the drop of
    /// each done case against its amplitude, fitted by `drop ≈ C |δ|^p`. `None` without
    /// that axis or without two cases whose path turned below the perfect critical point.
    pub fn koiter(&self) -> Option<KoiterFit> {
        let (a, d, s) = (
            self.column("imperfection.amplitude")?,
            self.column("drop")?,
            self.column("status")?,
        );
        let samples: Vec<(f64, f64)> = self
            .rows
            .iter()
            .filter(|r| r[s] == "done")
            .filter_map(|r| Some((r[a].parse().ok()?, r[d].parse().ok()?)))
            .collect();
        koiter_fit(&samples)
    }

    /// An empty table for these axes.
    pub fn new(axes: &[Axis]) -> SweepTable {
        let mut headers = vec!["case".to_string(), "status".to_string()];
        headers.extend(axes.iter().map(|a| a.key.clone()));
        headers.extend(RESULT_COLUMNS.iter().map(|c| c.to_string()));
        SweepTable {
            headers,
            rows: Vec::new(),
        }
    }

    /// The index of a column.
    pub fn column(&self, name: &str) -> Option<usize> {
        self.headers.iter().position(|h| h == name)
    }

    /// The cell of `row` in column `name`.
    pub fn get(&self, row: usize, name: &str) -> Option<&str> {
        let c = self.column(name)?;
        self.rows
            .get(row)
            .and_then(|r| r.get(c))
            .map(String::as_str)
    }

    /// Sorts the rows by case name (which starts with the case's zero-padded index).
    pub fn sort(&mut self) {
        self.rows.sort();
    }

    /// The table as CSV text.
    pub fn to_csv(&self) -> String {
        let mut w = csv::Writer::from_writer(Vec::new());
        let record = |w: &mut csv::Writer<Vec<u8>>, r: &[String]| {
            w.write_record(r)
                .expect("writing CSV into memory cannot fail");
        };
        record(&mut w, &self.headers);
        for r in &self.rows {
            record(&mut w, r);
        }
        let bytes = w.into_inner().expect("flushing into memory cannot fail");
        String::from_utf8(bytes).expect("the cells are strings")
    }

    /// Reads CSV text (`path` names it in errors).
    pub fn from_csv(text: &str, path: &str) -> Result<SweepTable, SweepError> {
        let bad = |message: String| SweepError::Table {
            path: path.into(),
            message,
        };
        let mut r = csv::ReaderBuilder::new()
            .has_headers(true)
            .from_reader(text.as_bytes());
        let headers: Vec<String> = r
            .headers()
            .map_err(|e| bad(e.to_string()))?
            .iter()
            .map(str::to_string)
            .collect();
        if headers.first().map(String::as_str) != Some("case")
            || headers.get(1).map(String::as_str) != Some("status")
        {
            return Err(bad(
                "not a sweep table: the header does not start with case,status".into(),
            ));
        }
        let mut rows = Vec::new();
        for rec in r.records() {
            let rec = rec.map_err(|e| bad(e.to_string()))?;
            let line = rec.position().map_or(0, |p| p.line());
            for (cell, column) in rec.iter().zip(&headers) {
                check_cell(cell, column).map_err(|expected| SweepError::Cell {
                    path: path.into(),
                    line,
                    column: column.clone(),
                    expected,
                    found: quoted(cell),
                })?;
            }
            rows.push(rec.iter().map(str::to_string).collect());
        }
        Ok(SweepTable { headers, rows })
    }

    /// Merges tables (of the shards of one sweep) into one: the same header throughout,
    /// each case once (a case found twice must have the same row, or one done and one
    /// failed: the done one is kept), sorted by case.
    pub fn merge(tables: &[(String, SweepTable)]) -> Result<SweepTable, SweepError> {
        let Some((_, first)) = tables.first() else {
            return Err(SweepError::Table {
                path: "--merge".into(),
                message: "no sweep tables found".into(),
            });
        };
        let mut out = SweepTable {
            headers: first.headers.clone(),
            rows: Vec::new(),
        };
        let mut by_case: std::collections::BTreeMap<String, Vec<String>> = Default::default();
        for (path, t) in tables {
            if t.headers != out.headers {
                return Err(SweepError::Table {
                    path: path.clone(),
                    message: format!(
                        "its columns ({}) differ from those of {} ({}): not the same sweep",
                        t.headers.join(","),
                        tables[0].0,
                        out.headers.join(",")
                    ),
                });
            }
            for row in &t.rows {
                let id = row[0].clone();
                match by_case.get(&id) {
                    None => {
                        by_case.insert(id, row.clone());
                    }
                    Some(old) if old == row => {}
                    Some(old) if old[1] != "done" && row[1] == "done" => {
                        by_case.insert(id, row.clone());
                    }
                    Some(old) if old[1] == "done" && row[1] != "done" => {}
                    Some(old) if without_wall(&out, old) == without_wall(&out, row) => {}
                    Some(_) => {
                        return Err(SweepError::Table {
                            path: path.clone(),
                            message: format!("case {id} has another row in an earlier table"),
                        })
                    }
                }
            }
        }
        out.rows = by_case.into_values().collect();
        Ok(out)
    }
}

/// Whether `cell` may stand in `column` of a sweep table: a status `done` or `failed`, a
/// finite number or nothing in a column of numbers; else what was expected.
fn check_cell(cell: &str, column: &str) -> Result<(), &'static str> {
    if column == "status" && cell != "done" && cell != "failed" {
        return Err("done or failed");
    }
    let number = cell.trim().parse::<f64>().is_ok_and(f64::is_finite);
    if NUMBER_COLUMNS.contains(&column) && !cell.trim().is_empty() && !number {
        return Err("a finite number or an empty cell");
    }
    Ok(())
}

/// A cell as a message quotes it: on one line, at most 40 characters.
fn quoted(cell: &str) -> String {
    let one_line = crate::output::csv::comment_safe(cell);
    if one_line.chars().count() > 40 {
        one_line.chars().take(40).collect::<String>() + "…"
    } else {
        one_line
    }
}

fn without_wall(t: &SweepTable, row: &[String]) -> Vec<String> {
    let wall = t.column("wall_s");
    row.iter()
        .enumerate()
        .filter(|(i, _)| Some(*i) != wall)
        .map(|(_, c)| c.clone())
        .collect()
}
