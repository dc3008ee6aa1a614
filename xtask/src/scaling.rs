//! Thread scaling of every registered preset (`anim::presets()`), through anim-core's
//! `DynScene` alone, so that a newly registered preset gets its row without any edit here: the
//! preset (its `quick_params` with `--quick`) stepped on rayon pools of 1, 2, ... threads; time
//! per step, speed-up over one thread, and whether the checkpoint after the first steps is bit
//! for bit the one-thread checkpoint (it must be: results do not depend on the thread count).
//!
//! A preset that ends before the timing does (its divergence guard fires, or its nominal
//! duration `run.steps()` is reached) restarts from its initial checkpoint; the restore is not
//! timed. `cargo xtask scaling` prints the table; `cargo xtask report` puts it in the report.

use crate::registry::differing_bits;
use anim_core::scene::{BuildContext, DynScene, Frame, Looped, Preset, SceneKind};
use std::fmt::Write as _;
use std::time::{Duration, Instant};

/// One measured row.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct Row {
    pub krate: String,
    /// The preset's name.
    pub scene: String,
    pub threads: usize,
    /// Seconds per step (NaN when the run failed).
    #[serde(with = "anim_core::cases::float")]
    pub seconds: f64,
    /// Speed-up over the one-thread run of the same scene.
    #[serde(with = "anim_core::cases::float")]
    pub speedup: f64,
    /// Whether the state after the first steps equals the one-thread state bit for bit.
    pub identical: Option<bool>,
    /// An error, if the scene failed; or the steps that failed within the preset's duration (each
    /// followed by a restart), which also fail the row.
    pub note: String,
}

/// The 1-minute load average (`/proc/loadavg`), if known: other processes on the same cores
/// take time from the threads being measured.
pub fn load_average() -> Option<f64> {
    std::fs::read_to_string("/proc/loadavg").ok()?.split_whitespace().next()?.parse().ok()
}

/// Steps compared for determinism before the timing starts.
pub const CHECK_STEPS: usize = 3;

/// Wall time of the timed steps per thread count, seconds (three batches share it).
fn budget(quick: bool) -> f64 {
    if quick { 0.25 } else { 2.0 }
}

/// What a scene is built by.
type Build<'a> = &'a (dyn Fn() -> Result<Box<dyn DynScene>, String> + Sync);

/// What [`measure`] found on one pool.
struct Measured {
    /// Median seconds per step.
    seconds: f64,
    /// The checkpoint and frame values after [`CHECK_STEPS`] steps.
    fingerprint: Vec<f64>,
    /// Steps that failed before the preset's duration ended (each followed by a restart).
    failures: Vec<String>,
}

/// The scene `build` makes, stepped by `dt` on a pool of `threads` threads (back to its start
/// every `duration` steps): its fingerprint after [`CHECK_STEPS`] steps, then the median of three
/// batches of at least two steps each, together `budget` seconds.
fn measure(
    build: Build<'_>,
    dt: f64,
    duration: usize,
    threads: usize,
    budget: f64,
) -> Result<Measured, String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        let mut s = Looped::new(build()?, dt, duration);
        for _ in 0..CHECK_STEPS {
            s.step()?;
        }
        let fingerprint = crate::cases::presets::fingerprint(s.scene(), &mut Frame::default());
        let mut batches = Vec::new();
        for _ in 0..3 {
            let start = Instant::now();
            let (mut n, mut stepping) = (0u32, Duration::ZERO);
            while n < 2 || start.elapsed().as_secs_f64() < budget / 3.0 {
                stepping += s.step()?;
                n += 1;
            }
            batches.push(stepping.as_secs_f64() / f64::from(n));
        }
        batches.sort_by(f64::total_cmp);
        Ok(Measured { seconds: batches[1], fingerprint, failures: s.failures().to_vec() })
    })
}

