//! ParaView series of a run: a `.pvd` collection whose `timestep` is the load parameter, and
//! one XML PolyData file (`.vtp`, ASCII) per output step. Each rod is a polyline through its
//! quaternion nodes, with point data: the curvatures `k1`, `k2`, `omega` (1/m), the
//! directors `d1`, `d2`, `d3`, the internal force `n` (N), the rod index and its chirality
//! (+1 right-, −1 left-handed); each joint is a vertex cell on each of its two rods.
//! A critical mode is the same geometry (the state at the critical point) with the mode's
//! centreline displacement as the vector field `displacement` (m per unit mode).
//!
//! The XML is written by hand: it is small and fixed, and the Rust VTK crates are stale.
//! Numbers are written in Rust's shortest round-trip form, so reading a file back gives the
//! values of the state exactly.

use super::csv::NonFinite;
use crate::model::quaternion::{self, Quat};
use crate::results::{ModeShape, Snapshot};
use std::fmt::Write as _;

/// Name of the collection file of a run's series.
pub const SERIES_FILE: &str = "series.pvd";

/// Name of the `.vtp` file of output step `step`.
pub fn step_file(step: usize) -> String {
    format!("step-{step:04}.vtp")
}

/// Name of the `.vtp` file of critical mode `index`.
pub fn mode_file(index: usize) -> String {
    format!("mode-{index}.vtp")
}

/// The `.pvd` collection: one data set per `(timestep, file)`, in the order given (ParaView
/// orders them by timestep, the load parameter).
pub fn pvd(case: &str, steps: &[(f64, String)]) -> Result<String, NonFinite> {
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\"?>\n");
    let _ = writeln!(out, "<!-- spira series, case {} -->", xml_comment(case));
    out.push_str("<VTKFile type=\"Collection\" version=\"1.0\" byte_order=\"LittleEndian\">\n");
    out.push_str("  <Collection>\n");
    for (k, (t, file)) in steps.iter().enumerate() {
        finite("timestep", k + 1, *t)?;
        let _ = writeln!(
            out,
            "    <DataSet timestep=\"{t:e}\" group=\"\" part=\"0\" file=\"{}\"/>",
            xml_attr(file)
        );
    }
    out.push_str("  </Collection>\n</VTKFile>\n");
    Ok(out)
}

/// The `.vtp` file of a state: its rods as polylines with their point data, its joints as
/// vertices.
pub fn vtp(case: &str, snapshot: &Snapshot) -> Result<String, NonFinite> {
    poly_data(
        &format!(
            "spira state, case {case}, eps = {:e}",
            snapshot.compression_ratio
        ),
        snapshot,
        None,
    )
}

/// The `.vtp` file of a critical mode: the state at the critical point with the mode's
/// displacement field.
pub fn mode_vtp(case: &str, index: usize, mode: &ModeShape) -> Result<String, NonFinite> {
    poly_data(
        &format!("spira critical mode {index}, case {case}"),
        &mode.shape,
        Some(&mode.displacement),
    )
}

