//! How the loop's per-particle stages are split over rayon's threads: in fixed chunks of
//! [`CHUNK`] items, each written by one task, so that the results are bitwise the same for any
//! number of threads; loops shorter than [`PARALLEL_MIN`] stay on the calling thread.

use anim_core::par::prelude::*;

/// Items per rayon task (small in unit tests, so that they exercise the parallel paths).
pub(super) const CHUNK: usize = if cfg!(test) { 16 } else { 256 };
/// Loops shorter than this run on the calling thread.
pub(super) const PARALLEL_MIN: usize = if cfg!(test) { 64 } else { 2048 };

/// Runs `f(first_index, chunk)` over `out` in chunks, in parallel for long arrays.
pub(super) fn for_each_chunk<T: Send>(out: &mut [T], f: impl Fn(usize, &mut [T]) + Sync) {
    if out.len() >= PARALLEL_MIN && anim_core::par::current_num_threads() > 1 {
        out.par_chunks_mut(CHUNK).enumerate().for_each(|(c, s)| f(c * CHUNK, s));
    } else {
        f(0, out);
    }
}
