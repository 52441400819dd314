//! CSV tables of a run: load path, tip reactions, state, critical points and their modes.
//!
//! Every table starts with `#` comment lines giving the case and the units, then the header
//! line and one row per record. The rows are [`Serialize`] structs written by the `csv`
//! crate, so the column names are the field names; numbers are written in scientific
//! notation with a fixed number of digits (the `e*` helpers of [`mod@format`]) and a missing
//! value is an empty cell.

use crate::discretisation::bulk::BULK_TOLERANCE;
use crate::discretisation::discrete_model::DiscreteModel;
use crate::results::{CriticalPoint, LoadPoint, ModeVertex, Snapshot, StepBulk};
use serde::Serialize;

/// Number formats of the cells: `{:.Ne}` scientific notation with `N` digits after the
/// point, and empty cells for missing values.
pub mod format {
    use serde::Serializer;

    /// `v`, with a negative zero as zero (`-0.0` would be written `-0e0`).
    pub fn unsigned_zero(v: f64) -> f64 {
        if v == 0.0 {
            0.0
        } else {
            v
        }
    }

    /// `{:.10e}`: lengths, strains, forces, energies.
    pub fn e10<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&format_args!("{:.10e}", unsigned_zero(*v)))
    }

    /// `{:.12e}`: a response compared at the 1e-10 level.
    pub fn e12<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&format_args!("{:.12e}", unsigned_zero(*v)))
    }

    /// `{:.6e}`: times, eigenvalues, relative errors and orders.
    pub fn e6<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&format_args!("{:.6e}", unsigned_zero(*v)))
    }

    /// `{:.3e}`: residual norms.
    pub fn e3<S: Serializer>(v: &f64, s: S) -> Result<S::Ok, S::Error> {
        s.collect_str(&format_args!("{:.3e}", unsigned_zero(*v)))
    }

    /// `{:.6e}`, or an empty cell.
    pub fn opt_e6<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => e6(v, s),
            None => s.serialize_str(""),
        }
    }

    /// `{:.10e}`, or an empty cell.
    pub fn opt_e10<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => e10(v, s),
            None => s.serialize_str(""),
        }
    }

    /// `{:.12e}`, or an empty cell.
    pub fn opt_e12<S: Serializer>(v: &Option<f64>, s: S) -> Result<S::Ok, S::Error> {
        match v {
            Some(v) => e12(v, s),
            None => s.serialize_str(""),
        }
    }
}

/// A table: the `#` comment lines (without `#`), then the header (the field names of `R`)
/// and `rows`. A table without rows still has its header line.
pub fn table<R: Serialize + Default>(
    comments: &[String],
    rows: impl IntoIterator<Item = R>,
) -> String {
    let mut text = Vec::new();
    for c in comments {
        text.extend_from_slice(b"# ");
        text.extend_from_slice(comment_safe(c).as_bytes());
        text.push(b'\n');
    }
    let start = text.len();
    let mut writer = ::csv::Writer::from_writer(text);
    let mut empty = true;
    for row in rows {
        writer.serialize(row).expect("a row of a CSV table");
        empty = false;
    }
    if empty {
        // the header comes with the first row: write one and keep the header
        writer
            .serialize(R::default())
            .expect("a row of a CSV table");
    }
    let mut text = writer.into_inner().expect("writing into memory");
    if empty {
        let header = text[start..]
            .iter()
            .position(|&b| b == b'\n')
            .map_or(text.len(), |i| start + i + 1);
        text.truncate(header);
    }
    String::from_utf8(text).expect("CSV of UTF-8 text")
}