/// The rows of one scene at each of `threads`; the first count is the reference of speed-up and
/// bits (a failed reference leaves the other rows without a comparison).
fn rows(
    krate: &str,
    scene: &str,
    threads: &[usize],
    measured: impl Fn(usize) -> Result<Measured, String>,
) -> Vec<Row> {
    let mut rows = Vec::new();
    let mut base: Option<Result<Measured, ()>> = None;
    for &t in threads {
        let result = measured(t);
        let reference = base.get_or_insert_with(|| {
            result
                .as_ref()
                .map(|m| Measured {
                    seconds: m.seconds,
                    fingerprint: m.fingerprint.clone(),
                    failures: Vec::new(),
                })
                .map_err(drop)
        });
        let row = match (result, reference) {
            (Ok(m), reference) => {
                let (speedup, identical) = match reference {
                    Ok(b) => {
                        (b.seconds / m.seconds, Some(differing_bits(&b.fingerprint, &m.fingerprint) == 0))
                    }
                    Err(()) => (f64::NAN, None),
                };
                let note = if m.failures.is_empty() {
                    String::new()
                } else {
                    format!(
                        "{} step(s) failed within the preset's duration: {}",
                        m.failures.len(),
                        m.failures[0]
                    )
                };
                Row {
                    krate: krate.into(),
                    scene: scene.into(),
                    threads: t,
                    seconds: m.seconds,
                    speedup,
                    identical,
                    note,
                }
            }
            (Err(e), _) => Row {
                krate: krate.into(),
                scene: scene.into(),
                threads: t,
                seconds: f64::NAN,
                speedup: f64::NAN,
                identical: None,
                note: e,
            },
        };
        rows.push(row);
    }
    rows
}

/// Whether a row passed: same bits as the reference and no failed step.
pub fn passed(row: &Row) -> bool {
    row.identical == Some(true) && row.note.is_empty()
}

/// Times `preset` of `kind` (quick parameters when `quick`) at each of `threads`.
pub fn run_preset(kind: &SceneKind, preset: &Preset, quick: bool, threads: &[usize]) -> Vec<Row> {
    let t0 = Instant::now();
    let make = || (kind.build)(preset.params_for(quick), &BuildContext::default()).map_err(|e| e.to_string());
    let rows = rows(kind.crate_name, preset.name, threads, |t| {
        measure(&make, preset.run.dt, preset.run.steps(), t, budget(quick))
    });
    eprintln!("  scaling {:<13} {:<18} {:>6.1} s", kind.crate_name, preset.name, t0.elapsed().as_secs_f64());
    rows
}

/// `cargo xtask scaling`: every selected preset at each of `threads`, the table printed; true
/// when every run finished with the one-thread bits and no failed step.
pub fn run(quick: bool, filter: Option<&str>, threads: &[usize]) -> bool {
    let start = Instant::now();
    eprintln!("thread scaling on {threads:?} threads{}", if quick { " (quick params)" } else { "" });
    let before = load_average();
    let mut all = Vec::new();
    for (kind, preset) in anim::presets() {
        if crate::suites::selected(filter, kind.crate_name, preset.name) {
            all.extend(run_preset(kind, &preset, quick, threads));
        }
    }
    println!("{}", markdown(&all));
    if let Some((a, b)) = before.zip(load_average()) {
        println!("1-minute load average {a:.2} before, {b:.2} after ({} cores)", crate::machine::cores());
    }
    let bad = all.iter().filter(|r| !passed(r)).count();
    println!(
        "scaling{}: {} rows, {bad} failed or not bit-identical, {:.0} s",
        if quick { " --quick" } else { "" },
        all.len(),
        start.elapsed().as_secs_f64()
    );
    bad == 0
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[Row]) -> String {
    let mut s = String::from(
        "| crate | scene | threads | time / step | speed-up over 1 thread | same bits as 1 thread |\n\
         | --- | --- | --- | --- | --- | --- |\n",
    );
    for r in rows {
        let same = match r.identical {
            Some(true) if r.note.is_empty() => "yes".to_string(),
            Some(true) => format!("yes; **{}**", r.note.replace('|', "/")),
            Some(false) => "**no**".to_string(),
            None if r.note.is_empty() => "no one-thread run to compare with".to_string(),
            None => format!("failed: {}", r.note.replace('|', "/")),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {} | {:.2} | {same} |",
            r.krate,
            r.scene,
            r.threads,
            crate::registry::seconds(r.seconds),
            r.speedup
        );
    }
    s
}

