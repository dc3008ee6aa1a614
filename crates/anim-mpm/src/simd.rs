//! Run-time choice of the AVX2 kernels: the token that proves the running CPU has AVX2, and
//! [`with_simd`], which runs a closure compiled with AVX2 enabled when it has.
//!
//! The decision is made once per simulation ([`Avx2::detect`]) and carried as
//! `Option<Avx2>`: `Some` selects the AVX2 kernels (module `avx2`) and compiles the rest of a
//! step's loops with AVX2 instruction selection, `None` the portable kernels. Off x86-64 the
//! token is an empty type, so only `None` exists. The arithmetic is the same either way (no
//! fused multiply-adds, the same operations in the same order), so both give the same bits.

/// Proof that the running CPU has AVX2: only [`Avx2::detect`] makes one.
#[cfg(target_arch = "x86_64")]
#[derive(Debug, Clone, Copy)]
pub(crate) struct Avx2(());

#[cfg(target_arch = "x86_64")]
impl Avx2 {
    /// `Some` when the CPU supports AVX2 (detected once and cached by `std`).
    pub(crate) fn detect() -> Option<Self> {
        std::is_x86_feature_detected!("avx2").then_some(Self(()))
    }
}

/// No AVX2 kernels off x86-64.
#[cfg(not(target_arch = "x86_64"))]
#[derive(Debug, Clone, Copy)]
pub(crate) enum Avx2 {}

#[cfg(not(target_arch = "x86_64"))]
impl Avx2 {
    /// Never available off x86-64.
    pub(crate) fn detect() -> Option<Self> {
        None
    }
}

/// Runs `f`, compiled with AVX2 enabled when `simd` is `Some` (same results either way: the
/// arithmetic is the same, only the instruction selection differs). `f` should be
/// `#[inline(always)]` so that it is compiled into the AVX2 function.
#[inline(always)]
pub(crate) fn with_simd<R>(simd: Option<Avx2>, f: impl FnOnce() -> R) -> R {
    match simd {
        #[cfg(target_arch = "x86_64")]
        Some(cpu) => run(cpu, f),
        _ => f(),
    }
}

/// Runs `f` compiled with AVX2 enabled (`f` is inlined into an AVX2 function; its arithmetic
/// is unchanged, only the instruction selection and vector width differ).
#[cfg(target_arch = "x86_64")]
#[allow(unsafe_code)]
#[inline(always)]
fn run<R>(_cpu: Avx2, f: impl FnOnce() -> R) -> R {
    // SAFETY: `run_k` only needs AVX2, whose presence `_cpu` proves: an `Avx2` is made by
    // `Avx2::detect` alone, after the run-time check.
    unsafe { run_k(f) }
}

#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2")]
fn run_k<R>(f: impl FnOnce() -> R) -> R {
    f()
}
