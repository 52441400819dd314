//! `spira`: the command-line face. With no arguments it opens the explorer on the built-in
//! thesis case (n = 8). The commands are in src/cli/, one file each; this file defines the
//! command line and hands each command to its file.

mod cli;

use anyhow::Result;
use clap::{Parser, Subcommand};
use cli::bench::Measure;
use spira::case::Setting;
use spira::output::figures::{Kinds, Rods, Steps};
use std::path::PathBuf;

#[derive(Parser)]
#[command(
    name = "spira",
    version,
    about = "Mechanics of tubular assemblies of helical rods"
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand)]
enum Command {
    /// Solve a case's load path and write load.csv, reactions.csv and state.csv.
    Run {
        /// Case file (TOML).
        case: PathBuf,
        /// Target compression ratio (default: the case's loading.target).
        #[arg(long = "to", allow_hyphen_values = true, value_name = "X")]
        to: Option<f64>,
        /// Number of equally spaced output steps in (0, target] (default: the case's;
        /// 1 to 100000).
        #[arg(long)]
        steps: Option<u64>,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Solve even a case whose size estimate exceeds the memory available.
        #[arg(long)]
        force: bool,
        /// Also write the state of every output step, state-<step>.csv.
        #[arg(long)]
        states: bool,
        /// Also draw the figures (load.svg; curvature and views of the last state) and
        /// write the state of every output step (as --states).
        #[arg(long)]
        figures: bool,
        /// Also write a ParaView series: series.pvd and one step-<k>.vtp per output step
        /// (and mode-<k>.vtp per critical point).
        #[arg(long)]
        vtk: bool,
        /// Override a key of the case, e.g. `--set geometry.helices=16` (repeatable); the
        /// value is checked as in the file.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<Setting>,
    },
    /// Draw the figures of `spira run` output folders: load.svg (the load curves of every
    /// run), and per run and state curvature-step<k>.svg and views-step<k>.svg; or of a
    /// sweep's folder: sweep-<key>.svg per swept key (critical ε and fz against it).
    Plot {
        /// Output folders of `spira run`, or one folder of `spira sweep`.
        #[arg(required = true)]
        dirs: Vec<PathBuf>,
        /// Folder for the figures (default: the run folder when one is given).
        #[arg(long)]
        out: Option<PathBuf>,
        /// States to draw: compression ratios (the nearest output state of each run),
        /// comma-separated, or `all`, or `last` (the default).
        #[arg(
            long = "eps",
            value_name = "EPS",
            default_value = "last",
            allow_hyphen_values = true,
            value_parser = cli::plot::states_flag
        )]
        states: Steps,
        /// Rod of the curvature profiles (from 0), or `all` to overlay every rod.
        #[arg(
            long = "rod",
            value_name = "ROD",
            default_value = "0",
            allow_hyphen_values = true,
            value_parser = cli::plot::rods_flag
        )]
        rods: Rods,
        /// Only these figures: `load`, `curvature`, `views`, comma-separated.
        #[arg(
            long = "only",
            value_name = "ONLY",
            default_value = "load,curvature,views",
            value_parser = cli::plot::kinds_flag
        )]
        kinds: Kinds,
    },
    /// Open the terminal explorer on a case (default: the built-in thesis n = 8 case).
    Tui {
        /// Case file (TOML).
        case: Option<PathBuf>,
        /// Folder for exported CSV files.
        #[arg(long, default_value = ".")]
        out: PathBuf,
        /// Override a key of the case, e.g. `--set geometry.helices=16` (repeatable); the
        /// value is checked as in the file.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<Setting>,
    },
    /// Work-precision study: solve the case's path on a ladder of meshes of linear and
    /// quadratic elements, time each and measure its error; print the table and write
    /// precision.csv and precision.svg.
    Precision {
        /// Case file (TOML).
        case: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
        /// Timed runs per mesh after one warm-up run (the best is kept; at most 1000).
        #[arg(long, default_value_t = 3)]
        repeats: u64,
        /// Study even a case whose size estimate exceeds the memory available.
        #[arg(long)]
        force: bool,
        /// Override a key of the case, e.g. `--set geometry.helices=16` (repeatable); the
        /// value is checked as in the file.
        #[arg(long = "set", value_name = "KEY=VALUE")]
        set: Vec<Setting>,
    },
    /// Continue the first critical point of a case's path in a numeric key of the case
    /// (a critical curve) and write critical-curve.csv and critical-curve.svg.
    Critical(cli::critical::CriticalArgs),
    /// Replay a session saved in the explorer (key `s`) headless and write the CSVs the
    /// explorer's export (`e`) would have written at its end.
    Replay {
        /// Session file (TOML) written by the explorer.
        session: PathBuf,
        /// Output folder.
        #[arg(long, default_value = "out")]
        out: PathBuf,
    },
    /// Time the load path of a case (default: thesis n = 8 to eps = 0.5).
    Bench {
        /// Case file (TOML).
        case: Option<PathBuf>,
        /// Timed repetitions after one warm-up run (at most 1000).
        #[arg(long, default_value_t = 5)]
        repeats: u64,
        /// Measure the explorer instead: key press to redrawn frame while a step solves.
        #[arg(long)]
        tui: bool,
        /// Measure a 16-case sweep instead: on every core, then one case after another.
        #[arg(long, conflicts_with = "tui")]
        sweep: bool,
        /// Measure the scaling with n instead: cold `spira run` processes of the thesis
        /// geometry for n = 8, 16, 32, 64, the symmetric pair and (up to n = FULL_MAX) the
        /// full model, time and peak memory.
        #[arg(long, conflicts_with_all = ["tui", "sweep"])]
        scaling: bool,
        /// Measure cold `spira run` processes instead: thesis n = 8 (the symmetric pair) and
        /// n = 1, one after the other REPEATS times (at least 3), their times and the ratio.
        #[arg(long, conflicts_with_all = ["tui", "sweep", "scaling", "case"])]
        cold: bool,
        /// Measure the infinite tube's cell instead: one state's lowest eigenvalue of every
        /// block H(p, k) on 65 axial phases, n = 8 and 64, beside the finite pair's blocks.
        #[arg(long, conflicts_with_all = ["tui", "sweep", "scaling", "cold", "case"])]
        cell: bool,
        /// With --scaling: the largest n solved as the full model too.
        #[arg(long, default_value_t = 16)]
        full_max: usize,
    },
    /// Run a sweep: the cases of a sweep file in parallel, each into its own folder, and one
    /// table, sweep.csv; or merge the tables of shard folders (--merge).
    Sweep {
        /// Sweep file (TOML).
        #[arg(required_unless_present = "merge")]
        sweep: Option<PathBuf>,
        /// Output folder (default: out/<sweep name>; with --merge, required).
        #[arg(long)]
        out: Option<PathBuf>,
        /// Cases at once (default: the cores).
        #[arg(long)]
        jobs: Option<usize>,
        /// Run only every N-th case starting at the K-th (1-based), e.g. 2/8. Inside a Slurm
        /// job array it defaults to the array task's place in the array.
        #[arg(long)]
        shard: Option<String>,
        /// Only validate the sweep and list its cases.
        #[arg(long)]
        check: bool,
        /// Read, check and run even a sweep of more than 10000 cases.
        #[arg(long)]
        force: bool,
        /// Merge the sweep tables in these folders (or files) into OUT/sweep.csv.
        #[arg(long, num_args = 1.., conflicts_with_all = ["sweep", "jobs", "shard", "check", "force"])]
        merge: Vec<PathBuf>,
    },
}

