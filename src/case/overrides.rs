//! What-ifs on a case file: `--set key=value` overrides of its keys, applied to the parsed
//! TOML document before the case reader's checks run, so that an overridden value is
//! checked exactly as the same value written in the file.

use super::error::CaseError;
use std::fmt;
use std::str::FromStr;
use toml::{Table, Value};

/// One override, `key=value`: a dotted key of a case file (`geometry.helices`) and a TOML
/// value (`16`, `0.3`, `true`, `"slide"`, `{ translation = "slide" }`); a value that is not
/// TOML is read as a string, so that `boundary.tip.translation=slide` needs no quotes.
#[derive(Clone, Debug, PartialEq)]
pub struct Setting {
    pub key: String,
    pub value: Value,
}

impl FromStr for Setting {
    type Err = String;

    /// Reads `key=value`; refuses a missing `=`, an empty key or an empty part of it.
    fn from_str(s: &str) -> Result<Setting, String> {
        let Some((key, value)) = s.split_once('=') else {
            return Err(format!(
                "expected key=value (e.g. geometry.helices=16), found `{s}`"
            ));
        };
        let key = key.trim();
        if key.is_empty() || key.split('.').any(|p| p.trim().is_empty()) {
            return Err(format!(
                "expected a dotted key of a case file (e.g. geometry.helices) before `=`, found `{key}`"
            ));
        }
        let key = key.split('.').map(str::trim).collect::<Vec<_>>().join(".");
        let value = value.trim();
        if value.is_empty() {
            return Err(format!("expected a value after `{key}=`, found nothing"));
        }
        Ok(Setting {
            key,
            value: toml_value(value),
        })
    }
}

impl Setting {
    /// The setting as the flag's argument: `geometry.helices=16`.
    pub fn as_flag(&self) -> String {
        format!("{}={}", self.key, self.value)
    }
}

impl fmt::Display for Setting {
    fn fmt(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "{} = {}", self.key, self.value)
    }
}

/// `text` read as a TOML value, or as a string when it is not one.
fn toml_value(text: &str) -> Value {
    format!("v = {text}")
        .parse::<Table>()
        .ok()
        .and_then(|mut t| t.remove("v"))
        .unwrap_or_else(|| Value::String(text.to_string()))
}

/// The settings as one line for a summary or a `#` header line: `geometry.helices = 16,
/// loading.target = 0.3`.
pub fn settings_line(settings: &[Setting]) -> String {
    settings
        .iter()
        .map(Setting::to_string)
        .collect::<Vec<_>>()
        .join(", ")
}

/// Sets the dotted `key` of a document to `value`, creating the tables on the way. Setting
/// `geometry.turns` removes `geometry.length` and the other way round (a case gives one).
pub fn set_key(doc: &mut Table, key: &str, value: Value) -> Result<(), String> {
    let parts: Vec<&str> = key.split('.').collect();
    let (last, path) = parts.split_last().expect("split gives one part at least");
    let mut table = doc;
    for (i, part) in path.iter().enumerate() {
        let entry = table
            .entry(part.to_string())
            .or_insert_with(|| Value::Table(Table::new()));
        table = match entry {
            Value::Table(t) => t,
            other => {
                return Err(format!(
                    "`{}` is {} in the case, not a table",
                    parts[..=i].join("."),
                    other.type_str()
                ))
            }
        };
    }
    if parts.len() == 2 && parts[0] == "geometry" {
        let other = match *last {
            "turns" => Some("length"),
            "length" => Some("turns"),
            _ => None,
        };
        if let Some(other) = other {
            table.remove(other);
        }
    }
    table.insert(last.to_string(), value);
    Ok(())
}

/// The text of the case file `text` (named `file`, its case named `name`) with `settings`
/// applied to its document, to be read by the case reader; the file is valid as it is.
pub(super) fn patched(
    text: &str,
    file: &str,
    name: &str,
    settings: &[Setting],
) -> Result<String, CaseError> {
    let mut doc: Table = text
        .parse()
        .map_err(|e: toml::de::Error| CaseError::syntax(&e, text, file))?;
    if !doc.contains_key("name") {
        doc.insert("name".into(), Value::String(name.to_string()));
    }
    for s in settings {
        set_key(&mut doc, &s.key, s.value.clone()).map_err(|message| CaseError::Set {
            file: file.to_string(),
            setting: s.as_flag(),
            message,
        })?;
    }
    toml::to_string(&doc).map_err(|e| CaseError::Set {
        file: file.to_string(),
        setting: settings.first().map_or_else(String::new, Setting::as_flag),
        message: format!("the case with it cannot be written as TOML: {e}"),
    })
}

/// The error of the case with `settings` applied, said about the setting its key belongs
/// to (the first setting when none does: the file alone was valid, so a setting made it
/// invalid).
pub(super) fn setting_error(file: &str, settings: &[Setting], e: &CaseError) -> CaseError {
    let key = e.key().unwrap_or("");
    let related = |s: &&Setting| {
        s.key == key
            || key.starts_with(&format!("{}.", s.key))
            || s.key.starts_with(&format!("{key}."))
    };
    let Some(s) = settings.iter().find(related).or(settings.first()) else {
        return CaseError::Set {
            file: file.to_string(),
            setting: String::new(),
            message: e.message(),
        };
    };
    let message = if key.is_empty() || related(&s) {
        e.message()
    } else {
        format!("with it, key `{key}`: {}", e.message())
    };
    CaseError::Set {
        file: file.to_string(),
        setting: s.as_flag(),
        message,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn setting(s: &str) -> Setting {
        s.parse().expect("a setting")
    }

    #[test]
    fn a_setting_reads_toml_values_and_bare_words_as_strings() {
        assert_eq!(setting("geometry.helices=16").value, Value::Integer(16));
        assert_eq!(setting("loading.target = 0.3").value, Value::Float(0.3));
        assert_eq!(
            setting("boundary.tip.translation=slide").value,
            Value::String("slide".into())
        );
        assert_eq!(
            setting("boundary.tip.translation=\"slide\"").value,
            Value::String("slide".into())
        );
        assert!(setting("boundary.tip={ translation = \"slide\" }")
            .value
            .is_table());
        assert_eq!(setting(" geometry . helices =8").key, "geometry.helices");
    }

    #[test]
    fn a_setting_without_key_or_value_is_refused() {
        for bad in [
            "geometry.helices",
            "=3",
            "geometry..helices=3",
            "geometry.helices=",
        ] {
            assert!(bad.parse::<Setting>().is_err(), "{bad}");
        }
    }
}
