//! `--set key=value` on a case: the override is put into the case file's document and read
//! by the same checks as the file, an error said about the setting and its key.

use spira::case::{Case, CaseError, Setting};

fn setting(s: &str) -> Setting {
    s.parse().expect("a setting")
}

#[test]
fn a_setting_overrides_the_key_and_is_checked_as_the_file_would_be() {
    let text = "[geometry]\nhelices = 8\n";
    let case = Case::parse_with(text, "c.toml", "c", &[setting("geometry.helices=16")])
        .expect("a valid override");
    assert_eq!(case.geometry.helices, 16);
    assert_eq!(case.name, "c");
    let e = Case::parse_with(text, "c.toml", "c", &[setting("geometry.helices=3")])
        .expect_err("3 helices");
    let shown = e.to_string();
    assert!(
        shown.starts_with("--set geometry.helices=3: expected "),
        "{shown}"
    );
    assert!(matches!(e, CaseError::Set { .. }), "{e:?}");
    assert_eq!(e.key(), Some("geometry.helices"));
    assert_eq!(e.file(), "c.toml");
    let e = Case::parse_with(text, "c.toml", "c", &[setting("geometry.helix=3")])
        .expect_err("an unknown key");
    assert!(e.to_string().contains("unknown field `helix`"), "{e}");
    assert_eq!(e.key(), Some("geometry.helix"));
    let e = Case::parse_with(text, "c.toml", "c", &[setting("geometry.helices.x=3")])
        .expect_err("a value is not a table");
    assert!(e.to_string().contains("not a table"), "{e}");
}

#[test]
fn a_setting_at_odds_with_another_key_of_the_file_is_refused_naming_the_setting() {
    let text = "[discretisation]\nelements = 12\n";
    Case::parse_with(text, "c.toml", "c", &[]).expect("valid as it is");
    let e = Case::parse_with(
        text,
        "c.toml",
        "c",
        &[setting("discretisation.accuracy=0.001")],
    )
    .expect_err("a mesh and an accuracy");
    let shown = e.to_string();
    assert!(
        shown.starts_with("--set discretisation.accuracy=0.001: "),
        "{shown}"
    );
    assert!(
        shown.contains("`elements`") && shown.contains("not both"),
        "{shown}"
    );
    // the same pair in the file is refused by the same check
    let both = "[discretisation]\nelements = 12\naccuracy = 0.001\n";
    let file_error = Case::parse_with(both, "c.toml", "c", &[]).expect_err("both in the file");
    assert_eq!(file_error.message(), e.message());
}

#[test]
fn turns_replace_the_length_of_the_file_and_a_name_stays() {
    let text = "name = \"mine\"\n[geometry]\nlength = 1.0\n";
    let case = Case::parse_with(text, "c.toml", "c", &[setting("geometry.turns=2")])
        .expect("turns instead of the length");
    assert!(case.geometry.length != 1.0);
    assert_eq!(case.name, "mine");
}

#[test]
fn the_files_own_error_comes_first() {
    let text = "[geometry]\nhelices = 5\n";
    let e = Case::parse_with(text, "c.toml", "c", &[setting("geometry.helices=8")])
        .expect_err("the file alone is invalid");
    assert_eq!(e.line(), Some(2), "{e}");
    assert!(
        e.to_string()
            .starts_with("c.toml:2: key `geometry.helices`"),
        "{e}"
    );
}
