//! Data parallelism that can be switched off: rayon's parallel iterators with the `parallel`
//! feature (on by default), a sequential stand-in with the same method names without it.
//!
//! Solver crates write their loops once, against [`prelude`]:
//!
//! ```
//! use anim_core::par::prelude::*;
//!
//! let mut y = vec![0.0; 10_000];
//! y.par_chunks_mut(1024).enumerate().for_each(|(c, chunk)| {
//!     for (i, v) in chunk.iter_mut().enumerate() {
//!         *v = (c * 1024 + i) as f64;
//!     }
//! });
//! assert_eq!(y[4321], 4321.0);
//! ```
//!
//! With the feature the loop runs on rayon's global pool; without it, `par_chunks_mut` is
//! `chunks_mut` and the loop runs on the calling thread. Every parallel loop of the workspace
//! gives results that do not depend on the thread count, so the two builds agree bit for bit.
//!
//! What the stand-in covers: `par_iter`, `par_iter_mut`, `par_chunks`, `par_chunks_mut`,
//! `into_par_iter` on ranges, `with_min_len` (ignored), [`join`] and [`current_num_threads`]
//! (`1`). Rayon's `reduce(identity, op)` has no sequential twin of the same name: write
//! `fold(identity(), op)` on a sequential iterator, or branch on [`PARALLEL`].

/// Whether this build runs parallel loops on rayon's pool (the `parallel` feature).
pub const PARALLEL: bool = cfg!(feature = "parallel");

/// The parallel-iterator traits: rayon's, or the sequential stand-ins.
pub mod prelude {
    #[cfg(feature = "parallel")]
    pub use rayon::prelude::*;

    #[cfg(not(feature = "parallel"))]
    pub use super::seq::{IntoParallelIterator, ParallelSlice, ParallelSliceMut, WithMinLen};
}

/// Work, in nanoseconds, that one parallel task must hold for handing it to another thread to
/// pay. A loop started from outside the pool, or split for a sleeping worker, costs a wake-up
/// and a sleep: the 2D lid-driven cavity (64 x 64 cells, ten frames of `anim run`) made 288,029
/// voluntary context switches and 1.19 s of system time against 1.97 s of user time when every
/// line loop of its pressure solve was split, about 4 us of system time per switch and two
/// switches per loop, on the 2-core machine the workspace is measured on. A task of 50 us holds
/// six such round trips; a loop whose halves hold less runs on the calling thread.
pub const TASK_NS: usize = 50_000;

/// The least number of items a parallel task takes when each costs about `ns_per_item`
/// nanoseconds: rayon's `with_min_len` argument that keeps a loop of less than [`TASK_NS`] per
/// half on the calling thread. Splitting never changes what a loop of independent items computes,
/// so results are the same for any value.
///
/// ```
/// use anim_core::par::{min_len, TASK_NS};
///
/// assert_eq!(min_len(1), TASK_NS);
/// assert_eq!(min_len(TASK_NS), 1);
/// assert_eq!(min_len(0), TASK_NS);
/// ```
#[must_use]
pub const fn min_len(ns_per_item: usize) -> usize {
    let per = if ns_per_item == 0 { 1 } else { ns_per_item };
    TASK_NS.div_ceil(per)
}

/// Runs two closures, in parallel with the `parallel` feature, one after the other without it.
#[inline]
pub fn join<A, B, RA, RB>(a: A, b: B) -> (RA, RB)
where
    A: FnOnce() -> RA + Send,
    B: FnOnce() -> RB + Send,
    RA: Send,
    RB: Send,
{
    #[cfg(feature = "parallel")]
    {
        rayon::join(a, b)
    }
    #[cfg(not(feature = "parallel"))]
    {
        (a(), b())
    }
}

/// The number of threads parallel loops run on: rayon's current pool, or `1`.
#[inline]
#[must_use]
pub fn current_num_threads() -> usize {
    #[cfg(feature = "parallel")]
    {
        rayon::current_num_threads()
    }
    #[cfg(not(feature = "parallel"))]
    {
        1
    }
}