fn main() {
    // Rust ignores SIGPIPE, so a closed pipe (`spira run … | head`) would make every
    // further print fail; a command-line tool ends quietly there instead
    #[cfg(unix)]
    // SAFETY: setting a signal's disposition to its default before any thread is started
    unsafe {
        libc::signal(libc::SIGPIPE, libc::SIG_DFL);
    }
    let cli = Cli::parse();
    if let Err(e) = dispatch(cli.command) {
        eprintln!("spira: error: {e:#}");
        std::process::exit(1);
    }
}

/// Runs `command` (the explorer on the built-in case without one).
fn dispatch(command: Option<Command>) -> Result<()> {
    let Some(command) = command else {
        return cli::tui::explore(None, PathBuf::from("."), &[]);
    };
    match command {
        Command::Tui { case, out, set } => cli::tui::explore(case, out, &set),
        Command::Critical(args) => cli::critical::critical(args),
        Command::Replay { session, out } => cli::replay::replay(&session, &out),
        Command::Run {
            case,
            to,
            steps,
            out,
            force,
            states,
            figures,
            vtk,
            set,
        } => cli::run::run(
            &case,
            &set,
            cli::run::Flags { to, steps, force },
            &out,
            cli::run::Extras {
                states: states || figures,
                figures,
                vtk,
            },
        ),
        Command::Plot {
            dirs,
            out,
            states,
            rods,
            kinds,
        } => cli::plot::plot(&dirs, out.as_deref(), &states, rods, kinds),
        Command::Bench {
            case,
            repeats,
            tui,
            sweep,
            scaling,
            cold,
            cell,
            full_max,
        } => {
            // clap lets at most one of the flags through
            let measure = if tui {
                Measure::Explorer
            } else if sweep {
                Measure::Sweep
            } else if cold {
                Measure::Cold
            } else if cell {
                Measure::Cell
            } else if scaling {
                Measure::Scaling { full_max }
            } else {
                Measure::Path
            };
            cli::bench::bench(case.as_deref(), repeats, measure)
        }
        Command::Sweep {
            sweep,
            out,
            jobs,
            shard,
            check,
            force,
            merge,
        } => {
            if merge.is_empty() {
                let file = sweep.expect("clap requires the sweep file without --merge");
                let flags = cli::sweep::SweepFlags {
                    out,
                    jobs,
                    shard: shard.as_deref(),
                    check,
                    force,
                };
                cli::sweep::sweep(&file, flags)
            } else {
                cli::sweep::merge(&merge, out)
            }
        }
        Command::Precision {
            case,
            out,
            repeats,
            force,
            set,
        } => cli::repeats_flag(repeats)
            .and_then(|r| cli::precision::precision(&case, &set, &out, r, force)),
    }
}
