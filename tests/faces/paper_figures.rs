//! Figures a paper can take, drawn by the real binary from shipped cases: no legend covers
//! a plotted point (judged from the drawing's own coordinates), no tick reads `-0`, no text
//! holds an absolute path, and a load-controlled path is plotted against `P/Pcrit`.

use crate::figures::{parse_xml, texts, Element};
use std::path::{Path, PathBuf};
use std::process::Command;

/// `spira` with `args` inside `dir`.
fn spira(dir: &Path, args: &[&str]) {
    let out = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(args)
        .current_dir(dir)
        .output()
        .expect("run the spira binary");
    assert!(
        out.status.success(),
        "spira {args:?}: {}",
        String::from_utf8_lossy(&out.stderr)
    );
}

fn case(name: &str) -> String {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("cases")
        .join(name)
        .display()
        .to_string()
}

/// The figures `spira run --figures` draws of thesis-n2 (5 steps) and euler-clamped, and
/// `spira plot --rod all` of the first, every path given absolute: (file, parsed SVG, text).
fn figures(dir: &Path) -> Vec<(String, Vec<Element>, String)> {
    let n2 = dir.join("n2").display().to_string();
    let euler = dir.join("euler").display().to_string();
    let all = dir.join("all").display().to_string();
    let n2_case = case("thesis-n2.toml");
    let euler_case = case("euler-clamped.toml");
    spira(
        dir,
        &["run", &n2_case, "--steps", "5", "--figures", "--out", &n2],
    );
    spira(dir, &["run", &euler_case, "--figures", "--out", &euler]);
    spira(
        dir,
        &[
            "plot",
            &n2,
            "--rod",
            "all",
            "--only",
            "curvature",
            "--out",
            &all,
        ],
    );
    let mut out = Vec::new();
    for folder in [&n2, &euler, &all] {
        let mut names: Vec<PathBuf> = std::fs::read_dir(folder)
            .expect("figures folder")
            .map(|e| e.expect("entry").path())
            .filter(|p| p.extension().is_some_and(|x| x == "svg"))
            .collect();
        names.sort();
        for p in names {
            let text = std::fs::read_to_string(&p).expect("svg");
            out.push((p.display().to_string(), parse_xml(&text), text));
        }
    }
    assert!(
        out.len() >= 7,
        "{:?}",
        out.iter().map(|f| &f.0).collect::<Vec<_>>()
    );
    out
}

fn number(e: &Element, name: &str) -> f64 {
    e.attrs[name].parse().expect("a number attribute")
}

/// The points of an element (px): a polyline's vertices and every pixel between them, a
/// circle's centre and four points of its rim, a text's anchor.
fn points(e: &Element) -> Vec<(f64, f64)> {
    match e.name.as_str() {
        "polyline" => {
            let vertices: Vec<(f64, f64)> = e.attrs["points"]
                .split_whitespace()
                .map(|p| {
                    let (x, y) = p.split_once(',').expect("x,y");
                    (x.parse().expect("x"), y.parse().expect("y"))
                })
                .collect();
            let mut out = vertices.clone();
            for w in vertices.windows(2) {
                let n = (w[1].0 - w[0].0).hypot(w[1].1 - w[0].1).ceil() as usize;
                for k in 1..n {
                    let t = k as f64 / n as f64;
                    out.push((
                        w[0].0 + t * (w[1].0 - w[0].0),
                        w[0].1 + t * (w[1].1 - w[0].1),
                    ));
                }
            }
            out
        }
        "circle" => {
            let (x, y, r) = (number(e, "cx"), number(e, "cy"), number(e, "r"));
            vec![(x, y), (x - r, y), (x + r, y), (x, y - r), (x, y + r)]
        }
        "text" => vec![(number(e, "x"), number(e, "y"))],
        "rect" => {
            let (x, y) = (number(e, "x"), number(e, "y"));
            let (w, h) = (number(e, "width"), number(e, "height"));
            vec![(x, y), (x + w, y + h)]
        }
        "line" => vec![
            (number(e, "x1"), number(e, "y1")),
            (number(e, "x2"), number(e, "y2")),
        ],
        _ => Vec::new(),
    }
}

