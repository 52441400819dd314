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
use std::sync::atomic::{AtomicBool, Ordering};
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

/// The built-in n = 8 case with internal steps of at most 1e-5 in ε: a step of Δε = 0.05
/// takes thousands of internal steps, a long solve that keeps making headway.
const SLOW_CASE: &str = r#"name = "slow"
[geometry]
helices = 8
[loading]
target = 0.5
steps = 10
[solver]
initial_step = 1e-5
max_step = 1e-5
"#;

/// The explorer in a pseudo-terminal; killed if the test fails.
struct Explorer {
    child: Child,
    /// The pseudo-terminal's controller side (`None` once hung up).
    master: Option<File>,
    screen: Arc<Mutex<Vec<u8>>>,
    /// Cleared to stop the reader thread, which holds the other copy of the controller.
    reading: Arc<AtomicBool>,
    reader: Option<std::thread::JoinHandle<()>>,
}

impl Explorer {
    fn spawn(case: &Path, out: &Path, cols: u16, rows: u16) -> Explorer {
        Explorer::spawn_args(
            &[case.as_os_str(), "--out".as_ref(), out.as_os_str()],
            cols,
            rows,
        )
    }

    /// `spira tui ARGS…` in a pseudo-terminal of `cols` x `rows`.
    fn spawn_args(args: &[&std::ffi::OsStr], cols: u16, rows: u16) -> Explorer {
        Explorer::spawn_term(args, cols, rows, "xterm-256color")
    }

    /// As [`Explorer::spawn_args`] with `TERM=term`.
    fn spawn_term(args: &[&std::ffi::OsStr], cols: u16, rows: u16, term: &str) -> Explorer {
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
            .args(args)
            .env("TERM", term)
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
        // non-blocking, so that the reader can be told to stop (and let go of its copy of
        // the controller side for a hang-up)
        // SAFETY: fcntl on a file descriptor this function owns
        unsafe {
            let fd = std::os::fd::AsRawFd::as_raw_fd(&reader);
            let flags = libc::fcntl(fd, libc::F_GETFL);
            libc::fcntl(fd, libc::F_SETFL, flags | libc::O_NONBLOCK);
        }
        let sink = Arc::clone(&screen);
        let reading = Arc::new(AtomicBool::new(true));
        let go_on = Arc::clone(&reading);
        // drain the output, or the child blocks once the pty buffer is full
        let reader = std::thread::spawn(move || {
            let mut buf = [0u8; 8192];
            loop {
                match reader.read(&mut buf) {
                    Ok(0) => break,
                    Ok(n) => sink.lock().unwrap().extend_from_slice(&buf[..n]),
                    Err(e) if e.kind() == std::io::ErrorKind::WouldBlock => {
                        if !go_on.load(Ordering::Relaxed) {
                            break;
                        }
                        std::thread::sleep(Duration::from_millis(2));
                    }
                    Err(e) if e.kind() == std::io::ErrorKind::Interrupted => {}
                    Err(_) => break,
                }
            }
        });
        Explorer {
            child,
            master: Some(File::from(master)),
            screen,
            reading,
            reader: Some(reader),
        }
    }

    /// Closes every copy of the controller side, as a terminal emulator that goes away
    /// (`tmux kill-session`, a dropped SSH connection) does: the explorer's terminal hangs
    /// up and it gets SIGHUP.
    fn hang_up(&mut self) {
        self.reading.store(false, Ordering::Relaxed);
        if let Some(r) = self.reader.take() {
            let _ = r.join();
        }
        self.master = None;
    }

    /// `spira tui CASE` in a pseudo-terminal with `TERM=dumb`.
    fn spawn_dumb(case: &Path) -> Explorer {
        Explorer::spawn_term(&[case.as_os_str()], 80, 24, "dumb")
    }

    fn press(&mut self, keys: &str) {
        let master = self.master.as_mut().expect("not hung up");
        master.write_all(keys.as_bytes()).expect("type");
        master.flush().unwrap();
    }

    fn output(&self) -> String {
        String::from_utf8_lossy(&self.screen.lock().unwrap()).into_owned()
    }

