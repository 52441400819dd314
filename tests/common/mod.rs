//! What several test files share: the tiny case the command-line tests run, the seeded
//! proptest runner of the fuzz tests (cases and seed from the environment), and the
//! listing of an output folder.
#![allow(dead_code)]

use proptest::test_runner::{Config, RngAlgorithm, TestRng, TestRunner};

/// Two thesis helices on a coarse mesh: quick to solve, still pin-jointed.
pub const TINY_CASE: &str = "\
name = \"tiny\"
[geometry]
helices = 2
[loading]
target = 0.1
steps = 2
[discretisation]
elements = 6
";

/// The whole number in environment variable `name`, or `default`.
pub fn env_or(name: &str, default: u64) -> u64 {
    std::env::var(name)
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(default)
}

/// A proptest runner of `cases` cases (environment variable `cases_var`, else
/// `default_cases`) from the seed `SPIRA_FUZZ_SEED` (default 12), without failure files.
pub fn seeded_runner(cases_var: &str, default_cases: u64, max_shrink_iters: u32) -> TestRunner {
    let cases = env_or(cases_var, default_cases) as u32;
    let seed = env_or("SPIRA_FUZZ_SEED", 12);
    let mut bytes = [0u8; 32];
    bytes[..8].copy_from_slice(&seed.to_le_bytes());
    let config = Config {
        cases,
        failure_persistence: None,
        max_shrink_iters,
        ..Config::default()
    };
    TestRunner::new_with_rng(config, TestRng::from_seed(RngAlgorithm::ChaCha, &bytes))
}

/// The names in folder `dir`, sorted (none if it does not exist).
pub fn listing(dir: &std::path::Path) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .map(|d| {
            d.map(|e| e.expect("entry").file_name().to_string_lossy().into_owned())
                .collect()
        })
        .unwrap_or_default();
    names.sort();
    names
}
