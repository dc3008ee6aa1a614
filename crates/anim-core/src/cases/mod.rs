//! Conformance checks, hard cases, soak runs and work-precision studies: the types every crate's
//! `cases` feature registers and `cargo xtask` runs (feature `cases`).
//!
//! A crate exports `pub fn register(r: &mut Registry)` from its own `cases` module; its tests run
//! the cases in quick mode and `cargo xtask conformance`, `stability` and `report` run them from
//! the workspace registry, so a check lives in one place and is run by both.

pub mod core;
pub mod float;
mod frontier;
pub mod roofline;
mod soak;
mod sweep;
mod threads;

pub use frontier::Frontier;
pub use soak::{
    Budget, Clock, ENERGY_STRIDE, Soak, SoakCase, drive, energy_above, energy_exceeds, finish, rejected,
};
pub use sweep::Sweep;
pub use threads::{across_threads, differing_bits};

use std::time::Instant;

/// Options every case receives.
#[derive(Debug, Clone, Copy)]
pub struct Ctx {
    /// Smaller sweeps for CI (`--quick`).
    pub quick: bool,
}

/// How a measured value is judged against its reference.
#[derive(Debug, Clone, Copy, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Judge {
    /// Pass when `|measured - reference| <= tolerance`.
    Near,
    /// Pass when `measured <= tolerance` (an error that must be small; reference is informative).
    AtMost,
    /// Pass when `measured >= tolerance`.
    AtLeast,
}

/// One conformance measurement with its verdict.
#[derive(Debug, Clone)]
pub struct Check {
    /// The crate the check belongs to (`anim-fem`).
    pub crate_name: &'static str,
    /// The reference problem.
    pub case: String,
    /// What is measured.
    pub metric: String,
    /// The measured value.
    pub measured: f64,
    /// The reference value.
    pub reference: f64,
    /// The tolerance, read according to `judge`.
    pub tolerance: f64,
    /// How `measured` is judged.
    pub judge: Judge,
    /// Where the reference comes from.
    pub source: &'static str,
}

impl Check {
    /// A check of `crate_name` that could not run (its model did not build, its reference did
    /// not load): measured NaN, so it fails, with `why` in the metric and on standard error.
    pub fn could_not_run(crate_name: &'static str, case: impl Into<String>, why: &str) -> Self {
        let case = case.into();
        eprintln!("{case}: {why}");
        Check {
            crate_name,
            case,
            metric: format!("could not run: {why}"),
            measured: f64::NAN,
            reference: 0.0,
            tolerance: 0.0,
            judge: Judge::AtMost,
            source: "-",
        }
    }

    /// Whether the measurement is finite and meets its rule.
    pub fn passed(&self) -> bool {
        if !self.measured.is_finite() {
            return false;
        }
        match self.judge {
            Judge::Near => (self.measured - self.reference).abs() <= self.tolerance,
            Judge::AtMost => self.measured <= self.tolerance,
            Judge::AtLeast => self.measured >= self.tolerance,
        }
    }

    /// The rule in words, for tables.
    pub fn rule(&self) -> String {
        match self.judge {
            Judge::Near => format!("|m - {}| <= {}", fmt_num(self.reference), fmt_num(self.tolerance)),
            Judge::AtMost => format!("<= {}", fmt_num(self.tolerance)),
            Judge::AtLeast => format!(">= {}", fmt_num(self.tolerance)),
        }
    }
}

/// How a conformance case runs: a plain function for a crate's reference problem, or a closure
/// over the preset it checks for the suites that run on every registered preset.
pub type CaseFn = Box<dyn Fn(&Ctx) -> Vec<Check> + Send + Sync>;

/// A conformance case: one reference problem, several checks.
pub struct ConformanceCase {
    /// The crate.
    pub crate_name: &'static str,
    /// The case's name.
    pub name: &'static str,
    /// Runs the case.
    pub run: CaseFn,
}

/// What a hard case did.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub enum Outcome {
    /// Ran to the end within its bounds.
    Stable(String),
    /// Diverged and the divergence was detected and reported (never a silent NaN).
    Diverged(String),
    /// Refused up front with a clear error.
    Rejected(String),
}

impl Outcome {
    /// The outcome's kind in words.
    pub fn kind(&self) -> &'static str {
        match self {
            Outcome::Stable(_) => "stable",
            Outcome::Diverged(_) => "diverged (detected)",
            Outcome::Rejected(_) => "rejected",
        }
    }

    /// The detail text.
    pub fn detail(&self) -> &str {
        match self {
            Outcome::Stable(s) | Outcome::Diverged(s) | Outcome::Rejected(s) => s,
        }
    }

    /// Whether this outcome is of the same kind as `other`.
    pub fn same_kind(&self, other: &Outcome) -> bool {
        std::mem::discriminant(self) == std::mem::discriminant(other)
    }
}

