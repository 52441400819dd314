//! Sweep files: a base case, axes over dotted case keys, combined as a product or zipped;
//! every generated case patched into the base document and read by the case reader before
//! anything runs.

use super::error::{InvalidCase, SweepError};
use crate::case::{set_key, Case, CaseError};
use std::path::Path;
use toml::{Table, Value};

/// How the axes combine.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Combine {
    /// Every combination: the first axis varies slowest.
    Product,
    /// The k-th value of every axis together (all axes of one length).
    Zip,
}

/// One axis: a dotted case key and its values, with the line of the sweep file it is on.
#[derive(Clone, Debug, PartialEq)]
pub struct Axis {
    pub key: String,
    pub values: Vec<Value>,
    pub line: usize,
}

/// One generated case: its place in the sorted case list, its folder name, its axis values
/// (one per axis), the patched TOML text and the case read from it.
#[derive(Clone, Debug)]
pub struct SweepCase {
    /// 0-based position in the case list (the order of generation).
    pub index: usize,
    /// Folder and row name: the index, then the axis values.
    pub id: String,
    pub values: Vec<Value>,
    pub text: String,
    pub case: Case,
}

/// A validated sweep.
#[derive(Clone, Debug)]
pub struct Sweep {
    /// The sweep file, as named in errors.
    pub file: String,
    pub name: String,
    pub combine: Combine,
    pub axes: Vec<Axis>,
    /// The axis continued as a critical curve (`continue = "key"`), by its place in
    /// [`Sweep::axes`]: for every combination of the other axes, the first critical point
    /// is continued along it instead of a path being run at each of its values.
    pub continued: Option<usize>,
    pub cases: Vec<SweepCase>,
}

const TOP_KEYS: [&str; 6] = ["name", "base", "combine", "continue", "case", "axes"];

/// The most cases a sweep may generate without `--force` (each is read and checked before
/// anything runs, and listed by `--check`).
pub const MAX_CASES: usize = 10_000;

impl Sweep {
    /// Reads a sweep file of at most [`MAX_CASES`] cases; a `base` case is looked for
    /// beside it.
    pub fn from_file(path: &Path) -> Result<Sweep, SweepError> {
        Sweep::from_file_with(path, MAX_CASES)
    }

    /// Reads a sweep file of at most `max_cases` cases (counted from its axes before any is
    /// generated); a `base` case is looked for beside it.
    pub fn from_file_with(path: &Path, max_cases: usize) -> Result<Sweep, SweepError> {
        let file = path.display().to_string();
        let text = std::fs::read_to_string(path).map_err(|reason| SweepError::Io {
            file: file.clone(),
            reason,
        })?;
        let dir = path.parent().unwrap_or(Path::new(""));
        let stem = path
            .file_stem()
            .map(|s| s.to_string_lossy().into_owned())
            .unwrap_or_else(|| "sweep".into());
        Sweep::parse_with(&text, &file, &stem, dir, max_cases)
    }

    /// Parses sweep text of at most [`MAX_CASES`] cases; `file` names it in errors, `stem`
    /// is the sweep's name when it gives none, `dir` is where a `base` file is looked for.
    /// Every generated case is validated.
    pub fn parse(text: &str, file: &str, stem: &str, dir: &Path) -> Result<Sweep, SweepError> {
        Sweep::parse_with(text, file, stem, dir, MAX_CASES)
    }

