//! CSV writers for load paths, reactions and states. Every file starts with `#` comment
//! lines giving the case and the units, then a header line. Files are written to a
//! temporary name and renamed, so a failed write leaves nothing half-written.

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
        "# eps: compression ratio (h0-h)/h0; h: tip height (m); fx,fy,fz: sum of tip reactions over rods / (n Pcrit), Pcrit = B1 (2 pi/L)^2, negative fz = compression; energy: total elastic energy (J); residual: Newton residual inf-norm"
    );
    let _ = writeln!(s, "step,eps,h,fx,fy,fz,energy,iterations,residual");
    for p in points {
        let _ = writeln!(
            s,
            "{},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{:.10e},{},{:.3e}",
            p.step,
            p.eps,
            p.height,
            p.load[0],
            p.load[1],
            p.load[2],
            p.energy,
            p.iterations,
            p.residual
        );
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

/// The three files of a run, written into `dir` (created if needed). Returns their paths.
pub fn write_run(
    dir: &Path,
    case: &str,
    points: &[LoadPoint],
    snapshot: &Snapshot,
) -> io::Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir)?;
    let files = [
        ("load.csv", load_csv(case, points)),
        ("reactions.csv", reactions_csv(case, points)),
        ("state.csv", state_csv(case, snapshot)),
    ];
    let mut out = Vec::new();
    for (name, text) in files {
        let p = dir.join(name);
        write_atomic(&p, &text)?;
        out.push(p);
    }
    Ok(out)
}
