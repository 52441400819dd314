//! Case files: the shipped cases parse to the thesis's values, and every kind of bad file in
//! `tests/invalid_cases/` is rejected with its own error, pointing at the file, the line and
//! the key, and saying what was expected.

use spira::case::{Case, CaseError};
use spira::discretisation::shape::Order;
use spira::model::boundary::{BoundaryConditions, EndCondition, Joints, Rotation, Translation};
use spira::solver::continuation::ContinuationSettings;
use std::f64::consts::PI;
use std::path::{Path, PathBuf};

fn manifest_dir() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn fixture(name: &str) -> PathBuf {
    manifest_dir()
        .join("tests/invalid_cases")
        .join(format!("{name}.toml"))
}

/// The error `Case::from_file` gives for a fixture, checked for what every case error must
/// carry: one line of text that starts with `file:line:`.
fn rejected(name: &str) -> CaseError {
    let path = fixture(name);
    let err = match Case::from_file(&path) {
        Ok(case) => panic!("{name}.toml was accepted: {case:?}"),
        Err(e) => e,
    };
    let text = err.to_string();
    let line = err
        .line()
        .unwrap_or_else(|| panic!("{name}: no line in {err:?}"));
    let file = path.display().to_string();
    assert_eq!(err.file(), file);
    assert!(
        text.starts_with(&format!("{file}:{line}: ")),
        "{name}: message does not start with file:line: {text}"
    );
    assert!(!text.contains('\n'), "{name}: not one line: {text}");
    err
}

/// Asserts the line, key and message fragments of an error.
fn check(err: &CaseError, line: usize, key: &str, fragments: &[&str]) {
    assert_eq!(err.line(), Some(line), "line of {err}");
    assert_eq!(err.key(), Some(key), "key of {err}");
    let text = err.to_string();
    assert!(
        text.contains(&format!("key `{key}`")),
        "key not named in: {text}"
    );
    for f in fragments {
        assert!(text.contains(f), "`{f}` missing from: {text}");
    }
}

fn is_unknown_key(e: &CaseError) -> bool {
    matches!(e, CaseError::UnknownKey { .. })
}
fn is_wrong_type(e: &CaseError) -> bool {
    matches!(e, CaseError::WrongType { .. })
}
fn is_invalid(e: &CaseError) -> bool {
    matches!(e, CaseError::Invalid { .. })
}

// ---- the folder of broken files ----

/// Every fixture, with the test below that checks its message. A new file in the folder
/// must be added here (and get a test), so none goes unchecked.
const FIXTURES: &[&str] = &[
    "accuracy-above-one",
    "accuracy-and-elements",
    "array-of-tables",
    "bad-order",
    "bad-translation",
    "float-for-integer",
    "infinite-target",
    "min-step-above-max-step",
    "nan-radius",
    "negative-b1",
    "negative-b3",
    "negative-radius",
    "odd-helices",
    "unknown-joint-kind",
    "elastic-without-springs",
    "negative-joint-stiffness",
    "springs-on-welded-joints",
    "string-for-number",
    "syntax-error",
    "target-at-base",
    "target-at-length",
    "target-below-base",
    "target-beyond-length",
    "turns-and-length",
    "unknown-key-in-inline-table",
    "unknown-key-in-table",
    "unknown-table",
    "unknown-top-level-key",
    "zero-elements",
    "zero-helices",
    "zero-pitch",
    "zero-steps",
    "date-for-number",
    "denormal-b1",
    "duplicate-key",
    "few-elements-per-turn",
    "flat-helix",
    "free-rotation-both-ends",
    "huge-helices",
    "huge-load-target",
    "huge-radius",
    "huge-turns",
    "imperfection-bow-on-helix",
    "imperfection-large-amplitude",
    "imperfection-mode-and-shape",
    "imperfection-no-amplitude",
    "imperfection-no-shape",
    "imperfection-unknown-shape",
    "loose-tolerance",
    "number-for-name",
    "sliding-both-ends",
    "sliding-in-a-tilted-cell",
    "stiffness-ratio",
    "tiny-turns",
    "too-many-joints",
];

#[test]
fn every_invalid_fixture_is_listed_and_rejected() {
    let mut found: Vec<String> = std::fs::read_dir(manifest_dir().join("tests/invalid_cases"))
        .expect("tests/invalid_cases exists")
        .map(|e| e.expect("readable entry").path())
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    found.sort();
    let mut listed: Vec<String> = FIXTURES.iter().map(|s| s.to_string()).collect();
    listed.sort();
    assert_eq!(found, listed, "tests/invalid_cases and FIXTURES differ");
    for name in FIXTURES {
        let text = rejected(name).to_string();
        // numbers in messages are short (no 309-digit 1e308)
        let longest = text
            .split(|c: char| !c.is_ascii_digit())
            .map(str::len)
            .max()
            .unwrap_or(0);
        assert!(longest <= 20, "{name}: a long number in: {text}");
    }
}