    /// [`Sweep::parse`] of at most `max_cases` cases.
    pub fn parse_with(
        text: &str,
        file: &str,
        stem: &str,
        dir: &Path,
        max_cases: usize,
    ) -> Result<Sweep, SweepError> {
        let doc: Table = text
            .parse()
            .map_err(|e: toml::de::Error| SweepError::Syntax {
                file: file.into(),
                line: line_of(text, e.span().map_or(0, |s| s.start)),
                message: e.message().trim().to_string(),
            })?;
        let src = Source { text, file };
        if let Some(k) = doc.keys().find(|k| !TOP_KEYS.contains(&k.as_str())) {
            return Err(src.key_error(
                k,
                format!(
                    "unknown key `{k}`; a sweep file has `name`, `base`, `combine`, `continue`, `[case]` and `[axes]`"
                ),
            ));
        }
        // the name is the default output folder's: safe for a file system, under `out/`
        let name = match doc.get("name") {
            None => folder_name(stem),
            Some(Value::String(s)) => folder_name(s),
            Some(v) => return Err(src.key_error("name", format!("expected a string, found {v}"))),
        };
        let combine = match doc.get("combine") {
            None => Combine::Product,
            Some(Value::String(s)) if s == "product" => Combine::Product,
            Some(Value::String(s)) if s == "zip" => Combine::Zip,
            Some(v) => {
                return Err(src.key_error(
                    "combine",
                    format!("expected \"product\" or \"zip\", found {v}"),
                ))
            }
        };
        let base = base_case(&doc, src, dir)?;
        let axes = axes_of(&doc, src)?;
        let continued = continued_axis(&doc, src, &axes, combine)?;
        count_cases(&axes, combine, src, max_cases)?;
        let combos = combinations(&axes, combine, file)?;
        let cases = generated_cases(&base, &axes, combos, file)?;
        Ok(Sweep {
            file: file.into(),
            name,
            combine,
            axes,
            continued,
            cases,
        })
    }
}

/// The sweep file being read: its text, and its name in errors.
#[derive(Clone, Copy)]
struct Source<'a> {
    text: &'a str,
    file: &'a str,
}

impl Source<'_> {
    /// An error about the top-level `key`, at its line.
    fn key_error(&self, key: &str, message: String) -> SweepError {
        SweepError::Key {
            file: self.file.into(),
            line: line_of_key(self.text, None, key),
            key: key.into(),
            message,
        }
    }
}

/// The base document every case is patched into, and its line in the sweep file (for
/// errors of a generated case that is not valid TOML).
struct BaseCase {
    doc: Table,
    line: usize,
}

/// The base case: the case file `base` names (read and checked as a case), then the inline
/// `[case]` table over it; at least one of the two.
fn base_case(doc: &Table, src: Source, dir: &Path) -> Result<BaseCase, SweepError> {
    let mut base = BaseCase {
        doc: Table::new(),
        line: 1,
    };
    if let Some(v) = doc.get("base") {
        let Value::String(rel) = v else {
            return Err(src.key_error(
                "base",
                format!("expected the path of a case file, found {v}"),
            ));
        };
        base.line = line_of_key(src.text, None, "base");
        base.doc = base_file(&dir.join(rel), src, base.line)?;
    }
    match doc.get("case") {
        None => {}
        Some(Value::Table(t)) => {
            base.line = line_of_section(src.text, "case").unwrap_or(base.line);
            merge(&mut base.doc, t);
        }
        Some(v) => return Err(src.key_error("case", format!("expected a table, found {v}"))),
    }
    if !doc.contains_key("base") && !doc.contains_key("case") {
        return Err(SweepError::Syntax {
            file: src.file.into(),
            line: 1,
            message: "a sweep needs a base case: `base = \"case.toml\"` or a `[case]` table".into(),
        });
    }
    Ok(base)
}

/// The case file at `path`, read as a case (its errors said as the base's, at `line` of the
/// sweep file) and as a TOML document.
fn base_file(path: &Path, src: Source, line: usize) -> Result<Table, SweepError> {
    let file = src.file;
    let base_file = path.display().to_string();
    let base_text = std::fs::read_to_string(path).map_err(|reason| SweepError::Key {
        file: file.into(),
        line,
        key: "base".into(),
        message: format!("cannot read case file {base_file}: {reason}"),
    })?;
    let as_base = |reason: CaseError| SweepError::Base {
        file: file.into(),
        line,
        reason,
    };
    Case::parse(&base_text, &base_file, "base").map_err(as_base)?;
    base_text
        .parse()
        .map_err(|e: toml::de::Error| SweepError::Key {
            file: file.into(),
            line,
            key: "base".into(),
            message: format!("{base_file}: {}", e.message().trim()),
        })
}

