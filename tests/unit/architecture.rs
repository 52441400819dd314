//! The crate's layers, checked on its sources: a module imports only from its own layer or
//! from layers below it, no two modules import each other, and no longer import cycle runs
//! through the files.
//!
//! The sources are read as text (std only): comments and string literals are dropped, then
//! every `crate::…`, `self::…` and `super::…` path (and `spira::…` in the binary) is read,
//! grouped `use` trees included (as are paths through the modules a file declares, such as
//! `app::App` in src/tui/mod.rs), and resolved to the file that defines the module it names.
//! `src/lib.rs` is exempt: it declares the modules. The modules src/main.rs declares
//! (`mod cli;`: src/cli/) belong to the binary, as src/main.rs does.

use std::collections::{BTreeMap, BTreeSet};
use std::fs;
use std::path::{Path, PathBuf};

/// The layers, lowest first, each with the top-level modules that belong to it. A module may
/// import from its own layer or from any layer before it in this table.
const LAYERS: &[(&str, &[&str])] = &[
    ("model", &["model"]),
    ("results", &["results"]),
    ("discretisation", &["discretisation"]),
    ("solver", &["solver"]),
    ("case", &["case"]),
    ("simulation", &["simulation"]),
    ("run", &["run"]),
    ("study", &["study"]),
    ("output", &["output"]),
    // runs cases (run) and writes tables (output)
    ("sweep", &["sweep"]),
    ("session", &["session"]),
    ("tui", &["tui"]),
    // src/main.rs, the modules it declares (src/cli/) and src/bin/, which may use anything
    // through `spira::`.
    ("binary", &[]),
];

/// The binary's layer: the last one.
const BINARY_LAYER: usize = LAYERS.len() - 1;

// ---------------------------------------------------------------------------------------
// The tests
// ---------------------------------------------------------------------------------------

#[test]
fn modules_respect_the_layers_and_do_not_import_each_other() {
    let problems = problems(&source_files());
    assert!(
        problems.is_empty(),
        "the layer rules of tests/unit/architecture.rs are broken:\n\n{}",
        problems.join("\n\n")
    );
}

#[test]
fn layer_table_covers_every_module_declared_in_lib_rs() {
    let lib = fs::read_to_string(src_dir().join("lib.rs")).expect("src/lib.rs");
    let missing: Vec<String> = declared_modules(&tokenize(&lib))
        .into_iter()
        .filter(|name| layer_of(name).is_none())
        .map(|name| format!("  `{name}`"))
        .collect();
    assert!(
        missing.is_empty(),
        "src/lib.rs declares modules that are in no layer; place them in LAYERS in \
         tests/unit/architecture.rs:\n{}",
        missing.join("\n")
    );
}

/// Every broken rule, one section per rule, one line per offence.
fn problems(files: &[SourceFile]) -> Vec<String> {
    let imports = imports(files);
    let mut sections = Vec::new();
    add_section(
        &mut sections,
        "modules in no layer",
        unplaced_modules(files),
    );
    add_section(
        &mut sections,
        "imports from a layer above",
        upward_imports(files, &imports),
    );
    add_section(
        &mut sections,
        "modules that import each other",
        mutual_imports(files, &imports),
    );
    add_section(
        &mut sections,
        "longer import cycles",
        longer_cycles(files, &imports),
    );
    sections
}

fn add_section(sections: &mut Vec<String>, title: &str, lines: Vec<String>) {
    if !lines.is_empty() {
        sections.push(format!("{title}:\n{}", lines.join("\n")));
    }
}

// ---------------------------------------------------------------------------------------
// The rules
// ---------------------------------------------------------------------------------------

/// One line per top-level module that the layer table does not place.
fn unplaced_modules(files: &[SourceFile]) -> Vec<String> {
    let mut seen = BTreeSet::new();
    files
        .iter()
        .filter(|file| file.role == Role::Library && file.layer().is_none())
        .filter(|file| seen.insert(file.module[0].clone()))
        .map(|file| {
            format!(
                "  {} (module `{}`) is in no layer: place it in LAYERS in tests/unit/architecture.rs",
                file.shown, file.module[0]
            )
        })
        .collect()
}