/// A box (x0, y0, x1, y1) in px.
type Frame = (f64, f64, f64, f64);

fn inside(f: Frame, (x, y): (f64, f64)) -> bool {
    x >= f.0 && x <= f.2 && y >= f.1 && y <= f.3
}

/// The legend frames of a document (grey `#999999` outlines) and its plotted elements:
/// curves (polylines of stroke width 2) and marks (circles), but not the legend's own
/// samples, which follow their frame and lie inside it.
fn legends_and_data(doc: &[Element]) -> (Vec<Frame>, Vec<&Element>) {
    let mut frames = Vec::new();
    let mut data = Vec::new();
    let mut open: Option<Frame> = None;
    for e in doc {
        let frame = e.name == "rect"
            && e.attrs.get("stroke").map(String::as_str) == Some("#999999")
            && e.attrs.get("fill").map(String::as_str) == Some("none");
        if frame {
            let (x, y) = (number(e, "x"), number(e, "y"));
            let f = (x, y, x + number(e, "width"), y + number(e, "height"));
            frames.push(f);
            open = Some(f);
            continue;
        }
        let pts = points(e);
        match open {
            Some(f) if !pts.is_empty() && pts.iter().all(|&p| inside(f, p)) => continue,
            _ if !pts.is_empty() => open = None,
            _ => {}
        }
        let curve =
            e.name == "polyline" && e.attrs.get("stroke-width").map(String::as_str) == Some("2");
        if curve || e.name == "circle" {
            data.push(e);
        }
    }
    (frames, data)
}

#[test]
fn no_legend_covers_a_plotted_point_no_tick_reads_minus_zero_and_no_path_is_absolute() {
    let dir = tempfile::tempdir().expect("scratch folder");
    let root = dir.path().display().to_string();
    let figures = figures(dir.path());
    let mut legends = 0;
    for (file, doc, svg) in &figures {
        let (frames, data) = legends_and_data(doc);
        legends += frames.len();
        assert!(!data.is_empty(), "{file}: no plotted curve or mark found");
        for f in &frames {
            for e in &data {
                let hit = points(e).into_iter().find(|&p| inside(*f, p));
                assert!(
                    hit.is_none(),
                    "{file}: legend {f:?} covers {hit:?} of {e:?}"
                );
            }
        }
        for t in texts(doc) {
            let minus_zero = t
                .strip_prefix('-')
                .is_some_and(|r| r.parse::<f64>() == Ok(0.0));
            assert!(!minus_zero, "{file}: a tick reads {t}");
            assert!(
                !t.contains(&root),
                "{file}: a text holds the path {root}: {t}"
            );
            assert!(
                !t.split_whitespace()
                    .any(|w| w.len() > 1 && w.starts_with('/')),
                "{file}: a text holds an absolute path: {t}"
            );
        }
        assert!(!svg.contains(env!("CARGO_MANIFEST_DIR")), "{file}");
        if file.ends_with("n2/load.svg") {
            assert_eq!(frames.len(), 1, "{file}: one legend for the three panels");
        }
    }
    assert!(legends >= 3, "legends found: {legends}");
}

#[test]
fn a_load_controlled_path_is_plotted_against_p_over_pcrit() {
    let dir = tempfile::tempdir().expect("scratch folder");
    let euler = dir.path().join("euler").display().to_string();
    spira(
        dir.path(),
        &[
            "run",
            &case("euler-clamped.toml"),
            "--figures",
            "--out",
            &euler,
        ],
    );
    let svg = std::fs::read_to_string(dir.path().join("euler/load.svg")).expect("load.svg");
    let texts = texts(&parse_xml(&svg));
    let has = |t: &str| texts.iter().any(|x| x == t);
    assert!(
        has("dead axial load on every tip P / Pcrit (–)"),
        "{texts:?}"
    );
    assert!(has("end-shortening ε = (h0 − h)/h0 (–)"), "{texts:?}");
    assert!(!texts.iter().any(|t| t.starts_with("Σ Fx")), "{texts:?}");
    // the load axis reaches the target 2.5, with the bifurcations at 1 and about 2.05
    assert!(has("2.5") && has("1"), "{texts:?}");
    assert!(has("bifurcation"), "{texts:?}");
}