/// The axis `continue` names, if any: an axis of numbers, at least two, in increasing or
/// decreasing order, of a product (each combination of the other axes is one curve).
fn continued_axis(
    doc: &Table,
    src: Source,
    axes: &[Axis],
    combine: Combine,
) -> Result<Option<usize>, SweepError> {
    let Some(v) = doc.get("continue") else {
        return Ok(None);
    };
    let error = |message: String| Err(src.key_error("continue", message));
    let Value::String(key) = v else {
        return error(format!("expected the key of an axis, found {v}"));
    };
    let Some(k) = axes.iter().position(|a| a.key == *key) else {
        let keys: Vec<&str> = axes.iter().map(|a| a.key.as_str()).collect();
        return error(format!(
            "`{key}` is not an axis; the axes are {}",
            keys.join(", ")
        ));
    };
    if combine == Combine::Zip && axes.len() > 1 {
        return error("a continued axis needs `combine = \"product\"`: each combination of the other axes is one curve along it".into());
    }
    let numbers: Option<Vec<f64>> = axes[k]
        .values
        .iter()
        .map(|v| v.as_float().or_else(|| v.as_integer().map(|i| i as f64)))
        .collect();
    let ordered = |x: &[f64]| {
        x.len() >= 2
            && x.iter().all(|v| v.is_finite())
            && (x.windows(2).all(|w| w[1] > w[0]) || x.windows(2).all(|w| w[1] < w[0]))
    };
    match numbers {
        Some(x) if ordered(&x) => Ok(Some(k)),
        _ => error(format!(
            "the continued axis `{key}` needs at least two numbers in increasing or decreasing order, found {}",
            Value::Array(axes[k].values.clone())
        )),
    }
}

/// The axes of the `[axes]` table of `doc`: at least one.
fn axes_of(doc: &Table, src: Source) -> Result<Vec<Axis>, SweepError> {
    let axes = match doc.get("axes") {
        None => Vec::new(),
        Some(Value::Table(t)) => axes(t, src.text, src.file)?,
        Some(v) => return Err(src.key_error("axes", format!("expected a table, found {v}"))),
    };
    if axes.is_empty() {
        return Err(SweepError::Key {
            file: src.file.into(),
            line: line_of_section(src.text, "axes").unwrap_or(1),
            key: "axes".into(),
            message: "no axes: give at least one, e.g. `\"geometry.helices\" = [2, 4, 8]`".into(),
        });
    }
    Ok(axes)
}

/// The cases of the value tuples `combos`: each named by its index and values, the base
/// patched with its values (and its name, unless an axis sets it), read as a case.
fn generated_cases(
    base: &BaseCase,
    axes: &[Axis],
    combos: Vec<Vec<Value>>,
    file: &str,
) -> Result<Vec<SweepCase>, SweepError> {
    let width = combos.len().to_string().len().max(3);
    let mut cases = Vec::with_capacity(combos.len());
    for (index, values) in combos.into_iter().enumerate() {
        let id = case_id(index, width, axes, &values);
        let mut doc = base.doc.clone();
        if !axes.iter().any(|a| a.key == "name") {
            doc.insert("name".into(), Value::String(id.clone()));
        }
        for (axis, value) in axes.iter().zip(&values) {
            set_key(&mut doc, &axis.key, value.clone()).map_err(|message| SweepError::Key {
                file: file.into(),
                line: axis.line,
                key: axis.key.clone(),
                message,
            })?;
        }
        let patched = toml::to_string(&doc).map_err(|e| SweepError::Syntax {
            file: file.into(),
            line: base.line,
            message: format!("case {id} cannot be written as TOML: {e}"),
        })?;
        let label = format!("{file} [{id}]");
        let case = Case::parse(&patched, &label, &id)
            .map_err(|e| generated_error(file, &id, axes, &values, &e))?;
        cases.push(SweepCase {
            index,
            id,
            values,
            text: patched,
            case,
        });
    }
    Ok(cases)
}

/// The axes of the `[axes]` table: every array under it, named by its dotted path (quoted
/// `"geometry.helices"` or bare `geometry.helices` alike), in the order of the file.
fn axes(table: &Table, text: &str, file: &str) -> Result<Vec<Axis>, SweepError> {
    let mut found = Vec::new();
    flatten(table, String::new(), &mut found);
    let mut axes = Vec::new();
    for (key, value) in found {
        let line = line_of_key(text, Some("axes"), &key);
        let values = match value {
            Value::Array(a) => a,
            v => {
                return Err(SweepError::Key {
                    file: file.into(),
                    line,
                    key,
                    message: format!("an axis is an array of values, found {v}"),
                })
            }
        };
        if values.is_empty() {
            return Err(SweepError::Key {
                file: file.into(),
                line,
                key,
                message: "an axis needs at least one value, found an empty array".into(),
            });
        }
        if key.split('.').any(str::is_empty) {
            return Err(SweepError::Key {
                file: file.into(),
                line,
                key,
                message: "an empty part in a dotted key".into(),
            });
        }
        axes.push(Axis { key, values, line });
    }
    axes.sort_by_key(|a| a.line);
    Ok(axes)
}

