//! CSV writers for load paths, reactions and states. Every file starts with `#` comment
//! lines giving the case and the units, then a header line. Files are written to a
//! temporary name and renamed, so a failed write leaves nothing half-written.

use crate::discretisation::model::DiscreteModel;
use crate::results::CriticalPoint;
use crate::results::{LoadPoint, Snapshot};
use std::fmt::Write as _;
use std::io;
use std::path::{Path, PathBuf};

/// Writes `contents` to `path` atomically (temporary file, then rename).
pub fn write_atomic(path: &Path, contents: &str) -> io::Result<()> {
    let tmp = path.with_extension("csv.partial");
    std::fs::write(&tmp, contents)?;
    std::fs::rename(&tmp, path)
}

/// `load.csv`: one row per output step.
pub fn load_csv(case: &str, points: &[LoadPoint]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# spira load path, case {case}");
    let _ = writeln!(
        s,
        "# eps: compression ratio (h0-h)/h0; h: mean tip height (m); fx,fy,fz: sum of tip reactions over rods / (n Pcrit), Pcrit = B1 (2 pi/L)^2, negative fz = compression; energy: total elastic energy (J); residual: Newton residual inf-norm; stable: 1 if the Hessian is positive definite on the constraints' tangent space; unstable_dirs: its negative eigenvalues; lowest_eig: its lowest eigenvalue in the metric of nodal rotations weighted by arc length (J/m; empty where not computed); parameter: load parameter (eps, or P/Pcrit under load control)"
    );
    let _ = writeln!(
        s,
        "step,eps,h,fx,fy,fz,energy,iterations,residual,stable,unstable_dirs,lowest_eig,parameter"
    );
    for p in points {
        let (stable, dirs, lowest) = match p.stability {
            Some(st) => (
                if st.is_stable() { "1" } else { "0" }.to_string(),
                st.unstable_directions.to_string(),
                st.lowest_eigenvalue
                    .map(|l| format!("{l:.6e}"))
                    .unwrap_or_default(),
            ),
            None => (String::new(), String::new(), String::new()),
        };
        let _ = writeln!(
            s,
            "{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{},{:.3e},{},{},{},{:.10e}",
            p.step,
            p.eps,
            p.height,
            p.load[0],
            p.load[1],
            p.load[2],
            p.energy,
            p.iterations,
            p.residual,
            stable,
            dirs,
            lowest,
            p.parameter
        );
    }
    s
}

/// `critical.csv`: the critical points of a path.
pub fn critical_csv(case: &str, critical: &[CriticalPoint]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# spira critical points, case {case}");
    let _ = writeln!(
        s,
        "# kind: limit-point or bifurcation; parameter: load parameter (eps, or P/Pcrit under load control); fx,fy,fz: sum of tip reactions / (n Pcrit); unstable_before/after: unstable directions either side; mode shapes in mode-<index>.csv"
    );
    let _ = writeln!(
        s,
        "index,kind,control,parameter,eps,fx,fy,fz,unstable_before,unstable_after"
    );
    for (i, c) in critical.iter().enumerate() {
        let _ = writeln!(
            s,
            "{},{},{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{},{}",
            i,
            c.kind.name(),
            c.control.name(),
            c.parameter,
            c.eps,
            c.load[0],
            c.load[1],
            c.load[2],
            c.unstable_before,
            c.unstable_after
        );
    }
    s
}

/// `mode-<k>.csv`: the centreline displacement of a critical mode at the element vertices
/// (unit norm over all primal unknowns; the sign is arbitrary).
pub fn mode_csv(
    case: &str,
    model: &DiscreteModel,
    index: usize,
    critical: &CriticalPoint,
) -> String {
    let mut s = String::new();
    let _ = writeln!(
        s,
        "# spira critical mode {index} ({}), case {case}, parameter = {:.10e}",
        critical.kind.name(),
        critical.parameter
    );
    let _ = writeln!(
        s,
        "# dx,dy,dz: mode displacement of the centreline at element vertices (m per unit mode)"
    );
    let _ = writeln!(s, "rod,s,s_over_l,dx,dy,dz");
    let length = model.length();
    for (id, rod) in model.rods.iter().enumerate() {
        for (v, &sv) in rod.mesh.vertices.iter().enumerate() {
            let _ = writeln!(
                s,
                "{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}",
                id,
                sv,
                sv / length,
                critical.mode[rod.r_dof(v, 0)],
                critical.mode[rod.r_dof(v, 1)],
                critical.mode[rod.r_dof(v, 2)]
            );
        }
    }
    s
}

