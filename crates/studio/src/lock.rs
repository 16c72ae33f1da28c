//! Mutex locking that survives a panicked holder.

use std::sync::{Mutex, MutexGuard};

/// Locks a mutex, recovering from a panicked holder (the data stays usable: every writer
/// replaces whole values).
pub fn lock<T>(m: &Mutex<T>) -> MutexGuard<'_, T> {
    m.lock().unwrap_or_else(|p| p.into_inner())
}
