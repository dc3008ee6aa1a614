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
//!
//! [`CountingAllocator::peak_bytes`] measures the other way round: the most bytes a closure
//! held at once beyond what was held when it started, what a scene's memory estimate
//! (`anim_core::scene::MemoryNeed`) is compared with.

use std::alloc::{GlobalAlloc, Layout, System};
use std::sync::atomic::{AtomicBool, AtomicIsize, AtomicUsize, Ordering};

/// The system allocator with a switchable allocation counter.
#[derive(Debug)]
pub struct CountingAllocator {
    on: AtomicBool,
    count: AtomicUsize,
    /// Bytes allocated minus bytes freed since [`CountingAllocator::peak_bytes`] began.
    live: AtomicIsize,
    /// The most `live` has been.
    peak: AtomicIsize,
}

impl CountingAllocator {
    /// A counter that is off.
    #[must_use]
    pub const fn new() -> Self {
        Self {
            on: AtomicBool::new(false),
            count: AtomicUsize::new(0),
            live: AtomicIsize::new(0),
            peak: AtomicIsize::new(0),
        }
    }

    /// Runs `f` and returns the most bytes it held at once (allocated and not yet freed, by any
    /// thread, beyond what was held when it started): the peak of its heap, what a memory
    /// estimate is compared with. Memory freed while `f` runs that was allocated before counts
    /// against it, so concurrent work elsewhere in the process can only lower the figure.
    /// Allocations are counted as by [`count`](Self::count) meanwhile.
    pub fn peak_bytes(&self, f: impl FnOnce()) -> usize {
        self.live.store(0, Ordering::SeqCst);
        self.peak.store(0, Ordering::SeqCst);
        let _ = self.count(f);
        usize::try_from(self.peak.load(Ordering::SeqCst)).unwrap_or(0)
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

    /// `bytes` more (or fewer, when negative) held, while counting.
    fn hold(&self, bytes: isize) {
        if self.on.load(Ordering::Relaxed) {
            let now = self.live.fetch_add(bytes, Ordering::Relaxed) + bytes;
            self.peak.fetch_max(now, Ordering::Relaxed);
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
        let ptr = unsafe { System.alloc(layout) };
        if !ptr.is_null() {
            self.hold(size(layout.size()));
        }
        ptr
    }

    unsafe fn alloc_zeroed(&self, layout: Layout) -> *mut u8 {
        self.note();
        // SAFETY: same contract as the caller's.
        let ptr = unsafe { System.alloc_zeroed(layout) };
        if !ptr.is_null() {
            self.hold(size(layout.size()));
        }
        ptr
    }

    unsafe fn dealloc(&self, ptr: *mut u8, layout: Layout) {
        self.hold(-size(layout.size()));
        // SAFETY: `ptr` came from `System` with this layout.
        unsafe { System.dealloc(ptr, layout) }
    }

    unsafe fn realloc(&self, ptr: *mut u8, layout: Layout, new_size: usize) -> *mut u8 {
        self.note();
        // SAFETY: same contract as the caller's.
        let moved = unsafe { System.realloc(ptr, layout, new_size) };
        if !moved.is_null() {
            self.hold(size(new_size) - size(layout.size()));
        }
        moved
    }
}

/// A size in bytes as a signed count (sizes of allocations never exceed `isize::MAX`).
fn size(bytes: usize) -> isize {
    isize::try_from(bytes).unwrap_or(isize::MAX)
}

/// What [`preset_step_allocations`] counted for one preset.
#[cfg(feature = "serde")]
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct PresetAllocations {
    /// The preset's name.
    pub preset: &'static str,
    /// Allocations per block of four steps, at most three blocks, stopping at a clean one.
    pub blocks: Vec<usize>,
}

/// The allocations of every preset of `kind` (at its quick parameters) once its first step is
/// done: blocks of four steps inside a 2-thread rayon pool (as a worker: a parallel call from a
/// thread outside every pool goes through rayon's global injector, which allocates now and
/// then), up to three blocks, stopping at the first clean one. The pool's own bookkeeping can
/// allocate now and then under load; a step that allocates does so in every block, so the last
/// block is 0 exactly when the steps allocate nothing. `alloc` must be the process's global
/// allocator.
///
/// # Errors
/// The preset's name and the message when one cannot be built or a step fails.
#[cfg(feature = "serde")]
pub fn preset_step_allocations(
    alloc: &CountingAllocator,
    kind: &crate::scene::SceneKind,
) -> Result<Vec<PresetAllocations>, String> {
    crate::par::with_threads(2, || {
        let mut out = Vec::new();
        for preset in (kind.presets)() {
            let name = preset.name;
            let mut scene = (kind.build)(preset.params_for(true), &crate::scene::BuildContext::default())
                .map_err(|e| format!("{name}: {e}"))?;
            let dt = preset.run.dt;
            scene.step(dt).map_err(|e| format!("{name}: step 1: {e}"))?;
            let blocks = step_allocations(alloc, scene.as_mut(), dt).map_err(|e| format!("{name}: {e}"))?;
            out.push(PresetAllocations { preset: name, blocks });
        }
        Ok(out)
    })?
}

/// The allocations of `scene`'s next steps by `dt`: blocks of four steps, up to three, stopping
/// at the first clean one (the last block is 0 exactly when the steps allocate nothing; a rayon
/// pool's bookkeeping can allocate now and then under load). Call it on a worker of a rayon pool
/// (`ThreadPool::install`) after the buffers are sized: a parallel call from a thread outside
/// every pool goes through rayon's global injector, which allocates now and then. `alloc` must
/// be the process's global allocator.
///
/// # Errors
/// The message of a step that fails.
#[cfg(feature = "serde")]
pub fn step_allocations(
    alloc: &CountingAllocator,
    scene: &mut dyn crate::scene::DynScene,
    dt: f64,
) -> Result<Vec<usize>, String> {
    let mut blocks = Vec::new();
    for _ in 0..3 {
        let mut failed = None;
        blocks.push(alloc.count(|| {
            for _ in 0..4 {
                if let Err(e) = scene.step(dt) {
                    failed = Some(e.to_string());
                    return;
                }
            }
        }));
        if let Some(e) = failed {
            return Err(e);
        }
        if blocks.last() == Some(&0) {
            break;
        }
    }
    Ok(blocks)
}

/// The most bytes building a scene of `kind` from `params`, stepping it once by `dt` and taking
/// its view (its [`Context`](crate::scene::Context) and a [`Frame`](crate::scene::Frame), what
/// a run draws and writes) hold at once ([`CountingAllocator::peak_bytes`]): what a kind's
/// memory estimate is compared with. This is done twice and the second time measured, so that
/// what a process allocates once for all its scenes (the rayon pool, a solver library's first
/// use) is not counted. `alloc` must be the process's global allocator.
///
/// # Errors
/// The message when the scene cannot be built or its step fails.
#[cfg(feature = "serde")]
pub fn build_and_step_peak(
    alloc: &CountingAllocator,
    kind: &crate::scene::SceneKind,
    params: &serde_json::Value,
    dt: f64,
) -> Result<usize, String> {
    let run = || -> Result<(), String> {
        let mut scene =
            (kind.build)(params, &crate::scene::BuildContext::default()).map_err(|e| e.to_string())?;
        scene.step(dt).map_err(|e| e.to_string())?;
        let context = scene.context();
        let mut frame = crate::scene::Frame::default();
        scene.frame(&mut frame);
        drop(std::hint::black_box((scene, context, frame)));
        Ok(())
    };
    run()?;
    let mut result = Ok(());
    let peak = alloc.peak_bytes(|| result = run());
    result.map(|()| peak)
}

/// The test that every preset of a scene kind steps without allocating once its first step is
/// done ([`preset_step_allocations`]), for a crate's integration test file of its own (the macro
/// installs the counting global allocator):
///
/// ```ignore
/// anim_core::preset_allocation_test!(anim_springs::KIND);
/// ```
#[cfg(feature = "serde")]
#[macro_export]
macro_rules! preset_allocation_test {
    ($kind:expr) => {
        #[global_allocator]
        static ALLOC: $crate::alloc_count::CountingAllocator = $crate::alloc_count::CountingAllocator::new();

        #[test]
        fn preset_steps_do_not_allocate() {
            let counted = $crate::alloc_count::preset_step_allocations(&ALLOC, &$kind)
                .unwrap_or_else(|e| panic!("{e}"));
            assert!(!counted.is_empty(), "the kind has no preset");
            for c in counted {
                assert_eq!(
                    c.blocks.last(),
                    Some(&0),
                    "{}: allocations per block of four steps {:?}",
                    c.preset,
                    c.blocks
                );
            }
        }
    };
}