/// Parses `--threads 1,2,4`: at least one count, each at least 1; 1 is put first (the reference
/// of speed-up and bits) wherever it was given, and added if missing.
pub fn parse_threads(s: &str) -> Result<Vec<usize>, String> {
    let mut v = Vec::new();
    for part in s.split(',') {
        let n: usize =
            part.trim().parse().map_err(|_| format!("--threads: `{part}` is not a thread count"))?;
        if n == 0 {
            return Err("--threads: counts start at 1".into());
        }
        if n != 1 && !v.contains(&n) {
            v.push(n);
        }
    }
    v.insert(0, 1);
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_lists_parse() {
        assert_eq!(parse_threads("1,2"), Ok(vec![1, 2]));
        assert_eq!(parse_threads("4, 8"), Ok(vec![1, 4, 8]));
        assert_eq!(parse_threads("4,1,2"), Ok(vec![1, 4, 2]));
        assert!(parse_threads("0").is_err());
        assert!(parse_threads("two").unwrap_err().contains("`two`"));
    }

    /// A scene of one number: each step adds `increment()` (the thread count, for a scene
    /// whose result depends on it); a step that would pass `limit` fails, as a divergence
    /// guard does.
    struct Counter {
        x: f64,
        t: f64,
        limit: f64,
        increment: fn() -> f64,
    }

    impl DynScene for Counter {
        fn step(&mut self, dt: f64) -> Result<anim_core::solver::StepReport, anim_core::scene::StepError> {
            let next = self.x + (self.increment)();
            if next > self.limit {
                return Err(anim_core::scene::StepError::new(std::io::Error::other("x past its limit")));
            }
            (self.x, self.t) = (next, self.t + dt);
            Ok(anim_core::solver::StepReport::default())
        }
        fn time(&self) -> f64 {
            self.t
        }
        fn save(&self) -> serde_json::Value {
            serde_json::json!({ "x": self.x, "t": self.t })
        }
        fn restore(&mut self, saved: &serde_json::Value) -> Result<(), anim_core::scene::CheckpointError> {
            self.x = anim_core::scene::saved_field(saved, "x")?;
            self.t = anim_core::scene::saved_field(saved, "t")?;
            Ok(())
        }
        fn method(&self) -> String {
            "counting".into()
        }
        fn context(&self) -> anim_core::scene::Context {
            anim_core::scene::Context::default()
        }
        fn frame(&self, out: &mut anim_core::scene::Frame) {
            out.time = self.t;
            out.points.clear();
            out.points.push(self.x);
        }
        fn reference_error(&self) -> Option<f64> {
            None
        }
        fn provoke_overflow(&mut self) -> Option<String> {
            None
        }
    }

    fn counter(limit: f64, increment: fn() -> f64) -> Result<Box<dyn DynScene>, String> {
        Ok(Box::new(Counter { x: 0.0, t: 0.0, limit, increment }))
    }

    #[test]
    fn a_thread_count_dependence_is_flagged() {
        let dependent = || counter(f64::INFINITY, || rayon::current_num_threads() as f64);
        let got = rows("anim-x", "s", &[1, 2], |t| measure(&dependent, 0.1, 1000, t, 0.01));
        assert_eq!(got.iter().map(|r| r.identical).collect::<Vec<_>>(), [Some(true), Some(false)], "{got:?}");
        let independent = || counter(f64::INFINITY, || 1.0);
        let got = rows("anim-x", "s", &[1, 2], |t| measure(&independent, 0.1, 1000, t, 0.01));
        assert_eq!(got.iter().map(|r| r.identical).collect::<Vec<_>>(), [Some(true), Some(true)], "{got:?}");
        assert!(got.iter().all(|r| r.seconds.is_finite() && r.speedup.is_finite()), "{got:?}");
    }

    #[test]
    fn a_scene_that_ends_restarts_from_its_initial_checkpoint() {
        let x = |r: &Looped| r.scene().save()["x"].as_f64();
        // Diverges at its 6th step: the run goes back to x = 0 and on, and says so.
        let mut r = Looped::new(counter(5.5, || 1.0).unwrap(), 0.1, 1000);
        for _ in 0..6 {
            r.step().unwrap();
        }
        assert_eq!((r.restarts(), x(&r)), (1, Some(1.0)));
        assert_eq!(r.failures().len(), 1, "{:?}", r.failures());
        assert!(r.failures()[0].contains("step 6"), "{:?}", r.failures());
        // Its nominal duration, 3 steps: the fourth starts over, and that is no failure.
        let mut r = Looped::new(counter(f64::INFINITY, || 1.0).unwrap(), 0.1, 3);
        for _ in 0..4 {
            r.step().unwrap();
        }
        assert_eq!((r.restarts(), x(&r), r.failures().len()), (1, Some(1.0), 0));
        // A scene that fails its first step is an error, not an endless restart.
        let mut r = Looped::new(counter(0.5, || 1.0).unwrap(), 0.1, 1000);
        assert!(r.step().unwrap_err().contains("x past its limit"));
        let got = rows("anim-x", "s", &[1], |t| measure(&|| counter(0.5, || 1.0), 0.1, 1000, t, 0.01));
        assert_eq!(got[0].identical, None, "{got:?}");
        assert!(got[0].note.contains("x past its limit"), "{got:?}");
        // A failure within the duration fails the row although the bits agree.
        let got = rows("anim-x", "s", &[1, 2], |t| measure(&|| counter(5.5, || 1.0), 0.1, 1000, t, 0.01));
        assert!(got.iter().all(|r| r.identical == Some(true) && !passed(r)), "{got:?}");
    }

    #[test]
    fn the_first_count_is_the_reference() {
        // The reference run fails: the others are not compared with anything.
        let got = rows("anim-x", "s", &[1, 2], |t| {
            if t == 1 {
                Err("no".into())
            } else {
                measure(&|| counter(f64::INFINITY, || 1.0), 0.1, 1000, t, 0.01)
            }
        });
        assert_eq!(got.iter().map(|r| r.identical).collect::<Vec<_>>(), [None, None], "{got:?}");
        assert!(got[1].speedup.is_nan(), "{got:?}");
    }

    #[test]
    fn a_registered_preset_gets_a_row_per_thread_count() {
        let (kind, preset) = anim::preset("oscillator").expect("the oscillator preset");
        let got = run_preset(kind, &preset, true, &[1, 2]);
        assert_eq!(got.len(), 2);
        assert!(got.iter().all(|r| r.identical == Some(true) && r.seconds > 0.0), "{got:?}");
        assert_eq!((got[0].krate.as_str(), got[0].scene.as_str()), ("anim-core", "oscillator"));
    }

    #[test]
    fn the_table_flags_a_thread_count_dependence() {
        let row = |threads, identical| Row {
            krate: "anim-x".into(),
            scene: "s".into(),
            threads,
            seconds: 1e-3 / threads as f64,
            speedup: threads as f64,
            identical,
            note: String::new(),
        };
        let md = markdown(&[row(1, Some(true)), row(2, Some(false))]);
        assert!(md.contains("| anim-x | s | 1 | 1.00 ms | 1.00 | yes |"), "{md}");
        assert!(md.contains("| anim-x | s | 2 | 500.00 us | 2.00 | **no** |"), "{md}");
    }
}
