//! A background job where the latest request wins (gitui's `AsyncSingleJob`): one thread
//! runs one job at a time; while it runs, only the latest submission is kept pending, and a
//! newer submission cancels the running job cooperatively — the job polls
//! [`Context::is_cancelled`] and returns early. Jobs deliver what they produce (progress
//! and results) over a channel through [`Context::send`].

use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::mpsc::Sender;
use std::sync::{Arc, Condvar, Mutex, PoisonError};
use std::thread::{self, JoinHandle};

/// Handle of the thread: submit jobs; dropping it (or [`Latest::close`]) stops the thread
/// once the job in progress notices.
pub struct Latest<J> {
    shared: Arc<Shared<J>>,
    thread: Option<JoinHandle<()>>,
}

struct Shared<J> {
    /// The job waiting to run, if any (only the latest is kept).
    next: Mutex<Option<J>>,
    wake: Condvar,
    /// Number of jobs submitted so far; a running job is cancelled when it moves on.
    submitted: AtomicU64,
    closed: AtomicBool,
}

/// What a running job sees: whether it should stop, and the channel for its output.
pub struct Context<'a, J, T> {
    shared: &'a Shared<J>,
    /// The submission number of this job.
    id: u64,
    tx: &'a Sender<T>,
    disconnected: AtomicBool,
}

impl<J, T> Context<'_, J, T> {
    /// True once a newer job was submitted, the handle was closed, or the receiver of the
    /// channel is gone: the job should stop as soon as it can.
    pub fn is_cancelled(&self) -> bool {
        self.shared.submitted.load(Ordering::SeqCst) != self.id
            || self.shared.closed.load(Ordering::SeqCst)
            || self.disconnected.load(Ordering::SeqCst)
    }

    /// Sends `value` to the receiver; false (and the job counts as cancelled) if it is gone.
    pub fn send(&self, value: T) -> bool {
        let sent = self.tx.send(value).is_ok();
        if !sent {
            self.disconnected.store(true, Ordering::SeqCst);
        }
        sent
    }
}

impl<J: Send + 'static> Latest<J> {
    /// Starts the thread `name`, which runs each job with `run`, its output going to `tx`.
    /// The thread ends when the handle is closed or the receiver of `tx` is gone.
    pub fn spawn<T, F>(name: &str, tx: Sender<T>, mut run: F) -> std::io::Result<Latest<J>>
    where
        T: Send + 'static,
        F: FnMut(J, &Context<J, T>) + Send + 'static,
    {
        let shared = Arc::new(Shared {
            next: Mutex::new(None),
            wake: Condvar::new(),
            submitted: AtomicU64::new(0),
            closed: AtomicBool::new(false),
        });
        let theirs = Arc::clone(&shared);
        let thread = thread::Builder::new()
            .name(name.to_string())
            .spawn(move || {
                while let Some((job, id)) = theirs.take_next() {
                    let ctx = Context {
                        shared: &theirs,
                        id,
                        tx: &tx,
                        disconnected: AtomicBool::new(false),
                    };
                    run(job, &ctx);
                    if ctx.disconnected.load(Ordering::SeqCst) {
                        return;
                    }
                }
            })?;
        Ok(Latest {
            shared,
            thread: Some(thread),
        })
    }

    /// Makes `job` the next to run, replacing any job still pending and cancelling the one
    /// running; false if the thread has ended.
    pub fn submit(&self, job: J) -> bool {
        if self.is_finished() || self.shared.closed.load(Ordering::SeqCst) {
            return false;
        }
        let mut next = self.shared.lock();
        *next = Some(job);
        self.shared.submitted.fetch_add(1, Ordering::SeqCst);
        self.shared.wake.notify_one();
        true
    }

    /// Whether the thread has ended.
    pub fn is_finished(&self) -> bool {
        self.thread.as_ref().is_none_or(|t| t.is_finished())
    }

    /// Drops the pending job and stops the thread once the running job (if any) notices;
    /// does not wait for it.
    pub fn close(&mut self) {
        self.shared.closed.store(true, Ordering::SeqCst);
        self.shared.lock().take();
        self.shared.wake.notify_one();
        self.thread = None;
    }
}

impl<J> Shared<J> {
    fn lock(&self) -> std::sync::MutexGuard<'_, Option<J>> {
        self.next.lock().unwrap_or_else(PoisonError::into_inner)
    }

    /// Waits for the next job and its submission number; `None` once closed.
    fn take_next(&self) -> Option<(J, u64)> {
        let mut next = self.lock();
        loop {
            if self.closed.load(Ordering::SeqCst) {
                return None;
            }
            if let Some(job) = next.take() {
                // read under the lock: `submit` bumps the count while holding it
                return Some((job, self.submitted.load(Ordering::SeqCst)));
            }
            next = self.wake.wait(next).unwrap_or_else(PoisonError::into_inner);
        }
    }
}

impl<J> Drop for Latest<J> {
    fn drop(&mut self) {
        self.shared.closed.store(true, Ordering::SeqCst);
        self.shared.wake.notify_one();
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::sync::mpsc;
    use std::time::{Duration, Instant};

    #[test]
    fn a_newer_submission_cancels_the_running_job_and_replaces_the_pending_one() {
        let (tx, rx) = mpsc::channel();
        let latest = Latest::spawn("latest-test", tx, |job: u32, ctx| {
            if job == 0 {
                // runs until cancelled
                let t0 = Instant::now();
                while !ctx.is_cancelled() && t0.elapsed() < Duration::from_secs(10) {
                    thread::sleep(Duration::from_millis(1));
                }
                let cancelled = ctx.is_cancelled();
                // time for the test to submit again before the next job is taken
                thread::sleep(Duration::from_millis(50));
                ctx.send((job, cancelled));
            } else {
                ctx.send((job, false));
            }
        })
        .expect("thread");
        assert!(latest.submit(0));
        thread::sleep(Duration::from_millis(50));
        assert!(latest.submit(1));
        assert!(latest.submit(2));
        let got: Vec<(u32, bool)> = (0..2)
            .map(|_| rx.recv_timeout(Duration::from_secs(10)).expect("answer"))
            .collect();
        assert_eq!(got, vec![(0, true), (2, false)]);
        assert!(rx.recv_timeout(Duration::from_millis(100)).is_err());
    }

    #[test]
    fn closing_ends_the_thread() {
        let (tx, rx) = mpsc::channel::<u32>();
        let mut latest = Latest::spawn("latest-test", tx, |job: u32, ctx| {
            ctx.send(job);
        })
        .expect("thread");
        assert!(latest.submit(7));
        assert_eq!(rx.recv_timeout(Duration::from_secs(10)), Ok(7));
        latest.close();
        assert!(!latest.submit(8));
        // the thread drops its sender when it ends
        assert!(rx.recv_timeout(Duration::from_secs(10)).is_err());
    }
}
