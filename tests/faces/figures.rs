//! Figures of runs: the SVG that `spira plot` and `spira run --figures`
//! write parses as XML and holds the curves, marks, labels and units asked for; bad run
//! folders give an error naming the file, line and column, and leave nothing behind.
//!
//! Most checks run on small run folders written here (a known load path with a stable and
//! an unstable stretch, a known state), so that what each figure must hold is known exactly.

use crate::common;

use spira::output::figures::{
    curvature_figure, load_figure, run_figures, stretches, views_figure, Kinds, Rods, Shade, Steps,
    K1_LEVELS,
};
use spira::output::read::{RunTables, TableError};
use std::collections::BTreeMap;
use std::path::{Path, PathBuf};
use std::process::Command;

// ------------------------------------------------------------------ a small XML reader

/// An element of a parsed document: its name, attributes and text.
#[derive(Debug, Clone)]
pub(crate) struct Element {
    pub(crate) name: String,
    pub(crate) attrs: BTreeMap<String, String>,
    pub(crate) text: String,
}

/// Parses `xml` strictly enough for what we write: every tag closes in order, attributes
/// are `name="value"` once each, entities are the five of XML or numeric, no `<` or `&`
/// stray in text; returns the elements in document order. Panics with the reason.
pub(crate) fn parse_xml(xml: &str) -> Vec<Element> {
    let mut out: Vec<Element> = Vec::new();
    let mut open: Vec<usize> = Vec::new();
    let mut rest = xml;
    let check_text = |t: &str| {
        let mut s = t;
        while let Some(i) = s.find('&') {
            let end = s[i..].find(';').expect("entity closed") + i;
            let ent = &s[i + 1..end];
            assert!(
                matches!(ent, "amp" | "lt" | "gt" | "quot" | "apos") || ent.starts_with('#'),
                "unknown entity &{ent};"
            );
            s = &s[end + 1..];
        }
    };
    while let Some(i) = rest.find('<') {
        let text = &rest[..i];
        check_text(text);
        if let Some(&top) = open.last() {
            out[top].text.push_str(text.trim());
        }
        let end = rest[i..].find('>').expect("tag closed") + i;
        let tag = &rest[i + 1..end];
        rest = &rest[end + 1..];
        if tag.starts_with('?') || tag.starts_with('!') {
            continue;
        }
        if let Some(name) = tag.strip_prefix('/') {
            let top = open
                .pop()
                .unwrap_or_else(|| panic!("</{name}> closes nothing"));
            assert_eq!(out[top].name, name.trim(), "closing tag");
            continue;
        }
        let self_closing = tag.ends_with('/');
        let body = tag.trim_end_matches('/');
        let name_end = body.find(char::is_whitespace).unwrap_or(body.len());
        let name = body[..name_end].to_string();
        assert!(!name.is_empty(), "a tag without a name: <{tag}>");
        let mut attrs = BTreeMap::new();
        let mut a = body[name_end..].trim();
        while !a.is_empty() {
            let eq = a
                .find('=')
                .unwrap_or_else(|| panic!("attribute without value in <{tag}>"));
            let key = a[..eq].trim().to_string();
            let after = a[eq + 1..].trim_start();
            assert!(
                after.starts_with('"'),
                "unquoted attribute {key} in <{tag}>"
            );
            let close = after[1..].find('"').expect("attribute value closed") + 1;
            let value = &after[1..close];
            assert!(!value.contains('<'), "< in an attribute of <{tag}>");
            check_text(value);
            assert!(
                attrs.insert(key.clone(), value.to_string()).is_none(),
                "attribute {key} twice in <{tag}>"
            );
            a = after[close + 1..].trim_start();
        }
        out.push(Element {
            name,
            attrs,
            text: String::new(),
        });
        if !self_closing {
            open.push(out.len() - 1);
        }
    }
    assert!(rest.trim().is_empty(), "text after the root element");
    assert!(open.is_empty(), "unclosed elements");
    assert_eq!(
        out.first().map(|e| e.name.as_str()),
        Some("svg"),
        "root is <svg>"
    );
    for e in &out {
        for v in e.attrs.values() {
            assert!(!v.contains("NaN") && !v.contains("inf"), "{e:?}");
        }
    }
    out
}

