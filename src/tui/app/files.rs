//! What leaves the explorer as files: the exports of the state on screen and its path, and
//! the session saved as a replayable script.

use super::explorer::{App, Message};
use crate::session::export;
use crate::session::script::Script;
use std::path::{Path, PathBuf};

impl App {
    /// File names of an export of the current state.
    pub fn export_names(&self) -> Option<Vec<String>> {
        let point = &self.screen.state.as_ref()?.point;
        Some(export::names(
            &self.case_label(),
            point.step,
            point.compression_ratio,
            self.screen.critical.len(),
        ))
    }

    fn place(&self) -> String {
        if self.out_dir == Path::new(".") {
            String::new()
        } else {
            format!(" in {}", self.out_dir.display())
        }
    }

    /// Writes the current state and the load path so far (with the conditions of each
    /// point and the session's events) into [`App::out_dir`], in the formats of
    /// `spira run`, and says so in the message line.
    pub fn export(&mut self) -> Vec<PathBuf> {
        let written = match self.screen.state.as_ref() {
            Some(state) => export::write(
                &self.out_dir,
                &export::Export {
                    label: &self.case_label(),
                    snapshot: &state.snapshot,
                    path: &self.screen.path,
                    conditions: &self.screen.conditions,
                    events: &self.screen.session_events(),
                    critical: &self.screen.critical,
                    modes: &self.screen.modes,
                },
            ),
            None => Err(std::io::Error::other("no converged state yet")),
        };
        match written {
            Ok(files) => {
                let names: Vec<String> = files
                    .iter()
                    .filter_map(|f| f.file_name())
                    .map(|f| f.to_string_lossy().into_owned())
                    .collect();
                self.message = Some(Message::Info(format!(
                    "wrote {}{}",
                    summarise(&names),
                    self.place()
                )));
                files
            }
            Err(e) => {
                self.message = Some(Message::Error(format!("export failed: {e}")));
                vec![]
            }
        }
    }

    /// The session so far as a replayable script.
    pub fn script(&self) -> Script {
        let case = self
            .case_file
            .as_ref()
            .map(|p| std::fs::canonicalize(p).unwrap_or_else(|_| p.clone()));
        // the events are those of the path on screen, as the jobs since its start are
        let mut script = Script::of(
            case,
            self.case_label(),
            self.screen.session_events(),
            &self.replay.ran(),
        );
        script.set = self.case_set.clone();
        script
    }

    /// Writes [`App::script`] to `<case>-session.toml` in [`App::out_dir`].
    pub fn save_session(&mut self) -> Option<PathBuf> {
        let name = format!("{}-session.toml", export::sanitise(&self.case_label()));
        let file = self.out_dir.join(name);
        let saved = std::fs::create_dir_all(&self.out_dir)
            .map_err(|e| e.to_string())
            .and_then(|()| self.script().write(&file).map_err(|e| e.to_string()));
        match saved {
            Ok(()) => {
                self.message = Some(Message::Info(format!(
                    "saved the session to {}; spira replay {} --out DIR writes its CSVs",
                    file.display(),
                    file.display()
                )));
                Some(file)
            }
            Err(e) => {
                self.message = Some(Message::Error(format!("saving the session failed: {e}")));
                None
            }
        }
    }
}

/// The names of an export for the message line: the tables by name, the mode files (one
/// per critical point) by their first and last.
fn summarise(names: &[String]) -> String {
    let is_mode = |n: &str| {
        n.rsplit_once("-mode-")
            .and_then(|(_, k)| k.strip_suffix(".csv"))
            .is_some_and(|k| !k.is_empty() && k.bytes().all(|b| b.is_ascii_digit()))
    };
    let (modes, tables): (Vec<&String>, Vec<&String>) = names.iter().partition(|n| is_mode(n));
    let tables: Vec<&str> = tables.iter().map(|n| n.as_str()).collect();
    match modes.as_slice() {
        [] => tables.join(", "),
        [one] => format!("{} and {one}", tables.join(", ")),
        [first, .., last] => format!(
            "{} and {} mode files {first} … {last}",
            tables.join(", "),
            modes.len()
        ),
    }
}
