//! The tables of a `spira run` output folder read back, for figures drawn after the run
//! (`spira plot`) or from the text a run is about to write (`spira run --figures`): the
//! load path (`load.csv`), its critical points (`critical.csv`), the states (`state.csv`,
//! `state-<step>.csv`) and the joints (`joints.csv`).
//!
//! Columns are found by their header names, so a table with more columns (a later version
//! of spira) still reads; a missing column, a cell that is not a number and a row of the
//! wrong length are errors naming the file, the line and the column.

use std::collections::BTreeMap;
use std::path::{Path, PathBuf};

/// A table of a run folder that cannot be read.
#[derive(Debug, thiserror::Error)]
pub enum TableError {
    #[error("{file}: missing: not a `spira run` output folder?")]
    Missing { file: PathBuf },
    /// The OS's reason, said once (kept out of the error chain, which a report walks).
    #[error("{file}: {reason}")]
    Io {
        file: PathBuf,
        reason: std::io::Error,
    },
    /// A table's name on something that is not a regular file (a FIFO, a socket, a
    /// device), which reading could wait on for ever.
    #[error("{file}: not a regular file ({what}); expected a table written by `spira run`")]
    NotAFile { file: PathBuf, what: &'static str },
    #[error("{file}: no column `{column}` in the header line")]
    MissingColumn { file: PathBuf, column: String },
    #[error("{file}:{line}: column `{column}`: expected {expected}, found `{found}`")]
    BadCell {
        file: PathBuf,
        line: u64,
        column: String,
        expected: &'static str,
        found: String,
    },
    #[error("{file}:{line}: {reason}")]
    BadRow {
        file: PathBuf,
        line: u64,
        reason: String,
    },
    #[error("{file}: no data rows")]
    Empty { file: PathBuf },
}

/// The columns of `load.csv` that hold numbers.
const LOAD_NUMBERS: [&str; 13] = [
    "step",
    "eps",
    "h",
    "fx",
    "fy",
    "fz",
    "energy",
    "iterations",
    "residual",
    "stable",
    "unstable_dirs",
    "lowest_eig",
    "parameter",
];

/// The columns of `critical.csv` that hold numbers.
const CRITICAL_NUMBERS: [&str; 10] = [
    "index",
    "parameter",
    "eps",
    "fx",
    "fy",
    "fz",
    "unstable_before",
    "unstable_after",
    "wavenumber",
    "multiplicity",
];

/// The columns of a state table that hold numbers.
const STATE_NUMBERS: [&str; 16] = [
    "rod", "s", "s_over_l", "x", "y", "z", "q1", "q2", "q3", "q4", "k1", "k2", "omega", "nx", "ny",
    "nz",
];

/// A table's rows with its columns found by name; `line` is the row's line in the file.
struct Table {
    file: PathBuf,
    header: Vec<String>,
    rows: Vec<(u64, Vec<String>)>,
}

impl Table {
    /// Reads CSV text (`#` lines are comments) of the file `file`.
    fn parse(file: &Path, text: &str) -> Result<Table, TableError> {
        let mut reader = ::csv::ReaderBuilder::new()
            .comment(Some(b'#'))
            .from_reader(text.as_bytes());
        let bad_row = |line: u64, e: ::csv::Error| TableError::BadRow {
            file: file.to_path_buf(),
            line,
            reason: match e.kind() {
                ::csv::ErrorKind::UnequalLengths {
                    expected_len, len, ..
                } => format!("{len} fields where the header has {expected_len}"),
                _ => e.to_string(),
            },
        };
        let header: Vec<String> = reader
            .headers()
            .map_err(|e| bad_row(e.position().map_or(1, |p| p.line()), e))?
            .iter()
            .map(|h| h.trim().to_string())
            .collect();
        let mut rows = Vec::new();
        for record in reader.records() {
            let record = record.map_err(|e| bad_row(e.position().map_or(0, |p| p.line()), e))?;
            let line = record.position().map_or(0, |p| p.line());
            rows.push((line, record.iter().map(str::to_string).collect()));
        }
        Ok(Table {
            file: file.to_path_buf(),
            header,
            rows,
        })
    }

