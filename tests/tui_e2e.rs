//! End to end: the real `spira tui` binary in a pseudo-terminal. Keys step the compression,
//! free the tips to slide, export and quit; the exported CSV must match `spira run` of the
//! same case under the same conditions at the same ε, and the terminal must be restored.
//! Unix only (a pseudo-terminal through rustix); needs nothing beyond the Rust toolchain.
#![cfg(unix)]

use rustix::pty::{grantpt, openpt, ptsname, unlockpt, OpenptFlags};
use rustix::termios::{tcsetwinsize, Winsize};
use std::fs::File;
use std::io::{Read, Write};
use std::os::fd::AsFd;
use std::os::unix::process::CommandExt;
use std::path::{Path, PathBuf};
use std::process::{Child, Command, ExitStatus, Stdio};
use std::sync::{Arc, Mutex};
use std::time::{Duration, Instant};

const SPIRA: &str = env!("CARGO_BIN_EXE_spira");
/// Generous: a debug build on a busy 2-core machine.
const TIMEOUT: Duration = Duration::from_secs(180);

/// A small case: one helix, 8 elements, so every step takes milliseconds.
fn case_text(tip_translation: &str) -> String {
    format!(
        r#"name = "e2e"
[geometry]
helices = 1
[boundary]
base = {{ translation = "fixed", rotation = "clamped" }}
tip = {{ translation = "{tip_translation}", rotation = "clamped" }}
joints = true
[loading]
target = 0.5
steps = 10
[discretisation]
elements = 8
"#
    )
}

/// The explorer in a pseudo-terminal; killed if the test fails.
struct Explorer {
    child: Child,
    master: File,
    screen: Arc<Mutex<Vec<u8>>>,
}

impl Explorer {
    fn spawn(case: &Path, out: &Path, cols: u16, rows: u16) -> Explorer {
        let master =
            openpt(OpenptFlags::RDWR | OpenptFlags::NOCTTY | OpenptFlags::CLOEXEC).expect("openpt");
        grantpt(&master).expect("grantpt");
        unlockpt(&master).expect("unlockpt");
        let name = ptsname(&master, Vec::new()).expect("ptsname");
        let slave = File::options()
            .read(true)
            .write(true)
            .open(name.to_str().expect("utf-8 pty name"))
            .expect("open the pty's terminal side");
        tcsetwinsize(
            slave.as_fd(),
            Winsize {
                ws_row: rows,
                ws_col: cols,
                ws_xpixel: 0,
                ws_ypixel: 0,
            },
        )
        .expect("window size");
        let mut cmd = Command::new(SPIRA);
        cmd.arg("tui")
            .arg(case)
            .arg("--out")
            .arg(out)
            .env("TERM", "xterm-256color")
            .stdin(Stdio::from(slave.try_clone().unwrap()))
            .stdout(Stdio::from(slave.try_clone().unwrap()))
            .stderr(Stdio::from(slave));
        // SAFETY: only async-signal-safe system calls between fork and exec.
        unsafe {
            cmd.pre_exec(|| {
                // a session of its own with the pty as controlling terminal, as a shell does
                rustix::process::setsid()?;
                rustix::process::ioctl_tiocsctty(std::io::stdin())?;
                Ok(())
            });
        }
        let child = cmd.spawn().expect("start spira tui");
        drop(cmd); // closes the parent's copies of the terminal side
        let screen = Arc::new(Mutex::new(Vec::new()));
        let mut reader = File::from(master.try_clone().expect("dup master"));
        let sink = Arc::clone(&screen);
        // drain the output, or the child blocks once the pty buffer is full
        std::thread::spawn(move || {
            let mut buf = [0u8; 8192];
            while let Ok(n) = reader.read(&mut buf) {
                if n == 0 {
                    break;
                }
                sink.lock().unwrap().extend_from_slice(&buf[..n]);
            }
        });
        Explorer {
            child,
            master: File::from(master),
            screen,
        }
    }

    fn press(&mut self, keys: &str) {
        self.master.write_all(keys.as_bytes()).expect("type");
        self.master.flush().unwrap();
    }

    fn output(&self) -> String {
        String::from_utf8_lossy(&self.screen.lock().unwrap()).into_owned()
    }

    /// Presses `e` until the export of step `step` exists (the state on screen is exported,
    /// so this also waits for the solver to get there).
    fn export_until(&mut self, out: &Path, step: usize) -> PathBuf {
        let load = out.join(format!("e2e-step{step}-load.csv"));
        let t0 = Instant::now();
        while !load.exists() {
            if let Ok(Some(status)) = self.child.try_wait() {
                panic!("spira tui exited early ({status}):\n{}", self.output());
            }
            assert!(
                t0.elapsed() < TIMEOUT,
                "no export of step {step} within {TIMEOUT:?}; screen output:\n{}",
                self.output()
            );
            self.press("e");
            std::thread::sleep(Duration::from_millis(150));
        }
        load
    }

    fn wait(&mut self) -> ExitStatus {
        let t0 = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().expect("wait") {
                return status;
            }
            assert!(t0.elapsed() < TIMEOUT, "spira tui did not quit");
            std::thread::sleep(Duration::from_millis(50));
        }
    }
}

impl Drop for Explorer {
    fn drop(&mut self) {
        if let Ok(None) = self.child.try_wait() {
            let _ = self.child.kill();
            let _ = self.child.wait();
        }
    }
}