pub(crate) fn texts(doc: &[Element]) -> Vec<String> {
    doc.iter()
        .filter(|e| e.name == "text")
        .map(|e| {
            e.text
                .replace("&lt;", "<")
                .replace("&gt;", ">")
                .replace("&quot;", "\"")
                .replace("&#39;", "'")
                .replace("&amp;", "&")
        })
        .collect()
}

/// The polylines of stroke colour `color` (`#RRGGBB`), as their points (px).
fn polylines(doc: &[Element], color: &str) -> Vec<Vec<(f64, f64)>> {
    doc.iter()
        .filter(|e| {
            e.name == "polyline" && e.attrs.get("stroke").map(String::as_str) == Some(color)
        })
        .map(|e| {
            e.attrs["points"]
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').expect("x,y");
                    (x.parse().expect("x"), y.parse().expect("y"))
                })
                .collect()
        })
        .collect()
}

fn length(line: &[(f64, f64)]) -> f64 {
    line.windows(2)
        .map(|w| (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1))
        .sum()
}

// ------------------------------------------------------------------ run folders made here

const BLUE: &str = "#1F77B4";
const RED: &str = "#D62728";

/// A load path of 7 output steps, stable to step 3, unstable from step 4 on, with a
/// bifurcation at ε = 0.35 between steps 3 and 4; and the extra columns a later version
/// may add to critical.csv.
fn load_csv() -> String {
    let mut s = String::from(
        "# spira load path, case synthetic\n# units\nstep,eps,h,fx,fy,fz,energy,iterations,residual,stable,unstable_dirs,lowest_eig,parameter\n",
    );
    for k in 0..7 {
        let eps = 0.1 * k as f64;
        let stable = if k <= 3 { 1 } else { 0 };
        s.push_str(&format!(
            "{k},{eps:e},0.5,{:e},0,{:e},1,3,1e-12,{stable},{},,{eps:e}\n",
            0.1 * eps,
            -10.0 * eps,
            1 - stable
        ));
    }
    s
}

fn critical_csv() -> &'static str {
    "# spira critical points, case synthetic\n# units\nindex,kind,control,parameter,eps,fx,fy,fz,unstable_before,unstable_after,wavenumber,multiplicity\n0,bifurcation,displacement,0.35,0.35,0.035,0,-3.5,0,1,1,2\n"
}

/// Two rods of 11 nodes, rod 1 a mirror of rod 0; κ1 varies along s.
fn state_csv(eps: f64) -> String {
    let mut s = format!(
        "# spira state, case synthetic, eps = {eps:e}\n# units\nrod,s,s_over_l,x,y,z,q1,q2,q3,q4,k1,k2,omega\n"
    );
    for rod in 0..2 {
        let sign = if rod == 0 { 1.0 } else { -1.0 };
        for i in 0..11 {
            let t = i as f64 / 10.0;
            let phi = 6.0 * t;
            s.push_str(&format!(
                "{rod},{:e},{t:e},{:e},{:e},{:e},0,0,0,1,{:e},{:e},{:e}\n",
                t * 1.4,
                0.06 * phi.cos(),
                sign * 0.06 * phi.sin(),
                0.5 * t,
                -14.0 + 3.0 * t,
                0.1 * t,
                sign * 6.0
            ));
        }
    }
    s
}

fn joints_csv() -> &'static str {
    "# spira pin joints, case synthetic\n# units\nrod,s,s_over_l\n0,0.42,0.3\n0,0.98,0.7\n1,0.42,0.3\n1,0.98,0.7\n"
}

fn scratch(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spira-figures-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).expect("scratch folder");
    dir
}

/// Writes the synthetic run into `dir`, with `state-<k>.csv` for steps 0, 3 and 6.
fn write_run(dir: &Path) {
    std::fs::create_dir_all(dir).expect("folder");
    std::fs::write(dir.join("load.csv"), load_csv()).unwrap();
    std::fs::write(dir.join("critical.csv"), critical_csv()).unwrap();
    std::fs::write(dir.join("joints.csv"), joints_csv()).unwrap();
    std::fs::write(dir.join("state.csv"), state_csv(0.6)).unwrap();
    for (k, eps) in [(0, 0.0), (3, 0.3), (6, 0.6)] {
        std::fs::write(dir.join(format!("state-{k}.csv")), state_csv(eps)).unwrap();
    }
}

