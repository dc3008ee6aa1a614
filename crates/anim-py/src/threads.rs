//! Where a step runs: with the GIL released, on a worker of the thread pool.

use pyo3::prelude::*;

/// Runs `f` with the GIL released on a worker of the rayon pool, and returns what it returns.
///
/// The solvers' parallel loops started from a thread outside the pool each hand their work to
/// the pool and wait to be woken; started from a worker, that worker takes part and nothing
/// waits. A 3D MPM step has several such loops, and driving it from outside the pool made it
/// about 5% slower than the same step in a Rust program that runs inside the pool.
pub fn detached<R: Send>(py: Python<'_>, f: impl FnOnce() -> R + Send) -> R {
    py.detach(|| anim_core::par::on_worker(f))
}
