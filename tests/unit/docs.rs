//! The generated parts of the documentation against what they document: the case-file
//! reference of `docs/case-files.md` against the case reader, and the column glossary of
//! `docs/output-files.md` against the `#` lines and headers the CSV writers produce.
//!
//! Each generated part sits between two marker lines of its page. After a change to the
//! reader's keys or to the CSV columns, regenerate both with
//! `SPIRA_BLESS=1 cargo test --release --test unit docs`.

use spira::case::{keys_markdown, Case, CaseError, DefaultDoc, RangeDoc, KEYS};
use spira::output::{run_files, RunFiles};
use spira::run::run_path;
use std::collections::BTreeSet;
use std::path::PathBuf;

const REGENERATE: &str = "SPIRA_BLESS=1 cargo test --release --test unit docs";

/// Checks (or, with `SPIRA_BLESS=1`, rewrites) the part of `docs/<page>` between the
/// markers of `part` against `rendering`.
fn check_generated(page: &str, part: &str, rendering: &str) {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("docs")
        .join(page);
    let text = std::fs::read_to_string(&path)
        .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
    let begin = format!("<!-- generated: {part}; regenerate with `{REGENERATE}` -->\n");
    let end = format!("<!-- end of generated: {part} -->");
    let start = text
        .find(&begin)
        .unwrap_or_else(|| panic!("docs/{page} lacks the line `{}`", begin.trim_end()))
        + begin.len();
    let stop = text[start..]
        .find(&end)
        .unwrap_or_else(|| panic!("docs/{page} lacks the line `{end}`"))
        + start;
    if std::env::var_os("SPIRA_BLESS").is_some() {
        let updated = format!("{}{rendering}{}", &text[..start], &text[stop..]);
        std::fs::write(&path, updated).expect("write the regenerated page");
        return;
    }
    let committed = &text[start..stop];
    if committed != rendering {
        let first = committed
            .lines()
            .zip(rendering.lines())
            .position(|(a, b)| a != b)
            .unwrap_or(committed.lines().count().min(rendering.lines().count()));
        panic!(
            "docs/{page}: the generated part `{part}` is out of date (first difference at its line {}); regenerate it with `{REGENERATE}`",
            first + 1
        );
    }
}

#[test]
fn docs_case_file_reference_is_the_rendering_of_the_key_table() {
    check_generated("case-files.md", "case keys", &keys_markdown());
}

/// The keys the reader names when it refuses an unknown one in `table` (the top level
/// when empty): serde's "expected one of `a`, `b`, …".
fn reader_keys(table: &str) -> BTreeSet<String> {
    let text = if table.is_empty() {
        "zz_not_a_key = 1\n".to_string()
    } else {
        format!("[{table}]\nzz_not_a_key = 1\n")
    };
    let err = Case::parse(&text, "probe.toml", "probe").expect_err("an unknown key is refused");
    let message = err.message();
    let listed = message
        .split_once("expected one of ")
        .unwrap_or_else(|| panic!("no list of keys in `{message}`"))
        .1;
    listed
        .split(", ")
        .map(|k| k.trim_matches('`').to_string())
        .collect()
}

#[test]
fn docs_key_table_holds_exactly_the_keys_the_reader_accepts() {
    let documented: BTreeSet<String> = KEYS.iter().map(|k| k.key.to_string()).collect();
    let mut accepted = BTreeSet::new();
    for top in reader_keys("") {
        let inner = reader_keys_or_value(&top);
        if inner.is_empty() {
            accepted.insert(top);
        } else {
            accepted.extend(inner.into_iter().map(|k| format!("{top}.{k}")));
        }
    }
    let missing: Vec<_> = accepted.difference(&documented).collect();
    let extra: Vec<_> = documented.difference(&accepted).collect();
    assert!(
        missing.is_empty() && extra.is_empty(),
        "src/case/keys.rs: keys the reader accepts without a row {missing:?}, rows the reader does not accept {extra:?}; add or remove the rows, then run `{REGENERATE}`"
    );
}