fn synthetic() -> RunTables {
    // a folder of its own for every call: the tests that read it run in parallel
    static CALLS: std::sync::atomic::AtomicUsize = std::sync::atomic::AtomicUsize::new(0);
    let call = CALLS.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let dir = scratch(&format!("tables-{call}"));
    write_run(&dir);
    RunTables::read(&dir).expect("the synthetic run reads")
}

// ------------------------------------------------------------------ the tables

#[test]
fn a_cells_run_is_named_by_the_helices_of_its_infinite_tube() {
    // a cell's states hold its own two rods; the legend gives the tube's n from the model line
    let dir = scratch("cell-legend");
    write_run(&dir);
    let load = load_csv().replacen(
        "# units\n",
        "# model: the cell of an infinitely long tube of 8 helices (one right and one left rod from a crossing to the next)\n# units\n",
        1,
    );
    std::fs::write(dir.join("load.csv"), load).unwrap();
    let cell = RunTables::read(&dir).expect("the cell's run reads");
    assert_eq!(cell.infinite_tube, Some(8));
    assert_eq!(cell.rods(), 2);
    let finite = synthetic();
    assert_eq!(finite.infinite_tube, None);
    let caption = ["command: spira plot cell finite".to_string()];
    let t = texts(&parse_xml(
        &load_figure(&[&cell, &finite], &caption).expect("drawn"),
    ));
    let legend = |run: &RunTables, rods: &str| {
        let line = format!("{} (synthetic), {rods}", run.label);
        t.iter().any(|s| s.trim() == line)
    };
    assert!(legend(&cell, "infinite tube, n = 8"), "{t:?}");
    assert!(legend(&finite, "n = 2"), "{t:?}");
}

#[test]
fn a_run_folder_reads_by_column_name_with_extra_columns() {
    let run = synthetic();
    assert_eq!(run.case, "synthetic");
    assert_eq!(run.path.len(), 7);
    assert_eq!(run.path[4].stable, Some(false));
    assert!((run.path[6].load[2] + 6.0).abs() < 1e-12);
    assert_eq!(
        run.critical.len(),
        1,
        "critical.csv with wavenumber,multiplicity"
    );
    assert_eq!(run.critical[0].kind, "bifurcation");
    assert_eq!(
        run.states.iter().map(|s| s.step).collect::<Vec<_>>(),
        [0, 3, 6]
    );
    assert!((run.states[1].eps - 0.3).abs() < 1e-12);
    assert_eq!(run.rods(), 2);
    assert_eq!(run.joints[&0], [0.3, 0.7]);
    assert_eq!(run.state_near(0.28).map(|s| s.step), Some(3));
}

#[test]
fn the_path_splits_at_the_critical_point_into_a_stable_and_an_unstable_stretch() {
    let run = synthetic();
    let s = stretches(&run.path, &run.critical);
    assert_eq!(s.len(), 2);
    assert!(!s[0].unstable && s[1].unstable);
    // steps 0..3, then the bifurcation, where the unstable stretch starts
    assert_eq!(s[0].vertices.len(), 5);
    assert!((s[0].vertices[4].0 - 0.35).abs() < 1e-12);
    assert_eq!(s[1].vertices[0], s[0].vertices[4]);
    assert_eq!(s[1].vertices.len(), 4);
}

// ------------------------------------------------------------------ the figures

