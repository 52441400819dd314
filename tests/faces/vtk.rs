//! The ParaView series of `spira run --vtk`, read back: the `.pvd` collection's
//! timesteps are the load parameters of load.csv, a `.vtp` gives the node positions and
//! curvatures of the state (exactly, and as state.csv prints them), its cells are the rods
//! and the joints, and a mode file carries the mode's displacement of mode-<k>.csv.

use spira::case::Case;
use spira::output::{write_run, RunFiles};
use spira::run::run_path_steps;
use std::path::{Path, PathBuf};

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spira-vtk-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    dir
}

/// The text of the `<DataArray … Name="name" …>` of `xml` (the first one), as numbers.
fn data_array(xml: &str, name: &str) -> Vec<f64> {
    let key = format!("Name=\"{name}\"");
    let at = xml
        .find(&key)
        .unwrap_or_else(|| panic!("no data array {name}"));
    let open = at + xml[at..].find('>').expect("end of the tag") + 1;
    let close = open + xml[open..].find("</DataArray>").expect("closing tag");
    xml[open..close]
        .split_whitespace()
        .map(|t| t.parse::<f64>().unwrap_or_else(|_| panic!("{name}: {t}")))
        .collect()
}

/// The value of attribute `attr` of the first element `tag` of `xml`.
fn attribute(xml: &str, tag: &str, attr: &str) -> String {
    let at = xml
        .find(&format!("<{tag} "))
        .unwrap_or_else(|| panic!("no <{tag}>"));
    let end = at + xml[at..].find('>').expect("end of the tag");
    let key = format!("{attr}=\"");
    let v = at + xml[at..end].find(&key).expect("attribute") + key.len();
    xml[v..v + xml[v..].find('"').expect("closing quote")].to_string()
}

/// The data rows of a CSV table of spira (comments skipped), as (header, rows of cells).
fn csv_rows(text: &str) -> (Vec<String>, Vec<Vec<String>>) {
    let mut lines = text.lines().filter(|l| !l.starts_with('#'));
    let header: Vec<String> = lines
        .next()
        .expect("header")
        .split(',')
        .map(String::from)
        .collect();
    let rows = lines
        .map(|l| l.split(',').map(String::from).collect())
        .collect();
    (header, rows)
}

fn column(header: &[String], name: &str) -> usize {
    header
        .iter()
        .position(|h| h == name)
        .unwrap_or_else(|| panic!("no column {name}"))
}

/// `x` as state.csv prints it (`{:.10e}`, a zero unsigned).
fn e10(x: f64) -> String {
    format!("{:.10e}", if x == 0.0 { 0.0 } else { x })
}