/// The keys of table `top`, or none when `top` is a value (`name`).
fn reader_keys_or_value(top: &str) -> BTreeSet<String> {
    match Case::parse(
        &format!("[{top}]\nzz_not_a_key = 1\n"),
        "probe.toml",
        "probe",
    ) {
        Err(e) if e.message().contains("expected one of") => reader_keys(top),
        _ => BTreeSet::new(),
    }
}

/// `value` given for dotted `key` as a case text.
fn case_with(key: &str, value: &str) -> String {
    match key.split_once('.') {
        Some((table, k)) => format!("[{table}]\n{k} = {value}\n"),
        None => format!("{key} = {value}\n"),
    }
}

#[test]
fn docs_defaults_given_as_values_read_as_the_defaults() {
    let default = Case::parse("", "empty.toml", "probe").expect("the empty case");
    for k in KEYS {
        if let DefaultDoc::Value(v) = k.default {
            let text = case_with(k.key, v);
            let case = Case::parse(&text, "probe.toml", "probe")
                .unwrap_or_else(|e| panic!("`{}` = {v}, its documented default: {e}", k.key));
            assert_eq!(
                case, default,
                "`{}` = {v} is documented as its default but reads another case",
                k.key
            );
        }
    }
}

/// Whether the reader refuses `value` for `key`, naming the key and the range `bounds`. A ribbon's lengths are
/// probed on a ribbon (they are refused otherwise whatever their value).
fn refused(key: &str, value: &str, bounds: &str) -> bool {
    let ribbon = "[rod]\nstress_free = \"straight\"\nenergy = \"sadowsky\"\n";
    let text = match key {
        "rod.width" => format!("{ribbon}thickness = 1e-6\nwidth = {value}\n"),
        "rod.thickness" => format!("{ribbon}width = 1e6\nthickness = {value}\n"),
        _ => case_with(key, value),
    };
    match Case::parse(&text, "probe.toml", "probe") {
        Err(e) => e.key() == Some(key) && e.message().contains(bounds),
        Ok(_) => false,
    }
}

#[test]
fn docs_ranges_are_refused_just_beyond_their_ends() {
    let mut checked = 0;
    for k in KEYS {
        let (below, above) = match k.range {
            RangeDoc::Number(lo, hi) => (
                format!("{:e}", lo * (1.0 - 1e-9)),
                format!("{:e}", hi * (1.0 + 1e-9)),
            ),
            RangeDoc::Whole(lo, hi) => ((lo - 1).to_string(), (hi + 1).to_string()),
            _ => continue,
        };
        let key = k.key;
        let bounds = k.range.text();
        for value in [below, above] {
            assert!(
                refused(key, &value, &bounds),
                "`{key}` = {value} is not refused as outside {bounds}"
            );
        }
        checked += 1;
    }
    assert!(checked >= 15, "only {checked} ranges checked");
}

#[test]
fn docs_names_are_the_names_the_reader_offers() {
    for k in KEYS {
        if let RangeDoc::Names(names) = k.range {
            let err = Case::parse(&case_with(k.key, "1"), "probe.toml", "probe")
                .expect_err("a number for a name is refused");
            let offered = offered_names(&err);
            let documented: BTreeSet<String> = names.iter().map(|n| n.to_string()).collect();
            assert_eq!(offered, documented, "the names of `{}`", k.key);
        }
    }
}

/// The quoted names of "expected one of "a", "b", found …".
fn offered_names(err: &CaseError) -> BTreeSet<String> {
    let message = err.message();
    let list = message
        .split_once("one of ")
        .and_then(|(_, rest)| rest.split_once(", found"))
        .unwrap_or_else(|| panic!("no list of names in `{message}`"))
        .0;
    list.split(", ")
        .map(|n| n.trim_matches('"').to_string())
        .collect()
}

