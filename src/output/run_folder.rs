//! A run's folder: the files a run writes (tables, modes, per-step states, a ParaView
//! series, figures), their names, and the headers that say which model was solved.

use super::beam::beam_csv;
use super::csv::{
    bulk_csv, check_finite, critical_csv, load_csv, mode_csv, reactions_csv, state_csv, with_note,
    NonFinite,
};
use super::dispersion::{bands_csv, dispersion_csv};
use super::files::write_folder;
use super::imperfection::imperfection_csv;
use super::joints_table::joints_csv;
use super::vtk;
use crate::discretisation::discrete_model::DiscreteModel;
use crate::results::{CriticalPoint, LoadPoint, ModeShape, Snapshot, StepBulk};
use crate::run::PathOutcome;
use crate::simulation::beam::StepBeam;
use crate::simulation::cell::StepDispersion;
use crate::simulation::flaw::ImperfectPath;
use std::io;
use std::path::{Path, PathBuf};

/// What a run leaves behind, for [`run_files`] and [`write_run`].
#[derive(Clone, Copy, Debug)]
pub struct RunFiles<'a> {
    pub case: &'a str,
    /// A `#` line for the header of every CSV file (the mesh an accuracy target chose).
    pub note: Option<&'a str>,
    /// A `#` line for the header of every CSV file: the case keys overridden on the command
    /// line.
    pub set: Option<&'a str>,
    pub points: &'a [LoadPoint],
    /// The last state.
    pub snapshot: &'a Snapshot,
    pub critical: &'a [CriticalPoint],
    pub model: &'a DiscreteModel,
    /// The bulk at every point of `points`.
    pub bulk: &'a [StepBulk],
    /// For a ParaView series (`--vtk`): the shape at every point of `points` (same order),
    /// and every critical point's mode on its state.
    pub series: Option<(&'a [Snapshot], &'a [ModeShape])>,
    /// For `state-<step>.csv` files (`--states`, `--figures`): `(output step, shape)`.
    pub states: &'a [(usize, Snapshot)],
    /// For an imperfect case: `imperfection.csv`.
    pub imperfection: Option<&'a ImperfectPath>,
    /// For the cell of an infinite tube: the dispersion at every output step
    /// (`dispersion.csv`, `bands.csv`).
    pub dispersion: &'a [StepDispersion],
    /// For the cell of an infinite tube: the tube as a beam at every output step
    /// (`beam.csv`).
    pub beam: &'a [StepBeam],
}