// ---- ranges of derived quantities, bounded work, messages in the user's terms ----

#[test]
fn a_radius_that_makes_the_length_infinite_is_refused() {
    let e = rejected("huge-radius");
    assert!(is_invalid(&e));
    check(
        &e,
        4,
        "geometry.radius",
        &["from 1e-6 to 1e6", "found 1e308"],
    );
}

#[test]
fn turns_that_overflow_the_mesh_or_vanish_are_refused() {
    check(
        &rejected("huge-turns"),
        3,
        "geometry.turns",
        &["from 0.01 to 1000", "found 1e308"],
    );
    check(
        &rejected("tiny-turns"),
        3,
        "geometry.turns",
        &["from 0.01 to 1000", "found 1e-300"],
    );
}

#[test]
fn millions_of_joints_are_refused_before_any_is_built() {
    let t = std::time::Instant::now();
    check(
        &rejected("too-many-joints"),
        3,
        "geometry.helices",
        &["1024 helices", "pin joints", "at most 1000000"],
    );
    assert!(t.elapsed().as_secs_f64() < 1.0);
}

#[test]
fn a_subnormal_stiffness_is_refused() {
    check(
        &rejected("denormal-b1"),
        3,
        "stiffness.b1",
        &["from 1e-12 to 1e12", "found 5e-324"],
    );
}

#[test]
fn stiffness_and_pitch_ratios_are_bounded() {
    check(
        &rejected("stiffness-ratio"),
        4,
        "stiffness.b3",
        &["B3/B1 from 0.0001 to 10000", "found 1e6"],
    );
    check(
        &rejected("flat-helix"),
        4,
        "geometry.pitch",
        &["pitch/radius ratio b/a from 0.001 to 1000", "found 0.0001"],
    );
}

#[test]
fn too_few_elements_per_turn_are_refused() {
    check(
        &rejected("few-elements-per-turn"),
        5,
        "discretisation.elements",
        &["elements per turn", "found 0.1"],
    );
}

#[test]
fn a_tolerance_that_accepts_the_initial_guess_is_refused() {
    check(
        &rejected("loose-tolerance"),
        3,
        "solver.tolerance",
        &["from 1e-14 to 1e-6", "not equilibria", "found 1"],
    );
}

#[test]
fn a_load_control_target_is_bounded() {
    check(
        &rejected("huge-load-target"),
        4,
        "loading.target",
        &["P/Pcrit from -100 to 100", "found 1e9"],
    );
}

#[test]
fn a_whole_number_beyond_64_bits_is_out_of_range_not_a_fraction() {
    let e = rejected("huge-helices");
    check(
        &e,
        3,
        "geometry.helices",
        &["9223372036854775808", "out of range"],
    );
    assert!(!e.to_string().contains("expected a whole number"), "{e}");
}

#[test]
fn a_date_for_a_number_says_date() {
    let e = rejected("date-for-number");
    assert!(is_wrong_type(&e));
    check(
        &e,
        3,
        "geometry.radius",
        &["expected a number", "TOML date", "1979-05-27"],
    );
    assert!(!e.to_string().contains("$__"), "{e}");
}

#[test]
fn a_duplicate_key_is_named() {
    let e = rejected("duplicate-key");
    assert_eq!(e.line(), Some(4));
    assert!(e.to_string().contains("duplicate key `radius`"), "{e}");
}

#[test]
fn a_number_for_a_name_lists_the_names() {
    let e = rejected("number-for-name");
    assert!(is_wrong_type(&e));
    check(
        &e,
        3,
        "loading.control",
        &["expected one of \"displacement\", \"force\"", "found `3`"],
    );
}

#[test]
fn free_rigid_motions_are_refused_naming_them() {
    let e = rejected("free-rotation-both-ends");
    check(
        &e,
        4,
        "boundary.tip.rotation",
        &[
            "spherical hinges",
            "turn about its chord",
            "free rigid motion",
        ],
    );
    let e = rejected("sliding-both-ends");
    check(
        &e,
        4,
        "boundary.tip.translation",
        &["both ends slide", "translate sideways", "free rigid motion"],
    );
    // joints tie the two rods into one body: hinged at both ends it is held at the base,
    // where the rods meet, and at the tip, where they meet again after a whole number of
    // half turns (the thesis's 3.5), so it turns about the line between
    let hinged = "[boundary]\nbase = { rotation = \"free\" }\ntip = { rotation = \"free\" }\n";
    let text = format!("[geometry]\nhelices = 2\n{hinged}");
    let e = Case::parse(&text, "hinged.toml", "hinged").expect_err("a free rotation");
    check(
        &e,
        5,
        "boundary.tip.rotation",
        &[
            "the assembly may turn as a whole about its chord",
            "free rigid motion",
        ],
    );
    // tips apart (1.3 turns): the body is held at three points, nothing is free
    let text = format!("[geometry]\nhelices = 2\nturns = 1.3\n{hinged}");
    Case::parse(&text, "hinged.toml", "hinged").unwrap_or_else(|e| panic!("{e}"));
    // the report: one end sliding, the other sliding radially, n = 1
    let e = Case::parse(
        "[boundary]\nbase = { translation = \"slide\" }\ntip = { translation = \"radial\" }\n",
        "radial.toml",
        "radial",
    )
    .expect_err("a free translation");
    check(
        &e,
        3,
        "boundary.tip.translation",
        &[
            "the base slides and the tip slides radially",
            "translate sideways as a whole",
            "free rigid motion",
        ],
    );
}