/// One helix whose tip slides, compressed past its sideways bifurcation on a coarse mesh:
/// a run with every kind of CSV file.
const GLOSSARY_CASE: &str = "\
name = \"glossary\"
[boundary]
tip = { translation = \"slide\", rotation = \"clamped\" }
[loading]
target = 0.2
steps = 2
[discretisation]
elements = 12
";

/// Euler's clamped column on a coarse mesh, flawed along its first mode: a run with
/// `imperfection.csv`.
const GLOSSARY_FLAW: &str = "\
[geometry]
radius = 0.0
pitch = 1.0
length = 1.0
[loading]
control = \"force\"
target = 1.1
steps = 2
[discretisation]
elements = 8
[imperfection]
mode = 0
amplitude = 1e-3
";

#[test]
fn docs_output_glossary_is_the_rendering_of_the_csv_headers() {
    let case = Case::parse(GLOSSARY_CASE, "glossary.toml", "glossary").expect("the case");
    let targets = case.output_parameters(case.loading.target, case.loading.steps);
    let outcome = run_path(&case, &targets, |_, _| {}).expect("the path");
    assert!(
        !outcome.critical.is_empty(),
        "the path has a critical point"
    );
    let states = [(0, outcome.snapshot.clone())];
    let run = RunFiles {
        states: &states,
        ..RunFiles::of(&case.name, None, &outcome)
    };
    let files = run_files(&run).expect("the files");
    let mut rendering = String::new();
    for (name, text) in &files {
        let shown = match name.as_str() {
            "mode-0.csv" => "mode-<k>.csv",
            "state-0.csv" => "state-<k>.csv",
            n if n.ends_with(".csv") && !n.starts_with("mode-") => n,
            _ => continue,
        };
        rendering.push_str(&glossary_of(shown, text));
    }
    // an imperfect case's own file: a coarse Euler column flawed along its first mode
    let flawed = Case::parse(GLOSSARY_FLAW, "flawed.toml", "flawed").expect("the case");
    let targets = flawed.output_parameters(flawed.loading.target, flawed.loading.steps);
    let outcome = run_path(&flawed, &targets, |_, _| {}).expect("the path");
    let files = run_files(&RunFiles::of(&flawed.name, None, &outcome)).expect("the files");
    let (_, text) = files
        .iter()
        .find(|(name, _)| name == "imperfection.csv")
        .expect("imperfection.csv");
    rendering.push_str(&glossary_of("imperfection.csv", text));
    check_generated("output-files.md", "csv columns", &rendering);
}

/// One file's header and glossary as Markdown: the header line, then its glossary (the
/// last `#` line) as a table of `columns: meaning` entries.
fn glossary_of(name: &str, text: &str) -> String {
    let comments: Vec<&str> = text
        .lines()
        .take_while(|l| l.starts_with('#'))
        .map(|l| l.trim_start_matches('#').trim())
        .collect();
    let header = text
        .lines()
        .find(|l| !l.starts_with('#'))
        .expect("a header line");
    let glossary = comments.last().expect("a glossary line");
    let mut prose = Vec::new();
    let mut rows = Vec::new();
    for entry in split_top(glossary, "; ") {
        match split_top(&entry, ": ").split_first() {
            Some((columns, rest)) if !rest.is_empty() => rows.push(format!(
                "| `{}` | {} |",
                cell(columns),
                cell(&rest.join(": "))
            )),
            _ => prose.push(entry),
        }
    }
    let mut out = format!("### `{name}`\n\nColumns: `{header}`\n\n");
    if !prose.is_empty() {
        out.push_str(&format!("{}.\n\n", prose.join("; ")));
    }
    if !rows.is_empty() {
        out.push_str("| columns | meaning |\n|---|---|\n");
        for r in rows {
            out.push_str(&r);
            out.push('\n');
        }
        out.push('\n');
    }
    out
}

/// Text for a table cell: a `|` would end the cell.
fn cell(text: &str) -> String {
    text.replace('|', "\\|")
}

/// `text` split at `sep` outside parentheses.
fn split_top(text: &str, sep: &str) -> Vec<String> {
    let mut parts = Vec::new();
    let mut depth = 0i32;
    let mut start = 0;
    let mut i = 0;
    while i < text.len() {
        let c = text[i..].chars().next().expect("a char");
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            _ => {}
        }
        if depth == 0 && text[i..].starts_with(sep) {
            parts.push(text[start..i].to_string());
            i += sep.len();
            start = i;
            continue;
        }
        i += c.len_utf8();
    }
    parts.push(text[start..].to_string());
    parts
}
