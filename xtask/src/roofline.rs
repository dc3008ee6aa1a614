//! `cargo xtask roofline [--filter S] [--threads 1,2,...]`: the distance of the registered hot
//! kernels (`anim_core::cases::roofline`, each crate's `cases` module) from this machine's
//! limits (Williams, Waterman & Patterson 2009).
//!
//! The limits are measured here, on one thread and on the full pool: memory bandwidth by a
//! STREAM-style triad `a = b + s c` (24 bytes an element, the write counted once as STREAM
//! does) and a read-only sum (8 bytes an element) over arrays of 128 MiB each, several times the
//! last-level cache; peak flop rates by independent multiply-add chains in `f32` and `f64`, once
//! as the build's instruction set compiles them (plain `a * m + c`, unfused; the default x86-64
//! target vectorises them to 128-bit SSE2 multiplies and adds) and once as 256-bit AVX2 FMA
//! intrinsics (chosen at run time where the CPU has them, as the workspace's AVX2 kernels are).
//! Limits are the fastest of the rounds (other work on the machine only lowers a rate), kernel
//! times the median. A kernel's bound uses the fastest measured bandwidth and
//! peak of its precision on the same thread count. Each kernel is timed in rounds that
//! alternate the thread counts; its time per item is the median over the rounds.

use crate::registry::fmt_num;
use crate::registry::roofline::{Kernel, Precision, attainable, bound_seconds, distance};
use crate::scaling::load_average;
use std::fmt::Write as _;
use std::hint::black_box;
use std::time::Instant;

/// Elements of each bandwidth array: 2^24 `f64`, 128 MiB.
const STREAM_LEN: usize = 1 << 24;
/// Rounds of every timing (median and range over them).
const ROUNDS: usize = 5;
/// Shortest timed batch, seconds.
const MIN_BATCH: f64 = 0.05;

/// The machine's limits on one thread count.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Limits {
    /// Threads.
    pub threads: usize,
    /// Triad bandwidth, bytes/s.
    pub triad: f64,
    /// Read-only sum bandwidth, bytes/s.
    pub read: f64,
    /// Peak flop rates, flops/s: `f32` and `f64` as the build compiles them.
    pub build: [f64; 2],
    /// The same with AVX2 + FMA (`None` where the CPU lacks them).
    pub fma: Option<[f64; 2]>,
}

impl Limits {
    /// The fastest measured bandwidth, bytes/s.
    pub fn bandwidth(&self) -> f64 {
        self.triad.max(self.read)
    }

    /// The fastest measured peak of `p`, flops/s.
    pub fn peak(&self, p: Precision) -> f64 {
        let i = usize::from(p == Precision::F64);
        self.fma.map_or(self.build[i], |f| f[i].max(self.build[i]))
    }
}

/// One kernel on one thread count.
#[derive(Debug, Clone)]
pub struct Row {
    pub krate: &'static str,
    pub name: &'static str,
    pub item: &'static str,
    pub precision: Precision,
    pub reason: &'static str,
    pub threads: usize,
    pub items: usize,
    pub bytes: f64,
    pub flops: f64,
    /// Median time per item, seconds, and the range over the rounds.
    pub seconds: f64,
    pub range: (f64, f64),
    /// An error from the kernel's setup, if it failed.
    pub error: Option<String>,
}

impl Row {
    /// The roofline bound on the time per item under `l`.
    pub fn bound(&self, l: &Limits) -> f64 {
        bound_seconds(self.bytes, self.flops, l.bandwidth(), l.peak(self.precision))
    }
}

/// Builds a pool of `t` threads.
fn pool(t: usize) -> Result<rayon::ThreadPool, String> {
    rayon::ThreadPoolBuilder::new().num_threads(t).build().map_err(|e| e.to_string())
}

/// Median and range of `v`.
fn median(mut v: Vec<f64>) -> (f64, (f64, f64)) {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return (f64::NAN, (f64::NAN, f64::NAN));
    }
    (v[v.len() / 2], (v[0], v[v.len() - 1]))
}

