//! A counting global allocator for the workspace's "no allocation per step" tests.
//!
//! **Invariant checked with it:** after the first step, a solver's `step` performs no heap
//! allocation. A test binary installs the allocator and counts the allocations made while it
//! steps:
//!
//! ```no_run
//! use anim_core::alloc_count::CountingAllocator;
//!
//! #[global_allocator]
//! static ALLOC: CountingAllocator = CountingAllocator::new();
//!
//! let made = ALLOC.count(|| {
//!     // step the simulation here
//! });
//! assert_eq!(made, 0);
//! ```
//!
//! Every request is forwarded unchanged to the system allocator; only allocations and
//! reallocations made while a [`CountingAllocator::count`] closure runs are counted (on any
//! thread: rayon workers included).

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicUsize, Ordering};

/// The system allocator with a switchable allocation counter.
#[derive(Debug)]
pub struct CountingAllocator {
    on: AtomicBool,
    count: AtomicUsize,
}

impl CountingAllocator {
    /// A counter that is off.
    #[must_use]
    pub const fn new() -> Self {
        Self { on: AtomicBool::new(false), count: AtomicUsize::new(0) }
    }

    /// Runs `f` and returns how many allocations and reallocations were made, by any thread,
    /// while it ran.
    pub fn count(&self, f: impl FnOnce()) -> usize {
        self.count.store(0, Ordering::SeqCst);
        self.on.store(true, Ordering::SeqCst);
        f();
        self.on.store(false, Ordering::SeqCst);
        self.count.load(Ordering::SeqCst)
    }

    fn note(&self) {
        if self.on.load(Ordering::Relaxed) {
            self.count.fetch_add(1, Ordering::Relaxed);
        }
    }
}

impl Default for CountingAllocator {
    fn default() -> Self {
        Self::new()
    }
}

// SAFETY: every call is forwarded unchanged to the system allocator with the caller's arguments;
// the counter has no effect on the memory handed out.
#[allow(unsafe_code)]
unsafe impl GlobalAlloc for CountingAllocator {
    unsafe fn alloc(&self, layout: Layout) -> *mut u8 {
        self.note();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc(layout) }
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        self.note();
        // SAFETY: same contract as the caller's.
        unsafe { System.alloc_zeroed(layout) }
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        // SAFETY: `ptr` came from `System` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        self.note();
        // SAFETY: same contract as the caller's.
        unsafe { System.realloc(ptr, layout, new_size) }
    }
}
