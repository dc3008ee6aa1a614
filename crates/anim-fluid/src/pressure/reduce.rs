//! Ordered reductions: sums, dot products and maximum norms over fixed chunks of [`CHUNK`]
//! entries, each chunk reduced in parallel and the partial results combined in chunk order, so
//! the result is the same bits for any number of threads. The caller provides the buffer of
//! partial results (`len.div_ceil(CHUNK)` entries), so no reduction allocates.

use rayon::prelude::*;

/// Sum of `f(range)` over fixed chunks of `0..len`, in chunk order (thread-count independent).
pub(super) fn chunked_sum(
    len: usize,
    partials: &mut [f64],
    f: impl Fn(std::ops::Range<usize>) -> f64 + Sync,
) -> f64 {
    let chunks = len.div_ceil(CHUNK);
    partials[..chunks]
        .par_iter_mut()
        .enumerate()
        .with_min_len(crate::grain::lines(CHUNK, crate::grain::ENTRY_NS))
        .for_each(|(q, p)| {
            *p = f(q * CHUNK..((q + 1) * CHUNK).min(len));
        });
    partials[..chunks].iter().sum()
}

/// Chunk length of the ordered reductions.
pub(crate) const CHUNK: usize = 4096;

/// `a . b`, summed over chunks in order.
pub(crate) fn dot(a: &[f64], b: &[f64], partials: &mut [f64]) -> f64 {
    chunked_sum(a.len(), partials, |r| a[r.clone()].iter().zip(&b[r]).map(|(x, y)| x * y).sum())
}

/// `max |a_i|` (0 for an empty slice).
pub(crate) fn max_abs(a: &[f64], partials: &mut [f64]) -> f64 {
    let chunks = a.len().div_ceil(CHUNK);
    partials[..chunks]
        .par_iter_mut()
        .enumerate()
        .with_min_len(crate::grain::lines(CHUNK, crate::grain::ENTRY_NS))
        .for_each(|(q, p)| {
            *p = a[q * CHUNK..((q + 1) * CHUNK).min(a.len())].iter().fold(0.0f64, |m, x| m.max(x.abs()));
        });
    partials[..chunks].iter().fold(0.0f64, |m, &x| m.max(x))
}
