//! The `spira run` command end to end: the real binary on small cases, its output files,
//! its exit status and its messages.

use crate::common;

use std::f64::consts::PI;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const LOAD_COLUMNS: &str = "step,eps,h,fx,fy,fz,energy,iterations,residual,stable,unstable_dirs,lowest_eig,parameter,twist,torque,torque_norm,tilt,bending_moment,bending_moment_norm,pressure,radius,lateral_pressure";
const REACTION_COLUMNS: &str = "step,eps,rod,chirality,fx,fy,fz,mx,my,mz";
const STATE_COLUMNS: &str = "rod,s,s_over_l,x,y,z,q1,q2,q3,q4,k1,k2,omega,nx,ny,nz";
const OUTPUTS: [&str; 3] = ["load.csv", "reactions.csv", "state.csv"];

/// Thesis geometry: h0 = 7 π b, L = 7 π c.
const H0: f64 = 7.0 * PI * 0.025;
const LENGTH: f64 = 7.0 * PI * 0.065;

/// A scratch folder under the system's temporary folder, removed when dropped.
struct Scratch(PathBuf);

impl Scratch {
    fn new(test: &str) -> Scratch {
        let dir = std::env::temp_dir().join(format!("spira-cli-{}-{test}", std::process::id()));
        let _ = std::fs::remove_dir_all(&dir);
        std::fs::create_dir_all(&dir).expect("create scratch folder");
        Scratch(dir)
    }
    fn path(&self, name: &str) -> PathBuf {
        self.0.join(name)
    }
    fn write(&self, name: &str, text: &str) -> PathBuf {
        let p = self.path(name);
        std::fs::write(&p, text).expect("write case");
        p
    }
}

impl Drop for Scratch {
    fn drop(&mut self) {
        let _ = std::fs::remove_dir_all(&self.0);
    }
}

/// Runs `spira` with `args` inside `dir` (so that nothing lands in the source tree).
pub(crate) fn spira(dir: &Path, args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(args)
        .current_dir(dir)
        .env("NO_COLOR", "1")
        .output()
        .expect("run the spira binary")
}

/// `spira run CASE --out OUT EXTRA...` inside `dir`.
fn spira_run(dir: &Scratch, case: &Path, out: &Path, extra: &[&str]) -> Output {
    let mut args = vec![
        "run",
        case.to_str().unwrap(),
        "--out",
        out.to_str().unwrap(),
    ];
    args.extend_from_slice(extra);
    spira(&dir.0, &args)
}

fn stderr(out: &Output) -> String {
    String::from_utf8_lossy(&out.stderr).into_owned()
}

fn assert_success(out: &Output) {
    assert!(
        out.status.success(),
        "spira failed ({:?})\nstdout:\n{}\nstderr:\n{}",
        out.status,
        String::from_utf8_lossy(&out.stdout),
        stderr(out)
    );
}

/// A failure whose report is one paragraph on stderr; returns it.
fn assert_failure(out: &Output) -> String {
    assert!(
        !out.status.success(),
        "spira succeeded where it should fail\nstdout:\n{}",
        String::from_utf8_lossy(&out.stdout)
    );
    let err = stderr(out);
    let text = err.trim();
    assert!(
        text.starts_with("spira: error: "),
        "not an error report: {err}"
    );
    assert!(!text.contains("\n\n"), "more than one paragraph: {err}");
    assert!(!text.contains("panicked"), "a panic, not a message: {err}");
    err
}

fn assert_no_outputs(dir: &Path) {
    for name in OUTPUTS {
        assert!(
            !dir.join(name).exists(),
            "{name} written although the run was refused"
        );
    }
}

/// A CSV file: the `#` comment lines, the header, and the rows split into fields.
struct Csv {
    comments: Vec<String>,
    header: String,
    rows: Vec<Vec<String>>,
}

impl Csv {
    fn read(path: &Path) -> Csv {
        let text = std::fs::read_to_string(path)
            .unwrap_or_else(|e| panic!("cannot read {}: {e}", path.display()));
        let mut lines = text.lines();
        let mut comments = Vec::new();
        let header = loop {
            let line = lines.next().expect("a header line after the comments");
            match line.strip_prefix('#') {
                Some(c) => comments.push(c.to_string()),
                None => break line.to_string(),
            }
        };
        let width = header.split(',').count();
        let rows: Vec<Vec<String>> = lines
            .map(|l| l.split(',').map(str::to_string).collect::<Vec<_>>())
            .collect();
        for r in &rows {
            assert_eq!(r.len(), width, "{}: ragged row {r:?}", path.display());
        }
        Csv {
            comments,
            header,
            rows,
        }
    }
    fn column(&self, name: &str) -> usize {
        self.header
            .split(',')
            .position(|c| c == name)
            .unwrap_or_else(|| panic!("no column {name} in {}", self.header))
    }
    fn numbers(&self, name: &str) -> Vec<f64> {
        let c = self.column(name);
        self.rows
            .iter()
            .map(|r| {
                r[c].parse::<f64>()
                    .unwrap_or_else(|e| panic!("{name} = {:?}: {e}", r[c]))
            })
            .collect()
    }
    fn strings(&self, name: &str) -> Vec<String> {
        let c = self.column(name);
        self.rows.iter().map(|r| r[c].clone()).collect()
    }
}