#[test]
fn accepted_cases_have_finite_bounded_derived_quantities_and_a_size() {
    for name in [
        "thesis-n1",
        "thesis-n2",
        "thesis-n4",
        "thesis-n8",
        "euler-clamped",
        "euler-pinned",
        "elastica",
    ] {
        let case = Case::from_file(&manifest_dir().join("cases").join(format!("{name}.toml")))
            .unwrap_or_else(|e| panic!("{e}"));
        let g = case.geometry;
        assert!(g.length.is_finite() && g.height0().is_finite() && g.height0() > 0.0);
        let pcrit = case.stiffness.euler_load(g.length);
        assert!(pcrit.is_finite() && pcrit > 0.0);
        let size = case.size_estimate();
        assert!(size.unknowns.is_finite() && size.memory_bytes().is_finite());
        // the estimate is an upper bound of the unknowns within a factor 2
        let exact = spira::run::run_path(&case, &[], |_, _| {})
            .map(|o| o.unknowns as f64)
            .unwrap_or(size.unknowns);
        assert!(
            size.unknowns >= exact && size.unknowns <= 2.0 * exact,
            "{name}: estimated {} unknowns, exactly {exact}",
            size.unknowns
        );
    }
}

#[test]
fn unknown_top_level_key() {
    let e = rejected("unknown-top-level-key");
    assert!(is_unknown_key(&e), "{e:?}");
    check(
        &e,
        2,
        "nmae",
        &["unknown field `nmae`", "`name`", "`geometry`"],
    );
}

#[test]
fn unknown_key_in_a_table() {
    let e = rejected("unknown-key-in-table");
    assert!(is_unknown_key(&e), "{e:?}");
    check(
        &e,
        4,
        "geometry.radios",
        &["unknown field `radios`", "expected one of", "`radius`"],
    );
}

#[test]
fn unknown_key_in_an_inline_table() {
    let e = rejected("unknown-key-in-inline-table");
    assert!(is_unknown_key(&e), "{e:?}");
    check(
        &e,
        4,
        "boundary.tip.rotaton",
        &["unknown field `rotaton`", "`rotation`"],
    );
}

#[test]
fn unknown_table() {
    let e = rejected("unknown-table");
    assert!(is_unknown_key(&e), "{e:?}");
    check(
        &e,
        5,
        "material",
        &["unknown table `[material]`", "`stiffness`"],
    );
}

#[test]
fn string_where_a_number_is_expected() {
    let e = rejected("string-for-number");
    assert!(is_wrong_type(&e), "{e:?}");
    check(
        &e,
        4,
        "geometry.radius",
        &["invalid type", "string \"0.06\"", "expected a number"],
    );
}

#[test]
fn fraction_where_a_whole_number_is_expected() {
    let e = rejected("float-for-integer");
    assert!(is_wrong_type(&e), "{e:?}");
    check(
        &e,
        3,
        "geometry.helices",
        &["invalid type", "2.5", "expected a whole number"],
    );
}

#[test]
fn an_unknown_joint_kind_is_refused_with_the_kinds() {
    let e = rejected("unknown-joint-kind");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "boundary.joints",
        &[
            "\"yes\"",
            "true (pin), false (none)",
            "\"welded\"",
            "\"elastic\"",
        ],
    );
}

#[test]
fn elastic_joints_without_springs_are_refused() {
    let e = rejected("elastic-without-springs");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "boundary.joint_stiffness",
        &["scissor", "out_of_plane", "N m/rad"],
    );
}

#[test]
fn a_negative_spring_is_refused_at_its_line() {
    let e = rejected("negative-joint-stiffness");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        5,
        "boundary.joint_stiffness.out_of_plane",
        &["from 0 to 1e12", "found -2"],
    );
}

#[test]
fn springs_on_joints_that_are_not_elastic_are_refused() {
    let e = rejected("springs-on-welded-joints");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        5,
        "boundary.joint_stiffness",
        &["joints = \"elastic\"", "found joints = welded"],
    );
}

#[test]
fn sliding_joints_in_a_tilted_cell_are_refused() {
    let e = rejected("sliding-in-a-tilted-cell");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        6,
        "boundary.joints",
        &[
            "bending cell does not carry sliding crossings",
            "found \"sliding\"",
        ],
    );
}