/// Leaves of a table that are not tables, with their dotted paths. A table value under
/// `[axes]` is a level of a dotted key; an axis's values are always in an array.
fn flatten(table: &Table, prefix: String, out: &mut Vec<(String, Value)>) {
    for (k, v) in table {
        let key = if prefix.is_empty() {
            k.clone()
        } else {
            format!("{prefix}.{k}")
        };
        match v {
            Value::Table(t) => flatten(t, key, out),
            v => out.push((key, v.clone())),
        }
    }
}

/// The value tuples of the cases.
fn combinations(
    axes: &[Axis],
    combine: Combine,
    file: &str,
) -> Result<Vec<Vec<Value>>, SweepError> {
    match combine {
        Combine::Zip => {
            let len = axes[0].values.len();
            if let Some(a) = axes.iter().find(|a| a.values.len() != len) {
                return Err(SweepError::Key {
                    file: file.into(),
                    line: a.line,
                    key: a.key.clone(),
                    message: format!(
                        "combine = \"zip\" needs axes of one length: `{}` has {len} values, this one {}",
                        axes[0].key,
                        a.values.len()
                    ),
                });
            }
            Ok((0..len)
                .map(|k| axes.iter().map(|a| a.values[k].clone()).collect())
                .collect())
        }
        Combine::Product => {
            let mut combos: Vec<Vec<Value>> = vec![Vec::new()];
            for a in axes {
                combos = combos
                    .into_iter()
                    .flat_map(|c| {
                        a.values.iter().map(move |v| {
                            let mut c = c.clone();
                            c.push(v.clone());
                            c
                        })
                    })
                    .collect();
            }
            Ok(combos)
        }
    }
}

/// Merges `over` into `base`, table by table.
fn merge(base: &mut Table, over: &Table) {
    for (k, v) in over {
        match (base.get_mut(k), v) {
            (Some(Value::Table(b)), Value::Table(o)) => merge(b, o),
            _ => {
                base.insert(k.clone(), v.clone());
            }
        }
    }
}

/// The error of a generated case, said about the axis its key belongs to.
fn generated_error(
    file: &str,
    id: &str,
    axes: &[Axis],
    values: &[Value],
    e: &CaseError,
) -> SweepError {
    let key = e.key().unwrap_or("").to_string();
    let related = |a: &Axis| {
        a.key == key
            || key.starts_with(&format!("{}.", a.key))
            || a.key.starts_with(&format!("{key}."))
    };
    let at = axes.iter().position(related).unwrap_or(0);
    let listed: Vec<String> = axes
        .iter()
        .zip(values)
        .map(|(a, v)| format!("{} = {}", a.key, inline(v)))
        .collect();
    SweepError::Generated(Box::new(InvalidCase {
        file: file.into(),
        line: axes[at].line,
        axis: axes[at].key.clone(),
        value: inline(&values[at]),
        case: id.into(),
        values: listed.join(", "),
        key: if key.is_empty() { "-".into() } else { key },
        message: e.message(),
    }))
}

/// A value as TOML writes it inline (`8`, `"slide"`, `{ translation = "slide", … }`).
pub fn inline(v: &Value) -> String {
    v.to_string()
}

/// A value as a table cell: strings without their quotes, everything else as TOML.
pub fn cell(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        v => v.to_string(),
    }
}

/// The folder name of a case: its index, then `name-value` per axis (the key without its
/// first part; the values of a table joined by `-`), safe for any file system.
fn case_id(index: usize, width: usize, axes: &[Axis], values: &[Value]) -> String {
    let mut id = format!("{:0width$}", index + 1);
    for (a, v) in axes.iter().zip(values) {
        let short = a.key.split_once('.').map_or(a.key.as_str(), |(_, r)| r);
        id.push('_');
        id.push_str(&slug(short));
        id.push('-');
        id.push_str(&slug(&flat(v)));
    }
    id
}

