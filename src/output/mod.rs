//! What a run and a study leave behind: CSV tables ([`csv`]), ParaView series ([`vtk`]), the
//! work-precision report and chart ([`precision`], [`chart`]), the figures of runs
//! ([`figures`], drawn from the tables read back by [`read`]), a run's folder ([`run_folder`])
//! and the files on disk, written atomically ([`files`]) through staging folders ([`staging`]).
//! Everything here reads results and studies; nothing computes them.

pub mod beam;
pub mod chart;
pub mod csv;
pub mod curve;
pub mod dispersion;
pub mod figures;
pub mod files;
pub mod imperfection;
mod joints_table;
pub mod legend;
pub mod precision;
pub mod read;
pub mod run_folder;
pub mod staging;
pub mod vtk;

pub use self::csv::{
    bulk_csv, check_finite, comment_safe, critical_csv, load_csv, mode_csv, mode_table,
    mode_vertices, reactions_csv, state_csv, with_note, NonFinite,
};
pub use self::files::write_atomic;
pub use self::joints_table::joints_csv;
pub use self::run_folder::{run_files, write_run, write_run_files, written_summary, RunFiles};