/// Checks `load.csv` in `dir` against a path of `steps` equal increments to `target`
/// (steps 0..=steps), and returns it.
fn check_load_path(dir: &Path, target: f64, steps: usize) -> Csv {
    let load = Csv::read(&dir.join("load.csv"));
    assert_eq!(load.header, LOAD_COLUMNS);
    assert!(!load.comments.is_empty(), "load.csv has no # comment lines");
    assert_eq!(load.rows.len(), steps + 1, "rows of load.csv");
    let step = load.numbers("step");
    let eps = load.numbers("eps");
    let h = load.numbers("h");
    for k in 0..=steps {
        let expected = target * k as f64 / steps as f64;
        assert_eq!(step[k], k as f64);
        assert!(
            (eps[k] - expected).abs() < 1e-12,
            "eps at step {k}: {} (expected {expected})",
            eps[k]
        );
        // displacement control: the tip is held at h = h0 (1 - eps)
        assert!(
            (h[k] - H0 * (1.0 - eps[k])).abs() < 1e-9,
            "h at step {k}: {} (expected {})",
            h[k],
            H0 * (1.0 - eps[k])
        );
    }
    for (k, r) in load.numbers("residual").iter().enumerate() {
        assert!(r.is_finite() && *r < 1e-6, "residual at step {k}: {r}");
    }
    load
}

#[test]
fn run_writes_the_three_files_with_their_columns() {
    let dir = Scratch::new("files");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let outdir = dir.path("out");
    assert_success(&spira_run(&dir, &case, &outdir, &[]));
    for name in OUTPUTS {
        assert!(outdir.join(name).is_file(), "{name} missing");
        assert!(
            !outdir.join(format!("{name}.partial")).exists(),
            "{name}.partial left behind"
        );
    }

    let load = check_load_path(&outdir, 0.1, 2);
    // compression is resisted: the summed axial reaction is negative once compressed
    assert!(load.numbers("fz")[2] < 0.0, "fz at eps = 0.1");
    // stored energy grows along a compression path that starts from the natural state
    let energy = load.numbers("energy");
    assert!(energy[1] > energy[0] && energy[2] > energy[1], "{energy:?}");

    let reactions = Csv::read(&outdir.join("reactions.csv"));
    assert_eq!(reactions.header, REACTION_COLUMNS);
    assert!(!reactions.comments.is_empty());
    assert_eq!(reactions.rows.len(), 3 * 2, "one row per rod per step");
    let mut chirality = reactions.strings("chirality");
    chirality.sort();
    chirality.dedup();
    assert_eq!(
        chirality,
        ["left", "right"],
        "n = 2 is one right, one left helix"
    );
    let mut rods = reactions.strings("rod");
    rods.sort();
    rods.dedup();
    assert_eq!(rods.len(), 2);

    let state = Csv::read(&outdir.join("state.csv"));
    assert_eq!(state.header, STATE_COLUMNS);
    assert!(
        state.comments[0].contains("eps = 1.0000000000e-1"),
        "state.csv is the state at the target: {:?}",
        state.comments[0]
    );
    let mut rods = state.strings("rod");
    rods.dedup();
    assert_eq!(rods.len(), 2, "rods appear in blocks");
    let (s_over_l, s, z) = (
        state.numbers("s_over_l"),
        state.numbers("s"),
        state.numbers("z"),
    );
    let (q1, q2, q3, q4) = (
        state.numbers("q1"),
        state.numbers("q2"),
        state.numbers("q3"),
        state.numbers("q4"),
    );
    let tip_height = H0 * (1.0 - 0.1);
    for i in 0..state.rows.len() {
        assert!((s[i] / LENGTH - s_over_l[i]).abs() < 1e-9, "row {i}: s/L");
        let norm = (q1[i] * q1[i] + q2[i] * q2[i] + q3[i] * q3[i] + q4[i] * q4[i]).sqrt();
        assert!((norm - 1.0).abs() < 1e-6, "row {i}: |q| = {norm}");
        if s_over_l[i] == 0.0 {
            assert!(z[i].abs() < 1e-9, "row {i}: base at z = 0, found {}", z[i]);
        }
        if s_over_l[i] == 1.0 {
            assert!(
                (z[i] - tip_height).abs() < 1e-8,
                "row {i}: tip at z = h, found {}",
                z[i]
            );
        }
    }
    assert_eq!(s_over_l.iter().filter(|&&x| x == 0.0).count(), 2);
    assert_eq!(s_over_l.iter().filter(|&&x| x == 1.0).count(), 2);
}

#[test]
fn to_and_steps_override_the_case() {
    let dir = Scratch::new("override");
    let case = dir.write("tiny.toml", common::TINY_CASE);

    let out1 = dir.path("compress");
    let out = spira_run(&dir, &case, &out1, &["--to", "0.06", "--steps", "3"]);
    assert_success(&out);
    check_load_path(&out1, 0.06, 3);

    // a negative target is extension, and must not be taken for an option
    let out2 = dir.path("extend");
    let out = spira_run(&dir, &case, &out2, &["--to", "-0.05", "--steps", "1"]);
    assert_success(&out);
    let load = check_load_path(&out2, -0.05, 1);
    assert!(load.numbers("fz")[1] > 0.0, "extension pulls: fz > 0");
}