impl<'a> RunFiles<'a> {
    /// The files of a path's outcome, without a ParaView series or per-step states.
    pub fn of(case: &'a str, note: Option<&'a str>, outcome: &'a PathOutcome) -> RunFiles<'a> {
        RunFiles {
            case,
            note,
            set: None,
            points: &outcome.points,
            snapshot: &outcome.snapshot,
            critical: &outcome.critical,
            model: &outcome.model,
            bulk: &outcome.bulk,
            series: None,
            states: &[],
            imperfection: outcome.imperfection.as_ref(),
            dispersion: &outcome.dispersion,
            beam: &outcome.beam,
        }
    }
}

/// The elastic hypotheses of the model and where its reference curvatures come from, for
/// the header of every file.
pub fn hypotheses_note(model: &DiscreteModel) -> String {
    format!(
        "elastic hypotheses: {}; reference curvatures: {}",
        model.elasticity.describe(),
        model.reference.name()
    )
}

/// Which model was solved, for the header of every file.
pub fn model_solved(model: &DiscreteModel) -> String {
    if let Some(cell) = model
        .assembly
        .cell
        .as_ref()
        .filter(|c| c.bending && c.m > 1)
    {
        return format!(
            "model: the bending cell of an infinitely long tube of {} helices (every rod over one axial period, 1/{} of a turn, periodic under the turn by the tilt about a transverse axis through the centre of curvature); stability only against perturbations of the bending cell's own period (its Bloch blocks are not computed)",
            2 * cell.m,
            cell.m
        );
    }
    if let Some(cell) = &model.assembly.cell {
        return format!(
            "model: the cell of an infinitely long tube of {} helices (one right and one left rod from a crossing to the next, helically periodic; each rod of the cell stands for the {} rods of its chirality); stability by the blocks H(p, k), p = 0..{}",
            2 * cell.m,
            cell.m,
            cell.m - 1
        );
    }
    match model.assembly.symmetry {
        Some(sym) => format!(
            "model: one right/left pair standing for all {} rods (the {}-fold rotational symmetry), stability of the whole assembly by its Bloch blocks p = 0..{}",
            sym.full_rods(),
            sym.m,
            sym.m / 2
        ),
        None => format!("model: the full assembly, {} rods", model.rods.len()),
    }
}

/// The files of a run as (name, text): load, reactions, state, joints and bulk, and when
/// there are critical points, `critical.csv` and one `mode-<k>.csv` each; for an imperfect
/// case `imperfection.csv`; the per-step
/// states when given; with a series, `series.pvd`, one `step-<k>.vtp` per output step and
/// one `mode-<k>.vtp` per critical point. Every CSV names the model solved and the note in
/// its header. A series holding a value that is not finite is refused.
pub fn run_files(run: &RunFiles) -> io::Result<Vec<(String, String)>> {
    let case = run.case;
    let mut files = vec![
        ("load.csv".to_string(), load_csv(case, run.points)),
        ("reactions.csv".to_string(), reactions_csv(case, run.points)),
        ("state.csv".to_string(), state_csv(case, run.snapshot)),
        ("joints.csv".to_string(), joints_csv(case, run.snapshot)),
        ("bulk.csv".to_string(), bulk_csv(case, run.bulk)),
    ];
    if !run.critical.is_empty() {
        files.push(("critical.csv".to_string(), critical_csv(case, run.critical)));
        for (i, c) in run.critical.iter().enumerate() {
            files.push((format!("mode-{i}.csv"), mode_csv(case, run.model, i, c)));
        }
    }
    if let Some(path) = run.imperfection {
        files.push(("imperfection.csv".to_string(), imperfection_csv(case, path)));
    }
    if !run.dispersion.is_empty() {
        files.push((
            "dispersion.csv".to_string(),
            dispersion_csv(case, run.dispersion),
        ));
        files.push(("bands.csv".to_string(), bands_csv(case, run.dispersion)));
    }
    if !run.beam.is_empty() {
        files.push(("beam.csv".to_string(), beam_csv(case, run.beam)));
    }
    for (step, snapshot) in run.states {
        files.push((format!("state-{step}.csv"), state_csv(case, snapshot)));
    }
    let solved = model_solved(run.model);
    let hypotheses = hypotheses_note(run.model);
    let mut files: Vec<(String, String)> = files
        .into_iter()
        .map(|(name, text)| (name, with_note(&text, &hypotheses)))
        .map(|(name, text)| (name, with_note(&text, &solved)))
        .map(|(name, text)| match run.note {
            Some(n) => (name, with_note(&text, n)),
            None => (name, text),
        })
        .map(|(name, text)| match run.set {
            Some(n) => (name, with_note(&text, n)),
            None => (name, text),
        })
        .collect();
    if let Some((shapes, modes)) = run.series {
        let refuse = |name: &str, e: NonFinite| {
            io::Error::new(io::ErrorKind::InvalidData, format!("{name}: {e}"))
        };
        let mut steps = Vec::new();
        for (p, shape) in run.points.iter().zip(shapes) {
            let name = vtk::step_file(p.step);
            let text = vtk::vtp(case, shape).map_err(|e| refuse(&name, e))?;
            steps.push((p.parameter, name.clone()));
            files.push((name, text));
        }
        let text = vtk::pvd(case, &steps).map_err(|e| refuse(vtk::SERIES_FILE, e))?;
        files.push((vtk::SERIES_FILE.to_string(), text));
        for (i, m) in modes.iter().enumerate() {
            let name = vtk::mode_file(i);
            let text = vtk::mode_vtp(case, i, m).map_err(|e| refuse(&name, e))?;
            files.push((name, text));
        }
    }
    Ok(files)
}

/// The files of a run ([`run_files`]) written into `dir` (created if needed) as one set.
/// Returns their paths.
pub fn write_run(dir: &Path, run: &RunFiles) -> io::Result<Vec<PathBuf>> {
    write_run_files(dir, &run_files(run)?)
}

/// Writes the files of a run (from [`run_files`], with figures if any) into `dir` as one
/// set ([`write_folder`]), after checking that no CSV holds a non-finite value. Returns
/// their paths.
pub fn write_run_files(dir: &Path, files: &[(String, String)]) -> io::Result<Vec<PathBuf>> {
    for (name, text) in files.iter().filter(|(n, _)| n.ends_with(".csv")) {
        check_finite(text)
            .map_err(|e| io::Error::new(io::ErrorKind::InvalidData, format!("{name}: {e}")))?;
    }
    write_folder(dir, files, is_run_file)
}

/// Whether `name` is a file a run writes: `load.csv`, `reactions.csv`, `state.csv`,
/// `joints.csv`, `bulk.csv`, `critical.csv`, `mode-<k>.csv`, `state-<k>.csv`, a figure
/// ([`is_figure_file`]), and of a series `series.pvd`, `step-<k>.vtp` and `mode-<k>.vtp`.
pub fn is_run_file(name: &str) -> bool {
    matches!(
        name,
        "load.csv"
            | "reactions.csv"
            | "state.csv"
            | "joints.csv"
            | "bulk.csv"
            | "critical.csv"
            | "series.pvd"
    ) || numbered(name, "mode-", ".csv")
        || numbered(name, "state-", ".csv")
        || numbered(name, "mode-", ".vtp")
        || numbered(name, "step-", ".vtp")
        || is_figure_file(name)
}

/// Whether `name` is a figure of a run: `load.svg`, `curvature-step<k>.svg` or
/// `views-step<k>.svg`.
pub fn is_figure_file(name: &str) -> bool {
    name == "load.svg"
        || numbered(name, "curvature-step", ".svg")
        || numbered(name, "views-step", ".svg")
}

/// The numbered files of a run, as the summary of what was written counts them: (prefix,
/// suffix, what one is, what several are).
const FAMILIES: [(&str, &str, &str, &str); 6] = [
    ("state-", ".csv", "state", "states"),
    ("mode-", ".csv", "mode table", "mode tables"),
    ("step-", ".vtp", "VTK step", "VTK steps"),
    ("mode-", ".vtp", "VTK mode", "VTK modes"),
    (
        "curvature-step",
        ".svg",
        "curvature figure",
        "curvature figures",
    ),
    ("views-step", ".svg", "views figure", "views figures"),
];

/// One line on the files written into `dir`: how many, the files of their own kind by
/// name and the numbered ones counted (`wrote 230 files to out: load.csv, …, load.svg (112
/// states, 113 VTK steps, 2 mode tables)`).
pub fn written_summary(dir: &Path, written: &[PathBuf]) -> String {
    let mut named = Vec::new();
    let mut counts = [0usize; FAMILIES.len()];
    for path in written {
        let name = path.file_name().map_or_else(
            || path.display().to_string(),
            |n| n.to_string_lossy().into_owned(),
        );
        match FAMILIES
            .iter()
            .position(|(prefix, suffix, ..)| numbered(&name, prefix, suffix))
        {
            Some(k) => counts[k] += 1,
            None => named.push(name),
        }
    }
    let counted: Vec<String> = FAMILIES
        .iter()
        .zip(counts)
        .filter(|(_, c)| *c > 0)
        .map(|((_, _, one, many), c)| format!("{c} {}", if c == 1 { one } else { many }))
        .collect();
    let files = if written.len() == 1 { "file" } else { "files" };
    let mut line = format!("wrote {} {files} to {}", written.len(), dir.display());
    if !named.is_empty() {
        line += &format!(": {}", named.join(", "));
    }
    if !counted.is_empty() {
        line += &format!(" ({})", counted.join(", "));
    }
    line
}

/// Whether `name` is `<prefix><whole number><suffix>`.
fn numbered(name: &str, prefix: &str, suffix: &str) -> bool {
    name.strip_prefix(prefix)
        .and_then(|r| r.strip_suffix(suffix))
        .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::output::staging::{host_name, process_alive, remove_stale, OWNER_FILE};

    #[test]
    fn the_summary_of_a_run_folder_names_its_tables_and_counts_its_numbered_files() {
        let mut names = vec!["load.csv", "critical.csv", "series.pvd", "load.svg"];
        let numbered: Vec<String> = (0..3)
            .map(|k| format!("state-{k}.csv"))
            .chain((0..3).map(|k| format!("step-{k}.vtp")))
            .chain(["mode-0.csv".into(), "mode-0.vtp".into()])
            .collect();
        names.extend(numbered.iter().map(String::as_str));
        let dir = Path::new("out/n2");
        let written: Vec<PathBuf> = names.iter().map(|n| dir.join(n)).collect();
        assert_eq!(
            written_summary(dir, &written),
            "wrote 12 files to out/n2: load.csv, critical.csv, series.pvd, load.svg \
             (3 states, 1 mode table, 3 VTK steps, 1 VTK mode)"
        );
        assert_eq!(
            written_summary(dir, &[dir.join("state-1.csv")]),
            "wrote 1 file to out/n2 (1 state)"
        );
    }

    #[test]
    fn a_folder_write_replaces_the_files_of_its_kind_and_keeps_others() {
        let dir = tempfile::tempdir().expect("scratch folder");
        let out = dir.path().join("out");
        std::fs::create_dir(&out).expect("folder");
        for name in [
            "mode-0.csv",
            "mode-12.csv",
            "critical.csv",
            "notes.txt",
            "mode-x.csv",
        ] {
            std::fs::write(out.join(name), "old").expect("write");
        }
        let files = vec![
            ("load.csv".to_string(), "a\n1\n".to_string()),
            ("state.csv".to_string(), "b\n2\n".to_string()),
        ];
        write_folder(&out, &files, is_run_file).expect("write");
        assert_eq!(
            listing(&out),
            ["load.csv", "mode-x.csv", "notes.txt", "state.csv"]
        );
        // nothing left beside the folder but the folder
        assert_eq!(listing(dir.path()), ["out"]);
    }

    #[test]
    fn a_failed_folder_write_leaves_the_previous_files() {
        let dir = tempfile::tempdir().expect("scratch folder");
        let out = dir.path().join("out");
        std::fs::create_dir_all(out.join("state.csv")).expect("a folder named state.csv");
        std::fs::write(out.join("load.csv"), "old").expect("write");
        let files = vec![
            ("load.csv".to_string(), "new".to_string()),
            ("state.csv".to_string(), "new".to_string()),
        ];
        assert!(write_folder(&out, &files, is_run_file).is_err());
        assert_eq!(listing(&out), ["load.csv", "state.csv"]);
        assert_eq!(
            std::fs::read_to_string(out.join("load.csv")).unwrap(),
            "old"
        );
        assert_eq!(listing(dir.path()), ["out"]);
    }

    /// A staging folder as [`staging_dir`] makes it, owned by process `pid` of `host`.
    fn fake_staging(parent: &Path, name: &str, pid: u32, host: &str) -> PathBuf {
        let p = parent.join(name);
        std::fs::create_dir_all(p.join("new")).expect("folder");
        std::fs::write(p.join("new/load.csv"), "half written").expect("write");
        std::fs::write(p.join(OWNER_FILE), format!("pid {pid}\nhost {host}\n")).expect("owner");
        p
    }

    /// The id of a process that has ended (and been reaped).
    fn dead_pid() -> u32 {
        let mut child = std::process::Command::new("true")
            .spawn()
            .expect("spawn true");
        let pid = child.id();
        child.wait().expect("wait");
        assert!(process_alive(pid) != Some(true), "{pid} is gone");
        pid
    }

    #[test]
    fn the_next_write_removes_staging_folders_whose_process_is_gone_and_nothing_else() {
        let dir = tempfile::tempdir().expect("scratch folder");
        let host = host_name();
        let dead = dead_pid();
        let me = std::process::id();
        fake_staging(dir.path(), ".spira-staging-killed", dead, &host);
        // a sweep's case folder that a killed sweep was writing
        fake_staging(dir.path(), ".spira-001_target-0.1-killed", dead, &host);
        // in use: this process's
        fake_staging(dir.path(), ".spira-staging-live", me, &host);
        // another machine's (a shared file system): its process cannot be told, recent
        fake_staging(dir.path(), ".spira-staging-remote", dead, "another-host");
        // not spira's: no owner file, an unreadable one, another prefix, a file
        std::fs::create_dir_all(dir.path().join(".spira-staging-nomarker/new")).expect("folder");
        let odd = dir.path().join(".spira-staging-odd");
        std::fs::create_dir(&odd).expect("folder");
        std::fs::write(odd.join(OWNER_FILE), "pid twelve\n").expect("write");
        fake_staging(dir.path(), "staging-killed", dead, &host);
        fake_staging(dir.path(), ".other-staging", dead, &host);
        std::fs::write(dir.path().join(".spira-staging-file"), "x").expect("write");
        let files = vec![("load.csv".to_string(), "a\n1\n".to_string())];
        write_folder(&dir.path().join("out"), &files, is_run_file).expect("write");
        assert_eq!(
            listing(dir.path()),
            [
                ".other-staging",
                ".spira-staging-file",
                ".spira-staging-live",
                ".spira-staging-nomarker",
                ".spira-staging-odd",
                ".spira-staging-remote",
                "out",
                "staging-killed",
            ]
        );
        // the live one is whole
        assert!(dir
            .path()
            .join(".spira-staging-live/new/load.csv")
            .is_file());
        // and once its process is gone, the next cleaning takes it
        std::fs::write(
            dir.path().join(".spira-staging-live").join(OWNER_FILE),
            format!("pid {dead}\nhost {host}\n"),
        )
        .expect("write");
        assert_eq!(
            remove_stale(dir.path()),
            [dir.path().join(".spira-staging-live")]
        );
    }

    fn listing(dir: &Path) -> Vec<String> {
        let mut names: Vec<String> = std::fs::read_dir(dir)
            .expect("folder")
            .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
            .collect();
        names.sort();
        names
    }
}