/// A row of `load.csv`.
#[derive(Serialize, Default)]
struct LoadRow {
    step: usize,
    /// Compression ratio `(h0 − h)/h0`.
    #[serde(serialize_with = "format::e10")]
    eps: f64,
    /// Mean tip height (m).
    #[serde(rename = "h", serialize_with = "format::e10")]
    height: f64,
    /// Sum of the tip reactions over the rods / (n Pcrit).
    #[serde(serialize_with = "format::e10")]
    fx: f64,
    #[serde(serialize_with = "format::e10")]
    fy: f64,
    #[serde(serialize_with = "format::e10")]
    fz: f64,
    /// Total elastic energy (J).
    #[serde(serialize_with = "format::e10")]
    energy: f64,
    iterations: usize,
    /// Newton residual, infinity norm.
    #[serde(serialize_with = "format::e3")]
    residual: f64,
    /// 1 stable, 0 unstable, empty where not computed.
    stable: Option<u8>,
    unstable_dirs: Option<usize>,
    /// Lowest eigenvalue of the constrained Hessian (J/m).
    #[serde(rename = "lowest_eig", serialize_with = "format::opt_e6")]
    lowest_eigenvalue: Option<f64>,
    /// Load parameter (`ε`, or `P/Pcrit` under load control).
    #[serde(serialize_with = "format::e10")]
    parameter: f64,
    /// Twist of the tip support (rad) and the torque about the axis on the rods (N m).
    #[serde(serialize_with = "format::e10")]
    twist: f64,
    #[serde(serialize_with = "format::e10")]
    torque: f64,
    /// `torque L / B1`.
    #[serde(serialize_with = "format::e10")]
    torque_norm: f64,
    /// Tilt of the tip support (rad) and the bending moment about its axis (N m).
    #[serde(serialize_with = "format::e10")]
    tilt: f64,
    #[serde(serialize_with = "format::e10")]
    bending_moment: f64,
    /// `bending_moment L / B1`.
    #[serde(serialize_with = "format::e10")]
    bending_moment_norm: f64,
    /// Radial line pressure (N/m), mean radius (m), lateral pressure (Pa).
    #[serde(serialize_with = "format::e10")]
    pressure: f64,
    #[serde(serialize_with = "format::e10")]
    radius: f64,
    #[serde(serialize_with = "format::e10")]
    lateral_pressure: f64,
}

/// The glossary of `load.csv`'s columns, for its comment line.
pub const LOAD_GLOSSARY: &str = "eps: compression ratio (h0-h)/h0; h: mean tip height (m); fx,fy,fz: sum of tip reactions over rods / (n Pcrit), Pcrit = B1 (2 pi/L)^2, negative fz = compression; energy: total elastic energy (J); residual: Newton residual inf-norm; stable: 1 if the Hessian is positive definite on the constraints' tangent space; unstable_dirs: its negative eigenvalues; lowest_eig: its lowest eigenvalue in the metric of nodal rotations weighted by arc length (J/m; empty where not computed); parameter: load parameter (eps, P/Pcrit under load control, twist or tilt in rad, pressure in N/m); twist: twist of the tip support about the axis (rad); torque: torque about the axis the support applies to the rods, summed (N m), torque_norm = torque L/B1; tilt: tilt of the tip support about the x axis through the tip's centre (rad); bending_moment: moment about that axis on the rods (N m), bending_moment_norm = bending_moment L/B1; pressure: radial line load q on every rod (N/m, inward); radius: the rods' mean distance from the axis (1/(n L)) sum int rho ds (m); lateral_pressure: n q L / (2 pi radius h), the pressure on the tube's surface (Pa)";

/// `load.csv`: one row per output step.
pub fn load_csv(case: &str, points: &[LoadPoint]) -> String {
    let comments = [
        format!("spira load path, case {case}"),
        LOAD_GLOSSARY.to_string(),
    ];
    let rows = points.iter().map(|p| LoadRow {
        step: p.step,
        eps: p.compression_ratio,
        height: p.height,
        fx: p.load[0],
        fy: p.load[1],
        fz: p.load[2],
        energy: p.energy,
        iterations: p.iterations,
        residual: p.residual,
        stable: p.stability.map(|st| u8::from(st.is_stable())),
        unstable_dirs: p.stability.map(|st| st.unstable_directions),
        lowest_eigenvalue: p.stability.and_then(|st| st.lowest_eigenvalue),
        parameter: p.parameter,
        twist: p.support.twist,
        torque: p.support.torque,
        torque_norm: p.support.torque / p.support.unit_moment,
        tilt: p.support.tilt,
        bending_moment: p.support.bending_moment,
        bending_moment_norm: p.support.bending_moment / p.support.unit_moment,
        pressure: p.support.pressure,
        radius: p.support.radius,
        lateral_pressure: p.support.lateral_pressure,
    });
    table(&comments, rows)
}