/// Times `f` on each pool in turn, `ROUNDS` rounds, `reps` calls per batch (calibrated on the
/// first pool so a batch lasts at least [`MIN_BATCH`]): per pool the median seconds per call
/// and its range.
fn interleaved(pools: &[rayon::ThreadPool], f: &mut (dyn FnMut() + Send)) -> Vec<(f64, (f64, f64))> {
    let Some(first) = pools.first() else { return Vec::new() };
    let once = first.install(|| {
        let t = Instant::now();
        f();
        t.elapsed().as_secs_f64().max(1e-9)
    });
    let reps = ((MIN_BATCH / once).ceil() as usize).clamp(1, 1_000_000);
    let mut times = vec![Vec::new(); pools.len()];
    for _ in 0..ROUNDS {
        for (p, t) in pools.iter().zip(&mut times) {
            t.push(p.install(|| {
                let start = Instant::now();
                for _ in 0..reps {
                    f();
                }
                start.elapsed().as_secs_f64() / reps as f64
            }));
        }
    }
    times.into_iter().map(median).collect()
}

/// `n` chain steps on 48 `f32` accumulators (12 SSE registers), `a = a m + c` unfused: the
/// build's instruction set, vectorised by the compiler. Returns a sum so nothing is dropped.
fn chains_f32(n: usize, m: f32, c: f32) -> f32 {
    let mut acc = [1.0f32; 48];
    for _ in 0..n {
        for a in &mut acc {
            *a = *a * m + c;
        }
    }
    acc.iter().sum()
}

/// As [`chains_f32`] on 24 `f64` accumulators.
fn chains_f64(n: usize, m: f64, c: f64) -> f64 {
    let mut acc = [1.0f64; 24];
    for _ in 0..n {
        for a in &mut acc {
            *a = *a * m + c;
        }
    }
    acc.iter().sum()
}

/// `n` fused multiply-add steps on 12 AVX registers of 8 `f32` (96 chains), written with the
/// intrinsics so that they stay 256-bit vectors.
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn fma_f32(n: usize, m: f32, c: f32) -> f32 {
    use std::arch::x86_64::{_mm256_cvtss_f32, _mm256_fmadd_ps, _mm256_set1_ps};
    let (mv, cv) = (_mm256_set1_ps(m), _mm256_set1_ps(c));
    let mut acc = [_mm256_set1_ps(1.0); 12];
    for _ in 0..n {
        for a in &mut acc {
            *a = _mm256_fmadd_ps(*a, mv, cv);
        }
    }
    black_box(&acc);
    _mm256_cvtss_f32(acc[0])
}

/// As [`fma_f32`] on 12 AVX registers of 4 `f64` (48 chains).
#[cfg(target_arch = "x86_64")]
#[target_feature(enable = "avx2,fma")]
fn fma_f64(n: usize, m: f64, c: f64) -> f64 {
    use std::arch::x86_64::{_mm256_cvtsd_f64, _mm256_fmadd_pd, _mm256_set1_pd};
    let (mv, cv) = (_mm256_set1_pd(m), _mm256_set1_pd(c));
    let mut acc = [_mm256_set1_pd(1.0); 12];
    for _ in 0..n {
        for a in &mut acc {
            *a = _mm256_fmadd_pd(*a, mv, cv);
        }
    }
    black_box(&acc);
    _mm256_cvtsd_f64(acc[0])
}

/// Whether this CPU has AVX2 and FMA.
fn has_fma() -> bool {
    #[cfg(target_arch = "x86_64")]
    {
        is_x86_feature_detected!("avx2") && is_x86_feature_detected!("fma")
    }
    #[cfg(not(target_arch = "x86_64"))]
    false
}

/// Runs the chain `which` (0, 1: build f32, f64; 2, 3: FMA f32, f64) for `n` steps; flops done.
#[allow(unsafe_code)]
fn chain(which: usize, n: usize) -> f64 {
    // Multiplier and addend from `black_box`: the chains converge to 1, never denormal.
    let (m, c) = (black_box(0.999_999), black_box(1e-6));
    let lanes = match which {
        0 => {
            black_box(chains_f32(n, m as f32, c as f32));
            48.0
        }
        1 => {
            black_box(chains_f64(n, m, c));
            24.0
        }
        #[cfg(target_arch = "x86_64")]
        2 if has_fma() => {
            // SAFETY: the CPU has AVX2 and FMA (checked just above), all `fma_f32` needs.
            black_box(unsafe { fma_f32(n, m as f32, c as f32) });
            96.0
        }
        #[cfg(target_arch = "x86_64")]
        3 if has_fma() => {
            // SAFETY: as above.
            black_box(unsafe { fma_f64(n, m, c) });
            48.0
        }
        _ => 0.0,
    };
    2.0 * lanes * n as f64
}

