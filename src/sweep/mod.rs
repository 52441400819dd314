//! Sweeps: many cases from one file. A sweep file names a base case and axes over dotted
//! case keys, combined as a product or zipped ([`plan`]); every generated case is read by
//! the case reader before anything runs. [`run_sweep`] runs the cases of a [`Shard`] in
//! parallel, each into its own folder written atomically, skips cases whose results are
//! complete, and writes one table ([`table`], `sweep.csv`); shard tables merge into one.
//! An axis may instead be continued as a critical curve ([`curves`]).

pub mod curves;
pub mod error;
pub mod figure;
pub mod merge;
pub mod plan;
pub mod runner;
pub mod shard;
pub mod table;

pub use curves::{run_curves, CurvesReport, SweptCurve, CURVES_CSV};
pub use error::{InvalidCase, SweepError};
pub use merge::merge_dirs;
pub use plan::{folder_name, Axis, Combine, Sweep, SweepCase, MAX_CASES};
pub use runner::{
    run_sweep, table_name, workers, CaseFinished, CaseStatus, RunOptions, SweepReport, CASE_FILE,
    MARKER,
};
pub use shard::Shard;
pub use table::SweepTable;