#[test]
fn sliding_joints_in_a_straight_cell_are_read() {
    let case = Case::parse(
        "[geometry]\nhelices = 8\n[boundary]\njoints = \"sliding\"\n[discretisation]\nmodel = \"cell\"\n",
        "s.toml",
        "s",
    )
    .unwrap_or_else(|e| panic!("{e}"));
    let m = case.model();
    assert_eq!(m.rods.len(), 2);
    // the cell's one crossing, at its rods' near ends, slides
    assert_eq!(m.slides.len(), 1);
}

#[test]
fn sliding_joints_choose_the_symmetric_pair_automatically() {
    let read = |model: &str| {
        Case::parse(
            &format!("[geometry]\nhelices = 8\n[boundary]\njoints = \"sliding\"\n[discretisation]\nmodel = \"{model}\"\n"),
            "s.toml",
            "s",
        )
        .unwrap_or_else(|e| panic!("{e}"))
    };
    for (model, rods) in [("auto", 2), ("pair", 2), ("full", 8)] {
        let case = read(model);
        assert_eq!(case.discretisation.symmetric, rods == 2, "{model}");
        let m = case.model();
        assert_eq!(m.rods.len(), rods, "{model}");
        assert!(!m.slides.is_empty(), "{model}");
    }
}

#[test]
fn joint_kinds_read_as_their_names_and_flags() {
    use spira::model::boundary::JointStiffness;
    let read = |text: &str| {
        Case::parse(&format!("[boundary]\n{text}\n"), "j.toml", "j")
            .unwrap_or_else(|e| panic!("{e}"))
            .boundary
            .joints
    };
    assert_eq!(read("joints = true"), Joints::Pin);
    assert_eq!(read("joints = \"pin\""), Joints::Pin);
    assert_eq!(read("joints = false"), Joints::None);
    assert_eq!(read("joints = \"none\""), Joints::None);
    assert_eq!(read("joints = \"welded\""), Joints::Welded);
    assert_eq!(read("joints = \"sliding\""), Joints::Sliding);
    assert_eq!(
        read("joints = \"elastic\"\njoint_stiffness = { scissor = 0.5, out_of_plane = 0 }"),
        Joints::Elastic(JointStiffness {
            scissor: 0.5,
            out_of_plane: 0.0
        })
    );
}

#[test]
fn array_of_tables_instead_of_a_table() {
    let e = rejected("array-of-tables");
    assert!(is_wrong_type(&e), "{e:?}");
    check(
        &e,
        2,
        "geometry",
        &["expected a table `[geometry]`", "array of tables"],
    );
}

#[test]
fn toml_syntax_error() {
    let e = rejected("syntax-error");
    assert!(matches!(e, CaseError::Syntax { .. }), "{e:?}");
    assert_eq!(e.line(), Some(2));
    assert_eq!(e.key(), None);
    let text = e.to_string();
    assert!(text.contains("not valid TOML"), "{text}");
    assert!(text.contains("expected `]`"), "{text}");
}

#[test]
fn negative_radius() {
    let e = rejected("negative-radius");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        4,
        "geometry.radius",
        &["positive radius", "found -0.06"],
    );
}

#[test]
fn not_a_number_radius() {
    let e = rejected("nan-radius");
    assert!(is_invalid(&e), "{e:?}");
    check(&e, 3, "geometry.radius", &["positive radius", "found NaN"]);
}

#[test]
fn zero_pitch() {
    let e = rejected("zero-pitch");
    assert!(is_invalid(&e), "{e:?}");
    check(&e, 4, "geometry.pitch", &["positive pitch", "found 0"]);
}

#[test]
fn negative_bending_stiffness() {
    let e = rejected("negative-b1");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "stiffness.b1",
        &["positive bending stiffness", "found -1"],
    );
}

#[test]
fn negative_torsional_stiffness() {
    let e = rejected("negative-b3");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        5,
        "stiffness.b3",
        &["positive torsional stiffness", "found -2"],
    );
}

#[test]
fn odd_number_of_helices() {
    let e = rejected("odd-helices");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "geometry.helices",
        &["1 or an even number", "right- and left-handed", "found 3"],
    );
}

#[test]
fn zero_helices() {
    let e = rejected("zero-helices");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "geometry.helices",
        &["number of helices from 1", "found 0"],
    );
}

#[test]
fn zero_steps() {
    let e = rejected("zero-steps");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        4,
        "loading.steps",
        &["number of output steps from 1", "found 0"],
    );
}

#[test]
fn zero_elements() {
    let e = rejected("zero-elements");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "discretisation.elements",
        &["number of elements per rod from 1", "found 0"],
    );
}

#[test]
fn unknown_element_order() {
    let e = rejected("bad-order");
    assert!(is_wrong_type(&e), "{e:?}");
    check(
        &e,
        4,
        "discretisation.order",
        &["unknown variant `cubic`", "`linear`", "`quadratic`"],
    );
}