/// A row of `critical.csv`.
#[derive(Serialize, Default)]
struct CriticalRow {
    index: usize,
    /// `limit-point`, `bifurcation` or `neutral`.
    kind: &'static str,
    /// Control of the path (`displacement` or `force`).
    control: &'static str,
    #[serde(serialize_with = "format::e10")]
    parameter: f64,
    #[serde(serialize_with = "format::e10")]
    eps: f64,
    /// Sum of the tip reactions / (n Pcrit).
    #[serde(serialize_with = "format::e10")]
    fx: f64,
    #[serde(serialize_with = "format::e10")]
    fy: f64,
    #[serde(serialize_with = "format::e10")]
    fz: f64,
    unstable_before: usize,
    unstable_after: usize,
    /// Circumferential wavenumber of the mode (empty for the full model).
    wavenumber: Option<usize>,
    multiplicity: usize,
}

/// `critical.csv`: the critical points of a path.
pub fn critical_csv(case: &str, critical: &[CriticalPoint]) -> String {
    let comments = [
        format!("spira critical points, case {case}"),
        "kind: limit-point, bifurcation, or neutral (a direction of zero energy to rounding along the path, such as a buckled isotropic rod turning about its axis: counted once, where it first flipped the count, and as stable); parameter: load parameter (eps, or P/Pcrit under load control); fx,fy,fz: sum of tip reactions / (n Pcrit); unstable_before/after: unstable directions either side (each mode of a multiple point counted); wavenumber: circumferential wavenumber p of the mode when the stability of a symmetric pair is judged by Bloch blocks (the mode repeats with phase 2 pi p/m from sector to sector; empty for the full model); multiplicity: modes crossing together (2 for 0 < p < m/2; on the full model the jump of the count, 2 at the double point of an isotropic rod); mode shapes, on the whole assembly, in mode-<index>.csv".to_string(),
    ];
    let rows = critical.iter().enumerate().map(|(i, c)| CriticalRow {
        index: i,
        kind: c.kind.name(),
        control: c.control.name(),
        parameter: c.parameter,
        eps: c.compression_ratio,
        fx: c.load[0],
        fy: c.load[1],
        fz: c.load[2],
        unstable_before: c.unstable_before,
        unstable_after: c.unstable_after,
        wavenumber: c.wavenumber,
        multiplicity: c.multiplicity,
    });
    table(&comments, rows)
}

/// A row of `mode-<k>.csv`.
#[derive(Serialize, Default)]
struct ModeRow {
    rod: usize,
    /// Arc length of the vertex (m).
    #[serde(serialize_with = "format::e10")]
    s: f64,
    #[serde(serialize_with = "format::e10")]
    s_over_l: f64,
    /// Mode displacement of the centreline (m per unit mode).
    #[serde(serialize_with = "format::e10")]
    dx: f64,
    #[serde(serialize_with = "format::e10")]
    dy: f64,
    #[serde(serialize_with = "format::e10")]
    dz: f64,
}

/// `mode-<k>.csv`: the centreline displacement of a critical mode at the element vertices
/// (unit norm over all primal unknowns; the sign is arbitrary).
pub fn mode_csv(
    case: &str,
    model: &DiscreteModel,
    index: usize,
    critical: &CriticalPoint,
) -> String {
    mode_table(case, index, critical, &mode_vertices(model, critical))
}

/// `mode-<k>.csv` of critical point `index` from its mode's displacement at the vertices
/// ([`mode_vertices`]).
pub fn mode_table(
    case: &str,
    index: usize,
    critical: &CriticalPoint,
    vertices: &[ModeVertex],
) -> String {
    let comments = [
        format!(
            "spira critical mode {index} ({}), case {case}, parameter = {:.10e}",
            critical.kind.name(),
            critical.parameter
        ),
        "dx,dy,dz: mode displacement of the centreline at element vertices (m per unit mode)"
            .to_string(),
    ];
    let rows = vertices.iter().map(|v| ModeRow {
        rod: v.rod,
        s: v.s,
        s_over_l: v.s_over_l,
        dx: v.displacement[0],
        dy: v.displacement[1],
        dz: v.displacement[2],
    });
    table(&comments, rows)
}

