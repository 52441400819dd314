//! `spira sweep --merge DIR… --out DIR`: the tables of shard folders (and the rows of their
//! complete case folders, so a shard killed before it wrote its table still counts) merged
//! into one `sweep.csv`.

use super::error::SweepError;
use super::runner::MARKER;
use super::table::SweepTable;
use std::path::{Path, PathBuf};

/// Merges the sweep tables found in `inputs` (folders, or table files) into `out/sweep.csv`.
/// In a folder: `sweep.csv`, every `sweep-shard-*.csv`, and the marker `row.csv` of every
/// case folder. Returns the table and its path.
pub fn merge_dirs(inputs: &[PathBuf], out: &Path) -> Result<(SweepTable, PathBuf), SweepError> {
    let mut tables = Vec::new();
    let read = |p: &Path, tables: &mut Vec<(String, SweepTable)>| -> Result<(), SweepError> {
        let name = p.display().to_string();
        let text = std::fs::read_to_string(p).map_err(|reason| SweepError::Io {
            file: name.clone(),
            reason,
        })?;
        tables.push((name.clone(), SweepTable::from_csv(&text, &name)?));
        Ok(())
    };
    for input in inputs {
        if input.is_file() {
            read(input, &mut tables)?;
            continue;
        }
        let entries = std::fs::read_dir(input).map_err(|reason| SweepError::Io {
            file: input.display().to_string(),
            reason,
        })?;
        let mut files = Vec::new();
        for e in entries.flatten() {
            let p = e.path();
            let name = e.file_name().to_string_lossy().into_owned();
            if p.is_file()
                && (name == "sweep.csv"
                    || (name.starts_with("sweep-shard-") && name.ends_with(".csv")))
            {
                files.push(p);
            } else if p.is_dir() && !name.starts_with('.') && p.join(MARKER).is_file() {
                files.push(p.join(MARKER));
            }
        }
        files.sort();
        for f in files {
            read(&f, &mut tables)?;
        }
    }
    let table = SweepTable::merge(&tables)?;
    std::fs::create_dir_all(out).map_err(|reason| SweepError::Write {
        path: out.display().to_string(),
        reason,
    })?;
    let path = out.join("sweep.csv");
    crate::output::write_atomic(&path, &table.to_csv()).map_err(|reason| SweepError::Write {
        path: path.display().to_string(),
        reason,
    })?;
    Ok((table, path))
}