#[test]
fn unknown_translation_in_an_inline_table() {
    let e = rejected("bad-translation");
    assert!(is_wrong_type(&e), "{e:?}");
    check(
        &e,
        4,
        "boundary.base.translation",
        &[
            "unknown variant `sideways`",
            "`fixed`",
            "`slide`",
            "`radial`",
        ],
    );
}

#[test]
fn both_turns_and_length() {
    let e = rejected("turns-and-length");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        5,
        "geometry.length",
        &["either `turns` or `length`, not both"],
    );
}

#[test]
fn accuracy_and_elements_together() {
    let e = rejected("accuracy-and-elements");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        4,
        "discretisation.accuracy",
        &["either `elements` (a mesh) or `accuracy`", "not both"],
    );
}

#[test]
fn accuracy_above_one() {
    let e = rejected("accuracy-above-one");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "discretisation.accuracy",
        &["a relative accuracy between 0 and 1", "found 5"],
    );
}

#[test]
fn accuracy_replaces_the_mesh_and_may_name_the_order() {
    let case = Case::parse(
        "[discretisation]\naccuracy = 1e-4\norder = \"linear\"\n",
        "a.toml",
        "a",
    )
    .expect("valid");
    let acc = case.discretisation.accuracy.expect("an accuracy");
    assert_eq!(acc.target, 1e-4);
    assert_eq!(acc.order, Some(Order::Linear));
    let case = Case::parse("[discretisation]\naccuracy = 1e-2\n", "a.toml", "a").expect("valid");
    assert_eq!(case.discretisation.accuracy.unwrap().order, None);
    // no accuracy: the mesh as given
    assert_eq!(
        Case::parse("", "a.toml", "a")
            .unwrap()
            .discretisation
            .accuracy,
        None
    );
    for bad in ["0", "-1e-3", "1.0", "nan"] {
        let e = Case::parse(
            &format!("[discretisation]\naccuracy = {bad}\n"),
            "a.toml",
            "a",
        )
        .expect_err(bad);
        assert_eq!(e.key(), Some("discretisation.accuracy"), "{bad}: {e}");
    }
}

#[test]
fn min_step_above_max_step() {
    let e = rejected("min-step-above-max-step");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        4,
        "solver.min_step",
        &["min_step ≤ max_step", "min_step = 0.05", "max_step = 0.01"],
    );
}

#[test]
fn target_with_the_tip_on_the_base() {
    let e = rejected("target-at-base");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "loading.target",
        &["compression ratio", "(-1.6, 1)", "found 1:", "on the base"],
    );
}

#[test]
fn target_with_the_tip_below_the_base() {
    let e = rejected("target-below-base");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "loading.target",
        &["compression ratio", "found 1.5", "below the base"],
    );
}

#[test]
fn target_with_the_rod_pulled_straight() {
    // a = 0.75, b = 1: c = 1.25, h0 = b L / c = 4 for L = 5, so eps = 1 - L/h0 = -0.25 exactly
    let e = rejected("target-at-length");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        9,
        "loading.target",
        &[
            "compression ratio",
            "(-0.25, 1)",
            "found -0.25",
            "equal to the rod length L = 5 m",
        ],
    );
}

#[test]
fn target_beyond_the_rod_length() {
    // thesis geometry: L/h0 = c/b = 2.6, so extension is bounded by eps > -1.6
    let e = rejected("target-beyond-length");
    assert!(is_invalid(&e), "{e:?}");
    check(
        &e,
        3,
        "loading.target",
        &[
            "compression ratio",
            "(-1.6, 1)",
            "found -2",
            "beyond the rod length",
        ],
    );
}

#[test]
fn infinite_target() {
    let e = rejected("infinite-target");
    assert!(is_invalid(&e), "{e:?}");
    check(&e, 3, "loading.target", &["compression ratio", "found inf"]);
}

#[test]
fn missing_file_is_an_io_error_naming_it() {
    let path = manifest_dir().join("tests/invalid_cases/no-such-case.toml");
    let e = Case::from_file(&path).expect_err("a missing file is an error");
    assert!(matches!(e, CaseError::Io { .. }), "{e:?}");
    assert_eq!(e.line(), None);
    let text = e.to_string();
    assert!(text.contains("no-such-case.toml"), "{text}");
    // said once, not repeated by a report that walks the error chain
    assert!(std::error::Error::source(&e).is_none());
}

// ---- valid cases ----

/// The thesis geometry (§4.1): a = 0.06 m, b = 0.025 m, c = 0.065 m, L = 7 π c.
fn assert_thesis_geometry(case: &Case, name: &str) {
    let g = &case.geometry;
    assert_eq!(g.radius, 0.06, "{name}");
    assert_eq!(g.pitch, 0.025, "{name}");
    assert!((g.c() - 0.065).abs() < 1e-12, "{name}: c = {}", g.c());
    let length = 7.0 * PI * 0.065;
    assert!(
        (g.length - length).abs() < 1e-12,
        "{name}: L = {}, expected 7 pi c = {length}",
        g.length
    );
    assert!((g.turns() - 3.5).abs() < 1e-12, "{name}");
    // h0 = 7 pi b
    assert!((g.height0() - 7.0 * PI * 0.025).abs() < 1e-12, "{name}");
    let s = &case.stiffness;
    assert_eq!((s.b1, s.b2, s.b3), (1.0, 1.0, 2.0), "{name}");
}

