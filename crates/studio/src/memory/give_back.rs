//! Freed memory given back to the system once the studio is idle (docs/studio.md, "Memory").
//!
//! The allocator keeps the pages a request frees for later allocations instead of returning
//! them: a smear restyle of every frame with copies and lines (~165 MB at its peak for the
//! robot, a 23 MB answer) stayed resident, unused, under the stopmo jobs that followed it,
//! which map their own pages on other threads. Once nothing has been reserved from the
//! pool for [`IDLE_BEFORE_GIVING_BACK`] after a reservation of at least
//! [`GIVE_BACK_AFTER_BYTES`] ended, the studio asks the allocator to return its free pages
//! (glibc's `malloc_trim`; a no-op with other C libraries). Nothing live moves; a dragged
//! slider (requests a few tens of milliseconds apart) is never interrupted by it.

use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Condvar, Mutex, Weak};
use std::time::{Duration, Instant};

use super::MemoryPool;
use crate::lock::lock;

/// How long the pool stays without reservations before the freed memory is given back.
pub const IDLE_BEFORE_GIVING_BACK: Duration = Duration::from_secs(1);

/// Smallest reservation whose end leads to giving memory back: a slider's restyle of the
/// frame on screen frees too little to matter.
pub const GIVE_BACK_AFTER_BYTES: u64 = 32 << 20;

/// The pool's schedule for giving memory back, and the thread that does it (started at the
/// first large reservation's end, ended with the pool).
#[derive(Debug)]
pub(super) struct GiveBack {
    idle: Duration,
    schedule: Mutex<Schedule>,
    wake: Condvar,
    given: AtomicU64,
}

#[derive(Debug, Default)]
struct Schedule {
    /// A large reservation ended since memory was last given back.
    owed: bool,
    /// When to give it back, if the pool stays idle until then.
    due: Option<Instant>,
    /// The thread runs.
    started: bool,
}

impl GiveBack {
    pub(super) fn new(idle: Duration) -> GiveBack {
        GiveBack {
            idle,
            schedule: Mutex::default(),
            wake: Condvar::new(),
            given: AtomicU64::new(0),
        }
    }

    /// A reservation of `bytes` from `pool` ended, leaving it `idle` (nothing reserved) or
    /// not.
    pub(super) fn released(pool: &Arc<MemoryPool>, bytes: u64, idle: bool) {
        let g = &pool.give_back;
        let mut s = lock(&g.schedule);
        s.owed |= bytes >= GIVE_BACK_AFTER_BYTES;
        if !(s.owed && idle) {
            return;
        }
        s.due = Some(Instant::now() + g.idle);
        if !s.started {
            s.started = true;
            let pool = Arc::downgrade(pool);
            let thread = std::thread::Builder::new()
                .name("studio-give-back".into())
                .spawn(move || run(&pool));
            // Without a thread the memory stays with the allocator, as before.
            s.started = thread.is_ok();
        }
        g.wake.notify_all();
    }

    /// How many times memory was given back.
    pub(super) fn count(&self) -> u64 {
        self.given.load(Ordering::SeqCst)
    }
}

/// Waits for the schedule's due time and gives memory back when the pool is still idle then
/// (a reservation running at that time reschedules when it ends); ends with the pool.
fn run(pool: &Weak<MemoryPool>) {
    while let Some(p) = pool.upgrade() {
        let g = &p.give_back;
        let s = lock(&g.schedule);
        let now = Instant::now();
        match s.due {
            // Bounded waits: the thread lets go of the pool to see whether it is gone.
            None => drop(g.wake.wait_timeout(s, g.idle)),
            Some(due) if now < due => drop(g.wake.wait_timeout(s, due - now)),
            Some(_) => {
                let mut s = s;
                s.due = None;
                if p.reserved() == 0 {
                    s.owed = false;
                    drop(s);
                    give_back_free_pages();
                    g.given.fetch_add(1, Ordering::SeqCst);
                }
            }
        }
    }
}

/// Returns the allocator's free pages to the system.
#[cfg(all(target_os = "linux", target_env = "gnu"))]
#[allow(unsafe_code)]
fn give_back_free_pages() {
    // SAFETY: `malloc_trim` takes no pointer and touches no live allocation; it only
    // releases the free pages of glibc's heaps (thread-safe, it locks each arena).
    unsafe {
        libc::malloc_trim(0);
    }
}

/// Returns the allocator's free pages to the system (nothing to ask other C libraries).
#[cfg(not(all(target_os = "linux", target_env = "gnu")))]
fn give_back_free_pages() {}