/// The centreline displacement of `critical`'s mode at the element vertices of every rod
/// of `model` (for a symmetric pair, of the whole assembly, where its mode was rebuilt).
pub fn mode_vertices(model: &DiscreteModel, critical: &CriticalPoint) -> Vec<ModeVertex> {
    // a symmetric pair's mode is written on the whole assembly, where it was rebuilt
    // (after a switch onto a branch that breaks the symmetry the model is the full one)
    let full = match (&critical.assembly_mode, model.assembly.symmetry) {
        (Some(m), Some(_)) => model.full_model().map(|f| (f, m)),
        _ => None,
    };
    let (model, mode) = match (&full, &critical.assembly_mode) {
        (Some((full, m)), _) => (full, m.as_slice()),
        (None, Some(m)) if m.len() == model.n_primal => (model, m.as_slice()),
        _ => (model, critical.mode.as_slice()),
    };
    let length = model.length();
    model
        .rods
        .iter()
        .enumerate()
        .flat_map(|(id, rod)| {
            rod.mesh
                .vertices
                .iter()
                .enumerate()
                .map(move |(v, &s)| ModeVertex {
                    rod: id,
                    s,
                    s_over_l: s / length,
                    displacement: [0, 1, 2].map(|k| mode[rod.r_dof(v, k)]),
                })
        })
        .collect()
}

/// A row of `reactions.csv`.
#[derive(Serialize, Default)]
struct ReactionRow {
    step: usize,
    #[serde(serialize_with = "format::e10")]
    eps: f64,
    rod: usize,
    /// `right` or `left`.
    chirality: &'static str,
    /// Tip force on the rod (N), global frame.
    #[serde(serialize_with = "format::e10")]
    fx: f64,
    #[serde(serialize_with = "format::e10")]
    fy: f64,
    #[serde(serialize_with = "format::e10")]
    fz: f64,
    /// Tip moment on the rod (N m), global frame.
    #[serde(serialize_with = "format::e10")]
    mx: f64,
    #[serde(serialize_with = "format::e10")]
    my: f64,
    #[serde(serialize_with = "format::e10")]
    mz: f64,
}

/// `reactions.csv`: one row per rod per output step, tip reaction force (N) and moment (N m).
pub fn reactions_csv(case: &str, points: &[LoadPoint]) -> String {
    let comments = [
        format!("spira tip reactions, case {case}"),
        "force (fx,fy,fz in N) and moment (mx,my,mz in N m) applied by the tip support to each rod, global frame".to_string(),
    ];
    let rows = points.iter().flat_map(|p| {
        p.reactions.iter().map(move |r| {
            let (f, m) = (r.tip.force, r.tip.moment);
            ReactionRow {
                step: p.step,
                eps: p.compression_ratio,
                rod: r.rod,
                chirality: r.chirality.name(),
                fx: f[0],
                fy: f[1],
                fz: f[2],
                mx: m[0],
                my: m[1],
                mz: m[2],
            }
        })
    });
    table(&comments, rows)
}

/// A row of `state.csv`: one quaternion node.
#[derive(Serialize, Default)]
struct NodeRow {
    rod: usize,
    /// Arc length (m).
    #[serde(serialize_with = "format::e10")]
    s: f64,
    #[serde(serialize_with = "format::e10")]
    s_over_l: f64,
    /// Centreline position (m).
    #[serde(serialize_with = "format::e10")]
    x: f64,
    #[serde(serialize_with = "format::e10")]
    y: f64,
    #[serde(serialize_with = "format::e10")]
    z: f64,
    /// Unit quaternion, vector part then scalar.
    #[serde(serialize_with = "format::e10")]
    q1: f64,
    #[serde(serialize_with = "format::e10")]
    q2: f64,
    #[serde(serialize_with = "format::e10")]
    q3: f64,
    #[serde(serialize_with = "format::e10")]
    q4: f64,
    /// Bending curvatures (1/m).
    #[serde(serialize_with = "format::e10")]
    k1: f64,
    #[serde(serialize_with = "format::e10")]
    k2: f64,
    /// Twist (1/m).
    #[serde(serialize_with = "format::e10")]
    omega: f64,
    /// Internal force (N), global frame.
    #[serde(serialize_with = "format::e10")]
    nx: f64,
    #[serde(serialize_with = "format::e10")]
    ny: f64,
    #[serde(serialize_with = "format::e10")]
    nz: f64,
}

/// `state.csv`: every quaternion node of every rod.
pub fn state_csv(case: &str, snapshot: &Snapshot) -> String {
    let comments = [
        format!("spira state, case {case}, eps = {:.10e}", snapshot.compression_ratio),
        "s: arc length (m); x,y,z: centreline (m); q1..q4: unit quaternion (vector, scalar); k1,k2,omega: curvatures (1/m), recovered from the Barlow points of the elements by a local least-squares fit; nx,ny,nz: internal force (N; at an element vertex the mean of the two elements)".to_string(),
    ];
    let rows = snapshot.rods.iter().flat_map(|rod| {
        rod.nodes.iter().map(move |n| NodeRow {
            rod: rod.rod,
            s: n.s,
            s_over_l: n.s_over_l,
            x: n.position[0],
            y: n.position[1],
            z: n.position[2],
            q1: n.quaternion[0],
            q2: n.quaternion[1],
            q3: n.quaternion[2],
            q4: n.quaternion[3],
            k1: n.curvature[0],
            k2: n.curvature[1],
            omega: n.curvature[2],
            nx: n.internal_force[0],
            ny: n.internal_force[1],
            nz: n.internal_force[2],
        })
    });
    table(&comments, rows)
}