#[test]
fn a_vtp_read_back_gives_the_state_of_state_csv_and_the_pvd_the_load_parameters() {
    let case = Case::from_file(Path::new("cases/thesis-n2.toml")).expect("shipped case");
    let targets = case.output_parameters(0.2, 2);
    let mut shapes = Vec::new();
    let out = run_path_steps(&case, &targets, None, None, |s| {
        shapes.push(s.snapshot.clone())
    })
    .expect("path");
    assert_eq!(shapes.len(), out.points.len());
    assert_eq!(shapes.last(), Some(&out.snapshot));
    let dir = temp_dir("state");
    let mut files = RunFiles::of(&case.name, None, &out);
    files.series = Some((&shapes, &out.modes));
    write_run(&dir, &files).expect("write");

    // the collection: one data set per output step, timestep = load parameter of load.csv
    let pvd = std::fs::read_to_string(dir.join("series.pvd")).expect("series.pvd");
    assert!(pvd.starts_with("<?xml") && pvd.trim_end().ends_with("</VTKFile>"));
    let (lh, lrows) = csv_rows(&std::fs::read_to_string(dir.join("load.csv")).unwrap());
    let pcol = column(&lh, "parameter");
    let sets: Vec<&str> = pvd.lines().filter(|l| l.contains("<DataSet ")).collect();
    assert_eq!(sets.len(), lrows.len());
    for (k, (line, row)) in sets.iter().zip(&lrows).enumerate() {
        let t: f64 = attribute(line, "DataSet", "timestep")
            .parse()
            .expect("number");
        assert_eq!(e10(t), row[pcol], "timestep of data set {k}");
        assert_eq!(t, out.points[k].parameter);
        let file = attribute(line, "DataSet", "file");
        assert_eq!(file, format!("step-{k:04}.vtp"));
        assert!(dir.join(&file).is_file());
    }

    // the last step against state.csv (the last state)
    let last = format!("step-{:04}.vtp", out.points.len() - 1);
    let vtp = std::fs::read_to_string(dir.join(&last)).expect("vtp");
    let (sh, srows) = csv_rows(&std::fs::read_to_string(dir.join("state.csv")).unwrap());
    let n_points: usize = attribute(&vtp, "Piece", "NumberOfPoints").parse().unwrap();
    assert_eq!(n_points, srows.len());
    let points = data_array(&vtp, "Points");
    assert_eq!(points.len(), 3 * n_points);
    let curv: Vec<Vec<f64>> = ["k1", "k2", "omega"]
        .iter()
        .map(|n| data_array(&vtp, n))
        .collect();
    let rods = data_array(&vtp, "rod");
    let chirality = data_array(&vtp, "chirality");
    let nodes: Vec<_> = out.snapshot.rods.iter().flat_map(|r| &r.nodes).collect();
    for (i, row) in srows.iter().enumerate() {
        for (c, name) in ["x", "y", "z"].iter().enumerate() {
            let v = points[3 * i + c];
            // exactly the state's value, and printed as state.csv prints it
            assert!(
                (v - nodes[i].position[c]).abs() <= 1e-12,
                "{name} at row {i}"
            );
            assert_eq!(e10(v), row[column(&sh, name)], "{name} at row {i}");
        }
        for (c, name) in ["k1", "k2", "omega"].iter().enumerate() {
            let v = curv[c][i];
            assert!(
                (v - nodes[i].curvature[c]).abs() <= 1e-12,
                "{name} at row {i}"
            );
            assert_eq!(e10(v), row[column(&sh, name)], "{name} at row {i}");
        }
        assert_eq!(rods[i].to_string(), row[column(&sh, "rod")]);
    }
    // rod 0 right-handed, rod 1 left-handed (n = 2)
    assert_eq!(chirality.first(), Some(&1.0));
    assert_eq!(chirality.last(), Some(&-1.0));
    // directors: orthonormal, d3 the tangent (unit), d1 x d2 = d3
    let d: Vec<Vec<f64>> = ["d1", "d2", "d3"]
        .iter()
        .map(|n| data_array(&vtp, n))
        .collect();
    for i in 0..n_points {
        let v = |k: usize| nalgebra::Vector3::new(d[k][3 * i], d[k][3 * i + 1], d[k][3 * i + 2]);
        assert!(
            (v(0).cross(&v(1)) - v(2)).norm() < 1e-12,
            "director triad at {i}"
        );
    }
    let force = data_array(&vtp, "internal_force");
    assert_eq!(force.len(), 3 * n_points);
    // the tip's internal force is the tip reaction (reactions.csv, last step)
    let r0 = &out.points.last().unwrap().reactions[0].tip.force;
    let tip = out.snapshot.rods[0].nodes.len() - 1;
    for c in 0..3 {
        assert!((force[3 * tip + c] - r0[c]).abs() <= 1e-9 * (1.0 + r0[c].abs()));
    }
    // cells: one polyline per rod through all its nodes, one vertex per joint per rod
    let n_lines: usize = attribute(&vtp, "Piece", "NumberOfLines").parse().unwrap();
    assert_eq!(n_lines, out.snapshot.rods.len());
    let lines_at = vtp.find("<Lines>").expect("lines");
    let offsets = data_array(&vtp[lines_at..], "offsets");
    let per_rod: Vec<f64> = out
        .snapshot
        .rods
        .iter()
        .scan(0usize, |acc, r| {
            *acc += r.nodes.len();
            Some(*acc as f64)
        })
        .collect();
    assert_eq!(offsets, per_rod);
    let n_verts: usize = attribute(&vtp, "Piece", "NumberOfVerts").parse().unwrap();
    let joints: usize = out.snapshot.rods.iter().map(|r| r.joints.len()).sum();
    assert!(joints > 0);
    assert_eq!(n_verts, joints);
    let verts_at = vtp.find("<Verts>").expect("verts");
    let ids = data_array(&vtp[verts_at..], "connectivity");
    for id in ids {
        // a joint's two vertices are at one place: its node on each rod
        let i = id as usize;
        let p = &points[3 * i..3 * i + 3];
        let partner = (0..n_points)
            .any(|j| rods[j] != rods[i] && (0..3).all(|c| (points[3 * j + c] - p[c]).abs() < 1e-9));
        assert!(partner, "joint vertex {i} has no partner on another rod");
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// Euler's clamped column under load control (buckling at P/Pcrit = 1): its mode file is the
/// critical state's geometry with the displacement of mode-0.csv at the element vertices.
#[test]
fn a_mode_vtp_carries_the_displacement_of_mode_csv() {
    let text = "name = \"euler\"\n[geometry]\nradius = 0.0\nlength = 1.0\n[stiffness]\nb1 = 1.0\nb2 = 2.0\nb3 = 2.0\n[loading]\ncontrol = \"force\"\ntarget = 1.1\nsteps = 1\n[discretisation]\nelements = 16\n";
    let case = Case::parse(text, "euler.toml", "euler").expect("valid case");
    let targets = case.output_parameters(case.loading.target, 1);
    let mut shapes = Vec::new();
    let out = run_path_steps(&case, &targets, None, None, |s| {
        shapes.push(s.snapshot.clone())
    })
    .expect("path");
    assert!(!out.critical.is_empty(), "Euler's column buckles");
    let dir = temp_dir("mode");
    let mut files = RunFiles::of(&case.name, None, &out);
    files.series = Some((&shapes, &out.modes));
    write_run(&dir, &files).expect("write");
    let vtp = std::fs::read_to_string(dir.join("mode-0.vtp")).expect("mode-0.vtp");
    let disp = data_array(&vtp, "displacement");
    let (mh, mrows) = csv_rows(&std::fs::read_to_string(dir.join("mode-0.csv")).unwrap());
    let nodes = &out.modes[0].shape.rods[0].nodes;
    assert_eq!(disp.len(), 3 * nodes.len());
    let scol = column(&mh, "s");
    for row in &mrows {
        let s: f64 = row[scol].parse().unwrap();
        let i = nodes
            .iter()
            .position(|n| (n.s - s).abs() < 1e-9)
            .expect("a vertex is a node");
        for (c, name) in ["dx", "dy", "dz"].iter().enumerate() {
            assert_eq!(
                e10(disp[3 * i + c]),
                row[column(&mh, name)],
                "{name} at s = {s}"
            );
        }
    }
    // between vertices the displacement is the linearised chord: close to the mean of the
    // neighbouring vertices for a smooth mode
    let scale = disp.iter().fold(0.0f64, |m, v| m.max(v.abs()));
    assert!(scale > 0.0);
    for i in (1..nodes.len() - 1).step_by(2) {
        for c in 0..3 {
            let mid = 0.5 * (disp[3 * (i - 1) + c] + disp[3 * (i + 1) + c]);
            assert!((disp[3 * i + c] - mid).abs() < 0.05 * scale, "mid-node {i}");
        }
    }
    let _ = std::fs::remove_dir_all(&dir);
}