#[test]
fn the_load_figure_has_solid_and_dashed_curves_per_run_marks_and_labelled_axes() {
    let a = synthetic();
    let mut b = synthetic();
    b.label = "second".to_string();
    for p in &mut b.path {
        p.stable = Some(true);
    }
    b.critical.clear();
    let caption = [
        "case synthetic".to_string(),
        "command: spira plot a b".to_string(),
    ];
    let svg = load_figure(&[&a, &b], &caption).expect("drawn");
    let doc = parse_xml(&svg);
    let t = texts(&doc);
    for label in [
        "compression ratio ε = (h0 − h)/h0 (–)",
        "Σ Fx / (n Pcrit) (–)",
        "Σ Fy / (n Pcrit) (–)",
        "Σ Fz / (n Pcrit) (–)",
        "command: spira plot a b",
        "bifurcation",
        "unstable (dashed)",
    ] {
        assert!(t.iter().any(|x| x == label), "no text `{label}` in {t:?}");
    }
    assert_eq!(t.iter().filter(|x| x.starts_with("Σ F")).count(), 3);
    // run a (blue): per panel one solid stretch of 5 vertices, dashes after; one legend line
    let blue = polylines(&doc, BLUE);
    let solid: Vec<_> = blue.iter().filter(|l| l.len() == 5).collect();
    assert_eq!(solid.len(), 3, "one stable stretch per panel");
    let dashes: Vec<_> = blue.iter().filter(|l| length(l) <= 8.5).collect();
    assert!(
        dashes.len() >= 3 * 5,
        "dashes of the unstable stretch: {}",
        dashes.len()
    );
    // run b (red): stable throughout, one polyline of 7 vertices per panel and no dashes
    let red = polylines(&doc, RED);
    assert_eq!(red.iter().filter(|l| l.len() == 7).count(), 3);
    assert!(red.iter().all(|l| l.len() == 7 || l.len() == 2), "{red:?}");
    assert_eq!(
        red.iter().filter(|l| l.len() == 2).count(),
        1,
        "one legend line: the panels share one legend"
    );
    // the bifurcation: a ring of run a's colour in each panel
    let rings = doc
        .iter()
        .filter(|e| e.name == "circle" && e.attrs.get("stroke").map(String::as_str) == Some(BLUE))
        .count();
    assert_eq!(rings, 3);
}

#[test]
fn the_curvature_figure_has_three_panels_with_units_joints_and_shading() {
    let run = synthetic();
    let state = &run.states[2];
    let shade = [Shade {
        from: 0.2,
        to: 0.8,
        label: "bulk".to_string(),
    }];
    let svg = curvature_figure(
        &run,
        state,
        Rods::One(1),
        &shade,
        &["case synthetic".into()],
    )
    .expect("drawn");
    let doc = parse_xml(&svg);
    let t = texts(&doc);
    for label in [
        "κ1 = d2′·d3 (1/m)",
        "κ2 = d3′·d1 (1/m)",
        "Ω = d1′·d2 (1/m)",
        "arc length s/L (–)",
        "joints",
        "bulk",
        "curvature profiles, rod 1, step 6 (ε = 0.6000)",
    ] {
        assert!(t.iter().any(|x| x == label), "no text `{label}` in {t:?}");
    }
    // one curve of 11 nodes per panel
    assert_eq!(
        polylines(&doc, BLUE)
            .iter()
            .filter(|l| l.len() == 11)
            .count(),
        3
    );
    // two joints per panel and one legend dot (the panels share the legend)
    let dots = doc
        .iter()
        .filter(|e| {
            e.name == "circle" && e.attrs.get("fill").map(String::as_str) == Some("#404040")
        })
        .count();
    assert_eq!(dots, 3 * 2 + 1);
    // all rods: one curve per rod per panel
    let svg = curvature_figure(&run, state, Rods::All, &[], &[]).expect("drawn");
    let doc = parse_xml(&svg);
    assert_eq!(
        polylines(&doc, BLUE)
            .iter()
            .filter(|l| l.len() == 11)
            .count(),
        3
    );
    assert_eq!(
        polylines(&doc, RED)
            .iter()
            .filter(|l| l.len() == 11)
            .count(),
        3
    );
    // a rod the state does not have
    let e = curvature_figure(&run, state, Rods::One(5), &[], &[]).expect_err("no rod 5");
    assert!(e.to_string().contains("no rod 5 (rods 0 to 1)"), "{e}");
}