#[test]
fn every_shipped_case_parses() {
    let (mut count, mut sweeps) = (0, 0);
    for entry in std::fs::read_dir(manifest_dir().join("cases")).expect("cases/ exists") {
        let path = entry.expect("readable entry").path();
        if path.extension().is_some_and(|x| x == "toml") {
            let stem = path.file_stem().expect("a name").to_string_lossy();
            if stem.starts_with("sweep-") {
                // a sweep file: every case it generates is valid
                spira::sweep::Sweep::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
                sweeps += 1;
            } else {
                Case::from_file(&path).unwrap_or_else(|e| panic!("{e}"));
                count += 1;
            }
        }
    }
    assert!(count >= 4, "expected the four thesis cases, found {count}");
    assert!(
        sweeps >= 2,
        "expected the two shipped sweeps, found {sweeps}"
    );
}

#[test]
fn thesis_cases_have_the_thesis_values() {
    for n in [1, 2, 4, 8] {
        let name = format!("thesis-n{n}");
        let case = Case::from_file(&manifest_dir().join(format!("cases/{name}.toml")))
            .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(case.name, name);
        assert_eq!(case.geometry.helices, n, "{name}");
        assert_thesis_geometry(&case, &name);
        let clamped = EndCondition {
            translation: Translation::Fixed,
            rotation: Rotation::Clamped,
        };
        assert_eq!(case.boundary.base, clamped, "{name}");
        assert_eq!(case.boundary.tip, clamped, "{name}");
        assert_eq!(case.boundary.joints, Joints::Pin, "{name}");
        assert_eq!(case.loading.target, 0.5, "{name}");
        assert!(case.discretisation.elements >= 48, "{name}");
        assert_eq!(case.discretisation.order, Order::Quadratic, "{name}");
    }
}

#[test]
fn minimal_case_takes_the_thesis_defaults() {
    let case = Case::parse("[geometry]\nhelices = 2\n", "minimal.toml", "minimal")
        .unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(case.name, "minimal");
    assert_eq!(case.geometry.helices, 2);
    assert_thesis_geometry(&case, "minimal");
    assert_eq!(case.boundary, BoundaryConditions::default());
    assert_eq!(case.boundary.base, EndCondition::CLAMPED);
    assert_eq!(case.boundary.joints, Joints::Pin);
    assert_eq!(case.loading.target, 0.5);
    assert_eq!(case.loading.steps, 10);
    assert_eq!(case.discretisation.elements, 48);
    assert_eq!(case.discretisation.order, Order::Quadratic);
    assert_eq!(case.solver, ContinuationSettings::default());
}

#[test]
fn empty_case_is_one_thesis_helix() {
    let case = Case::parse("", "empty.toml", "empty").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(case.geometry.helices, 1);
    assert_thesis_geometry(&case, "empty");
}

#[test]
fn half_an_end_condition_keeps_the_other_half() {
    let text = "[boundary]\ntip = { translation = \"slide\" }\nbase = { rotation = \"free\" }\n";
    let case = Case::parse(text, "ends.toml", "ends").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(
        case.boundary.tip,
        EndCondition {
            translation: Translation::Slide,
            rotation: Rotation::Clamped
        }
    );
    assert_eq!(
        case.boundary.base,
        EndCondition {
            translation: Translation::Fixed,
            rotation: Rotation::Free
        }
    );
}

#[test]
fn length_may_be_given_instead_of_turns() {
    let text = "[geometry]\nhelices = 4\nlength = 1.5\n";
    let case = Case::parse(text, "length.toml", "length").unwrap_or_else(|e| panic!("{e}"));
    assert_eq!(case.geometry.length, 1.5);
    assert!((case.geometry.turns() - 1.5 / (2.0 * PI * 0.065)).abs() < 1e-12);
}

#[test]
fn default_case_is_the_thesis_n8_case() {
    let case = Case::default_case();
    assert_eq!(case.geometry.helices, 8);
    assert_eq!(case.name, "thesis-n8");
    assert_thesis_geometry(&case, "default");
    let file = Case::from_file(&manifest_dir().join("cases/thesis-n8.toml")).unwrap();
    assert_eq!(case, file);
}

