//! The studio's memory pool: every request is checked against the job budget alone, so
//! several requests each under it could together run the machine out of memory. A heavy
//! request (stylize, export, animate, a stopmo job) reserves the memory its job estimates
//! ([`anim::budget::JobMemory`], the estimate the tool crate checks) from one pool the size
//! of the job budget before it starts, and gives it back when done ([`Reservation`] is
//! dropped on success, error or panic). When the pool cannot hold it, the request waits a
//! short bounded time for others to finish, then is answered 503 ("busy, retry"). Once the
//! pool has been idle a moment after a large job, the memory freed is given back to the
//! system ([`IDLE_BEFORE_GIVING_BACK`]).

mod give_back;

use give_back::GiveBack;
pub use give_back::{GIVE_BACK_AFTER_BYTES, IDLE_BEFORE_GIVING_BACK};

use std::sync::{Arc, Condvar, Mutex};
use std::time::{Duration, Instant};

use anim::budget::JobMemory;

use crate::error::{ApiError, ApiResult};
use crate::lock::lock;

/// How long a request waits for other jobs to give memory back before it is answered 503:
/// long enough for a slider's previous restyle to finish, short enough to answer promptly.
pub const DEFAULT_RESERVE_WAIT: Duration = Duration::from_secs(1);

/// Memory shared by the requests running at once.
#[derive(Debug)]
pub struct MemoryPool {
    capacity: u64,
    wait: Duration,
    reserved: Mutex<u64>,
    released: Condvar,
    give_back: GiveBack,
}

/// Bytes reserved from a [`MemoryPool`] until dropped.
#[derive(Debug)]
#[must_use = "the memory is given back when the reservation is dropped"]
pub struct Reservation {
    pool: Arc<MemoryPool>,
    bytes: u64,
}

impl MemoryPool {
    /// A pool of `capacity` bytes; a request waits at most `wait` for room.
    pub fn new(capacity: u64, wait: Duration) -> Arc<MemoryPool> {
        MemoryPool::giving_back_after(capacity, wait, IDLE_BEFORE_GIVING_BACK)
    }

    /// [`MemoryPool::new`] giving freed memory back after `idle` without reservations
    /// instead of [`IDLE_BEFORE_GIVING_BACK`].
    pub fn giving_back_after(capacity: u64, wait: Duration, idle: Duration) -> Arc<MemoryPool> {
        Arc::new(MemoryPool {
            capacity,
            wait,
            reserved: Mutex::new(0),
            released: Condvar::new(),
            give_back: GiveBack::new(idle),
        })
    }

    /// A pool of the job budget ([`anim::budget::max_job_bytes`]) waiting
    /// [`DEFAULT_RESERVE_WAIT`].
    pub fn job_budget() -> Arc<MemoryPool> {
        MemoryPool::new(anim::budget::max_job_bytes(), DEFAULT_RESERVE_WAIT)
    }

    /// The pool's size in bytes.
    pub fn capacity(&self) -> u64 {
        self.capacity
    }

    /// Bytes reserved now.
    pub fn reserved(&self) -> u64 {
        *lock(&self.reserved)
    }

    /// How many times the pool gave freed memory back to the system.
    pub fn times_given_back(&self) -> u64 {
        self.give_back.count()
    }

    /// Reserves `memory` for the job of `label` (blocking at most the pool's wait).
    ///
    /// # Errors
    /// 413 when `memory` is larger than the whole pool (naming its parts and the pool's
    /// size), 503 when the jobs running now hold too much of it to fit `memory` in time.
    pub fn reserve(self: &Arc<Self>, label: &str, memory: &JobMemory) -> ApiResult<Reservation> {
        memory
            .check_within(
                self.capacity,
                "lower --fps, pick a shorter clip or ask for less",
            )
            .map_err(|e| ApiError::too_large(format!("{label}: {e}")))?;
        let bytes = memory.total();
        let deadline = Instant::now() + self.wait;
        let mut reserved = lock(&self.reserved);
        loop {
            if *reserved + bytes <= self.capacity {
                *reserved += bytes;
                return Ok(Reservation {
                    pool: self.clone(),
                    bytes,
                });
            }
            let now = Instant::now();
            if now >= deadline {
                return Err(ApiError::busy(format!(
                    "{label}: the studio is busy with other jobs ({} of its {} bytes of memory \
                     reserved, this one needs {}): retry when they finish",
                    anim::human_number(*reserved as f64),
                    anim::human_number(self.capacity as f64),
                    anim::human_number(bytes as f64),
                )));
            }
            reserved = self
                .released
                .wait_timeout(reserved, deadline - now)
                .map_or_else(|p| p.into_inner().0, |(g, _)| g);
        }
    }
}

