//! Long jobs (stopmo) on worker threads: the page polls progress and may cancel; the server
//! never waits for them.
//!
//! A job reports stages through [`Progress::stage`], which also tells it when it was
//! cancelled; a cancelled job's result is dropped even if the work had already finished.

use std::collections::BTreeMap;
use std::sync::atomic::{AtomicBool, AtomicU64, Ordering};
use std::sync::{Arc, Mutex};
use std::time::Instant;

use serde::Serialize;
use serde_json::Value;

use crate::lock::lock;

/// Where a job is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum JobState {
    /// Working.
    Running,
    /// Finished with a result.
    Done,
    /// Finished with an error.
    Failed,
    /// Cancelled by the page.
    Cancelled,
}

/// What the page sees of a job.
#[derive(Debug, Clone, Serialize)]
pub struct JobStatus {
    /// Job id.
    pub id: u64,
    /// What it does (e.g. `stopmo.segment`).
    pub kind: String,
    /// Where it is.
    pub state: JobState,
    /// The current stage's name.
    pub stage: String,
    /// Fraction done, 0 to 1.
    pub progress: f32,
    /// Seconds since it started.
    pub seconds: f64,
    /// The error, when it failed.
    pub error: Option<String>,
    /// The result, when done.
    pub result: Option<Value>,
}

#[derive(Debug)]
struct Job {
    status: Mutex<JobStatus>,
    cancel: AtomicBool,
    start: Instant,
}

/// A running job's handle for reporting progress.
#[derive(Debug, Clone)]
pub struct Progress {
    job: Arc<Job>,
}

/// The job was cancelled.
#[derive(Debug, Clone, Copy, PartialEq, Eq, thiserror::Error)]
#[error("cancelled")]
pub struct Cancelled;

impl Progress {
    /// Enters stage `name` at `fraction` done; `Err(Cancelled)` when the page cancelled.
    pub fn stage(&self, name: &str, fraction: f32) -> Result<(), Cancelled> {
        if self.job.cancel.load(Ordering::SeqCst) {
            return Err(Cancelled);
        }
        let mut s = lock(&self.job.status);
        s.stage = name.to_string();
        s.progress = fraction.clamp(0.0, 1.0);
        Ok(())
    }

    /// Whether the page cancelled.
    pub fn cancelled(&self) -> bool {
        self.job.cancel.load(Ordering::SeqCst)
    }
}

/// Every job of the session.
#[derive(Debug, Default)]
pub struct Jobs {
    next: AtomicU64,
    jobs: Mutex<BTreeMap<u64, Arc<Job>>>,
}

impl Jobs {
    /// Starts `work` on a new thread; returns the job id at once.
    pub fn start<F>(&self, kind: &str, work: F) -> u64
    where
        F: FnOnce(&Progress) -> Result<Value, String> + Send + 'static,
    {
        let id = self.next.fetch_add(1, Ordering::SeqCst) + 1;
        let job = Arc::new(Job {
            status: Mutex::new(JobStatus {
                id,
                kind: kind.to_string(),
                state: JobState::Running,
                stage: "queued".into(),
                progress: 0.0,
                seconds: 0.0,
                error: None,
                result: None,
            }),
            cancel: AtomicBool::new(false),
            start: Instant::now(),
        });
        lock(&self.jobs).insert(id, job.clone());
        let progress = Progress { job: job.clone() };
        std::thread::spawn(move || {
            let outcome =
                std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| work(&progress)))
                    .unwrap_or_else(|_| Err("the job stopped on an internal error".into()));
            let mut s = lock(&job.status);
            if job.cancel.load(Ordering::SeqCst) {
                s.state = JobState::Cancelled;
            } else {
                match outcome {
                    Ok(v) => {
                        s.state = JobState::Done;
                        s.progress = 1.0;
                        s.result = Some(v);
                    }
                    Err(e) => {
                        s.state = JobState::Failed;
                        s.error = Some(e);
                    }
                }
            }
            s.seconds = job.start.elapsed().as_secs_f64();
        });
        id
    }

    /// The status of job `id`.
    pub fn status(&self, id: u64) -> Option<JobStatus> {
        let job = lock(&self.jobs).get(&id)?.clone();
        let mut s = lock(&job.status).clone();
        if s.state == JobState::Running {
            s.seconds = job.start.elapsed().as_secs_f64();
        }
        Some(s)
    }

    /// Asks job `id` to stop; its result will be dropped. `false` for an unknown id.
    pub fn cancel(&self, id: u64) -> bool {
        let Some(job) = lock(&self.jobs).get(&id).cloned() else {
            return false;
        };
        job.cancel.store(true, Ordering::SeqCst);
        let mut s = lock(&job.status);
        if s.state == JobState::Running {
            s.stage = "cancelling".into();
        }
        true
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::time::Duration;

    fn wait(jobs: &Jobs, id: u64) -> JobStatus {
        for _ in 0..500 {
            let s = jobs.status(id).unwrap();
            if s.state != JobState::Running {
                return s;
            }
            std::thread::sleep(Duration::from_millis(10));
        }
        panic!("job {id} did not finish");
    }

    #[test]
    fn a_job_reports_its_result_and_a_cancelled_one_drops_it() {
        let jobs = Jobs::default();
        let ok = jobs.start("t", |p| {
            p.stage("one", 0.5).map_err(|e| e.to_string())?;
            Ok(serde_json::json!(42))
        });
        let s = wait(&jobs, ok);
        assert_eq!(
            (s.state, s.result),
            (JobState::Done, Some(serde_json::json!(42)))
        );

        let (tx, rx) = std::sync::mpsc::channel::<()>();
        let slow = jobs.start("t", move |p| {
            rx.recv().ok();
            p.stage("two", 0.5).map_err(|e| e.to_string())?;
            Ok(serde_json::json!(1))
        });
        assert_eq!(jobs.status(slow).unwrap().state, JobState::Running);
        assert!(jobs.cancel(slow));
        tx.send(()).unwrap();
        let s = wait(&jobs, slow);
        assert_eq!(s.state, JobState::Cancelled);
        assert!(s.result.is_none());
        assert!(!jobs.cancel(999));
    }

    #[test]
    fn a_panicking_job_fails_without_taking_the_server_down() {
        let jobs = Jobs::default();
        let id = jobs.start("t", |_| panic!("boom"));
        let s = wait(&jobs, id);
        assert_eq!(s.state, JobState::Failed);
    }
}
