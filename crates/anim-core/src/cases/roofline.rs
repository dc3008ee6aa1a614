//! Hot kernels for the roofline table (`cargo xtask roofline`): each crate registers its
//! kernels with what one item of work is, the bytes it moves and the flops it does per item,
//! counted from the kernel's code, and a closure that runs the kernel once; xtask times the
//! closure and sets the achieved rates against the machine's measured memory bandwidth and
//! peak flop rate (Williams, Waterman & Patterson 2009, "Roofline: an insightful visual
//! performance model for multicore architectures").
//!
//! The bound of a kernel that moves `B` bytes and does `F` flops per item, on a machine of
//! bandwidth `W` bytes/s and peak `P` flops/s, is the attainable rate `min(P, W F / B)`, i.e. the
//! time per item `max(F / P, B / W)` ([`bound_seconds`]); the kernel's distance from it is its
//! measured time over that bound ([`distance`]).

/// The floating-point width of a kernel's arithmetic: which peak flop rate bounds it.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Precision {
    /// Single precision (`f32`).
    F32,
    /// Double precision (`f64`).
    F64,
}

impl Precision {
    /// `"f32"` or `"f64"`.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Precision::F32 => "f32",
            Precision::F64 => "f64",
        }
    }
}

/// A kernel's problem, built once by [`Kernel::setup`]: what one run of [`KernelRun::run`]
/// processes and costs.
pub struct KernelRun {
    /// Items one run processes (particles, constraint projections, springs).
    pub items: usize,
    /// Bytes read and written per item from and to memory, counted from the kernel's code
    /// (arrays larger than the last-level cache; data assumed cache-resident excluded).
    pub bytes_per_item: f64,
    /// Floating-point operations per item, counted from the kernel's code (an add, a multiply, a
    /// division or a square root counts one; a fused multiply-add two).
    pub flops_per_item: f64,
    /// Runs the kernel once over its problem (repeatable: the timing calls it many times), on the
    /// calling thread's rayon pool.
    pub run: Box<dyn FnMut() + Send>,
}

impl std::fmt::Debug for KernelRun {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("KernelRun")
            .field("items", &self.items)
            .field("bytes_per_item", &self.bytes_per_item)
            .field("flops_per_item", &self.flops_per_item)
            .finish_non_exhaustive()
    }
}

/// A registered hot kernel.
pub struct Kernel {
    /// The crate (`anim-mpm`).
    pub crate_name: &'static str,
    /// The kernel's name (`P2G 3D`).
    pub name: &'static str,
    /// What one item is (`particle`, `constraint`, `spring`).
    pub item: &'static str,
    /// The width of its arithmetic.
    pub precision: Precision,
    /// Why the kernel cannot come within 2x of its bound, printed beside its row (empty when it
    /// should).
    pub reason: &'static str,
    /// Builds the kernel's problem once (`quick`: a small one, for tests) and returns it with
    /// its counts and its run.
    pub setup: fn(quick: bool) -> Result<KernelRun, String>,
}

/// The roofline bound on the time of one item, seconds: `max(flops / peak, bytes / bandwidth)`,
/// with `bandwidth` in bytes/s and `peak` in flops/s (the time at the attainable rate
/// `min(peak, bandwidth x intensity)`).
///
/// ```
/// use anim_core::cases::roofline::bound_seconds;
/// // 100 bytes at 10 GB/s take 10 ns; 50 flops at 10 GFLOP/s 5 ns: memory bound, 10 ns.
/// assert_eq!(bound_seconds(100.0, 50.0, 10e9, 10e9), 1e-8);
/// ```
#[must_use]
pub fn bound_seconds(bytes: f64, flops: f64, bandwidth: f64, peak: f64) -> f64 {
    (bytes / bandwidth).max(flops / peak)
}

/// The attainable flop rate of a kernel of arithmetic intensity `intensity` (flops per byte):
/// `min(peak, bandwidth x intensity)`.
#[must_use]
pub fn attainable(intensity: f64, bandwidth: f64, peak: f64) -> f64 {
    peak.min(bandwidth * intensity)
}

/// How far a measured time per item is from its bound: `seconds / bound` (1 at the bound).
#[must_use]
pub fn distance(seconds: f64, bound: f64) -> f64 {
    seconds / bound
}

/// Builds every kernel `register` registers in quick mode, checks its counts are positive and
/// finite and runs it once; one line per failure (what a crate's `cases` test asserts through
/// [`crate::cases::quick_failures`]).
#[must_use]
pub fn quick_kernel_failures(kernels: &[Kernel]) -> Vec<String> {
    let mut failures = Vec::new();
    for k in kernels {
        let at = format!("{} / kernel {}", k.crate_name, k.name);
        match (k.setup)(true) {
            Ok(mut run) => {
                let counts = [run.bytes_per_item, run.flops_per_item];
                if run.items == 0 || !counts.iter().all(|c| c.is_finite() && *c > 0.0) {
                    failures.push(format!("{at}: counts not positive: {run:?}"));
                }
                (run.run)();
            }
            Err(e) => failures.push(format!("{at}: setup failed: {e}")),
        }
    }
    failures
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bound_is_the_slower_of_memory_and_arithmetic() {
        // A triad on f64 moves 24 bytes (two reads, one write) for 2 flops: at 20 GB/s and
        // 40 GFLOP/s it is memory bound, 1.2 ns per element, attainable 20e9 * 2 / 24 flops/s.
        let (bw, peak) = (20e9, 40e9);
        let b = bound_seconds(24.0, 2.0, bw, peak);
        assert!((b - 1.2e-9).abs() < 1e-21, "{b}");
        assert!((attainable(2.0 / 24.0, bw, peak) - 20e9 / 12.0).abs() < 1e-3);
        // 2 flops / (24 / 20e9 s) is the attainable rate: the same bound seen from the rate side.
        assert!((2.0 / b - attainable(2.0 / 24.0, bw, peak)).abs() < 1e-3);
        // 1000 flops on 8 bytes: compute bound, 25 ns at 40 GFLOP/s; the rate is capped at peak.
        assert!((bound_seconds(8.0, 1000.0, bw, peak) - 25e-9).abs() < 1e-21);
        assert_eq!(attainable(125.0, bw, peak), peak);
        // The ridge point: intensity peak / bandwidth = 2 flops/byte is bound both ways.
        assert!((bound_seconds(10.0, 20.0, bw, peak) - 0.5e-9).abs() < 1e-21);
        // A kernel taking 3 ns against a 1.2 ns bound is 2.5x from it.
        assert!((distance(3e-9, b) - 2.5).abs() < 1e-12);
    }

    #[test]
    fn a_kernel_with_zero_counts_or_a_failed_setup_is_reported() {
        let ok = Kernel {
            crate_name: "anim-core",
            name: "ok",
            item: "element",
            precision: Precision::F64,
            reason: "",
            setup: |_| {
                Ok(KernelRun { items: 4, bytes_per_item: 8.0, flops_per_item: 1.0, run: Box::new(|| {}) })
            },
        };
        let zero = Kernel {
            name: "zero",
            setup: |_| {
                Ok(KernelRun { items: 4, bytes_per_item: 0.0, flops_per_item: 1.0, run: Box::new(|| {}) })
            },
            ..ok
        };
        let failed = Kernel { name: "failed", setup: |_| Err("no memory".into()), ..ok };
        let f = quick_kernel_failures(&[ok, zero, failed]);
        assert_eq!(f.len(), 2, "{f:?}");
        assert!(f[0].contains("zero") && f[1].contains("no memory"), "{f:?}");
    }
}