    fn column(&self, name: &str) -> Result<usize, TableError> {
        self.header
            .iter()
            .position(|h| h == name)
            .ok_or_else(|| TableError::MissingColumn {
                file: self.file.clone(),
                column: name.to_string(),
            })
    }

    /// Every cell of the columns `numeric` the table has (the columns `spira run` writes
    /// numbers in) empty or a finite number, but those of the columns `read`, whose reader
    /// says what it expects of them.
    fn numbers_in(self, numeric: &[&str], read: &[&str]) -> Result<Table, TableError> {
        for (col, name) in self.header.iter().enumerate() {
            if !numeric.contains(&name.as_str()) || read.contains(&name.as_str()) {
                continue;
            }
            for row in &self.rows {
                let cell = row.1[col].trim();
                if !cell.is_empty() && !cell.parse::<f64>().is_ok_and(f64::is_finite) {
                    return Err(self.bad(row.0, col, "a finite number or an empty cell", cell));
                }
            }
        }
        Ok(self)
    }

    fn non_empty(self) -> Result<Table, TableError> {
        if self.rows.is_empty() {
            return Err(TableError::Empty { file: self.file });
        }
        Ok(self)
    }

    fn bad(&self, line: u64, col: usize, expected: &'static str, found: &str) -> TableError {
        // a cell as the message quotes it: on one line, and not a page long
        let mut found: String = crate::output::csv::comment_safe(found);
        if found.chars().count() > 40 {
            found = found.chars().take(40).collect::<String>() + "…";
        }
        TableError::BadCell {
            file: self.file.clone(),
            line,
            column: self.header[col].clone(),
            expected,
            found,
        }
    }

    /// The finite number in column `col` of a row.
    fn number(&self, row: &(u64, Vec<String>), col: usize) -> Result<f64, TableError> {
        let cell = row.1[col].trim();
        match cell.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            _ => Err(self.bad(row.0, col, "a finite number", cell)),
        }
    }

    /// The whole number in column `col` of a row.
    fn count(&self, row: &(u64, Vec<String>), col: usize) -> Result<usize, TableError> {
        let cell = row.1[col].trim();
        cell.parse::<usize>()
            .map_err(|_| self.bad(row.0, col, "a whole number", cell))
    }

    /// `0`, `1` or an empty cell in column `col` of a row.
    fn flag(&self, row: &(u64, Vec<String>), col: usize) -> Result<Option<bool>, TableError> {
        match row.1[col].trim() {
            "" => Ok(None),
            "1" => Ok(Some(true)),
            "0" => Ok(Some(false)),
            cell => Err(self.bad(row.0, col, "1, 0 or an empty cell", cell)),
        }
    }
}

/// The helices of the infinitely long tube whose cell the tables are of, from the header's
/// model line (`# model: the cell of an infinitely long tube of 8 helices …`).
fn infinite_tube(text: &str) -> Option<usize> {
    text.lines()
        .take_while(|l| l.starts_with('#'))
        .filter_map(|l| l.strip_prefix("# model: "))
        .find_map(|m| {
            let (_, rest) = m.split_once("cell of an infinitely long tube of ")?;
            rest.split_whitespace().next()?.parse().ok()
        })
}

/// The first `#` line's words after `case ` up to a comma: the case name a table names.
fn case_name(text: &str) -> Option<String> {
    let first = text.lines().next()?.strip_prefix('#')?;
    let (_, rest) = first.split_once(", case ")?;
    Some(rest.split(',').next().unwrap_or(rest).trim().to_string())
}

/// One output step of a load path (a row of `load.csv`).
#[derive(Clone, Debug, PartialEq)]
pub struct PathPoint {
    pub step: usize,
    /// Compression ratio `ε = (h0 − h)/h0`.
    pub eps: f64,
    /// Load parameter (`ε`, or `P/Pcrit` under load control).
    pub parameter: f64,
    /// `(1/(n Pcrit)) Σ F_tip`, per component.
    pub load: [f64; 3],
    /// Whether the state is stable, where it was judged.
    pub stable: Option<bool>,
    /// The other load components' displacements and forces (when the table has them).
    pub support: Option<SupportColumns>,
}