/// Measures the limits on each pool (`threads[i]` threads in `pools[i]`), interleaved rounds;
/// each limit is the fastest round's.
fn limits(threads: &[usize], pools: &[rayon::ThreadPool]) -> Vec<Limits> {
    let mut a = vec![0.0f64; STREAM_LEN];
    let b: Vec<f64> = (0..STREAM_LEN).map(|i| (i % 7) as f64).collect();
    let c: Vec<f64> = (0..STREAM_LEN).map(|i| (i % 5) as f64).collect();
    // Four chunks per thread of the largest pool (a multiple of 8 elements).
    let chunk = (STREAM_LEN / (4 * threads.iter().copied().max().unwrap_or(1))).next_multiple_of(8);
    let triad = interleaved(pools, &mut || {
        use rayon::prelude::*;
        a.par_chunks_mut(chunk).zip(b.par_chunks(chunk)).zip(c.par_chunks(chunk)).for_each(|((a, b), c)| {
            for ((a, b), c) in a.iter_mut().zip(b).zip(c) {
                *a = b + 3.0 * c;
            }
        });
        black_box(&a);
    });
    let read = interleaved(pools, &mut || {
        use rayon::prelude::*;
        let s: f64 = b
            .par_chunks(chunk)
            .map(|b| {
                let mut acc = [0.0f64; 8];
                for x in b.chunks_exact(8) {
                    for k in 0..8 {
                        acc[k] += x[k];
                    }
                }
                acc.iter().sum::<f64>()
            })
            .sum();
        black_box(s);
    });
    let steps = 1 << 16;
    let mut peaks = Vec::new();
    for which in 0..4 {
        let flops = chain(which, 1) * steps as f64;
        let t = interleaved(pools, &mut || {
            rayon::broadcast(|_| chain(which, steps));
        });
        peaks.push((flops, t));
    }
    threads
        .iter()
        .enumerate()
        .map(|(i, &threads)| {
            // The fastest round: other work on the machine only ever lowers a rate.
            let rate = |w: usize| threads as f64 * peaks[w].0 / peaks[w].1[i].1.0;
            Limits {
                threads,
                triad: 24.0 * STREAM_LEN as f64 / triad[i].1.0,
                read: 8.0 * STREAM_LEN as f64 / read[i].1.0,
                build: [rate(0), rate(1)],
                fma: has_fma().then(|| [rate(2), rate(3)]),
            }
        })
        .collect()
}

/// A time per item in nanoseconds, three significant digits.
fn ns(s: f64) -> String {
    let x = s * 1e9;
    if !x.is_finite() {
        "-".into()
    } else if x >= 100.0 {
        format!("{x:.0} ns")
    } else if x >= 10.0 {
        format!("{x:.1} ns")
    } else {
        format!("{x:.2} ns")
    }
}

/// The CPU's clock from `/proc/cpuinfo` (MHz), if given.
fn mhz() -> Option<f64> {
    let s = std::fs::read_to_string("/proc/cpuinfo").ok()?;
    s.lines().find(|l| l.starts_with("cpu MHz"))?.split(':').nth(1)?.trim().parse().ok()
}

/// Measures the limits and every registered kernel whose crate or name contains `filter` on
/// `threads`; returns the Markdown section (tables and notes).
pub fn measure(filter: Option<&str>, threads: &[usize]) -> String {
    let start = Instant::now();
    let load_before = load_average();
    let mut ps = Vec::new();
    for &t in threads {
        match pool(t) {
            Ok(p) => ps.push(p),
            Err(e) => return format!("could not run: a pool of {t} threads: {e}\n"),
        }
    }
    eprintln!("roofline: machine limits on {threads:?} threads");
    let limits = limits(threads, &ps);
    let kernels: Vec<Kernel> = anim::cases()
        .kernels
        .into_iter()
        .filter(|k| crate::suites::selected(filter, k.crate_name, k.name))
        .collect();
    let mut rows = Vec::new();
    for k in &kernels {
        let t = Instant::now();
        let base = |threads, error| Row {
            krate: k.crate_name,
            name: k.name,
            item: k.item,
            precision: k.precision,
            reason: k.reason,
            threads,
            items: 0,
            bytes: f64::NAN,
            flops: f64::NAN,
            seconds: f64::NAN,
            range: (f64::NAN, f64::NAN),
            error,
        };
        match (k.setup)(false) {
            Ok(mut run) => {
                let timed = interleaved(&ps, &mut *run.run);
                for (&threads, (s, (lo, hi))) in threads.iter().zip(timed) {
                    let n = run.items as f64;
                    rows.push(Row {
                        items: run.items,
                        bytes: run.bytes_per_item,
                        flops: run.flops_per_item,
                        seconds: s / n,
                        range: (lo / n, hi / n),
                        ..base(threads, None)
                    });
                }
            }
            Err(e) => rows.extend(threads.iter().map(|&t| base(t, Some(e.clone())))),
        }
        eprintln!("  {:<55} {:>6.1} s", k.name, t.elapsed().as_secs_f64());
    }
    markdown(&limits, &rows, load_before.zip(load_average()), start.elapsed().as_secs_f64())
}