#[test]
fn bad_case_file_is_refused_naming_file_line_and_key() {
    // (fixture, line, key, what was expected)
    let fixtures = [
        (
            "unknown-key-in-table",
            4,
            "geometry.radios",
            "unknown field",
        ),
        ("negative-radius", 4, "geometry.radius", "positive radius"),
        (
            "string-for-number",
            4,
            "geometry.radius",
            "expected a number",
        ),
        ("bad-translation", 4, "boundary.base.translation", "`slide`"),
        ("odd-helices", 3, "geometry.helices", "even number"),
        (
            "target-beyond-length",
            3,
            "loading.target",
            "beyond the rod length",
        ),
    ];
    let dir = Scratch::new("bad-case");
    let out_dir = dir.path("out");
    for (name, line, key, expected) in fixtures {
        let case = Path::new(env!("CARGO_MANIFEST_DIR"))
            .join("tests/invalid_cases")
            .join(format!("{name}.toml"));
        let file = case.display().to_string();
        let out = spira_run(&dir, &case, &out_dir, &[]);
        let err = assert_failure(&out);
        assert!(
            err.contains(&format!("{file}:{line}: key `{key}`")),
            "{name}: file, line and key not named: {err}"
        );
        assert!(
            err.contains(expected),
            "{name}: `{expected}` missing: {err}"
        );
        assert!(!out_dir.exists(), "{name}: output folder created");
    }
}

#[test]
fn toml_syntax_error_is_refused_with_its_line() {
    let dir = Scratch::new("syntax");
    let case = dir.write("broken.toml", "[geometry]\nhelices = 2\nradius = \n");
    let out = spira_run(&dir, &case, &dir.path("out"), &[]);
    let err = assert_failure(&out);
    assert!(
        err.contains(&format!("{}:3: not valid TOML", case.display())),
        "{err}"
    );
    assert_no_outputs(&dir.path("out"));
}

#[test]
fn target_outside_the_geometric_range_is_refused() {
    let dir = Scratch::new("target");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let out_dir = dir.path("out");
    for (to, why) in [
        ("1.2", "below the base"),
        ("1", "on the base"),
        ("-2", "beyond the rod length"),
        ("nan", "found NaN"),
    ] {
        let out = spira_run(&dir, &case, &out_dir, &["--to", to]);
        let err = assert_failure(&out);
        assert!(err.contains("--to"), "--to {to}: option not named: {err}");
        assert!(err.contains("compression ratio"), "--to {to}: {err}");
        assert!(err.contains(why), "--to {to}: `{why}` missing: {err}");
        assert_no_outputs(&out_dir);
    }
}

#[test]
fn zero_steps_on_the_command_line_is_refused() {
    let dir = Scratch::new("steps");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let out_dir = dir.path("out");
    let out = spira_run(&dir, &case, &out_dir, &["--steps", "0"]);
    let err = assert_failure(&out);
    assert!(err.contains("--steps"), "{err}");
    assert!(err.contains("at least 1"), "{err}");
    assert_no_outputs(&out_dir);
}

#[test]
fn missing_case_file_is_refused() {
    let dir = Scratch::new("missing");
    let case = dir.path("no-such-case.toml");
    let out = spira_run(&dir, &case, &dir.path("out"), &[]);
    let err = assert_failure(&out);
    assert!(err.contains("cannot read case file"), "{err}");
    assert!(err.contains(&case.display().to_string()), "{err}");
    // the reason is given once
    assert_eq!(err.matches("os error").count(), 1, "{err}");
    assert_no_outputs(&dir.path("out"));
}

/// Extension almost to the straight rod (the limit is eps = 1 - L/h0 = -1.6) in three fixed
/// steps of 0.5333 with no cut-back allowed (`min_step = max_step`) and at most 20 Newton
/// iterations. The first steps converge in about half of that; the last jumps to within
/// 1e-4 of the straight rod, where the axial stiffness runs away and the corrector from
/// the tangent predictor cannot converge.
const FAILING_CASE: &str = "\
name = \"overstretched\"
[geometry]
helices = 2
[loading]
target = -1.5999
steps = 3
[discretisation]
elements = 8
[solver]
max_iterations = 20
initial_step = 0.5333
min_step = 0.5333
max_step = 0.5333
";

