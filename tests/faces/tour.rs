//! The README's tour: the `spira run` printed there is what the command prints, but for
//! the wall times, the memory and the residuals (the last digits of a residual near the
//! Newton tolerance depend on the machine's floating-point kernels).

use std::path::PathBuf;
use std::process::Command;

/// The first `console` block of the README that runs `spira run`: the command's arguments
/// and the printed lines.
fn tour() -> (Vec<String>, Vec<String>) {
    let readme = PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("README.md");
    let text = std::fs::read_to_string(&readme).expect("README.md");
    let mut lines = text.lines();
    while let Some(line) = lines.next() {
        if line.trim() == "```console" {
            let block: Vec<&str> = lines.by_ref().take_while(|l| l.trim() != "```").collect();
            if let Some(command) = block.first().and_then(|l| l.strip_prefix("$ spira run ")) {
                let args = std::iter::once("run")
                    .chain(command.split_whitespace())
                    .map(String::from)
                    .collect();
                let printed = block[1..].iter().map(|l| l.to_string()).collect();
                return (args, printed);
            }
        }
    }
    panic!("README.md has no ```console block starting with `$ spira run`");
}

/// A printed line with what varies from run to run replaced by `…`.
fn steady(line: &str) -> String {
    let words: Vec<&str> = line.split_whitespace().collect();
    // an output step: step, eps, load, iterations, residual, time, unstable directions
    if words.len() == 7 && words[0].parse::<usize>().is_ok() && words[1].contains('.') {
        return format!(
            "{} {} {} {} … … {}",
            words[0], words[1], words[2], words[3], words[6]
        );
    }
    if line.starts_with("peak memory") {
        return "peak memory …".to_string();
    }
    if let (Some(start), Some(end)) = (line.find(" in "), line.find(" ms:")) {
        if line.starts_with("reached") && start < end {
            return format!("{} in … ms:{}", &line[..start], &line[end + 4..]);
        }
    }
    words.join(" ")
}

#[test]
fn the_readmes_tour_prints_what_spira_run_prints() {
    let (args, printed) = tour();
    let root = PathBuf::from(env!("CARGO_MANIFEST_DIR"));
    let scratch = tempfile::tempdir().expect("a scratch folder");
    // the command as typed in the repository, its output folder in the scratch folder
    std::os::unix::fs::symlink(root.join("cases"), scratch.path().join("cases"))
        .expect("link the cases");
    let out = Command::new(env!("CARGO_BIN_EXE_spira"))
        .args(&args)
        .current_dir(scratch.path())
        .output()
        .expect("run spira");
    assert!(
        out.status.success(),
        "`spira {}` failed: {}",
        args.join(" "),
        String::from_utf8_lossy(&out.stderr)
    );
    let stdout = String::from_utf8(out.stdout).expect("UTF-8 output");
    let expected: Vec<String> = printed.iter().map(|l| steady(l)).collect();
    let actual: Vec<String> = stdout.lines().map(steady).collect();
    for (k, (e, a)) in expected.iter().zip(&actual).enumerate() {
        assert_eq!(
            e,
            a,
            "README.md's tour, printed line {}: the README says the first, `spira {}` prints the second; paste the command's output into the README",
            k + 1,
            args.join(" ")
        );
    }
    assert_eq!(
        expected.len(),
        actual.len(),
        "README.md's tour prints {} lines, the command {}",
        expected.len(),
        actual.len()
    );
}