/// `src/x.rs imports crate::y (layer A -> layer B)` for every import of a higher layer.
fn upward_imports(files: &[SourceFile], imports: &[Import]) -> Vec<String> {
    imports
        .iter()
        .filter_map(|import| {
            let from = files[import.from].layer()?;
            let to = files[import.to].layer()?;
            (to > from).then(|| {
                format!(
                    "  {} imports {} ({} -> {})",
                    files[import.from].shown,
                    import.shown,
                    layer_label(from),
                    layer_label(to)
                )
            })
        })
        .collect()
}

/// One line per pair of files that import each other, naming both imports.
fn mutual_imports(files: &[SourceFile], imports: &[Import]) -> Vec<String> {
    let by_edge: BTreeMap<(usize, usize), &Import> = imports
        .iter()
        .map(|import| ((import.from, import.to), import))
        .collect();
    by_edge
        .iter()
        .filter(|((a, b), _)| a < b)
        .filter_map(|(&(a, b), there)| {
            let back = by_edge.get(&(b, a))?;
            Some(format!(
                "  {} and {} import each other ({} imports {}, {} imports {})",
                files[a].shown,
                files[b].shown,
                files[a].shown,
                there.shown,
                files[b].shown,
                back.shown
            ))
        })
        .collect()
}

/// One line per cycle of three or more files found by a depth-first search (every cyclic
/// graph yields at least one; cycles of two are the mutual imports).
fn longer_cycles(files: &[SourceFile], imports: &[Import]) -> Vec<String> {
    let mut graph: BTreeMap<usize, BTreeSet<usize>> = BTreeMap::new();
    for import in imports {
        graph.entry(import.from).or_default().insert(import.to);
    }
    let mut search = CycleSearch {
        graph: &graph,
        state: vec![Visit::Unvisited; files.len()],
        stack: Vec::new(),
        cycles: BTreeSet::new(),
    };
    for node in 0..files.len() {
        if search.state[node] == Visit::Unvisited {
            search.visit(node);
        }
    }
    search
        .cycles
        .iter()
        .map(|cycle| {
            let mut names: Vec<&str> = cycle.iter().map(|&n| files[n].shown.as_str()).collect();
            names.push(&files[cycle[0]].shown);
            format!("  {}", names.join(" -> "))
        })
        .collect()
}

#[derive(Clone, Copy, PartialEq)]
enum Visit {
    Unvisited,
    OnStack,
    Done,
}

struct CycleSearch<'a> {
    graph: &'a BTreeMap<usize, BTreeSet<usize>>,
    state: Vec<Visit>,
    stack: Vec<usize>,
    cycles: BTreeSet<Vec<usize>>,
}

impl CycleSearch<'_> {
    fn visit(&mut self, node: usize) {
        self.state[node] = Visit::OnStack;
        self.stack.push(node);
        for &next in self.graph.get(&node).into_iter().flatten() {
            match self.state[next] {
                Visit::Unvisited => self.visit(next),
                Visit::OnStack => self.close_cycle_at(next),
                Visit::Done => {}
            }
        }
        self.stack.pop();
        self.state[node] = Visit::Done;
    }

    /// A back edge to `start`: the stack from `start` up is a cycle.
    fn close_cycle_at(&mut self, start: usize) {
        let from = self
            .stack
            .iter()
            .position(|&n| n == start)
            .expect("on stack");
        let mut cycle = self.stack[from..].to_vec();
        if cycle.len() > 2 {
            let smallest = (0..cycle.len())
                .min_by_key(|&i| cycle[i])
                .expect("non-empty");
            cycle.rotate_left(smallest);
            self.cycles.insert(cycle);
        }
    }
}

fn layer_of(top_module: &str) -> Option<usize> {
    LAYERS
        .iter()
        .position(|(_, modules)| modules.contains(&top_module))
}

fn layer_label(layer: usize) -> String {
    format!("layer {layer} {}", LAYERS[layer].0)
}

// ---------------------------------------------------------------------------------------
// The source files and the imports between them
// ---------------------------------------------------------------------------------------

#[derive(Clone, Copy, PartialEq, Debug)]
enum Role {
    /// A module of the library.
    Library,
    /// src/lib.rs: exempt.
    Root,
    /// src/main.rs, a module it declares (src/cli/…) or src/bin/…: imports the library as
    /// `spira::`.
    Binary,
}