/// The roofline section: the limits, then one row per kernel and thread count.
pub fn markdown(limits: &[Limits], rows: &[Row], load: Option<(f64, f64)>, secs: f64) -> String {
    let gb = |b: f64| format!("{:.1}", b / 1e9);
    let mut md = String::new();
    let _ = writeln!(
        md,
        "Measured by `cargo xtask roofline` in {secs:.0} s on {}.{} Limits first: memory bandwidth \
         (triad `a = b + 3 c`, 24 bytes an element; read-only sum, 8 bytes an element; arrays of \
         128 MiB), peak flop rates of independent multiply-add chains as this build compiles them \
         and with AVX2 + FMA enabled (where the CPU has them).\n",
        crate::machine::Machine::this().describe(),
        load.map_or(String::new(), |(a, b)| format!(
            " The 1-minute load average was {a:.2} before and {b:.2} after: other work on the cores \
             lowers every measured rate, the limits as much as the kernels."
        ))
    );
    let _ = writeln!(
        md,
        "| threads | triad GB/s | read GB/s | f32 GFLOP/s (build) | f64 GFLOP/s (build) | f32 GFLOP/s (AVX2+FMA) | f64 GFLOP/s (AVX2+FMA) |\n\
         | --- | --- | --- | --- | --- | --- | --- |"
    );
    for l in limits {
        let f = |x: Option<f64>| x.map_or("-".into(), gb);
        let _ = writeln!(
            md,
            "| {} | {} | {} | {} | {} | {} | {} |",
            l.threads,
            gb(l.triad),
            gb(l.read),
            gb(l.build[0]),
            gb(l.build[1]),
            f(l.fma.map(|f| f[0])),
            f(l.fma.map(|f| f[1]))
        );
    }
    if let Some(mhz) = mhz() {
        // Two FMA units of 256 bits per core, the common x86 design since Haswell and Zen 2.
        let _ = writeln!(
            md,
            "\nNominal per core at the {mhz:.0} MHz /proc/cpuinfo reports, assuming two 256-bit FMA \
             units: {:.1} GFLOP/s f32, {:.1} GFLOP/s f64 (measured on one thread: {} and {}).",
            mhz * 32.0 / 1e3,
            mhz * 16.0 / 1e3,
            limits.first().map_or("-".into(), |l| gb(l.peak(Precision::F32))),
            limits.first().map_or("-".into(), |l| gb(l.peak(Precision::F64)))
        );
    }
    let _ = writeln!(
        md,
        "\nKernels: bytes and flops per item as counted from each kernel's code (the count is \
         documented at its registration); achieved rates from the median time per item over \
         {ROUNDS} rounds alternating the thread counts (range in brackets); the bound is \
         `min(peak, bandwidth x intensity)` with the fastest bandwidth and the peak of the \
         kernel's precision on the same threads; distance = time / bound time.\n"
    );
    let _ = writeln!(
        md,
        "| crate | kernel | items of one run | threads | time / item | GB/s | GFLOP/s | flops / byte | bound GFLOP/s | bound time / item | distance | why not within 2x |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- | --- |"
    );
    for r in rows {
        if let Some(e) = &r.error {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} | could not run: {e} | | | | | | | |",
                r.krate, r.name, r.item, r.threads
            );
            continue;
        }
        let Some(l) = limits.iter().find(|l| l.threads == r.threads) else { continue };
        let bound = r.bound(l);
        let ai = r.flops / r.bytes;
        let d = distance(r.seconds, bound);
        let roof = attainable(ai, l.bandwidth(), l.peak(r.precision));
        let limited =
            if r.bytes / l.bandwidth() >= r.flops / l.peak(r.precision) { "memory" } else { "compute" };
        let _ = writeln!(
            md,
            "| {} | {} | {} x {} | {} | {} [{} - {}] | {} | {} | {} | {} ({limited}, {}) | {} | {d:.1}x | {} |",
            r.krate,
            r.name,
            r.items,
            r.item,
            r.threads,
            ns(r.seconds),
            ns(r.range.0),
            ns(r.range.1),
            gb(r.bytes / r.seconds),
            gb(r.flops / r.seconds),
            fmt_num(ai),
            gb(roof),
            r.precision.name(),
            ns(bound),
            if d <= 2.0 {
                "-"
            } else if r.reason.is_empty() {
                "(no reason registered)"
            } else {
                r.reason
            }
        );
    }
    md
}