#[test]
fn the_views_figure_has_the_three_projections_at_one_scale_and_a_colour_bar() {
    let run = synthetic();
    let svg = views_figure(&run.states[2], &["case synthetic".into()]).expect("drawn");
    let doc = parse_xml(&svg);
    let t = texts(&doc);
    for label in ["X-Y", "Z-Y", "Z-X", "κ1 (1/m)", "x (m)", "y (m)", "z (m)"] {
        assert!(t.iter().any(|x| x == label), "no text `{label}` in {t:?}");
    }
    // rods drawn in every view: each rod's 10 segments in runs of one colour, 3 views
    let rod_lines: Vec<&Element> = doc
        .iter()
        .filter(|e| {
            e.name == "polyline" && e.attrs.get("stroke-width").map(String::as_str) == Some("2")
        })
        .collect();
    let segments: usize = rod_lines
        .iter()
        .map(|e| e.attrs["points"].split_whitespace().count() - 1)
        .sum();
    assert_eq!(segments, 3 * 2 * 10);
    // κ1 rises along the rods: several colours, and the colour bar's K1_LEVELS boxes
    let colours: std::collections::BTreeSet<&str> = rod_lines
        .iter()
        .map(|e| e.attrs["stroke"].as_str())
        .collect();
    assert!(colours.len() >= 8, "{colours:?}");
    let boxes = doc
        .iter()
        .filter(|e| e.name == "rect" && e.attrs.get("stroke").map(String::as_str) == Some("none"))
        .filter(|e| colours.contains(e.attrs["fill"].as_str()) || e.attrs["fill"] != "#FFFFFF")
        .count();
    assert!(boxes >= K1_LEVELS, "colour bar boxes: {boxes}");
}

fn two_runs() -> Vec<RunTables> {
    let mut a = synthetic();
    a.label = "synthetic".to_string();
    let mut b = a.clone();
    b.label = "other".to_string();
    vec![a, b]
}

#[test]
fn run_figures_names_the_files_by_step_and_by_run_when_there_are_several() {
    let a = synthetic();
    let one = run_figures(
        std::slice::from_ref(&a),
        &Steps::Near(vec![0.0, 0.31]),
        Rods::One(0),
        Kinds::ALL,
        "spira plot x",
    )
    .expect("drawn");
    let names: Vec<&str> = one.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        [
            "load.svg",
            "curvature-step0.svg",
            "views-step0.svg",
            "curvature-step3.svg",
            "views-step3.svg"
        ]
    );
    let mut b = a.clone();
    b.label = "other".to_string();
    let two = run_figures(
        &[a, b],
        &Steps::Last,
        Rods::All,
        Kinds::ALL,
        "spira plot x y",
    )
    .expect("drawn");
    let names: Vec<&str> = two.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(names.len(), 5);
    assert!(names.contains(&"other-views-step6.svg"), "{names:?}");
    let only = Kinds {
        load: false,
        curvature: true,
        views: false,
    };
    let some = run_figures(&two_runs(), &Steps::Last, Rods::All, only, "x").expect("drawn");
    let names: Vec<&str> = some.iter().map(|(n, _)| n.as_str()).collect();
    assert_eq!(
        names,
        ["synthetic-curvature-step6.svg", "other-curvature-step6.svg"]
    );
    for (_, svg) in &two {
        parse_xml(svg);
        assert!(svg.contains("command: spira plot x y"));
    }
}

// ------------------------------------------------------------------ bad folders

#[test]
fn a_folder_without_load_csv_is_refused_naming_the_file() {
    let dir = scratch("no-load");
    std::fs::write(dir.join("state.csv"), state_csv(0.0)).unwrap();
    let e = RunTables::read(&dir).expect_err("no load.csv");
    assert!(matches!(e, TableError::Missing { .. }), "{e:?}");
    assert!(e.to_string().contains("load.csv: missing"), "{e}");
}