/// The columns of `load.csv` on twist, tilt and pressure, with the tip height.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SupportColumns {
    /// Mean tip height (m).
    pub height: f64,
    pub twist: f64,
    pub torque: f64,
    pub tilt: f64,
    pub bending_moment: f64,
    pub pressure: f64,
    pub radius: f64,
    pub lateral_pressure: f64,
}

/// A critical point of a path (a row of `critical.csv`).
#[derive(Clone, Debug, PartialEq)]
pub struct CriticalMark {
    /// `limit-point`, `bifurcation` or `neutral`.
    pub kind: String,
    pub parameter: f64,
    pub eps: f64,
    /// `(1/(n Pcrit)) Σ F_tip`.
    pub load: [f64; 3],
}

/// One node of a rod in a state (a row of `state.csv`).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct StateNode {
    /// `s/L`.
    pub s_over_l: f64,
    /// Centreline position (m).
    pub position: [f64; 3],
    /// `(κ1, κ2, Ω)` (1/m).
    pub curvature: [f64; 3],
}

/// The nodes of every rod in one state, rods in their order in the file.
#[derive(Clone, Debug, PartialEq)]
pub struct StateTable {
    /// Output step of the state (the last step of the path for `state.csv`).
    pub step: usize,
    /// Compression ratio of the state.
    pub eps: f64,
    /// `(rod index, its nodes in order of s)`.
    pub rods: Vec<(usize, Vec<StateNode>)>,
}

/// Reads `load.csv` (text `text` of the file `file`).
pub fn load_path(file: &Path, text: &str) -> Result<Vec<PathPoint>, TableError> {
    let read = ["step", "eps", "parameter", "fx", "fy", "fz", "stable"];
    let t = Table::parse(file, text)?
        .numbers_in(&LOAD_NUMBERS, &read)?
        .non_empty()?;
    let cols = read.map(|c| t.column(c));
    let [step, eps, parameter, fx, fy, fz, stable] = transpose(cols)?;
    // the other components' columns, read when the table has every one of them
    let names = [
        "h",
        "twist",
        "torque",
        "tilt",
        "bending_moment",
        "pressure",
        "radius",
        "lateral_pressure",
    ];
    let support: Option<Vec<usize>> = names.iter().map(|c| t.column(c).ok()).collect();
    t.rows
        .iter()
        .map(|r| {
            let support = match &support {
                Some(c) => {
                    let v = |k: usize| t.number(r, c[k]);
                    Some(SupportColumns {
                        height: v(0)?,
                        twist: v(1)?,
                        torque: v(2)?,
                        tilt: v(3)?,
                        bending_moment: v(4)?,
                        pressure: v(5)?,
                        radius: v(6)?,
                        lateral_pressure: v(7)?,
                    })
                }
                None => None,
            };
            Ok(PathPoint {
                step: t.count(r, step)?,
                eps: t.number(r, eps)?,
                parameter: t.number(r, parameter)?,
                load: [t.number(r, fx)?, t.number(r, fy)?, t.number(r, fz)?],
                stable: t.flag(r, stable)?,
                support,
            })
        })
        .collect()
}

/// Reads `critical.csv`.
pub fn critical_points(file: &Path, text: &str) -> Result<Vec<CriticalMark>, TableError> {
    let read = ["kind", "parameter", "eps", "fx", "fy", "fz"];
    let t = Table::parse(file, text)?.numbers_in(&CRITICAL_NUMBERS, &read)?;
    let cols = read.map(|c| t.column(c));
    let [kind, parameter, eps, fx, fy, fz] = transpose(cols)?;
    t.rows
        .iter()
        .map(|r| {
            Ok(CriticalMark {
                kind: r.1[kind].trim().to_string(),
                parameter: t.number(r, parameter)?,
                eps: t.number(r, eps)?,
                load: [t.number(r, fx)?, t.number(r, fy)?, t.number(r, fz)?],
            })
        })
        .collect()
}