#[test]
fn solver_failure_writes_what_was_reached_and_says_where_and_why() {
    let dir = Scratch::new("solver-failure");
    let case = dir.write("overstretched.toml", FAILING_CASE);
    let out_dir = dir.path("out");
    let out = spira_run(&dir, &case, &out_dir, &[]);
    let err = assert_failure(&out);

    // what was reached is written: step 0, the converged output steps, and last the
    // converged state where the continuation stopped (short of the target)
    let load = Csv::read(&out_dir.join("load.csv"));
    assert_eq!(load.header, LOAD_COLUMNS);
    let reached_steps = load.rows.len() - 1;
    assert!(
        (1..=3).contains(&reached_steps),
        "expected a failure after the first step, got {reached_steps} steps: {err}"
    );
    let eps = load.numbers("eps");
    for (k, e) in eps[..eps.len() - 1].iter().enumerate() {
        let expected = -1.5999 * k as f64 / 3.0;
        assert!((e - expected).abs() < 1e-12, "eps at step {k}: {e}");
    }
    let reached = *eps.last().unwrap();
    assert!(
        reached > -1.5999 && reached <= eps[eps.len() - 2],
        "{eps:?}"
    );
    assert!(Csv::read(&out_dir.join("reactions.csv")).rows.len() == 2 * (reached_steps + 1));
    let state = Csv::read(&out_dir.join("state.csv"));
    assert!(
        state.comments[0].contains(&format!("eps = {reached:.10e}")),
        "state.csv is not the last converged state: {:?}",
        state.comments[0]
    );

    // where: the eps reached, as in load.csv, and the target
    let at = err
        .find("stopped at eps = ")
        .unwrap_or_else(|| panic!("where it stopped is not said: {err}"));
    let said: f64 = err[at + "stopped at eps = ".len()..]
        .split(|c: char| !(c.is_ascii_digit() || c == '.' || c == '-'))
        .next()
        .and_then(|s| s.parse().ok())
        .unwrap_or_else(|| panic!("no number after `stopped at eps = `: {err}"));
    assert!(
        (said - reached).abs() < 1e-6,
        "message says eps = {said}, load.csv ends at {reached}"
    );
    assert!(err.contains("-1.5999"), "target not named: {err}");
    // why: the corrector's failure
    assert!(err.contains("Newton"), "no reason given: {err}");
    assert!(err.contains("were written"), "{err}");
}

/// A pulled tube (the shipped straight clamped n = 8, target ε = −0.5) folds at
/// ε = −0.3428: the run stops there, says so with the case's target, lists the fold in
/// critical.csv, writes no state beyond [target, 0] nor at or below the base, exits
/// non-zero, and its summary does not say "reached".
#[test]
fn a_displacement_path_stops_at_its_fold_and_says_so() {
    let dir = Scratch::new("fold");
    let case = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("cases/hypotheses/n8-straight-clamped-extension.toml");
    let out_dir = dir.path("out");
    let out = spira_run(&dir, &case, &out_dir, &[]);
    assert!(!out.status.success(), "a path short of its target fails");
    // progress lines ("still solving") may come first on a loaded machine
    let stderr = stderr(&out);
    let err = stderr
        .lines()
        .find(|l| l.starts_with("spira: error: "))
        .unwrap_or_else(|| panic!("no error report: {stderr}"));
    assert!(!stderr.contains("panicked"), "{stderr}");
    assert!(err.contains("limit point (fold)"), "{err}");
    assert!(err.contains("target -0.500000"), "{err}");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(
        !stdout.lines().any(|l| l.starts_with("reached")),
        "{stdout}"
    );
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("stopped at eps = -0.342795")),
        "{stdout}"
    );
    let load = Csv::read(&out_dir.join("load.csv"));
    let eps = load.numbers("eps");
    for (e, h) in eps.iter().zip(load.numbers("h")) {
        assert!((-0.5..=0.0).contains(e) && h > 0.0, "eps = {e}, h = {h}");
    }
    let critical = Csv::read(&out_dir.join("critical.csv"));
    assert_eq!(critical.strings("kind"), ["limit-point"]);
    let fold = critical.numbers("eps")[0];
    assert!((fold + 0.342795).abs() < 1e-5, "{fold}");
    assert_eq!(*eps.last().unwrap(), fold, "the path ends at its fold");
}

/// Ctrl-C (SIGINT) stops `spira run` at its last converged state and the files
/// are written as after a failure. The case (8 helices in steps of 0.001) takes tens of
/// seconds, so the signal arrives mid-path.
#[cfg(unix)]
#[test]
fn ctrl_c_stops_run_keeping_what_was_reached() {
    use rustix::process::{kill_process, Pid, Signal};
    let dir = Scratch::new("ctrl-c");
    let case = dir.path("free.toml");
    std::fs::write(
        &case,
        "name = \"slow\"\n[geometry]\nhelices = 8\n[loading]\nsteps = 500\n\
         [solver]\ninitial_step = 0.001\nmax_step = 0.001\n",
    )
    .unwrap();
    let out = dir.path("out");
    let child = Command::new(env!("CARGO_BIN_EXE_spira"))
        .arg("run")
        .arg(&case)
        .arg("--out")
        .arg(&out)
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("spira run");
    std::thread::sleep(std::time::Duration::from_secs(3));
    let pid = Pid::from_raw(child.id() as i32).expect("pid");
    let sent = std::time::Instant::now();
    kill_process(pid, Signal::INT).expect("SIGINT");
    let output = child.wait_with_output().expect("wait");
    let took = sent.elapsed();
    let stderr = String::from_utf8_lossy(&output.stderr);
    assert!(!output.status.success(), "a stopped run is a failure");
    assert!(stderr.contains("interrupted"), "{stderr}");
    let stdout = String::from_utf8_lossy(&output.stdout);
    assert!(
        stdout
            .lines()
            .any(|l| l.starts_with("interrupted at eps = ")),
        "{stdout}"
    );
    assert!(
        took < std::time::Duration::from_secs(10),
        "stopped after {took:?}"
    );
    for f in OUTPUTS {
        assert!(out.join(f).exists(), "{f} written");
    }
}

// ---- bad input, bounded work ----