#[test]
fn a_malformed_cell_or_row_is_refused_naming_file_line_and_column() {
    let dir = scratch("bad-cell");
    write_run(&dir);
    // line 6 of the file: the header is line 3, step 2 is line 6
    let bad = load_csv().replacen("-2e0,", "-2e0x,", 1);
    assert_ne!(bad, load_csv());
    std::fs::write(dir.join("load.csv"), &bad).unwrap();
    let e = RunTables::read(&dir).expect_err("a bad cell");
    let msg = e.to_string();
    assert!(
        msg.ends_with("load.csv:6: column `fz`: expected a finite number, found `-2e0x`"),
        "{msg}"
    );
    // a row with a field too few
    let short: String = load_csv()
        .lines()
        .enumerate()
        .map(|(i, l)| {
            if i == 4 {
                l.rsplit_once(',').unwrap().0.to_string()
            } else {
                l.to_string()
            }
        })
        .flat_map(|l| [l, "\n".to_string()])
        .collect();
    std::fs::write(dir.join("load.csv"), short).unwrap();
    let msg = RunTables::read(&dir).expect_err("a short row").to_string();
    assert!(
        msg.contains("load.csv:5: 12 fields where the header has 13"),
        "{msg}"
    );
    // a missing column in a state
    std::fs::write(dir.join("load.csv"), load_csv()).unwrap();
    std::fs::write(
        dir.join("state-3.csv"),
        state_csv(0.3).replace(",omega", ",twist"),
    )
    .unwrap();
    let msg = RunTables::read(&dir).expect_err("no omega").to_string();
    assert!(msg.contains("state-3.csv: no column `omega`"), "{msg}");
}

fn spira(args: &[&str]) -> std::process::Output {
    Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(args)
        .output()
        .expect("spira runs")
}