/// Reads a state table (`state.csv` or `state-<step>.csv`) of output step `step`; its ε
/// is the one its first `#` line states (`eps = …`), else `eps`.
pub fn state(file: &Path, text: &str, step: usize, eps: f64) -> Result<StateTable, TableError> {
    let read = ["rod", "s_over_l", "x", "y", "z", "k1", "k2", "omega"];
    let t = Table::parse(file, text)?
        .numbers_in(&STATE_NUMBERS, &read)?
        .non_empty()?;
    let cols = read.map(|c| t.column(c));
    let [rod, s, x, y, z, k1, k2, omega] = transpose(cols)?;
    let mut rods: Vec<(usize, Vec<StateNode>)> = Vec::new();
    for r in &t.rows {
        let id = t.count(r, rod)?;
        let node = StateNode {
            s_over_l: t.number(r, s)?,
            position: [t.number(r, x)?, t.number(r, y)?, t.number(r, z)?],
            curvature: [t.number(r, k1)?, t.number(r, k2)?, t.number(r, omega)?],
        };
        match rods.iter_mut().find(|(k, _)| *k == id) {
            Some((_, nodes)) => nodes.push(node),
            None => rods.push((id, vec![node])),
        }
    }
    let stated = text
        .lines()
        .next()
        .and_then(|l| l.split_once("eps = "))
        .and_then(|(_, v)| v.trim().parse::<f64>().ok())
        .filter(|v| v.is_finite());
    Ok(StateTable {
        step,
        eps: stated.unwrap_or(eps),
        rods,
    })
}

/// Reads `joints.csv`: the arc lengths `s/L` of the joints of each rod.
pub fn joints(file: &Path, text: &str) -> Result<BTreeMap<usize, Vec<f64>>, TableError> {
    let read = ["rod", "s_over_l"];
    let t = Table::parse(file, text)?.numbers_in(&["rod", "s", "s_over_l"], &read)?;
    let [rod, s] = transpose(read.map(|c| t.column(c)))?;
    let mut out: BTreeMap<usize, Vec<f64>> = BTreeMap::new();
    for r in &t.rows {
        out.entry(t.count(r, rod)?)
            .or_default()
            .push(t.number(r, s)?);
    }
    Ok(out)
}

fn transpose<const N: usize>(
    cols: [Result<usize, TableError>; N],
) -> Result<[usize; N], TableError> {
    let mut out = [0; N];
    for (o, c) in out.iter_mut().zip(cols) {
        *o = c?;
    }
    Ok(out)
}