struct SourceFile {
    /// The path as shown in messages: `src/tui/app.rs`.
    shown: String,
    /// The module the file defines: `["tui", "app"]` (empty for lib.rs and binaries).
    module: Vec<String>,
    role: Role,
    text: String,
}

impl SourceFile {
    /// The file at `src/` + `segments` (`["tui", "app.rs"]`) with its text, in a crate whose
    /// src/main.rs declares no module.
    fn new(segments: &[String], text: String) -> SourceFile {
        SourceFile::in_crate(segments, text, &[])
    }

    /// The file at `src/` + `segments` with its text, in a crate whose src/main.rs declares
    /// the modules `binary_modules` (`["cli"]`): their files belong to the binary.
    fn in_crate(segments: &[String], text: String, binary_modules: &[String]) -> SourceFile {
        let (module, role) = module_and_role(segments, binary_modules);
        SourceFile {
            shown: format!("src/{}", segments.join("/")),
            module,
            role,
            text,
        }
    }

    fn layer(&self) -> Option<usize> {
        match self.role {
            Role::Library => layer_of(&self.module[0]),
            Role::Binary => Some(BINARY_LAYER),
            Role::Root => None,
        }
    }

    /// The first segments of the paths this file refers to the library by: `crate`, `self`,
    /// `super` and the names of the modules it declares (`app::App` in src/tui/mod.rs), or
    /// `spira` in the binary.
    fn roots(&self, tokens: &[Token]) -> Vec<String> {
        match self.role {
            Role::Library => ["crate", "self", "super"]
                .map(String::from)
                .into_iter()
                .chain(declared_modules(tokens))
                .collect(),
            Role::Binary => vec!["spira".to_string()],
            Role::Root => Vec::new(),
        }
    }
}

/// One file importing from another (once per pair, whatever the number of paths).
struct Import {
    from: usize,
    to: usize,
    /// The imported module as an absolute path: `crate::solver::newton`.
    shown: String,
}

fn src_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("src")
}

/// Every `.rs` file under src/, in path order.
fn source_files() -> Vec<SourceFile> {
    let src = src_dir();
    let mut paths = Vec::new();
    collect_rust_files(&src, &mut paths);
    paths.sort();
    source_tree(
        paths
            .iter()
            .map(|path| {
                let relative = path.strip_prefix(&src).expect("under src/");
                let segments: Vec<String> = relative
                    .components()
                    .map(|c| c.as_os_str().to_string_lossy().into_owned())
                    .collect();
                (segments, fs::read_to_string(path).expect("readable source"))
            })
            .collect(),
    )
}

/// The source files of a crate from their paths under src/ (as segments) and texts: the
/// modules its src/main.rs declares are the binary's.
fn source_tree(files: Vec<(Vec<String>, String)>) -> Vec<SourceFile> {
    let binary_modules = files
        .iter()
        .find(|(segments, _)| segments.len() == 1 && segments[0] == "main.rs")
        .map(|(_, text)| declared_modules(&tokenize(text)))
        .unwrap_or_default();
    files
        .into_iter()
        .map(|(segments, text)| SourceFile::in_crate(&segments, text, &binary_modules))
        .collect()
}