/// A row of `bulk.csv`: the bulk of one rod at one output step.
#[derive(Serialize, Default)]
struct BulkRow {
    step: usize,
    #[serde(serialize_with = "format::e10")]
    eps: f64,
    rod: usize,
    /// `right` or `left`.
    chirality: &'static str,
    /// Extent of the bulk, `s/L`.
    #[serde(serialize_with = "format::e10")]
    bulk_start: f64,
    #[serde(serialize_with = "format::e10")]
    bulk_end: f64,
    /// Boundary-layer lengths at the base and the tip (m).
    #[serde(serialize_with = "format::e10")]
    layer_base: f64,
    #[serde(serialize_with = "format::e10")]
    layer_tip: f64,
    /// Fitted helix: radius and pitch parameter (m).
    #[serde(serialize_with = "format::e10")]
    radius: f64,
    #[serde(serialize_with = "format::e10")]
    pitch: f64,
    /// Mean curvatures over the bulk (1/m).
    #[serde(serialize_with = "format::e10")]
    k1: f64,
    #[serde(serialize_with = "format::e10")]
    k2: f64,
    #[serde(serialize_with = "format::e10")]
    omega: f64,
    /// Love's axial force (N) and couple (N m) for the fitted helix.
    #[serde(serialize_with = "format::opt_e10")]
    love_force: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    love_moment: Option<f64>,
    /// The rod's tip reaction: axial force (N) and couple about the tube axis (N m).
    #[serde(serialize_with = "format::e10")]
    fz: f64,
    #[serde(serialize_with = "format::e10")]
    mz: f64,
    /// Axial force per rod of the infinite tube at this eps (N), and the finite
    /// assembly's mean tip fz over it.
    #[serde(serialize_with = "format::opt_e10")]
    tube_force: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    tube_ratio: Option<f64>,
    /// Under radial pressure: the infinite tube's bulk radius with no axial force (m), and
    /// the mean fitted bulk radius over it.
    #[serde(serialize_with = "format::opt_e10")]
    tube_radius: Option<f64>,
    #[serde(serialize_with = "format::opt_e10")]
    radius_ratio: Option<f64>,
}

/// `bulk.csv`: the bulk of every rod at every output step, the helix fitted there, Love's
/// wrench for it beside the rod's reactions, and the infinite tube beside the assembly.
pub fn bulk_csv(case: &str, steps: &[StepBulk]) -> String {
    let comments = [
        format!("spira bulk, case {case}; bulk = longest stretch where k1, k2, omega stay within {} x 1/c0 of one helix", BULK_TOLERANCE),
        "bulk_start,bulk_end: extent of the bulk (s/L); layer_base,layer_tip: boundary-layer lengths (m); radius,pitch: fitted helix a and b (m); k1,k2,omega: mean curvatures over the bulk (1/m); love_force (N, tension positive), love_moment (N m): Love's closed form for the fitted helix; fz (N), mz (N m): the rod's tip reaction, axial force and couple about the tube axis; tube_force: Love's axial force per rod of the infinite tube (c = c0, b = b0 (1 - eps)) (N); tube_ratio: mean tip fz of the rods / tube_force; tube_radius: under radial pressure, the infinite tube's bulk radius with no axial force, the pantograph's closed form (m); radius_ratio: the rods' mean bulk radius / tube_radius".to_string(),
    ];
    let rows = steps.iter().flat_map(|st| {
        st.rods.iter().map(move |b| BulkRow {
            step: st.step,
            eps: st.compression_ratio,
            rod: b.rod,
            chirality: b.chirality.name(),
            bulk_start: b.start_over_l(),
            bulk_end: b.end_over_l(),
            layer_base: b.start,
            layer_tip: b.length - b.end,
            radius: b.radius,
            pitch: b.pitch,
            k1: b.curvature[0],
            k2: b.curvature[1],
            omega: b.curvature[2],
            love_force: b.love_force,
            love_moment: b.love_moment,
            fz: b.axial_force,
            mz: b.axial_moment,
            tube_force: st.tube_force,
            tube_ratio: st.tube_ratio,
            tube_radius: st.tube_radius,
            radius_ratio: st.radius_ratio,
        })
    });
    table(&comments, rows)
}