#[test]
fn spira_plot_on_a_bad_folder_fails_and_writes_nothing() {
    let dir = scratch("cli-bad");
    let good = dir.join("good");
    write_run(&good);
    let bad = dir.join("bad");
    write_run(&bad);
    std::fs::write(
        bad.join("critical.csv"),
        critical_csv().replace("0.35,0.35", "0.35,abc"),
    )
    .unwrap();
    let out = dir.join("figs");
    let o = spira(&[
        "plot",
        good.to_str().unwrap(),
        bad.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(!o.status.success());
    let err = String::from_utf8_lossy(&o.stderr);
    assert!(
        err.contains("critical.csv:4: column `eps`: expected a finite number, found `abc`"),
        "{err}"
    );
    assert!(
        common::listing(&out).is_empty(),
        "{:?}",
        common::listing(&out)
    );
    let o = spira(&["plot", dir.join("missing").to_str().unwrap()]);
    assert!(!o.status.success());
    // several runs need --out; a bad --eps and --rod are refused
    let o = spira(&["plot", good.to_str().unwrap(), good.to_str().unwrap()]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--out DIR is needed"));
    let o = spira(&["plot", good.to_str().unwrap(), "--eps", "0.1,x"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--eps: expected compression ratios"));
    let o = spira(&["plot", good.to_str().unwrap(), "--rod", "-1"]);
    assert!(String::from_utf8_lossy(&o.stderr).contains("--rod: expected a rod number"));
    let o = spira(&["plot", good.to_str().unwrap(), "--only", "load,pdf"]);
    assert!(String::from_utf8_lossy(&o.stderr)
        .contains("--only: expected `load`, `curvature` or `views`, found `pdf`"));
    assert!(!common::listing(&good).iter().any(|n| n.ends_with(".svg")));
}

#[test]
fn spira_run_figures_writes_states_joints_and_figures_and_spira_plot_redraws_them() {
    let dir = scratch("cli-run");
    let case = dir.join("pair.toml");
    std::fs::write(
        &case,
        "name = \"pair\"\n[geometry]\nhelices = 2\nturns = 1.5\n[discretisation]\nelements = 12\n[loading]\ntarget = 0.2\nsteps = 2\n",
    )
    .unwrap();
    let out = dir.join("run");
    let o = spira(&[
        "run",
        case.to_str().unwrap(),
        "--figures",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    let names = common::listing(&out);
    for f in [
        "load.csv",
        "state.csv",
        "state-0.csv",
        "state-1.csv",
        "state-2.csv",
        "joints.csv",
        "load.svg",
        "curvature-step2.svg",
        "views-step2.svg",
    ] {
        assert!(names.iter().any(|n| n == f), "no {f} in {names:?}");
    }
    let load = std::fs::read_to_string(out.join("load.svg")).unwrap();
    parse_xml(&load);
    assert!(
        load.contains("command: spira run"),
        "the caption names the command"
    );
    // the joints of a pair: every crossing ties rod 0 and rod 1, so both have rows
    let joints = std::fs::read_to_string(out.join("joints.csv")).unwrap();
    let rows: Vec<&str> = joints
        .lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .collect();
    assert!(!rows.is_empty() && rows.len() % 2 == 0, "{joints}");
    // the curvature figure marks them
    let curvature = std::fs::read_to_string(out.join("curvature-step2.svg")).unwrap();
    assert!(texts(&parse_xml(&curvature)).iter().any(|t| t == "joints"));
    // redrawn by spira plot, at other steps, into another folder
    let figs = dir.join("figs");
    let o = spira(&[
        "plot",
        out.to_str().unwrap(),
        "--eps",
        "all",
        "--rod",
        "all",
        "--out",
        figs.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", String::from_utf8_lossy(&o.stderr));
    assert_eq!(
        common::listing(&figs),
        [
            "curvature-step0.svg",
            "curvature-step1.svg",
            "curvature-step2.svg",
            "load.svg",
            "views-step0.svg",
            "views-step1.svg",
            "views-step2.svg"
        ]
    );
    // a run without --figures into the same folder takes the stale figures away
    let o = spira(&[
        "run",
        case.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success());
    let names = common::listing(&out);
    assert!(
        !names
            .iter()
            .any(|n| n.ends_with(".svg") || n.starts_with("state-")),
        "{names:?}"
    );
}

#[test]
fn a_generic_line_chart_draws_solid_and_dashed_curves_and_shaded_intervals() {
    use spira::output::chart::{lines_svg, Curve, LinePanel};
    // the shape of a finite-against-closed-form comparison (e.g. the bulk's force)
    let finite: Vec<(f64, f64)> = (0..=10)
        .map(|k| (0.05 * k as f64, -10.0 * 0.05 * k as f64))
        .collect();
    let closed: Vec<(f64, f64)> = finite.iter().map(|&(e, f)| (e, 1.1 * f)).collect();
    let panel = LinePanel {
        title: "axial force".to_string(),
        x_label: "compression ratio ε (–)".to_string(),
        y_label: "Fz (N)".to_string(),
        curves: vec![
            Curve {
                label: "finite assembly".to_string(),
                points: finite,
                dashed: false,
                marked: false,
                color: 0,
            },
            Curve {
                label: "closed form".to_string(),
                points: closed,
                dashed: true,
                marked: false,
                color: 1,
            },
        ],
        shaded: vec![(0.1, 0.2, "bulk".to_string())],
    };
    let svg = lines_svg("comparison", &["command: test".to_string()], &[panel]).expect("drawn");
    let doc = parse_xml(&svg);
    let t = texts(&doc);
    for label in [
        "Fz (N)",
        "compression ratio ε (–)",
        "finite assembly",
        "closed form",
        "bulk",
    ] {
        assert!(t.iter().any(|x| x == label), "no `{label}` in {t:?}");
    }
    assert_eq!(
        polylines(&doc, BLUE)
            .iter()
            .filter(|l| l.len() == 11)
            .count(),
        1
    );
    assert!(
        polylines(&doc, RED)
            .iter()
            .filter(|l| length(l) <= 8.5)
            .count()
            > 10,
        "dashes"
    );
}

#[test]
fn the_files_of_a_run_include_its_states_joints_and_figures_but_not_a_study() {
    use spira::output::run_folder::{is_figure_file, is_run_file};
    for name in [
        "state-0.csv",
        "state-12.csv",
        "joints.csv",
        "load.svg",
        "curvature-step3.svg",
        "views-step10.svg",
    ] {
        assert!(is_run_file(name), "{name}");
    }
    for name in [
        "state-.csv",
        "state-x.csv",
        "precision.svg",
        "notes.svg",
        "views-step.svg",
    ] {
        assert!(!is_run_file(name), "{name}");
    }
    assert!(is_figure_file("curvature-step3.svg") && !is_figure_file("state-3.csv"));
}