/// Runs `f` on a worker of rayon's global pool when called from outside any pool, on the calling
/// thread otherwise (and always without the `parallel` feature); returns what `f` returns.
///
/// A parallel loop started from a thread outside the pool hands its work to the pool and sleeps
/// until a worker wakes it: two context switches per loop, even on a one-thread pool and for a
/// loop that is not split. Started from a worker, the worker takes part and nothing waits. A
/// step of a grid fluid or a FLIP substep runs hundreds of loops, so a caller stepping a scene
/// from its own thread runs the step through this function: one hand-over per step instead of
/// one per loop. The result is the same either way.
///
/// ```
/// let sum = anim_core::par::on_worker(|| (1..=100).sum::<u32>());
/// assert_eq!(sum, 5050);
/// ```
pub fn on_worker<R: Send>(f: impl FnOnce() -> R + Send) -> R {
    #[cfg(feature = "parallel")]
    {
        if rayon::current_thread_index().is_none() {
            return rayon::scope(|_| f());
        }
    }
    f()
}

/// Runs `f` on a pool of `threads` threads (its parallel loops use that many) with the
/// `parallel` feature; without it, runs `f` on the calling thread.
///
/// # Errors
/// The pool could not be built (the operating system refused the threads).
pub fn with_threads<R: Send>(threads: usize, f: impl FnOnce() -> R + Send) -> Result<R, String> {
    #[cfg(feature = "parallel")]
    {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
        Ok(pool.install(f))
    }
    #[cfg(not(feature = "parallel"))]
    {
        let _ = threads;
        Ok(f())
    }
}

/// The sequential stand-ins, used when the `parallel` feature is off.
#[cfg(not(feature = "parallel"))]
mod seq {
    /// `par_iter` and `par_chunks` on slices, as plain iterators.
    pub trait ParallelSlice<T> {
        /// `iter()`.
        fn par_iter(&self) -> std::slice::Iter<'_, T>;
        /// `chunks(n)`.
        fn par_chunks(&self, n: usize) -> std::slice::Chunks<'_, T>;
    }

    impl<T> ParallelSlice<T> for [T] {
        #[inline]
        fn par_iter(&self) -> std::slice::Iter<'_, T> {
            self.iter()
        }
        #[inline]
        fn par_chunks(&self, n: usize) -> std::slice::Chunks<'_, T> {
            self.chunks(n)
        }
    }

    /// `par_iter_mut` and `par_chunks_mut` on slices, as plain iterators.
    pub trait ParallelSliceMut<T> {
        /// `iter_mut()`.
        fn par_iter_mut(&mut self) -> std::slice::IterMut<'_, T>;
        /// `chunks_mut(n)`.
        fn par_chunks_mut(&mut self, n: usize) -> std::slice::ChunksMut<'_, T>;
    }

    impl<T> ParallelSliceMut<T> for [T] {
        #[inline]
        fn par_iter_mut(&mut self) -> std::slice::IterMut<'_, T> {
            self.iter_mut()
        }
        #[inline]
        fn par_chunks_mut(&mut self, n: usize) -> std::slice::ChunksMut<'_, T> {
            self.chunks_mut(n)
        }
    }

    /// `into_par_iter` on anything iterable, as `into_iter`.
    pub trait IntoParallelIterator: IntoIterator + Sized {
        /// `into_iter()`.
        #[inline]
        fn into_par_iter(self) -> Self::IntoIter {
            self.into_iter()
        }
    }

    impl<I: IntoIterator> IntoParallelIterator for I {}

    /// rayon's splitting hint, ignored by a sequential iterator.
    pub trait WithMinLen: Iterator + Sized {
        /// Returns the iterator unchanged.
        #[inline]
        fn with_min_len(self, _min: usize) -> Self {
            self
        }
    }

    impl<I: Iterator> WithMinLen for I {}
}