/// A named hard case with the outcome it is expected to have.
pub struct StabilityCase {
    /// The crate.
    pub crate_name: &'static str,
    /// The case's name.
    pub name: &'static str,
    /// Expected outcome kind (the detail text is ignored).
    pub expected: fn() -> Outcome,
    /// Runs the case.
    pub run: fn(&Ctx) -> Outcome,
}

/// One point of a work-precision curve.
#[derive(Debug, Clone, Copy, serde::Serialize, serde::Deserialize)]
pub struct Point {
    /// The swept parameter (time step, resolution, iterations).
    #[serde(with = "crate::cases::float")]
    pub param: f64,
    /// Median wall time of one run, seconds.
    #[serde(with = "crate::cases::float")]
    pub seconds: f64,
    /// Error against the reference.
    #[serde(with = "crate::cases::float")]
    pub error: f64,
}

/// One method's curve.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct Series {
    /// The method.
    pub label: String,
    /// The curve, in sweep order.
    pub points: Vec<Point>,
}

/// A work-precision study: error against wall time for several methods on one problem.
#[derive(Debug, Clone, serde::Serialize, serde::Deserialize)]
pub struct StudyResult {
    /// Title.
    pub title: String,
    /// File stem for the SVG and table.
    pub slug: String,
    /// What the error measures.
    pub error_label: String,
    /// What the swept parameter is.
    pub param_label: String,
    /// One curve per method.
    pub series: Vec<Series>,
}

/// A registered work-precision study.
pub struct Study {
    /// The crate.
    pub crate_name: &'static str,
    /// The study's name.
    pub name: &'static str,
    /// Runs the study.
    pub run: fn(&Ctx) -> StudyResult,
}