/// `cargo xtask roofline`: prints the section; false when a kernel could not run.
pub fn run(filter: Option<&str>, threads: &[usize]) -> bool {
    let start = Instant::now();
    let md = measure(filter, threads);
    println!("{md}");
    eprintln!("roofline finished in {:.1} s", start.elapsed().as_secs_f64());
    !md.contains("could not run")
}

#[cfg(test)]
mod tests {
    use super::*;

    fn limits() -> Limits {
        Limits { threads: 1, triad: 20e9, read: 25e9, build: [10e9, 5e9], fma: Some([40e9, 20e9]) }
    }

    fn row(bytes: f64, flops: f64, precision: Precision, seconds: f64) -> Row {
        Row {
            krate: "anim-x",
            name: "k",
            item: "particle",
            precision,
            reason: "",
            threads: 1,
            items: 10,
            bytes,
            flops,
            seconds,
            range: (seconds, seconds),
            error: None,
        }
    }

    #[test]
    fn a_kernel_is_bound_by_the_fastest_bandwidth_and_its_precisions_peak() {
        let l = limits();
        assert_eq!(l.bandwidth(), 25e9);
        assert_eq!(l.peak(Precision::F32), 40e9);
        assert_eq!(l.peak(Precision::F64), 20e9);
        // 100 bytes, 10 flops: 4 ns at 25 GB/s against 0.5 ns of f64 arithmetic.
        assert!((row(100.0, 10.0, Precision::F64, 8e-9).bound(&l) - 4e-9).abs() < 1e-20);
        // 100 bytes, 1000 flops of f32: 25 ns at 40 GFLOP/s.
        assert!((row(100.0, 1000.0, Precision::F32, 8e-9).bound(&l) - 25e-9).abs() < 1e-20);
        // Without FMA the build's peak bounds it: 1000 flops at 10 GFLOP/s, 100 ns.
        let plain = Limits { fma: None, ..l };
        assert!((row(100.0, 1000.0, Precision::F32, 8e-9).bound(&plain) - 100e-9).abs() < 1e-20);
    }

    #[test]
    fn the_table_gives_the_distance_and_the_reason_beyond_2x() {
        let l = limits();
        let mut far = row(100.0, 10.0, Precision::F64, 12e-9);
        far.reason = "a latency chain";
        let near = row(100.0, 10.0, Precision::F64, 6e-9);
        let md = markdown(&[l], &[near, far], Some((1.0, 2.0)), 3.0);
        // 6 ns against 4 ns: 1.5x, no reason needed; 12 ns: 3.0x with its reason.
        assert!(md.contains("| 1.5x | - |"), "{md}");
        assert!(md.contains("| 3.0x | a latency chain |"), "{md}");
        assert!(md.contains("(memory, f64)"), "{md}");
        assert!(md.contains("1.00 before and 2.00 after"), "{md}");
    }

    #[test]
    fn the_chains_do_the_flops_they_count() {
        assert_eq!(chain(0, 10), 2.0 * 48.0 * 10.0);
        assert_eq!(chain(1, 10), 2.0 * 24.0 * 10.0);
        // The chains converge to 1 from 1: a * m + c with m + c = 1 keeps them there.
        assert!((chains_f64(1000, 0.999_999, 1e-6) - 24.0).abs() < 1e-9);
    }

    #[test]
    fn every_registered_kernel_has_positive_counts_and_runs() {
        let failures = anim_core::cases::roofline::quick_kernel_failures(&anim::cases().kernels);
        assert!(failures.is_empty(), "{}", failures.join("\n"));
        assert!(anim::cases().kernels.len() >= 7);
    }
}