fn collect_rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in fs::read_dir(dir).expect("readable directory") {
        let path = entry.expect("directory entry").path();
        if path.is_dir() {
            collect_rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// `["tui", "app.rs"]` → `tui::app`; `["tui", "mod.rs"]` → `tui`; the binary's files
/// (src/main.rs, src/bin/…, and the modules `binary_modules` that src/main.rs declares) have
/// no module of the library.
fn module_and_role(segments: &[String], binary_modules: &[String]) -> (Vec<String>, Role) {
    let binary_module = |first: &str| {
        binary_modules
            .iter()
            .any(|m| first == m || first == format!("{m}.rs"))
    };
    match segments {
        [only] if only == "lib.rs" => (Vec::new(), Role::Root),
        [only] if only == "main.rs" => (Vec::new(), Role::Binary),
        [first, ..] if first == "bin" => (Vec::new(), Role::Binary),
        [first, ..] if binary_module(first) => (Vec::new(), Role::Binary),
        _ => {
            let mut module: Vec<String> = segments
                .iter()
                .map(|s| s.trim_end_matches(".rs").to_string())
                .collect();
            if module.last().is_some_and(|last| last == "mod") {
                module.pop();
            }
            (module, Role::Library)
        }
    }
}

/// The imports between files, in file order, once per pair, self-references left out.
fn imports(files: &[SourceFile]) -> Vec<Import> {
    let modules: BTreeMap<&[String], usize> = files
        .iter()
        .enumerate()
        .filter(|(_, file)| file.role == Role::Library)
        .map(|(index, file)| (file.module.as_slice(), index))
        .collect();
    let mut found = Vec::new();
    for (from, file) in files.iter().enumerate() {
        let mut targets = BTreeSet::new();
        let tokens = tokenize(&file.text);
        for written in written_paths(&tokens, &file.roots(&tokens)) {
            let here = [file.module.as_slice(), written.scope.as_slice()].concat();
            let Some(path) = absolute(&written.path, &here) else {
                continue;
            };
            let Some(to) = owning_file(&path, &modules) else {
                continue;
            };
            if to != from && targets.insert(to) {
                let root = if file.role == Role::Binary {
                    "spira"
                } else {
                    "crate"
                };
                let shown = format!("{root}::{}", files[to].module.join("::"));
                found.push(Import { from, to, shown });
            }
        }
    }
    found
}

/// The absolute module path a written path names, or `None` when it leaves the crate.
/// `here` is the module the path is written in (inline modules included); a path that does
/// not start with `crate`, `spira`, `self` or `super` starts with a module declared here.
fn absolute(written: &[String], here: &[String]) -> Option<Vec<String>> {
    let (first, rest) = written.split_first()?;
    let mut path = match first.as_str() {
        "crate" | "spira" => Vec::new(),
        "self" => here.to_vec(),
        "super" => here.split_last()?.1.to_vec(),
        child => [here, &[child.to_string()]].concat(),
    };
    for segment in rest {
        match segment.as_str() {
            "super" => {
                path.pop()?;
            }
            "self" => {}
            _ => path.push(segment.clone()),
        }
    }
    Some(path)
}

/// The file defining the longest prefix of `path` that is a module; `None` for items of the
/// crate root.
fn owning_file(path: &[String], modules: &BTreeMap<&[String], usize>) -> Option<usize> {
    (1..=path.len())
        .rev()
        .find_map(|length| modules.get(&path[..length]).copied())
}

/// The names of the `mod name;` declarations.
fn declared_modules(tokens: &[Token]) -> Vec<String> {
    tokens
        .windows(3)
        .filter_map(|window| match window {
            [Token::Ident(keyword), Token::Ident(name), Token::Other(';')] if keyword == "mod" => {
                Some(name.clone())
            }
            _ => None,
        })
        .collect()
}

// ---------------------------------------------------------------------------------------
// Reading Rust: tokens without comments and literals, then paths
// ---------------------------------------------------------------------------------------

#[derive(Debug, Clone, PartialEq)]
enum Token {
    /// An identifier or keyword (numbers come out as these too; they never start a path).
    Ident(String),
    /// `::`
    PathSep,
    /// `{`
    Open,
    /// `}`
    Close,
    Comma,
    Star,
    Other(char),
}

/// The tokens of a source file, comments, string and character literals left out.
fn tokenize(source: &str) -> Vec<Token> {
    let chars: Vec<char> = source.chars().collect();
    let mut tokens = Vec::new();
    let mut i = 0;
    while i < chars.len() {
        let c = chars[i];
        let next = chars.get(i + 1).copied();
        if c.is_whitespace() {
            i += 1;
        } else if c == '/' && next == Some('/') {
            i = end_of_line(&chars, i);
        } else if c == '/' && next == Some('*') {
            i = end_of_block_comment(&chars, i);
        } else if let Some(end) = end_of_raw_string(&chars, i) {
            i = end;
        } else if c == '"' {
            i = end_of_string(&chars, i);
        } else if c == '\'' {
            i = end_of_char_or_lifetime_mark(&chars, i);
        } else if is_word_char(c) {
            let start = i;
            while i < chars.len() && is_word_char(chars[i]) {
                i += 1;
            }
            tokens.push(Token::Ident(chars[start..i].iter().collect()));
        } else if c == ':' && next == Some(':') {
            tokens.push(Token::PathSep);
            i += 2;
        } else {
            tokens.push(match c {
                '{' => Token::Open,
                '}' => Token::Close,
                ',' => Token::Comma,
                '*' => Token::Star,
                other => Token::Other(other),
            });
            i += 1;
        }
    }
    tokens
}

fn is_word_char(c: char) -> bool {
    c.is_alphanumeric() || c == '_'
}

fn end_of_line(chars: &[char], from: usize) -> usize {
    (from..chars.len())
        .find(|&i| chars[i] == '\n')
        .unwrap_or(chars.len())
}

/// Block comments nest in Rust.
fn end_of_block_comment(chars: &[char], from: usize) -> usize {
    let mut depth = 0;
    let mut i = from;
    while i < chars.len() {
        match (chars[i], chars.get(i + 1)) {
            ('/', Some('*')) => {
                depth += 1;
                i += 2;
            }
            ('*', Some('/')) => {
                depth -= 1;
                i += 2;
                if depth == 0 {
                    return i;
                }
            }
            _ => i += 1,
        }
    }
    chars.len()
}

/// `r"…"`, `r#"…"#`, `br"…"`, `cr#"…"#`: the position after it, if one starts here.
fn end_of_raw_string(chars: &[char], from: usize) -> Option<usize> {
    let mut i = from;
    if matches!(chars[i], 'b' | 'c') {
        i += 1;
    }
    if chars.get(i) != Some(&'r') {
        return None;
    }
    i += 1;
    let hashes = chars[i..].iter().take_while(|&&c| c == '#').count();
    i += hashes;
    if chars.get(i) != Some(&'"') {
        return None;
    }
    i += 1;
    while i < chars.len() {
        let closes = chars[i] == '"'
            && chars[i + 1..]
                .iter()
                .take(hashes)
                .filter(|&&c| c == '#')
                .count()
                == hashes;
        if closes {
            return Some(i + 1 + hashes);
        }
        i += 1;
    }
    Some(chars.len())
}

/// `"…"` with escapes (a `b` or `c` prefix is read as a word before it, harmlessly).
fn end_of_string(chars: &[char], from: usize) -> usize {
    let mut i = from + 1;
    while i < chars.len() {
        match chars[i] {
            '\\' => i += 2,
            '"' => return i + 1,
            _ => i += 1,
        }
    }
    chars.len()
}

/// A character literal (`'"'`, `'\''`, `'{'`) is skipped; a lifetime's mark only.
fn end_of_char_or_lifetime_mark(chars: &[char], from: usize) -> usize {
    if chars.get(from + 1) == Some(&'\\') {
        return (from + 2..chars.len())
            .find(|&i| chars[i] == '\'')
            .map_or(chars.len(), |i| i + 1);
    }
    if chars.get(from + 2) == Some(&'\'') {
        return from + 3;
    }
    from + 1
}

/// A path as written, with the inline modules (`mod tests { … }`) it is written inside.
#[derive(Debug, PartialEq)]
struct Written {
    path: Vec<String>,
    scope: Vec<String>,
}

/// Every path starting with one of `roots` followed by `::`, use trees expanded.
fn written_paths(tokens: &[Token], roots: &[String]) -> Vec<Written> {
    let mut found = Vec::new();
    let mut inline_modules: Vec<(String, usize)> = Vec::new();
    let mut depth = 0;
    let mut i = 0;
    while i < tokens.len() {
        match &tokens[i] {
            Token::Open => depth += 1,
            Token::Close => {
                if inline_modules.last().is_some_and(|(_, d)| *d == depth) {
                    inline_modules.pop();
                }
                depth = depth.saturating_sub(1);
            }
            Token::Ident(word) if word == "mod" => {
                if let (Some(Token::Ident(name)), Some(Token::Open)) =
                    (tokens.get(i + 1), tokens.get(i + 2))
                {
                    depth += 1;
                    inline_modules.push((name.clone(), depth));
                    i += 3;
                    continue;
                }
            }
            Token::Ident(word) if roots.contains(word) && starts_path(tokens, i) => {
                let scope: Vec<String> = inline_modules.iter().map(|(n, _)| n.clone()).collect();
                let mut paths = Vec::new();
                i = read_use_tree(tokens, i, Vec::new(), &mut paths);
                found.extend(paths.into_iter().map(|path| Written {
                    path,
                    scope: scope.clone(),
                }));
                continue;
            }
            _ => {}
        }
        i += 1;
    }
    found
}

/// A root word starts a path when `::` follows it and none precedes it.
fn starts_path(tokens: &[Token], i: usize) -> bool {
    tokens.get(i + 1) == Some(&Token::PathSep) && (i == 0 || tokens[i - 1] != Token::PathSep)
}

/// Reads one path or use tree from `tokens[i]`, appending the full path of every leaf to
/// `out` (a glob or `{self}` names its prefix); returns the position after it.
fn read_use_tree(
    tokens: &[Token],
    mut i: usize,
    mut prefix: Vec<String>,
    out: &mut Vec<Vec<String>>,
) -> usize {
    loop {
        match tokens.get(i) {
            Some(Token::Ident(segment)) => {
                prefix.push(segment.clone());
                i += 1;
            }
            Some(Token::Star) => {
                i += 1;
                break;
            }
            Some(Token::Open) => return read_use_group(tokens, i + 1, &prefix, out),
            _ => break,
        }
        if tokens.get(i) == Some(&Token::PathSep) {
            i += 1;
        } else {
            break;
        }
    }
    out.push(prefix);
    i
}

/// The trees of `{a::b, c as d, e::{f, g}}`, from after the `{` to after the `}`.
fn read_use_group(
    tokens: &[Token],
    mut i: usize,
    prefix: &[String],
    out: &mut Vec<Vec<String>>,
) -> usize {
    while i < tokens.len() {
        match tokens[i] {
            Token::Close => return i + 1,
            Token::Comma => i += 1,
            _ => {
                let start = i;
                i = read_use_tree(tokens, i, prefix.to_vec(), out);
                // skip a rename (`as name`) up to the next `,` or `}`
                while i < tokens.len() && !matches!(tokens[i], Token::Comma | Token::Close) {
                    i += 1;
                }
                i = i.max(start + 1);
            }
        }
    }
    i
}

// ---------------------------------------------------------------------------------------
// The reader's own checks
// ---------------------------------------------------------------------------------------

fn paths_in(source: &str, roots: &[&str]) -> Vec<String> {
    let roots: Vec<String> = roots.iter().map(|r| r.to_string()).collect();
    written_paths(&tokenize(source), &roots)
        .into_iter()
        .map(|w| w.path.join("::"))
        .collect()
}

#[test]
fn reader_expands_grouped_uses_over_several_lines() {
    let source =
        "use crate::{\n    model::{self, loading::Control},\n    results as r,\n    solver::*,\n};";
    assert_eq!(
        paths_in(source, &["crate"]),
        [
            "crate::model::self",
            "crate::model::loading::Control",
            "crate::results",
            "crate::solver"
        ]
    );
}

#[test]
fn reader_finds_inline_paths_and_ignores_comments_and_strings() {
    let source = r##"
        // use crate::tui;
        /// crate::output::write
        /* crate::run /* nested */ crate::session */
        let s = "crate::chart"; let r = r#"crate::study"#; let q = '"';
        match c { crate::model::loading::Control::Force => 1, _ => 2 }
        let h = crate::model::helix::Helix { turns: 1 };
        let v = crate::precision::order::<f64>();
    "##;
    assert_eq!(
        paths_in(source, &["crate"]),
        [
            "crate::model::loading::Control::Force",
            "crate::model::helix::Helix",
            "crate::precision::order"
        ]
    );
}

#[test]
fn super_and_self_resolve_to_the_module_they_name() {
    let here = |path: &str| path.split("::").map(String::from).collect::<Vec<_>>();
    assert_eq!(
        absolute(&here("super::worker::Job"), &here("tui::app")),
        Some(here("tui::worker::Job"))
    );
    assert_eq!(
        absolute(&here("super::super::model"), &here("solver::newton")),
        Some(here("model"))
    );
    assert_eq!(
        absolute(&here("self::app::App"), &here("tui")),
        Some(here("tui::app::App"))
    );
    let written = written_paths(
        &tokenize("mod tests { use super::*; }\nuse super::x;"),
        &["super".to_string()],
    );
    assert_eq!(written[0].scope, ["tests"]);
    assert!(written[1].scope.is_empty());
}

#[test]
fn rules_report_unplaced_modules_upward_imports_and_cycles() {
    let file = |path: &str, text: &str| {
        let segments: Vec<String> = path.split('/').map(String::from).collect();
        SourceFile::new(&segments, text.to_string())
    };
    let files = [
        file(
            "lib.rs",
            "pub mod gadget; pub mod model; pub mod solver; pub mod tui;",
        ),
        file("gadget.rs", ""),
        file("model/mod.rs", "pub mod helix;\nfn f() { helix::turn(); }"),
        file(
            "model/helix.rs",
            "use crate::{\n    tui::App,\n};\nuse super::*;",
        ),
        file("solver/mod.rs", "pub mod a; pub mod b; pub mod c;"),
        file("solver/a.rs", "use super::b::B;"),
        file("solver/b.rs", "use crate::solver::c::C;"),
        file("solver/c.rs", "fn f() -> super::a::A { todo!() }"),
        file("tui/mod.rs", "use crate::model::helix; // crate::solver"),
        file("main.rs", "use spira::tui::App;"),
    ];
    let report = problems(&files).join("\n");
    let expected = [
        "src/gadget.rs (module `gadget`) is in no layer",
        "src/model/helix.rs imports crate::tui (layer 0 model -> layer 11 tui)",
        "src/model/mod.rs and src/model/helix.rs import each other \
         (src/model/mod.rs imports crate::model::helix, src/model/helix.rs imports crate::model)",
        "src/model/helix.rs and src/tui/mod.rs import each other",
        "src/solver/a.rs -> src/solver/b.rs -> src/solver/c.rs -> src/solver/a.rs",
    ];
    for line in expected {
        assert!(report.contains(line), "missing {line:?} in:\n{report}");
    }
    assert!(
        !report.contains("main.rs"),
        "the binary may use anything:\n{report}"
    );
    assert!(
        !report.contains("solver/mod.rs"),
        "comments are not imports:\n{report}"
    );
}

#[test]
fn modules_declared_in_main_rs_are_the_binary() {
    let file = |path: &str, text: &str| {
        let segments: Vec<String> = path.split('/').map(String::from).collect();
        (segments, text.to_string())
    };
    let files = source_tree(vec![
        file("lib.rs", "pub mod model; pub mod tui;"),
        file("model/mod.rs", ""),
        file("tui/mod.rs", "use crate::model::Helix;"),
        file(
            "main.rs",
            "mod cli;\nmod flags;\nfn main() { cli::run::run(); }",
        ),
        file("cli/mod.rs", "pub mod run;"),
        file(
            "cli/run.rs",
            "use spira::tui::App; use crate::cli::mod_of_binary;",
        ),
        file("flags.rs", "use spira::model::Helix;"),
    ]);
    let roles: Vec<(&str, Role)> = files.iter().map(|f| (f.shown.as_str(), f.role)).collect();
    assert_eq!(
        roles,
        [
            ("src/lib.rs", Role::Root),
            ("src/model/mod.rs", Role::Library),
            ("src/tui/mod.rs", Role::Library),
            ("src/main.rs", Role::Binary),
            ("src/cli/mod.rs", Role::Binary),
            ("src/cli/run.rs", Role::Binary),
            ("src/flags.rs", Role::Binary),
        ]
    );
    let report = problems(&files).join("\n");
    assert!(report.is_empty(), "the binary may use anything:\n{report}");
    // a module of the library named as a binary's would be placed by the layer table
    let library = source_tree(vec![file("cli/mod.rs", "use crate::tui::App;")]);
    assert_eq!(library[0].role, Role::Library);
    assert!(problems(&library)
        .join("\n")
        .contains("src/cli/mod.rs (module `cli`) is in no layer"));
}
