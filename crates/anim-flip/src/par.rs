//! When a parallel loop pays for itself.
//!
//! Handing part of a loop to another thread of rayon's pool costs a few microseconds of wake-up
//! (a futex call, and the idle worker's spinning with `sched_yield` after it), and from outside
//! the pool every parallel loop also waits for a worker to pick it up. A substep of a small grid
//! runs dozens of loops of a few microseconds each, so splitting them costs more system time
//! than the work takes in user time. Every parallel loop of the crate therefore gives each task
//! at least a fixed amount of work ([`MIN_PARTICLES`] particles or [`MIN_ENTRIES`] grid
//! entries, about 50-100 us of work per task) through rayon's `with_min_len`, and runs on the
//! calling thread, without touching the pool, when the pool has a single thread. Whether a loop
//! splits never changes its result: every loop writes disjoint outputs or reduces in a fixed
//! order.

/// Particles per parallel task (transfers, advection, CFL and finiteness scans).
#[cfg(not(test))]
pub(crate) const MIN_PARTICLES: usize = 4096;

/// Grid entries (faces or cells) per parallel task.
#[cfg(not(test))]
pub(crate) const MIN_ENTRIES: usize = 16_384;

/// The crate's unit tests split loops into tasks of a few items, so that their small scenes take
/// the parallel paths the thresholds reserve for large ones (results do not depend on it).
#[cfg(test)]
pub(crate) const MIN_PARTICLES: usize = 8;

/// As [`MIN_PARTICLES`] for grid entries, in the unit tests.
#[cfg(test)]
pub(crate) const MIN_ENTRIES: usize = 8;

/// The `with_min_len` of a loop whose items hold `per_item` particles or entries each, with at
/// least `min` per task: never split on a one-thread pool.
#[inline]
pub(crate) fn min_len(min: usize, per_item: usize) -> usize {
    if rayon::current_num_threads() < 2 { usize::MAX } else { min.div_ceil(per_item.max(1)) }
}

/// Whether `len` items of at least `min` per task make two or more tasks on a pool of two or
/// more threads.
#[inline]
pub(crate) fn pays(len: usize, min: usize) -> bool {
    rayon::current_num_threads() >= 2 && len >= 2 * min
}