/// What a study's measurements serve besides its report section: the scenes `anim run
/// --tolerance` picks a method for from its points, and extra tolerances for its
/// cheapest-method tables.
#[derive(Debug, Clone, Copy)]
pub struct StudyUse {
    /// The study's slug ([`StudyResult::slug`]).
    pub study: &'static str,
    /// The scenes it measures: a kind (`"harmonic-oscillator"`, any scene of it) or kind and
    /// preset joined by a slash (`"fem/cantilever-beam"`, that preset only); `None` when no
    /// scene picks from it.
    pub scene: Option<&'static str>,
    /// Simulated time the study measured over (`None`: the error is not a trajectory's, e.g. a
    /// steady state or one pressure projection).
    pub horizon: Option<f64>,
    /// The study problem's parameters the picker scales by (names and values), quick or full.
    pub problem: fn(quick: bool) -> Vec<(&'static str, f64)>,
    /// Tolerances added to the standard ones in its cheapest-method tables.
    pub extra_tolerances: &'static [f64],
}

impl StudyUse {
    /// The study `study` serves the scenes `scene`, measured over `horizon`, with no problem
    /// parameters and no extra tolerances (set them with struct update syntax).
    #[must_use]
    pub const fn scene(study: &'static str, scene: &'static str, horizon: Option<f64>) -> Self {
        Self { study, scene: Some(scene), horizon, problem: no_problem, extra_tolerances: &[] }
    }
}

/// A study problem without parameters to scale by.
#[must_use]
pub fn no_problem(_quick: bool) -> Vec<(&'static str, f64)> {
    Vec::new()
}

/// Everything registered.
#[derive(Default)]
pub struct Registry {
    /// Conformance cases.
    pub conformance: Vec<ConformanceCase>,
    /// Hard cases.
    pub stability: Vec<StabilityCase>,
    /// Work-precision studies.
    pub studies: Vec<Study>,
    /// Soak runs.
    pub soak: Vec<SoakCase>,
    /// What the studies' measurements serve (scenes for `--tolerance`, extra tolerances).
    pub study_uses: Vec<StudyUse>,
    /// Hot kernels for the roofline table (`cargo xtask roofline`).
    pub kernels: Vec<roofline::Kernel>,
}

/// The larger of `a` and `b`, NaN when either is NaN: a running maximum of errors that keeps a
/// NaN marking a failed measurement (`f64::max` returns the other operand and drops it).
///
/// ```
/// use anim_core::cases::nan_max;
/// assert_eq!(nan_max(1.0, 2.0), 2.0);
/// assert!(nan_max(f64::NAN, 2.0).is_nan());
/// assert!(nan_max(3.0, f64::NAN).is_nan());
/// assert!([0.5, f64::NAN, 0.1].into_iter().fold(0.0, nan_max).is_nan());
/// ```
#[must_use]
pub fn nan_max(a: f64, b: f64) -> f64 {
    if a.is_nan() || b.is_nan() { f64::NAN } else { a.max(b) }
}

/// Median wall time of `f`, in seconds: repeats `f` in batches until each batch lasts at least
/// `min_batch` seconds, over `batches` batches. The first call calibrates the batch size; when
/// one call already lasts `min_batch`, that call is the first batch, so a slow `f` runs
/// `batches` times and not once more.
///
/// ```
/// use anim_core::cases::median_seconds;
///
/// let mut calls = 0;
/// let s = median_seconds(3, 0.0, || calls += 1);
/// assert_eq!(calls, 3);
/// assert!(s >= 0.0);
/// ```
pub fn median_seconds(batches: usize, min_batch: f64, mut f: impl FnMut()) -> f64 {
    // Calibrate the repeat count on one call.
    let start = Instant::now();
    f();
    let once = start.elapsed().as_secs_f64().max(1e-9);
    let reps = ((min_batch / once).ceil() as usize).clamp(1, 1_000_000);
    let mut times = Vec::with_capacity(batches.max(1));
    if reps == 1 {
        times.push(once);
    }
    while times.len() < batches.max(1) {
        let start = Instant::now();
        for _ in 0..reps {
            f();
        }
        times.push(start.elapsed().as_secs_f64() / reps as f64);
    }
    times.sort_by(f64::total_cmp);
    times[times.len() / 2]
}

/// A duration for tables: `us`, `ms` or `s` with two decimals; `-` when not finite.
pub fn seconds(s: f64) -> String {
    if !s.is_finite() {
        return "-".into();
    }
    if s < 1e-3 {
        format!("{:.2} us", s * 1e6)
    } else if s < 1.0 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

/// Formats a number compactly for tables.
pub fn fmt_num(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if !x.is_finite() {
        format!("{x}")
    } else if x.abs() >= 1e-3 && x.abs() < 1e4 {
        let s = format!("{x:.4}");
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        format!("{x:.3e}")
    }
}

/// Registers anim-core's own cases (its integrators, Lie groups and linear algebra).
pub fn register(r: &mut Registry) {
    self::core::register(r);
}

/// Runs every conformance and stability case that `register` registers, in quick mode, and
/// returns one line per failed check or unexpected outcome (empty when everything passes): what
/// a crate's `tests/cases.rs` asserts. Its roofline kernels are built in quick mode and run once,
/// their counts checked positive ([`roofline::quick_kernel_failures`]).
///
/// ```
/// use anim_core::cases::{Check, ConformanceCase, Judge, Registry, quick_failures};
///
/// fn register(r: &mut Registry) {
///     r.conformance.push(ConformanceCase {
///         crate_name: "anim-core",
///         name: "one plus one",
///         run: Box::new(|_| {
///             vec![Check {
///                 crate_name: "anim-core",
///                 case: "one plus one".into(),
///                 metric: "sum".into(),
///                 measured: 1.0 + 1.0,
///                 reference: 2.0,
///                 tolerance: 0.0,
///                 judge: Judge::Near,
///                 source: "arithmetic",
///             }]
///         }),
///     });
/// }
/// assert!(quick_failures(register).is_empty());
/// ```
#[must_use]
pub fn quick_failures(register: fn(&mut Registry)) -> Vec<String> {
    let mut r = Registry::default();
    register(&mut r);
    let ctx = Ctx { quick: true };
    let mut failures = Vec::new();
    for case in &r.conformance {
        let checks = (case.run)(&ctx);
        if checks.is_empty() {
            failures.push(format!("{} / {}: no checks", case.crate_name, case.name));
        }
        for c in checks.iter().filter(|c| !c.passed()) {
            failures.push(format!(
                "{} / {} / {}: measured {} against {} ({})",
                c.crate_name,
                c.case,
                c.metric,
                fmt_num(c.measured),
                c.rule(),
                c.source
            ));
        }
    }
    for case in &r.stability {
        let (expected, got) = ((case.expected)(), (case.run)(&ctx));
        if !got.same_kind(&expected) {
            failures.push(format!(
                "{} / {}: expected {}, got {}: {}",
                case.crate_name,
                case.name,
                expected.kind(),
                got.kind(),
                got.detail()
            ));
        }
    }
    failures.extend(roofline::quick_kernel_failures(&r.kernels));
    failures
}

/// The test a crate's `cases` module declares with one line: every conformance and stability
/// case of `register` passes in quick mode (see [`quick_failures`]).
///
/// `cargo ci` skips this test in its test run (`--skip
/// conformance_and_hard_cases_pass_in_quick_mode`) because its suites step runs the same cases
/// right after, all crates in one process; `cargo test -p <crate> --features cases` runs it.
#[macro_export]
macro_rules! quick_cases_test {
    ($register:path) => {
        #[cfg(test)]
        mod quick_cases {
            #[test]
            fn conformance_and_hard_cases_pass_in_quick_mode() {
                let failures = $crate::cases::quick_failures($register);
                assert!(failures.is_empty(), "{}", failures.join("\n"));
            }
        }
    };
}

crate::quick_cases_test!(crate::cases::register);