/// Data rows of a CSV written by spira (after `#` comments and the header).
fn rows(text: &str) -> Vec<Vec<f64>> {
    text.lines()
        .filter(|l| !l.starts_with('#'))
        .skip(1)
        .map(|l| {
            l.split(',')
                .map(|v| v.parse::<f64>().unwrap_or(f64::NAN))
                .collect()
        })
        .collect()
}

fn header(text: &str) -> Vec<String> {
    text.lines()
        .find(|l| !l.starts_with('#'))
        .unwrap_or("")
        .split(',')
        .map(str::to_string)
        .collect()
}

/// `a` and `b` agree to 1e-8 relative, with an absolute floor `abs` for values near zero.
fn close(a: f64, b: f64, abs: f64) -> bool {
    (a - b).abs() <= 1e-8 * a.abs().max(b.abs()) + abs
}

fn compare(what: &str, ours: &str, theirs: &str, ours_rows: &[Vec<f64>], columns: &[(&str, f64)]) {
    let h = header(ours);
    assert_eq!(h, header(theirs), "{what}: same columns");
    let expected = rows(theirs);
    assert_eq!(
        ours_rows.len(),
        expected.len(),
        "{what}: same number of rows"
    );
    for (k, (a, b)) in ours_rows.iter().zip(&expected).enumerate() {
        for &(name, abs) in columns {
            let c = h.iter().position(|x| x == name).expect("column");
            assert!(
                close(a[c], b[c], abs),
                "{what}, row {k}, {name}: explorer {} vs spira run {}",
                a[c],
                b[c]
            );
        }
    }
}

fn temp_dir(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("spira-e2e-{name}-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    dir
}

#[test]
fn explorer_steps_toggles_exports_like_spira_run_and_quits() {
    let dir = temp_dir("explorer");
    let clamped = dir.join("e2e.toml");
    std::fs::write(&clamped, case_text("fixed")).unwrap();
    let out = dir.join("export");

    let mut tui = Explorer::spawn(&clamped, &out, 100, 30);
    tui.export_until(&out, 0); // the natural state is on screen
    tui.press("t"); // tip translation fixed -> slide, re-solved at ε = 0
    tui.export_until(&out, 1);
    for step in 2..=4 {
        tui.press("l"); // one step of Δε = 0.05
        tui.export_until(&out, step);
    }
    tui.press("q");
    let status = tui.wait();
    let screen = tui.output();
    assert!(status.success(), "exit status {status}; output:\n{screen}");
    // the terminal was put back: alternate screen left, cursor shown, after the last frame
    let left = screen.rfind("\x1b[?1049l").expect("alternate screen left");
    let shown = screen.rfind("\x1b[?25h").expect("cursor shown");
    assert!(left > screen.rfind("\x1b[?1049h").unwrap() && shown > 0);

    // the same conditions from the start with `spira run`, the same ε
    let slide = dir.join("e2e-slide.toml");
    std::fs::write(&slide, case_text("slide")).unwrap();
    let run_out = dir.join("run");
    let run = Command::new(SPIRA)
        .args([
            "run",
            slide.to_str().unwrap(),
            "--to",
            "0.15",
            "--steps",
            "3",
            "--out",
        ])
        .arg(&run_out)
        .output()
        .expect("spira run");
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );

    let ours = std::fs::read_to_string(out.join("e2e-step4-load.csv")).unwrap();
    let theirs = std::fs::read_to_string(run_out.join("load.csv")).unwrap();
    let ours_rows = rows(&ours);
    assert_eq!(ours_rows.len(), 5, "natural, slide at ε = 0, three steps");
    let eps: Vec<f64> = ours_rows.iter().map(|r| r[1]).collect();
    for (e, want) in eps.iter().zip([0.0, 0.0, 0.05, 0.1, 0.15]) {
        assert!((e - want).abs() < 1e-9, "ε path {eps:?}");
    }
    // from the moment the tips slide the explorer's path is spira run's
    compare(
        "load.csv",
        &ours,
        &theirs,
        &ours_rows[1..],
        &[
            ("eps", 1e-12),
            ("h", 1e-12),
            ("fx", 1e-8),
            ("fy", 1e-8),
            ("fz", 1e-8),
            ("energy", 1e-10),
        ],
    );
    let ours = std::fs::read_to_string(out.join("e2e-step4-state.csv")).unwrap();
    let theirs = std::fs::read_to_string(run_out.join("state.csv")).unwrap();
    compare(
        "state.csv",
        &ours,
        &theirs,
        &rows(&ours),
        &[
            ("s", 1e-12),
            ("x", 1e-9),
            ("y", 1e-9),
            ("z", 1e-9),
            ("k1", 1e-7),
            ("k2", 1e-7),
            ("omega", 1e-7),
        ],
    );
    let ours = std::fs::read_to_string(out.join("e2e-step4-reactions.csv")).unwrap();
    assert_eq!(rows(&ours).len(), 5, "one rod, five points");
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn explorer_in_a_small_terminal_says_so_and_quits_cleanly() {
    let dir = temp_dir("small");
    let case = dir.join("e2e.toml");
    std::fs::write(&case, case_text("fixed")).unwrap();
    let mut tui = Explorer::spawn(&case, &dir, 60, 20);
    let t0 = Instant::now();
    while !tui.output().contains("terminal too small") {
        assert!(t0.elapsed() < TIMEOUT, "no message:\n{}", tui.output());
        std::thread::sleep(Duration::from_millis(50));
    }
    tui.press("q");
    let status = tui.wait();
    assert!(status.success(), "exit status {status}");
    let _ = std::fs::remove_dir_all(&dir);
}