#[test]
fn steps_on_the_command_line_are_bounded_like_the_case_files() {
    let dir = Scratch::new("steps-bound");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let out_dir = dir.path("out");
    for steps in ["18446744073709551615", "1000000000", "100001"] {
        let out = spira_run(&dir, &case, &out_dir, &["--steps", steps]);
        assert_ne!(out.status.code(), Some(101), "--steps {steps} panicked");
        let err = assert_failure(&out);
        assert!(err.contains("--steps"), "{err}");
        assert!(err.contains("from 1 to 100000"), "{err}");
        assert_no_outputs(&out_dir);
    }
    // beyond 64 bits: clap's own refusal, naming the flag, still no panic
    let out = spira_run(
        &dir,
        &case,
        &out_dir,
        &["--steps", "99999999999999999999999"],
    );
    assert_eq!(out.status.code(), Some(2));
    assert!(stderr(&out).contains("--steps"), "{}", stderr(&out));
}

#[test]
fn a_non_finite_to_is_refused_naming_the_flag() {
    let dir = Scratch::new("to-inf");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let out_dir = dir.path("out");
    for to in ["-inf", "inf", "NaN", "1e308"] {
        let out = spira_run(&dir, &case, &out_dir, &["--to", to]);
        let err = assert_failure(&out);
        assert!(err.contains("--to: "), "--to {to}: {err}");
        assert!(err.contains("compression ratio"), "--to {to}: {err}");
        assert!(!err.contains("unexpected argument"), "--to {to}: {err}");
        assert!(err.len() < 400, "--to {to}: a long message: {err}");
        assert_no_outputs(&out_dir);
    }
    // under load control the target is bounded too
    let force = dir.write(
        "force.toml",
        "[geometry]\nradius = 0.0\npitch = 1.0\nlength = 1.0\n[loading]\ncontrol = \"force\"\n",
    );
    let out = spira_run(&dir, &force, &out_dir, &["--to", "1e9"]);
    let err = assert_failure(&out);
    assert!(
        err.contains("--to: expected a load P/Pcrit from -100 to 100"),
        "{err}"
    );
}

#[test]
fn a_bad_target_in_the_case_does_not_blame_to() {
    let dir = Scratch::new("no-to");
    let case = dir.write("t.toml", "[loading]\ntarget = 2.0\n");
    let err = assert_failure(&spira_run(&dir, &case, &dir.path("out"), &[]));
    assert!(!err.contains("--to"), "{err}");
    assert!(err.contains("key `loading.target`"), "{err}");
}

#[test]
fn repeats_are_bounded() {
    let dir = Scratch::new("repeats");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let c = case.to_str().unwrap();
    for args in [
        ["precision", c, "--repeats", "18446744073709551615"],
        ["bench", c, "--repeats", "1000001"],
    ] {
        let err = assert_failure(&spira(&dir.0, &args));
        assert!(err.contains("--repeats: expected"), "{err}");
    }
}

#[test]
fn a_case_far_beyond_memory_is_refused_at_once_with_its_estimate() {
    let dir = Scratch::new("too-big");
    let case = dir.write(
        "huge.toml",
        "[geometry]\nhelices = 512\nturns = 1.5\n[discretisation]\nsymmetric = false\n",
    );
    let t = std::time::Instant::now();
    let err = assert_failure(&spira_run(&dir, &case, &dir.path("out"), &[]));
    assert!(t.elapsed().as_secs_f64() < 1.0);
    for fragment in [
        "memory",
        "unknowns",
        "nonzeros",
        "per factorisation",
        "`geometry.helices`",
        "--force",
    ] {
        assert!(err.contains(fragment), "`{fragment}` missing: {err}");
    }
    assert_no_outputs(&dir.path("out"));
}