fn poly_data(
    title: &str,
    snapshot: &Snapshot,
    displacement: Option<&Vec<Vec<[f64; 3]>>>,
) -> Result<String, NonFinite> {
    // point numbering: the nodes of rod 0, then of rod 1, …
    let mut first = Vec::with_capacity(snapshot.rods.len());
    let mut n_points = 0;
    for rod in &snapshot.rods {
        first.push(n_points);
        n_points += rod.nodes.len();
    }
    // joints: the node at each joint's arc length, on each rod
    let mut verts = Vec::new();
    for (r, rod) in snapshot.rods.iter().enumerate() {
        for &s in &rod.joints {
            let tol = 1e-9 * rod.nodes.last().map_or(1.0, |n| n.s.abs().max(1.0));
            if let Some(k) = rod.nodes.iter().position(|n| (n.s - s).abs() <= tol) {
                verts.push(first[r] + k);
            }
        }
    }
    let nodes = || snapshot.rods.iter().flat_map(|r| r.nodes.iter());
    let directors = |i: usize| {
        nodes()
            .map(move |n| {
                let q: Quat = n.quaternion.into();
                let d = quaternion::rotation(&q).column(i).into_owned();
                [d[0], d[1], d[2]]
            })
            .collect::<Vec<[f64; 3]>>()
    };
    let mut out = String::new();
    out.push_str("<?xml version=\"1.0\"?>\n");
    let _ = writeln!(out, "<!-- {} -->", xml_comment(title));
    out.push_str("<VTKFile type=\"PolyData\" version=\"1.0\" byte_order=\"LittleEndian\">\n");
    out.push_str("  <PolyData>\n");
    let _ = writeln!(
        out,
        "    <Piece NumberOfPoints=\"{n_points}\" NumberOfVerts=\"{}\" NumberOfLines=\"{}\" NumberOfStrips=\"0\" NumberOfPolys=\"0\">",
        verts.len(),
        snapshot.rods.len()
    );
    out.push_str("      <Points>\n");
    let positions: Vec<[f64; 3]> = nodes().map(|n| n.position).collect();
    vectors(&mut out, "Points", &positions)?;
    out.push_str("      </Points>\n");
    out.push_str("      <PointData Scalars=\"k1\" Vectors=\"d3\">\n");
    for (c, name) in ["k1", "k2", "omega"].iter().enumerate() {
        let v: Vec<f64> = nodes().map(|n| n.curvature[c]).collect();
        scalars(&mut out, name, &v)?;
    }
    for (i, name) in ["d1", "d2", "d3"].iter().enumerate() {
        vectors(&mut out, name, &directors(i))?;
    }
    let force: Vec<[f64; 3]> = nodes().map(|n| n.internal_force).collect();
    vectors(&mut out, "internal_force", &force)?;
    if let Some(d) = displacement {
        let d: Vec<[f64; 3]> = d.iter().flatten().copied().collect();
        vectors(&mut out, "displacement", &d)?;
    }
    let rod_index: Vec<i64> = snapshot
        .rods
        .iter()
        .flat_map(|r| r.nodes.iter().map(move |_| r.rod as i64))
        .collect();
    integers(&mut out, "rod", &rod_index);
    let chirality: Vec<i64> = snapshot
        .rods
        .iter()
        .flat_map(|r| r.nodes.iter().map(move |_| r.chirality.sign() as i64))
        .collect();
    integers(&mut out, "chirality", &chirality);
    out.push_str("      </PointData>\n");
    // cells
    out.push_str("      <Verts>\n");
    let vert_ids: Vec<i64> = verts.iter().map(|&v| v as i64).collect();
    integers(&mut out, "connectivity", &vert_ids);
    let vert_offsets: Vec<i64> = (1..=verts.len() as i64).collect();
    integers(&mut out, "offsets", &vert_offsets);
    out.push_str("      </Verts>\n");
    out.push_str("      <Lines>\n");
    let line_ids: Vec<i64> = (0..n_points as i64).collect();
    integers(&mut out, "connectivity", &line_ids);
    let mut offsets = Vec::with_capacity(snapshot.rods.len());
    let mut end = 0i64;
    for rod in &snapshot.rods {
        end += rod.nodes.len() as i64;
        offsets.push(end);
    }
    integers(&mut out, "offsets", &offsets);
    out.push_str("      </Lines>\n");
    out.push_str("    </Piece>\n  </PolyData>\n</VTKFile>\n");
    Ok(out)
}

fn finite(name: &str, row: usize, v: f64) -> Result<(), NonFinite> {
    if v.is_finite() {
        Ok(())
    } else {
        Err(NonFinite {
            column: name.to_string(),
            row,
            value: v.to_string(),
        })
    }
}

fn scalars(out: &mut String, name: &str, v: &[f64]) -> Result<(), NonFinite> {
    let _ = writeln!(
        out,
        "        <DataArray type=\"Float64\" Name=\"{name}\" format=\"ascii\">"
    );
    for (k, x) in v.iter().enumerate() {
        finite(name, k + 1, *x)?;
        let _ = writeln!(out, "          {x:e}");
    }
    out.push_str("        </DataArray>\n");
    Ok(())
}

fn vectors(out: &mut String, name: &str, v: &[[f64; 3]]) -> Result<(), NonFinite> {
    let _ = writeln!(
        out,
        "        <DataArray type=\"Float64\" Name=\"{name}\" NumberOfComponents=\"3\" format=\"ascii\">"
    );
    for (k, x) in v.iter().enumerate() {
        for c in x {
            finite(name, k + 1, *c)?;
        }
        let _ = writeln!(out, "          {:e} {:e} {:e}", x[0], x[1], x[2]);
    }
    out.push_str("        </DataArray>\n");
    Ok(())
}

fn integers(out: &mut String, name: &str, v: &[i64]) {
    let _ = writeln!(
        out,
        "        <DataArray type=\"Int64\" Name=\"{name}\" format=\"ascii\">"
    );
    for chunk in v.chunks(12) {
        let line: Vec<String> = chunk.iter().map(|x| x.to_string()).collect();
        let _ = writeln!(out, "          {}", line.join(" "));
    }
    out.push_str("        </DataArray>\n");
}

/// `text` safe inside an XML comment (no `--`, no control characters).
fn xml_comment(text: &str) -> String {
    super::csv::comment_safe(text).replace("--", "- -")
}

/// `text` safe as an XML attribute value.
fn xml_attr(text: &str) -> String {
    text.replace('&', "&amp;")
        .replace('"', "&quot;")
        .replace('<', "&lt;")
        .replace('>', "&gt;")
}