/// `reactions.csv`: one row per rod per output step, tip reaction force (N) and moment (N m).
pub fn reactions_csv(case: &str, points: &[LoadPoint]) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# spira tip reactions, case {case}");
    let _ = writeln!(
        s,
        "# force (fx,fy,fz in N) and moment (mx,my,mz in N m) applied by the tip support to each rod, global frame"
    );
    let _ = writeln!(s, "step,eps,rod,chirality,fx,fy,fz,mx,my,mz");
    for p in points {
        for r in &p.reactions {
            let (f, m) = (r.tip.force, r.tip.moment);
            let _ = writeln!(
                s,
                "{},{:.10e},{},{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}",
                p.step,
                p.eps,
                r.rod,
                r.chirality.name(),
                f[0],
                f[1],
                f[2],
                m[0],
                m[1],
                m[2]
            );
        }
    }
    s
}

/// `state.csv`: every quaternion node of every rod.
pub fn state_csv(case: &str, snapshot: &Snapshot) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "# spira state, case {case}, eps = {:.10e}", snapshot.eps);
    let _ = writeln!(
        s,
        "# s: arc length (m); x,y,z: centreline (m); q1..q4: unit quaternion (vector, scalar); k1,k2,omega: curvatures (1/m)"
    );
    let _ = writeln!(s, "rod,s,s_over_l,x,y,z,q1,q2,q3,q4,k1,k2,omega");
    for rod in &snapshot.rods {
        for n in &rod.nodes {
            let _ = writeln!(
                s,
                "{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e}",
                rod.rod,
                n.s,
                n.s_over_l,
                n.position[0],
                n.position[1],
                n.position[2],
                n.quaternion[0],
                n.quaternion[1],
                n.quaternion[2],
                n.quaternion[3],
                n.curvature[0],
                n.curvature[1],
                n.curvature[2]
            );
        }
    }
    s
}

/// `csv` (a file of this module) with `note` as one more `#` line after its first line,
/// e.g. the mesh an accuracy target chose and its estimated error.
pub fn with_note(csv: &str, note: &str) -> String {
    let note = note.replace(['\n', '\r'], " ");
    match csv.split_once('\n') {
        Some((first, rest)) => format!("{first}\n# {note}\n{rest}"),
        None => format!("{csv}\n# {note}\n"),
    }
}

/// The files of a run, written into `dir` (created if needed): load, reactions and state,
/// and when there are critical points, `critical.csv` and one `mode-<k>.csv` each.
/// Returns their paths.
pub fn write_run(
    dir: &Path,
    case: &str,
    points: &[LoadPoint],
    snapshot: &Snapshot,
    critical: &[CriticalPoint],
    model: &DiscreteModel,
) -> io::Result<Vec<PathBuf>> {
    write_run_noted(dir, case, None, points, snapshot, critical, model)
}

/// [`write_run`] with `note`, when given, as a `#` line in the header of every file.
pub fn write_run_noted(
    dir: &Path,
    case: &str,
    note: Option<&str>,
    points: &[LoadPoint],
    snapshot: &Snapshot,
    critical: &[CriticalPoint],
    model: &DiscreteModel,
) -> io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let mut files = vec![
        ("load.csv".to_string(), load_csv(case, points)),
        ("reactions.csv".to_string(), reactions_csv(case, points)),
        ("state.csv".to_string(), state_csv(case, snapshot)),
    ];
    if !critical.is_empty() {
        files.push(("critical.csv".to_string(), critical_csv(case, critical)));
        for (i, c) in critical.iter().enumerate() {
            files.push((format!("mode-{i}.csv"), mode_csv(case, model, i, c)));
        }
    }
    let mut out = Vec::new();
    for (name, text) in files {
        let text = match note {
            Some(n) => with_note(&text, n),
            None => text,
        };
        let p = dir.join(name);
        write_atomic(&p, &text)?;
        out.push(p);
    }
    Ok(out)
}