    /// Presses `e` until the export of step `step` exists (the state on screen is exported,
    /// so this also waits for the solver to get there).
    fn export_until(&mut self, out: &Path, step: usize) -> PathBuf {
        let t0 = Instant::now();
        loop {
            if let Some(load) = export_file(out, step, "load") {
                return load;
            }
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
    }

    /// Waits until the output after byte `from` contains `text`; returns when it did.
    fn wait_for(&mut self, from: usize, text: &str, within: Duration) -> Option<Instant> {
        let t0 = Instant::now();
        loop {
            let out = self.screen.lock().unwrap()[from..].to_vec();
            if String::from_utf8_lossy(&out).contains(text) {
                return Some(Instant::now());
            }
            if t0.elapsed() > within {
                return None;
            }
            std::thread::sleep(Duration::from_millis(5));
        }
    }

    fn len(&self) -> usize {
        self.screen.lock().unwrap().len()
    }

    /// After the child has exited: waits (at most 2 s) until the reader thread has taken
    /// what the child wrote last, i.e. until the output stops growing for 100 ms.
    fn drain(&self) {
        let t0 = Instant::now();
        let mut seen = self.len();
        let mut quiet = Instant::now();
        while t0.elapsed() < Duration::from_secs(2) && quiet.elapsed() < Duration::from_millis(100)
        {
            std::thread::sleep(Duration::from_millis(10));
            let now = self.len();
            if now != seen {
                seen = now;
                quiet = Instant::now();
            }
        }
    }

    fn wait(&mut self) -> ExitStatus {
        let t0 = Instant::now();
        loop {
            if let Some(status) = self.child.try_wait().expect("wait") {
                self.drain();
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

/// The export of `step` of kind `kind` (`load`, `state`, `reactions`) in `out`, if written:
/// its name also gives the state's ε (`e2e-step4-eps0.1500-load.csv`).
fn export_file(out: &Path, step: usize, kind: &str) -> Option<PathBuf> {
    let prefix = format!("e2e-step{step}-");
    let suffix = format!("-{kind}.csv");
    std::fs::read_dir(out)
        .ok()?
        .flatten()
        .map(|e| e.path())
        .find(|p| {
            p.file_name()
                .and_then(|n| n.to_str())
                .is_some_and(|n| n.starts_with(&prefix) && n.ends_with(&suffix))
        })
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
    // the explorer's load table adds the conditions of each row
    let mut theirs_h = header(theirs);
    if h.last().is_some_and(|c| c == "conditions") {
        theirs_h.push("conditions".into());
    }
    assert_eq!(h, theirs_h, "{what}: same columns");
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

    let ours = std::fs::read_to_string(export_file(&out, 4, "load").unwrap()).unwrap();
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
    let ours = std::fs::read_to_string(export_file(&out, 4, "state").unwrap()).unwrap();
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
    let ours = std::fs::read_to_string(export_file(&out, 4, "reactions").unwrap()).unwrap();
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

/// The terminal was put back after the last frame: alternate screen left, cursor shown.
fn assert_restored(screen: &str) {
    let entered = screen
        .rfind("\x1b[?1049h")
        .expect("alternate screen entered");
    let left = screen.rfind("\x1b[?1049l").expect("alternate screen left");
    let shown = screen.rfind("\x1b[?25h").expect("cursor shown");
    assert!(
        left > entered && shown > entered,
        "restored after the last frame"
    );
}

/// A long solve: on the n = 8 case with tiny internal steps, a step of Δε
/// takes thousands of internal steps. (The hanging scene, both ends sliding, is
/// refused now as a free rigid motion.) The `c` key must stop it within 1 s and leave the
/// last converged state on screen.
#[test]
fn a_long_solve_is_cancelled_within_a_second_of_the_key() {
    let dir = temp_dir("cancel");
    let case = dir.join("slow.toml");
    std::fs::write(&case, SLOW_CASE).unwrap();
    let mut tui = Explorer::spawn(&case, &dir, 80, 24);
    assert!(
        tui.wait_for(0, "idle", TIMEOUT).is_some(),
        "{}",
        tui.output()
    );
    let from = tui.len();
    tui.press("\x1b[C");
    // the screen is redrawn cell by cell, so of "ε → 0.05000… 0.0 s · c cancels" only
    // what differs from the idle line is written
    assert!(
        tui.wait_for(from, "c cancels", TIMEOUT).is_some(),
        "{}",
        tui.output()
    );
    // still at it a second later (the screen only redraws the cells that change, so the
    // elapsed time and the progress are all that move)
    let solving_from = tui.len();
    std::thread::sleep(Duration::from_secs(1));
    assert!(
        !String::from_utf8_lossy(&tui.screen.lock().unwrap()[solving_from..]).contains("idle"),
        "the step solves for longer than a second"
    );
    // key to redrawn screen while the solve runs: open the help (and close it again with
    // another key, which only closes it)
    let mut latencies = Vec::new();
    for _ in 0..6 {
        let from = tui.len();
        let t = Instant::now();
        tui.press("?");
        let done = tui
            .wait_for(from, "any key closes", Duration::from_secs(2))
            .unwrap_or_else(|| panic!("help not drawn:\n{}", tui.output()));
        latencies.push(done - t);
        std::thread::sleep(Duration::from_millis(60));
        tui.press("z");
        std::thread::sleep(Duration::from_millis(100));
    }
    latencies.sort();
    eprintln!(
        "key -> redrawn screen during the long solve: median {:?}, max {:?}",
        latencies[latencies.len() / 2],
        latencies[latencies.len() - 1]
    );
    assert!(latencies[latencies.len() / 2] < Duration::from_millis(50));
    let from = tui.len();
    let pressed = Instant::now();
    tui.press("c");
    let done = tui
        .wait_for(from, "cancelled", Duration::from_secs(5))
        .unwrap_or_else(|| panic!("no cancel within 5 s:\n{}", tui.output()));
    let took = done - pressed;
    eprintln!("cancel key -> cancelled on screen: {took:?}");
    assert!(took < Duration::from_secs(1), "cancel took {took:?}");
    assert!(tui.wait_for(from, "idle", Duration::from_secs(1)).is_some());
    assert!(tui.output()[..].contains("last converged state"));
    tui.press("q");
    let status = tui.wait();
    assert!(status.success(), "exit status {status}");
    assert_restored(&tui.output());
    let _ = std::fs::remove_dir_all(&dir);
}

/// SIGTERM and SIGHUP (a dropped SSH connection) restore the terminal and end the explorer
/// with status 128 + the signal's number.
#[test]
fn sigterm_and_sighup_restore_the_terminal() {
    use rustix::process::{kill_process, Pid, Signal};
    for signal in [Signal::TERM, Signal::HUP] {
        let dir = temp_dir("signal");
        let case = dir.join("e2e.toml");
        std::fs::write(&case, case_text("fixed")).unwrap();
        let mut tui = Explorer::spawn(&case, &dir, 80, 24);
        assert!(
            tui.wait_for(0, "idle", TIMEOUT).is_some(),
            "{}",
            tui.output()
        );
        let pid = Pid::from_raw(tui.child.id() as i32).expect("pid");
        kill_process(pid, signal).expect("signal");
        let status = tui.wait();
        // as a shell expects of a process a signal ended: 128 + the signal's number
        let expected = 128 + signal.as_raw();
        assert_eq!(
            status.code(),
            Some(expected),
            "{signal:?}: exit status {status}"
        );
        assert_restored(&tui.output());
        let _ = std::fs::remove_dir_all(&dir);
    }
}

/// TERM=dumb gets a message pointing to `spira run`, not the screen.
#[test]
fn a_dumb_terminal_is_refused_with_a_pointer_to_spira_run() {
    let dir = temp_dir("dumb");
    let case = dir.join("e2e.toml");
    std::fs::write(&case, case_text("fixed")).unwrap();
    let mut tui = Explorer::spawn_dumb(&case);
    let status = tui.wait();
    assert!(!status.success());
    let out = tui.output();
    assert!(out.contains("spira run"), "{out}");
    assert!(!out.contains("\x1b[?1049h"), "no full screen");
    let _ = std::fs::remove_dir_all(&dir);
}

/// A terminal that goes away during a long solve (`tmux kill-session`, a dropped SSH
/// connection): the explorer gets SIGHUP with a terminal every read of which fails. It
/// must end (it used to stay, a core busy, in the terminal library's read loop).
#[test]
fn a_hang_up_during_a_long_solve_ends_the_explorer() {
    let dir = temp_dir("hangup");
    let case = dir.join("slow.toml");
    std::fs::write(&case, SLOW_CASE).unwrap();
    let mut tui = Explorer::spawn(&case, &dir, 80, 24);
    assert!(
        tui.wait_for(0, "idle", TIMEOUT).is_some(),
        "{}",
        tui.output()
    );
    let from = tui.len();
    tui.press("\x1b[C");
    // the screen is redrawn cell by cell, so of "ε → 0.05000… 0.0 s · c cancels" only
    // what differs from the idle line is written
    assert!(
        tui.wait_for(from, "c cancels", TIMEOUT).is_some(),
        "{}",
        tui.output()
    );
    tui.hang_up();
    let status = tui.wait();
    // ended by the hang-up (128 + SIGHUP), or by the loop on the terminal's read error
    // when that came first
    assert!(
        matches!(status.code(), Some(0 | 129)),
        "exit status {status}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}