/// `state-<step>.csv` → `step`.
pub fn state_step(name: &str) -> Option<usize> {
    let k = name.strip_prefix("state-")?.strip_suffix(".csv")?;
    (!k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
        .then(|| k.parse().ok())
        .flatten()
}

/// Everything a run folder says that figures show.
#[derive(Clone, Debug, PartialEq)]
pub struct RunTables {
    /// How the run is named in legends and file names (the folder's name).
    pub label: String,
    /// The case, as the tables name it (empty if they do not).
    pub case: String,
    pub path: Vec<PathPoint>,
    pub critical: Vec<CriticalMark>,
    /// The states found, by output step: `state-<step>.csv`, and `state.csv` as the last
    /// step of the path when no `state-<step>.csv` has that step.
    pub states: Vec<StateTable>,
    /// Joints' `s/L` per rod (empty when the folder has no `joints.csv`).
    pub joints: BTreeMap<usize, Vec<f64>>,
    /// The helices of the infinitely long tube, when the run solved its cell (whose states
    /// hold the cell's rods only).
    pub infinite_tube: Option<usize>,
}

impl RunTables {
    /// Reads the tables of a run from `files` (file name and text) of a folder `dir` (used
    /// in messages only). `load.csv` and at least one state are required; `critical.csv`
    /// and `joints.csv` are read when present.
    pub fn from_files(
        label: &str,
        dir: &Path,
        files: &BTreeMap<String, String>,
    ) -> Result<RunTables, TableError> {
        let need = |name: &str| {
            files.get(name).ok_or_else(|| TableError::Missing {
                file: dir.join(name),
            })
        };
        let load = need("load.csv")?;
        let path = load_path(&dir.join("load.csv"), load)?;
        let critical = match files.get("critical.csv") {
            Some(text) => critical_points(&dir.join("critical.csv"), text)?,
            None => Vec::new(),
        };
        let joints = match files.get("joints.csv") {
            Some(text) => joints(&dir.join("joints.csv"), text)?,
            None => BTreeMap::new(),
        };
        let eps_of = |step: usize| path.iter().find(|p| p.step == step).map_or(0.0, |p| p.eps);
        let mut states = Vec::new();
        for (name, text) in files {
            if let Some(step) = state_step(name) {
                states.push(state(&dir.join(name), text, step, eps_of(step))?);
            }
        }
        let last = path.last().map_or(0, |p| p.step);
        if !states.iter().any(|s| s.step == last) {
            let text = need("state.csv")?;
            states.push(state(&dir.join("state.csv"), text, last, eps_of(last))?);
        }
        states.sort_by_key(|s| s.step);
        Ok(RunTables {
            label: label.to_string(),
            case: case_name(load).unwrap_or_default(),
            infinite_tube: infinite_tube(load),
            path,
            critical,
            states,
            joints,
        })
    }

    /// Reads the tables of the run folder `dir`, labelled by the folder's name.
    pub fn read(dir: &Path) -> Result<RunTables, TableError> {
        let io = |file: PathBuf| move |reason| TableError::Io { file, reason };
        let entries = std::fs::read_dir(dir).map_err(io(dir.to_path_buf()))?;
        let mut files = BTreeMap::new();
        for entry in entries {
            let entry = entry.map_err(io(dir.to_path_buf()))?;
            let name = entry.file_name().to_string_lossy().into_owned();
            let wanted = matches!(
                name.as_str(),
                "load.csv" | "critical.csv" | "joints.csv" | "state.csv"
            ) || state_step(&name).is_some();
            if !wanted {
                continue;
            }
            // what the name leads to (a link is followed)
            let kind = std::fs::metadata(entry.path()).map_err(io(entry.path()))?;
            if kind.is_dir() {
                continue;
            }
            if !kind.is_file() {
                return Err(TableError::NotAFile {
                    file: entry.path(),
                    what: special_file(&kind),
                });
            }
            let text = std::fs::read_to_string(entry.path()).map_err(io(entry.path()))?;
            files.insert(name, text);
        }
        let label = dir
            .canonicalize()
            .ok()
            .and_then(|d| d.file_name().map(|n| n.to_string_lossy().into_owned()))
            .unwrap_or_else(|| dir.display().to_string());
        RunTables::from_files(&label, dir, &files)
    }

    /// Number of rods (of the states' first).
    pub fn rods(&self) -> usize {
        self.states.first().map_or(0, |s| s.rods.len())
    }

    /// The state nearest to compression ratio `eps`.
    pub fn state_near(&self, eps: f64) -> Option<&StateTable> {
        self.states
            .iter()
            .min_by(|a, b| (a.eps - eps).abs().total_cmp(&(b.eps - eps).abs()))
    }
}

/// What a file that is not a regular file or a folder is, for messages.
fn special_file(meta: &std::fs::Metadata) -> &'static str {
    #[cfg(unix)]
    {
        use std::os::unix::fs::FileTypeExt as _;
        let t = meta.file_type();
        if t.is_fifo() {
            return "a FIFO";
        }
        if t.is_socket() {
            return "a socket";
        }
        if t.is_block_device() || t.is_char_device() {
            return "a device";
        }
    }
    let _ = meta;
    "a special file"
}