/// The first line `spira run` prints on `case` (then the run is stopped) and, when that is
/// empty, what it said on stderr.
fn first_line_of_run(dir: &Scratch, case: &Path) -> (String, String) {
    use std::io::{BufRead as _, BufReader};
    let mut child = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args([
            "run",
            case.to_str().unwrap(),
            "--out",
            dir.path("out").to_str().unwrap(),
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run spira");
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .expect("a line");
    let _ = child.kill();
    let _ = child.wait();
    let mut err = String::new();
    if first.is_empty() {
        std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    }
    (first, err)
}

/// A symmetric pair standing for 512 helices (the default `symmetric = "auto"`) is small in
/// unknowns but factorises 129 Bloch blocks per stability check: `spira run` prints that
/// estimate first; a pair whose block factorisations exceed the memory is refused at once
/// with its estimate and the key.
#[test]
fn a_pair_of_many_helices_prints_its_bloch_work_and_one_beyond_memory_is_refused() {
    let dir = Scratch::new("bloch-size");
    let case = dir.write("n512.toml", "[geometry]\nhelices = 512\n");
    let (first, err) = first_line_of_run(&dir, &case);
    if first.is_empty() {
        assert!(err.contains("would need about"), "{err}");
    } else {
        assert!(first.starts_with("size estimate: 2 rods"), "{first}");
        assert!(first.contains("129 Bloch blocks per check"), "{first}");
        assert!(first.contains("per load step"), "{first}");
    }
    let huge = dir.write(
        "n512-fine.toml",
        "[geometry]\nhelices = 512\n[discretisation]\nelements = 30000\n",
    );
    let estimate = spira::case::Case::from_file(&huge).unwrap().size_estimate();
    let fits = spira::case::available_memory().is_none_or(|a| estimate.memory_bytes() <= a);
    if !fits {
        let err = assert_failure(&spira_run(&dir, &huge, &dir.path("out"), &[]));
        for fragment in [
            "would need about",
            "Bloch blocks",
            "`discretisation.elements`",
            "--force",
        ] {
            assert!(err.contains(fragment), "`{fragment}` missing: {err}");
        }
        assert_no_outputs(&dir.path("out"));
    } else {
        let (first, _) = first_line_of_run(&dir, &huge);
        assert!(first.contains("Bloch blocks"), "{first}");
    }
}

#[test]
fn a_long_case_prints_its_size_before_solving() {
    let dir = Scratch::new("long");
    let case = dir.write(
        "n64.toml",
        "[geometry]\nhelices = 64\nturns = 10\n[discretisation]\nsymmetric = false\n",
    );
    let (first, err) = first_line_of_run(&dir, &case);
    // either the estimate, or on a small machine the refusal with it
    if first.is_empty() {
        assert!(err.contains("would need about"), "{err}");
    } else {
        assert!(first.starts_with("size estimate: 64 rods"), "{first}");
        assert!(
            first.contains("unknowns") && first.contains("memory about"),
            "{first}"
        );
    }
}

#[test]
fn a_name_with_line_breaks_stays_in_its_comment_lines() {
    let dir = Scratch::new("name");
    let case = dir.write(
        "named.toml",
        &common::TINY_CASE.replace("name = \"tiny\"", "name = \"x\\n1,2,3\\r4\""),
    );
    let out_dir = dir.path("out");
    assert_success(&spira_run(&dir, &case, &out_dir, &[]));
    for name in OUTPUTS {
        let text = std::fs::read_to_string(out_dir.join(name)).unwrap();
        let mut lines = text.lines().skip_while(|l| l.starts_with('#'));
        let header = lines.next().unwrap();
        assert!(
            header.starts_with("step,") || header.starts_with("rod,"),
            "{name}: {header}"
        );
        assert!(!text.contains('\r'), "{name}: a raw carriage return");
        assert!(text.contains("x 1,2,3 4"), "{name}: the name is not kept");
    }
}

#[test]
fn a_run_replaces_the_previous_runs_files_and_leaves_nothing_temporary() {
    let dir = Scratch::new("replace");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let out_dir = dir.path("out");
    std::fs::create_dir_all(&out_dir).unwrap();
    for old in [
        "critical.csv",
        "mode-0.csv",
        "mode-7.csv",
        "load.csv.partial",
    ] {
        std::fs::write(out_dir.join(old), "old run").unwrap();
    }
    std::fs::write(out_dir.join("notes.txt"), "mine").unwrap();
    assert_success(&spira_run(&dir, &case, &out_dir, &[]));
    let mut names: Vec<String> = std::fs::read_dir(&out_dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    // the user's files stay; a stale .partial of an older spira is not of our making now
    assert_eq!(
        names,
        [
            "bulk.csv",
            "joints.csv",
            "load.csv",
            "load.csv.partial",
            "notes.txt",
            "reactions.csv",
            "state.csv"
        ]
    );
    let beside: Vec<String> = std::fs::read_dir(&dir.0)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with('.'))
        .collect();
    assert!(beside.is_empty(), "temporary folders left: {beside:?}");
}

#[test]
fn a_folder_in_the_way_fails_the_write_and_keeps_the_old_files() {
    let dir = Scratch::new("in-the-way");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let out_dir = dir.path("out");
    std::fs::create_dir_all(out_dir.join("state.csv")).unwrap();
    std::fs::write(out_dir.join("load.csv"), "old run").unwrap();
    let err = assert_failure(&spira_run(&dir, &case, &out_dir, &[]));
    assert!(err.contains("state.csv"), "{err}");
    assert_eq!(
        std::fs::read_to_string(out_dir.join("load.csv")).unwrap(),
        "old run"
    );
    assert!(!out_dir.join("reactions.csv").exists());
}

#[test]
fn a_closed_pipe_ends_the_run_quietly() {
    use std::io::{BufRead as _, BufReader};
    let dir = Scratch::new("pipe");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    let mut child = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args([
            "run",
            case.to_str().unwrap(),
            "--out",
            dir.path("out").to_str().unwrap(),
            // two lines per step: more than a pipe holds, so the writes go on after it
            // is closed
            "--steps",
            "3000",
        ])
        .stdout(std::process::Stdio::piped())
        .stderr(std::process::Stdio::piped())
        .spawn()
        .expect("run spira");
    let mut first = String::new();
    BufReader::new(child.stdout.take().unwrap())
        .read_line(&mut first)
        .expect("a line");
    // the reader is gone (as `| head -1` leaves): the rest of the output has nowhere to go
    let mut err = String::new();
    std::io::Read::read_to_string(&mut child.stderr.take().unwrap(), &mut err).unwrap();
    let _ = child.wait();
    assert!(first.starts_with("spira run: case"), "{first}");
    assert!(!err.contains("panicked"), "{err}");
}

/// Whether `dir` holds the whole set of files of one run with `--states --vtk`: the tables,
/// and a `state-<k>.csv` and a `step-<k>.vtp` for exactly the steps of its `load.csv`.
fn is_whole_run(dir: &Path) -> Result<(), String> {
    let names = common::listing(dir);
    for name in [
        "load.csv",
        "reactions.csv",
        "state.csv",
        "joints.csv",
        "bulk.csv",
        "series.pvd",
    ] {
        if !names.iter().any(|n| n == name) {
            return Err(format!("{name} missing: {names:?}"));
        }
    }
    let load = Csv::read(&dir.join("load.csv"));
    let steps: Vec<String> = load.rows.iter().map(|r| r[0].clone()).collect();
    let numbered = |prefix: &str, suffix: &str| -> Vec<String> {
        let mut k: Vec<u64> = names
            .iter()
            .filter_map(|n| n.strip_prefix(prefix)?.strip_suffix(suffix)?.parse().ok())
            .collect();
        k.sort_unstable();
        k.iter().map(u64::to_string).collect()
    };
    for (prefix, suffix) in [("state-", ".csv"), ("step-", ".vtp")] {
        if numbered(prefix, suffix) != steps {
            return Err(format!(
                "{prefix}<k>{suffix} for {:?}, load.csv has steps {steps:?}",
                numbered(prefix, suffix)
            ));
        }
    }
    Ok(())
}

/// SIGTERM or SIGINT, once or twice, at moments spread over the solve and the write phase of
/// a run with many files (`--states --vtk`, 40 steps: about 90 files): a first signal stops
/// the solve at its last converged state and the files are written; a second ends the
/// process, but not while they are written. Asserted after every attempt: no staging folder
/// beside the output folder or in it, no temporary file, the exit status a clean stop or
/// the signal's 128 + n (never a panic's 101 or a death by the signal), and the output
/// folder holding either the previous run's files untouched or a whole new set. The
/// moments are found by the run's own output (the line of a given step), then a delay of
/// 0 to 40 ms and a second signal 0.2 or 10 ms later: a schedule, not a measurement (the
/// binary before this test, which SIGTERM killed at once, left its staging folder behind
/// at delays of 20 and 40 ms after the last step's line on this machine).
#[test]
fn a_signal_during_the_write_phase_leaves_the_old_files_or_the_whole_new_set() {
    use std::io::{BufRead as _, BufReader};
    let dir = Scratch::new("signal-write");
    let steps = 40;
    let case = dir.write(
        "many.toml",
        &common::TINY_CASE.replace("steps = 2", &format!("steps = {steps}")),
    );
    let old_case = dir.write("old.toml", common::TINY_CASE);
    let out = dir.path("out");
    let mut tally = std::collections::BTreeMap::new();
    for attempt in 0..16u32 {
        // the previous run's files: a whole set of 2 steps, and a file of the user's
        let _ = std::fs::remove_dir_all(&out);
        assert_success(&spira_run(&dir, &old_case, &out, &["--states", "--vtk"]));
        std::fs::write(out.join("notes.txt"), "mine").expect("write");
        let old_load = std::fs::read(out.join("load.csv")).expect("old load.csv");
        let old_names = common::listing(&out);
        let mut child = Command::new(env!("CARGO_BIN_EXE_spira"))
            .args([
                "run",
                case.to_str().unwrap(),
                "--out",
                out.to_str().unwrap(),
                "--states",
                "--vtk",
            ])
            .current_dir(&dir.0)
            .stdout(std::process::Stdio::piped())
            .stderr(std::process::Stdio::piped())
            .spawn()
            .expect("run spira");
        // the signal after the line of this step (the last one: the write phase follows)
        let at_step = if attempt % 4 == 3 { steps / 2 } else { steps };
        let delay = std::time::Duration::from_millis([0, 5, 20, 40][(attempt / 4) as usize]);
        let signal = if attempt % 2 == 0 {
            libc::SIGTERM
        } else {
            libc::SIGINT
        };
        let twice = attempt % 3 != 2;
        let mut lines = BufReader::new(child.stdout.take().unwrap()).lines();
        for line in lines.by_ref() {
            let line = line.expect("stdout");
            let step = line
                .split_whitespace()
                .next()
                .and_then(|w| w.parse::<usize>().ok());
            if step == Some(at_step) {
                break;
            }
        }
        std::thread::sleep(delay);
        let pid = child.id() as libc::pid_t;
        // SAFETY: kill(2) on the child's pid, which is not reaped before `wait` below
        unsafe { libc::kill(pid, signal) };
        if twice {
            let gap = if attempt % 2 == 0 { 200 } else { 10_000 };
            std::thread::sleep(std::time::Duration::from_micros(gap));
            // SAFETY: as above
            unsafe { libc::kill(pid, signal) };
        }
        let drain = std::thread::spawn(move || lines.count());
        let status = child.wait().expect("wait");
        drain.join().expect("stdout drained");
        use std::os::unix::process::ExitStatusExt as _;
        assert_eq!(
            status.signal(),
            None,
            "attempt {attempt}: killed by a signal"
        );
        let code = status.code().expect("an exit code");
        assert!(
            [0, 1, 128 + signal].contains(&code),
            "attempt {attempt}: exit status {code}"
        );
        // nothing temporary beside the folder or in it
        assert_eq!(
            common::listing(&dir.0),
            ["many.toml", "old.toml", "out"],
            "attempt {attempt}"
        );
        let names = common::listing(&out);
        assert!(
            names.iter().all(|n| !n.starts_with(".spira")),
            "attempt {attempt}: {names:?}"
        );
        assert!(names.iter().any(|n| n == "notes.txt"));
        let new_load = std::fs::read(out.join("load.csv")).expect("load.csv");
        let kept = if new_load == old_load {
            // untouched: the old set, all of it
            assert_eq!(names, old_names, "attempt {attempt}");
            "old set"
        } else {
            "new set"
        };
        if let Err(e) = is_whole_run(&out) {
            panic!("attempt {attempt} ({kept}, exit {code}): {e}");
        }
        *tally.entry((kept, code)).or_insert(0) += 1;
    }
    eprintln!("outcomes (set kept, exit status): {tally:?}");
}

/// A `kill -9` during the write phase leaves the run's staging folder beside the
/// output folder; the next run into the same parent removes it (its owner, named in
/// `.spira-owner`, is gone), and keeps a staging folder of a live process (this test's),
/// one without an owner file, and folders and files that are not spira's.
#[test]
fn the_next_run_removes_the_staging_folder_of_a_killed_run_and_nothing_else() {
    use spira::output::staging::{owner_record, OWNER_FILE};
    let dir = Scratch::new("stale-staging");
    let case = dir.write("tiny.toml", common::TINY_CASE);
    // a process that has ended: a run killed by SIGKILL
    let mut killed = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(["run", case.to_str().unwrap(), "--out"])
        .arg(dir.path("killed-out"))
        .current_dir(&dir.0)
        .stdout(std::process::Stdio::null())
        .stderr(std::process::Stdio::null())
        .spawn()
        .expect("spira run");
    let dead = killed.id();
    let _ = killed.kill();
    killed.wait().expect("killed");
    let _ = std::fs::remove_dir_all(dir.path("killed-out"));
    let staging = |name: &str, owner: Option<u32>| {
        let p = dir.path(name);
        std::fs::create_dir_all(p.join("new")).expect("folder");
        std::fs::write(p.join("new/load.csv"), "half written").expect("write");
        if let Some(pid) = owner {
            std::fs::write(p.join(OWNER_FILE), owner_record(pid)).expect("owner");
        }
    };
    staging(".spira-staging-KiLlEd", Some(dead));
    staging(".spira-staging-LiVe00", Some(std::process::id()));
    staging(".spira-staging-NoOwnr", None);
    staging("results-of-mine", Some(dead));
    let out = dir.path("out");
    assert_success(&spira_run(&dir, &case, &out, &[]));
    let mut names: Vec<String> = std::fs::read_dir(&dir.0)
        .expect("scratch")
        .map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
        .collect();
    names.sort();
    assert_eq!(
        names,
        [
            ".spira-staging-LiVe00",
            ".spira-staging-NoOwnr",
            "out",
            "results-of-mine",
            "tiny.toml"
        ]
    );
    assert!(dir.path(".spira-staging-LiVe00/new/load.csv").is_file());
    for name in OUTPUTS {
        assert!(out.join(name).is_file(), "{name}");
    }
}

/// `spira bench --cold` times whole `spira run` processes of thesis n = 8 and n = 1 one after
/// the other and reports each one's best and median and their ratios: the ratios are those
/// of the times it prints (no wall-clock bound is asserted: the machine's load moves them).
#[test]
fn the_cold_bench_times_whole_runs_of_eight_helices_and_of_one_side_by_side() {
    let dir = Scratch::new("bench-cold");
    let out = spira(&dir.0, &["bench", "--cold", "--repeats", "3"]);
    assert_success(&out);
    let text = String::from_utf8_lossy(&out.stdout).into_owned();
    assert!(text.contains("cold `spira run` processes"), "{text}");
    let row = |n: &str| -> (f64, f64) {
        let line = text
            .lines()
            .find(|l| l.split_whitespace().next() == Some(n))
            .unwrap_or_else(|| panic!("no row for n = {n}: {text}"));
        let v: Vec<f64> = line
            .split_whitespace()
            .skip(1)
            .take(2)
            .map(|x| x.parse().expect("a time in ms"))
            .collect();
        assert!(v[0] > 0.0 && v[0] <= v[1], "best then median: {line}");
        (v[0], v[1])
    };
    let (best8, median8) = row("8");
    let (best1, median1) = row("1");
    let ratios = text
        .lines()
        .find_map(|l| l.strip_prefix("n = 8 / n = 1: "))
        .unwrap_or_else(|| panic!("no ratio line: {text}"));
    let r: Vec<f64> = ratios
        .split(|c: char| !(c.is_ascii_digit() || c == '.'))
        .filter(|s| !s.is_empty())
        .take(2)
        .map(|x| x.parse().expect("a ratio"))
        .collect();
    // ratios printed to 0.01, times to 0.1 ms (of tens of ms)
    let close = |a: f64, b: f64| (a - b).abs() <= 0.006 + 0.01 * b;
    assert!(
        close(r[0], best8 / best1),
        "{ratios} against {best8} / {best1}"
    );
    assert!(
        close(r[1], median8 / median1),
        "{ratios} against {median8} / {median1}"
    );
    // a case file has no place here: the bench runs its own two cases (a usage error)
    let refused = spira(&dir.0, &["bench", "x.toml", "--cold"]);
    assert_eq!(refused.status.code(), Some(2));
    let err = stderr(&refused);
    assert!(err.contains("cannot be used with '--cold'"), "{err}");
}