impl Reservation {
    /// Bytes held.
    pub fn bytes(&self) -> u64 {
        self.bytes
    }
}

impl Drop for Reservation {
    fn drop(&mut self) {
        let idle = {
            let mut reserved = lock(&self.pool.reserved);
            *reserved = reserved.saturating_sub(self.bytes);
            self.pool.released.notify_all();
            *reserved == 0
        };
        // Outside the lock on `reserved`: the give-back thread reads it under its own.
        GiveBack::released(&self.pool, self.bytes, idle);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn job(bytes: u64) -> JobMemory {
        JobMemory::new().bytes("a test job", bytes)
    }

    #[test]
    fn a_job_waits_for_room_then_is_refused_and_fits_once_the_others_are_done() {
        let pool = MemoryPool::new(100, Duration::from_millis(20));
        let first = pool.reserve("a", &job(60)).unwrap();
        assert_eq!(pool.reserved(), 60);
        let busy = pool.reserve("b", &job(50)).unwrap_err();
        assert_eq!(busy.status.as_u16(), 503, "{}", busy.message);
        assert!(busy.message.contains("busy with other jobs"), "{busy}");
        let small = pool.reserve("c", &job(40)).unwrap();
        drop(first);
        assert_eq!(pool.reserved(), 40);
        let second = pool.reserve("b", &job(50)).unwrap();
        assert_eq!(second.bytes(), 50);
        drop((small, second));
        assert_eq!(pool.reserved(), 0);
        let whole = pool.reserve("d", &job(101)).unwrap_err();
        assert_eq!(whole.status.as_u16(), 413, "{}", whole.message);
        assert!(
            whole
                .message
                .starts_with("d: memory of the job (a test job)"),
            "{whole}"
        );
    }

    #[test]
    fn a_waiting_job_starts_when_a_running_one_gives_its_memory_back() {
        let pool = MemoryPool::new(100, Duration::from_secs(10));
        let first = pool.reserve("a", &job(100)).unwrap();
        let waiter = {
            let pool = pool.clone();
            std::thread::spawn(move || pool.reserve("b", &job(100)).map(|r| r.bytes()))
        };
        std::thread::sleep(Duration::from_millis(20));
        drop(first);
        assert_eq!(waiter.join().unwrap().unwrap(), 100);
        assert_eq!(pool.reserved(), 0);
    }

    /// Waits up to 5 s for the pool to have given memory back `times` times.
    fn given_back(pool: &MemoryPool, times: u64) -> bool {
        let end = Instant::now() + Duration::from_secs(5);
        while pool.times_given_back() < times && Instant::now() < end {
            std::thread::sleep(Duration::from_millis(5));
        }
        pool.times_given_back() >= times
    }

    #[test]
    fn freed_memory_goes_back_once_the_pool_is_idle_after_a_large_job() {
        let idle = Duration::from_millis(30);
        let pool = MemoryPool::giving_back_after(1 << 40, Duration::ZERO, idle);
        // A small job frees too little to matter.
        drop(
            pool.reserve("slider", &job(GIVE_BACK_AFTER_BYTES - 1))
                .unwrap(),
        );
        std::thread::sleep(idle * 4);
        assert_eq!(pool.times_given_back(), 0);
        // A large job ends while another runs: nothing until the pool is idle.
        let running = pool.reserve("running", &job(10)).unwrap();
        drop(pool.reserve("large", &job(GIVE_BACK_AFTER_BYTES)).unwrap());
        std::thread::sleep(idle * 4);
        assert_eq!(pool.times_given_back(), 0);
        drop(running);
        assert!(given_back(&pool, 1), "not given back once idle");
        // Once: nothing large ended since.
        drop(pool.reserve("slider", &job(10)).unwrap());
        std::thread::sleep(idle * 4);
        assert_eq!(pool.times_given_back(), 1);
        drop(pool.reserve("large", &job(GIVE_BACK_AFTER_BYTES)).unwrap());
        assert!(
            given_back(&pool, 2),
            "not given back after the second large job"
        );
    }

    #[test]
    fn a_panicking_job_gives_its_memory_back() {
        let pool = MemoryPool::new(100, Duration::ZERO);
        let p = pool.clone();
        let panicked = std::thread::spawn(move || {
            let _held = p.reserve("a", &job(100)).unwrap();
            panic!("the job failed");
        })
        .join();
        assert!(panicked.is_err());
        assert_eq!(pool.reserved(), 0);
        assert!(pool.reserve("b", &job(100)).is_ok());
    }
}