#[test]
fn target_check_names_the_limit_crossed() {
    let case = Case::default_case();
    assert_eq!(case.check_target(0.5), Ok(()));
    assert_eq!(case.check_target(-1.5), Ok(()));
    let base = case.check_target(1.2).unwrap_err();
    assert!(base.to_string().contains("below the base"), "{base}");
    let length = case.check_target(-2.0).unwrap_err();
    assert!(
        length.to_string().contains("beyond the rod length"),
        "{length}"
    );
    let nan = case.check_target(f64::NAN).unwrap_err();
    assert!(nan.to_string().contains("found NaN"), "{nan}");
}

#[test]
fn output_steps_are_equally_spaced_up_to_the_target() {
    let case = Case::default_case();
    let eps = case.output_parameters(0.3, 3);
    assert_eq!(eps.len(), 3);
    for (k, e) in eps.iter().enumerate() {
        assert!((e - 0.1 * (k + 1) as f64).abs() < 1e-15, "{eps:?}");
    }
    assert_eq!(*eps.last().unwrap(), 0.3);
}

// ---------------------------------------------------------------- elastic hypotheses

#[test]
fn the_elastic_hypotheses_default_to_kirchhoff_rods_stress_free_in_their_discrete_helix() {
    use spira::discretisation::discrete_model::Reference;
    use spira::model::elasticity::{Elasticity, Energy, StressFree};
    let case = Case::parse("", "empty.toml", "empty").unwrap();
    assert_eq!(case.rod, Elasticity::default());
    assert_eq!(case.rod.stress_free, StressFree::Helix);
    assert_eq!(case.rod.energy, Energy::Kirchhoff);
    assert_eq!(case.discretisation.reference, Reference::Discrete);
    let text = "[rod]\nstress_free = \"straight\"\nenergy = \"sadowsky\"\nwidth = 0.02\nthickness = 2e-4\n[discretisation]\nreference = \"continuum\"\n";
    let case = Case::parse(text, "ribbon.toml", "ribbon").unwrap();
    assert_eq!(case.rod.stress_free, StressFree::Straight);
    match case.rod.energy {
        Energy::Sadowsky(r) => {
            assert_eq!((r.width, r.thickness), (0.02, 2e-4));
            // η = √60 t / w²
            assert!((r.regularisation() - 60f64.sqrt() * 2e-4 / 4e-4).abs() < 1e-12);
        }
        Energy::Kirchhoff => panic!("expected a ribbon"),
    }
    assert_eq!(case.discretisation.reference, Reference::Continuum);
}

fn refused(text: &str) -> CaseError {
    Case::parse(text, "rod.toml", "rod").expect_err("refused")
}

#[test]
fn a_ribbon_stress_free_when_helical_is_refused_naming_the_key() {
    // Sadowsky's ribbon is stress-free when flat; with the default stress_free = "helix"
    let e = refused(
        "[geometry]\nhelices = 2\n[rod]\nenergy = \"sadowsky\"\nwidth = 0.02\nthickness = 1e-4\n",
    );
    check(
        &e,
        4,
        "rod.energy",
        &["rod.toml:4", "stress_free = \"straight\"", "flat"],
    );
    assert!(is_invalid(&e));
    let e = refused(
        "[rod]\nstress_free = \"helix\"\nenergy = \"sadowsky\"\nwidth = 0.02\nthickness = 1e-4\n",
    );
    check(&e, 3, "rod.energy", &["straight"]);
}

#[test]
fn a_ribbon_needs_its_width_and_thickness_and_a_rod_refuses_them() {
    let e = refused("[rod]\nstress_free = \"straight\"\nenergy = \"sadowsky\"\nthickness = 1e-4\n");
    check(&e, 3, "rod.width", &["width", "regularisation"]);
    let e = refused("[rod]\nstress_free = \"straight\"\nenergy = \"sadowsky\"\nwidth = 0.01\nthickness = 0.02\n");
    check(&e, 5, "rod.thickness", &["thinner", "0.01", "0.02"]);
    let e = refused("[rod]\nstress_free = \"straight\"\nenergy = \"sadowsky\"\nwidth = -1.0\nthickness = 1e-4\n");
    check(&e, 4, "rod.width", &["positive length", "-1"]);
    let e = refused("[rod]\nwidth = 0.02\n");
    check(&e, 2, "rod.width", &["sadowsky"]);
}

#[test]
fn an_unknown_hypothesis_lists_the_names() {
    let e = refused("[rod]\nenergy = \"cosserat\"\n");
    check(
        &e,
        2,
        "rod.energy",
        &["cosserat", "`kirchhoff` or `sadowsky`"],
    );
    let e = refused("[rod]\nstress_free = \"curved\"\n");
    check(&e, 2, "rod.stress_free", &["`helix` or `straight`"]);
    let e = refused("[discretisation]\nreference = \"exact\"\n");
    check(
        &e,
        2,
        "discretisation.reference",
        &["`discrete` or `continuum`"],
    );
}