fn flat(v: &Value) -> String {
    match v {
        Value::String(s) => s.clone(),
        Value::Table(t) => t.values().map(flat).collect::<Vec<_>>().join("-"),
        Value::Array(a) => a.iter().map(flat).collect::<Vec<_>>().join("-"),
        v => v.to_string(),
    }
}

/// A sweep's name as a folder name: `slug`ged, without leading dots (no `..`, no hidden
/// folder), at most 100 characters; `sweep` when nothing is left.
pub fn folder_name(name: &str) -> String {
    let s: String = slug(name)
        .trim_start_matches('.')
        .chars()
        .take(100)
        .collect();
    if s.is_empty() {
        "sweep".into()
    } else {
        s
    }
}

/// Refuses axes that make more than `max` cases, counted before any is generated.
fn count_cases(axes: &[Axis], combine: Combine, src: Source, max: usize) -> Result<(), SweepError> {
    let lengths: Vec<usize> = axes.iter().map(|a| a.values.len()).collect();
    let (count, how) = match combine {
        // unequal lengths are refused with the combinations
        Combine::Zip => (
            lengths.iter().copied().max().unwrap_or(0),
            "zipped".to_string(),
        ),
        Combine::Product => (
            lengths.iter().fold(1usize, |n, &l| n.saturating_mul(l)),
            lengths
                .iter()
                .map(usize::to_string)
                .collect::<Vec<_>>()
                .join(" × "),
        ),
    };
    if count <= max {
        return Ok(());
    }
    let count = if count == usize::MAX {
        format!("more than {}", usize::MAX - 1)
    } else {
        count.to_string()
    };
    Err(SweepError::Key {
        file: src.file.into(),
        line: line_of_section(src.text, "axes").unwrap_or(1),
        key: "axes".into(),
        message: format!(
            "the axes make {count} cases ({how}); a sweep of more than {max} cases is read, checked and listed only with --force"
        ),
    })
}

fn slug(s: &str) -> String {
    s.chars()
        .map(|c| {
            if c.is_ascii_alphanumeric() || matches!(c, '.' | '+' | '-') {
                c
            } else {
                '_'
            }
        })
        .collect()
}

/// 1-based line of a byte offset.
fn line_of(text: &str, offset: usize) -> usize {
    text[..offset.min(text.len())].matches('\n').count() + 1
}

/// The line of a `[section]` header.
fn line_of_section(text: &str, section: &str) -> Option<usize> {
    text.lines()
        .position(|l| header(l).as_deref() == Some(section))
        .map(|i| i + 1)
}

fn header(line: &str) -> Option<String> {
    let l = line.trim();
    let l = l.split('#').next().unwrap_or("").trim();
    (l.starts_with('[') && !l.starts_with("[[") && l.ends_with(']'))
        .then(|| l[1..l.len() - 1].trim().to_string())
}

/// The line a key is written on, in the top level (`section` None) or under `[section]`:
/// the key bare, quoted or dotted, then `=`. Falls back to the section's header, then 1.
fn line_of_key(text: &str, section: Option<&str>, key: &str) -> usize {
    let forms = [
        key.to_string(),
        format!("\"{key}\""),
        format!("'{key}'"),
        key.split('.')
            .map(|p| format!("\"{p}\""))
            .collect::<Vec<_>>()
            .join("."),
    ];
    let mut current: Option<String> = None;
    for (i, line) in text.lines().enumerate() {
        if let Some(h) = header(line) {
            current = Some(h);
            continue;
        }
        let in_section = match (section, &current) {
            (None, None) => true,
            (Some(s), Some(c)) => c == s,
            _ => false,
        };
        if !in_section {
            continue;
        }
        let l = line.trim_start();
        for f in &forms {
            if let Some(rest) = l.strip_prefix(f.as_str()) {
                if rest.trim_start().starts_with('=') {
                    return i + 1;
                }
            }
        }
    }
    section.and_then(|s| line_of_section(text, s)).unwrap_or(1)
}