/// `text` made safe for one `#` comment line: line breaks and other control characters
/// (a case name may hold them) become spaces.
pub fn comment_safe(text: &str) -> String {
    text.chars()
        .map(|c| if c.is_control() { ' ' } else { c })
        .collect()
}

/// A cell of a table that holds no finite number.
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
#[error("refusing to write a non-finite value ({value}) in column `{column}`, row {row}")]
pub struct NonFinite {
    pub column: String,
    /// Data row, 1-based (the header not counted).
    pub row: usize,
    pub value: String,
}

/// Checks that no cell of `csv` (a table of this module) is `NaN`, `inf` or `-inf`, and
/// says the first column that holds one.
pub fn check_finite(csv: &str) -> Result<(), NonFinite> {
    const NON_FINITE: [&[u8]; 6] = [b"nan", b"inf", b"-inf", b"+inf", b"infinity", b"-infinity"];
    let mut reader = ::csv::ReaderBuilder::new()
        .flexible(true)
        .comment(Some(b'#'))
        .from_reader(csv.as_bytes());
    let header = reader.byte_headers().cloned().unwrap_or_default();
    let mut record = ::csv::ByteRecord::new();
    let mut row = 0;
    // bytes read from memory: no reading error can occur
    while let Ok(true) = reader.read_byte_record(&mut record) {
        row += 1;
        for (i, cell) in record.iter().enumerate() {
            let t = cell.trim_ascii();
            if NON_FINITE.iter().any(|w| t.eq_ignore_ascii_case(w)) {
                let text = |b: &[u8]| String::from_utf8_lossy(b).into_owned();
                return Err(NonFinite {
                    column: header.get(i).map_or("?".to_string(), text),
                    row,
                    value: text(cell),
                });
            }
        }
    }
    Ok(())
}

/// `csv` (a table of this module) with `note` as one more `#` line after its first line,
/// e.g. the mesh an accuracy target chose and its estimated error.
pub fn with_note(csv: &str, note: &str) -> String {
    let note = comment_safe(note);
    match csv.split_once('\n') {
        Some((first, rest)) => format!("{first}\n# {note}\n{rest}"),
        None => format!("{csv}\n# {note}\n"),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_negative_zero_is_written_as_zero() {
        #[derive(Serialize, Default)]
        struct Row {
            #[serde(serialize_with = "format::e10")]
            a: f64,
            #[serde(serialize_with = "format::e6")]
            b: f64,
            #[serde(serialize_with = "format::opt_e12")]
            c: Option<f64>,
            #[serde(serialize_with = "format::e3")]
            d: f64,
        }
        let text = table(
            &[],
            [Row {
                a: -0.0,
                b: -0.0,
                c: Some(-0.0),
                d: -0.0,
            }],
        );
        assert_eq!(
            text,
            "a,b,c,d\n0.0000000000e0,0.000000e0,0.000000000000e0,0.000e0\n"
        );
    }

    #[derive(Serialize, Default)]
    struct Row {
        name: String,
        #[serde(serialize_with = "format::e10")]
        value: f64,
        #[serde(serialize_with = "format::opt_e6")]
        maybe: Option<f64>,
        count: Option<usize>,
    }

    #[test]
    fn a_table_has_its_comments_header_and_rows_in_the_given_formats() {
        let rows = [
            Row {
                name: "a".into(),
                value: 1.5,
                maybe: Some(-2.0e-3),
                count: Some(3),
            },
            Row {
                name: "b, \"c\"".into(),
                value: 0.0,
                maybe: None,
                count: None,
            },
        ];
        let text = table(&["first".to_string(), "second".to_string()], rows);
        assert_eq!(
            text,
            "# first\n# second\nname,value,maybe,count\n\
             a,1.5000000000e0,-2.000000e-3,3\n\
             \"b, \"\"c\"\"\",0.0000000000e0,,\n"
        );
    }

    #[test]
    fn a_table_without_rows_keeps_its_header() {
        let text = table(&["only".to_string()], Vec::<Row>::new());
        assert_eq!(text, "# only\nname,value,maybe,count\n");
    }
}