/// A symmetric pair of n = 2m rods judges stability by ⌊m/2⌋ + 1 Bloch blocks (p = 0 ..=
/// m/2, docs/theory.md §7), of which p = 0 and, for even m, p = m/2 are real and the others
/// complex (the pair's pattern with complex entries: four times a real block's work): the
/// size estimate counts that work, so that a pair of many helices is long (its estimate
/// printed) and one whose block factorisations exceed the memory is refused naming the key.
#[test]
fn the_size_estimate_counts_the_bloch_blocks_of_a_symmetric_pair() {
    let parse =
        |text: &str| Case::parse(text, "pair.toml", "pair").unwrap_or_else(|e| panic!("{e}"));
    for (n, blocks, real) in [
        (4usize, 2.0, 2.0),
        (6, 2.0, 1.0),
        (8, 3.0, 2.0),
        (512, 129.0, 2.0),
    ] {
        let pair = parse(&format!("[geometry]\nhelices = {n}\n"));
        assert!(pair.discretisation.symmetric, "n = {n}: auto is the pair");
        let size = pair.size_estimate();
        assert_eq!(size.blocks, blocks, "n = {n}");
        let complex = blocks - real;
        assert!(
            (size.block_entries - (real + 4.0 * complex) * size.factor_entries).abs()
                <= 1e-9 * size.block_entries,
            "n = {n}"
        );
        // the full model has no blocks, and the pair's blocks cost memory and time
        let full = parse(&format!(
            "[geometry]\nhelices = {n}\n[discretisation]\nsymmetric = false\n"
        ))
        .size_estimate();
        assert_eq!(full.blocks, 0.0);
        assert_eq!(full.block_seconds_per_step(), 0.0);
        assert!(size.block_seconds_per_step() > 0.0);
    }
    // 512 helices under auto: 2304 joints per rod, a pair of 88 k unknowns whose 129
    // blocks per check make each load step long; its estimate says so
    let n512 = parse("[geometry]\nhelices = 512\n").size_estimate();
    assert!(n512.is_large());
    assert!(n512.block_seconds_per_step() > spira::case::LONG_STEP_SECONDS);
    let said = n512.to_string();
    assert!(said.contains("129 Bloch blocks per check"), "{said}");
    assert!(said.contains("per load step"), "{said}");
    // a small pair is not long
    let n8 = parse("[geometry]\nhelices = 8\n").size_estimate();
    assert!(!n8.is_large(), "{n8}");
    // a pair whose blocks exceed the memory is refused with the key to change
    let fine = parse("[geometry]\nhelices = 512\n[discretisation]\nelements = 30000\n");
    let est = fine.size_estimate();
    let e = est
        .check_fits(Some(8e9))
        .expect_err("more than 8 GB of block factorisations");
    let msg = e.to_string();
    assert!(msg.contains("`discretisation.elements`"), "{msg}");
    assert!(msg.contains("Bloch blocks"), "{msg}");
    // without the blocks it would have fitted: the pair's own solve is a few GB
    assert!(est.memory_bytes() - 2.0 * 2.0 * 24.0 * est.factor_entries < 8e9);
}

#[test]
fn imperfections_are_checked_key_by_key() {
    let cases: [(&str, usize, &str, &[&str]); 6] = [
        (
            "imperfection-bow-on-helix",
            3,
            "imperfection.shape",
            &["straight rod", "found radius 0.06 m"],
        ),
        (
            "imperfection-large-amplitude",
            3,
            "imperfection.amplitude",
            &["from -0.1 to 0.1", "found 0.5"],
        ),
        (
            "imperfection-mode-and-shape",
            3,
            "imperfection.shape",
            &["one of `mode` or `shape`", "found both"],
        ),
        (
            "imperfection-no-amplitude",
            4,
            "imperfection.amplitude",
            &["an amplitude", "found none"],
        ),
        (
            "imperfection-no-shape",
            1,
            "imperfection",
            &["`mode = k`", "found neither"],
        ),
        (
            "imperfection-unknown-shape",
            2,
            "imperfection.shape",
            &["one of \"bow\"", "found \"kink\""],
        ),
    ];
    for (name, line, key, fragments) in cases {
        let e = rejected(name);
        assert!(is_invalid(&e), "{name}: {e:?}");
        check(&e, line, key, fragments);
    }
}

#[test]
fn shipped_imperfect_cases_read_their_flaws() {
    use spira::case::{Imperfection, ImperfectionShape};
    let case = Case::from_file(&manifest_dir().join("cases/euler-clamped-imperfect.toml"))
        .expect("shipped case");
    assert_eq!(
        case.imperfection,
        Some(Imperfection {
            shape: ImperfectionShape::Mode(0),
            amplitude: 1e-3
        })
    );
    // a negative amplitude takes the other side of the mode
    let text = "[imperfection]\nmode = 2\namplitude = -0.05\n";
    let case = Case::parse(text, "flaw.toml", "flaw").expect("valid");
    assert_eq!(case.imperfection.map(|i| i.amplitude), Some(-0.05));
    // no table: the perfect structure
    assert_eq!(Case::parse("", "p.toml", "p").unwrap().imperfection, None);
}
