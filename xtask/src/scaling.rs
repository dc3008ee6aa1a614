//! Thread scaling of every registered preset (`anim::presets()`), through anim-core's
//! `DynScene` alone, so that a newly registered preset gets its row without any edit here: the
//! preset (its `quick_params` with `--quick`) stepped on rayon pools of 1, 2, ... threads; time
//! per step, speed-up over one thread, and whether the checkpoint after the first steps is bit
//! for bit the one-thread checkpoint (it must be: results do not depend on the thread count).
//!
//! A preset that ends before the timing does (its divergence guard fires, or its nominal
//! duration `run.steps()` is reached) restarts from its initial checkpoint; the restore is not
//! timed. `cargo xtask scaling` prints the table; `cargo xtask report` puts it in the report.

use anim_core::scene::{BuildContext, DynScene, Preset, SceneKind};
use std::fmt::Write as _;
use std::time::{Duration, Instant};

/// FNV-1a over bytes.
fn hash_bytes(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x100_0000_01b3))
}

/// The parameters a suite runs a preset with: `quick_params` in quick mode (where it has them).
pub fn params(preset: &Preset, quick: bool) -> &serde_json::Value {
    if quick { preset.quick_params.as_ref().unwrap_or(&preset.params) } else { &preset.params }
}

/// Builds `preset` of `kind` (quick or full parameters).
pub fn build(kind: &SceneKind, preset: &Preset, quick: bool) -> Result<Box<dyn DynScene>, String> {
    (kind.build)(params(preset, quick), &BuildContext::default()).map_err(|e| e.to_string())
}

/// A scene stepped for as long as the timing needs: back to its initial checkpoint after
/// `duration` steps, or when a step fails (once per failure: a step that fails right after the
/// restart is an error).
struct Runner {
    scene: Box<dyn DynScene>,
    start: serde_json::Value,
    dt: f64,
    duration: usize,
    /// Steps since the last (re)start.
    since_start: usize,
    restarts: usize,
}

impl Runner {
    fn new(scene: Box<dyn DynScene>, dt: f64, duration: usize) -> Self {
        let start = scene.save();
        Self { scene, start, dt, duration: duration.max(1), since_start: 0, restarts: 0 }
    }

    fn restart(&mut self) -> Result<(), String> {
        self.scene.restore(&self.start).map_err(|e| format!("restart from the initial checkpoint: {e}"))?;
        self.since_start = 0;
        self.restarts += 1;
        Ok(())
    }

    /// One step; its wall time, restarts excluded.
    fn step(&mut self) -> Result<Duration, String> {
        if self.since_start >= self.duration {
            self.restart()?;
        }
        let t = Instant::now();
        let mut result = self.scene.step(self.dt).map(drop);
        let mut elapsed = t.elapsed();
        if let Err(e) = &result
            && self.since_start > 0
        {
            eprintln!(
                "    step {} failed ({e}); restarting from the initial checkpoint",
                self.since_start + 1
            );
            self.restart()?;
            let t = Instant::now();
            result = self.scene.step(self.dt).map(drop);
            elapsed = t.elapsed();
        }
        result.map_err(|e| format!("step {}: {e}", self.since_start + 1))?;
        self.since_start += 1;
        Ok(elapsed)
    }

    /// A hash of the checkpoint's bytes.
    fn fingerprint(&self) -> u64 {
        hash_bytes(self.scene.save().to_string().as_bytes())
    }
}

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
    /// An error, if the scene failed.
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

/// (seconds per step, fingerprint after [`CHECK_STEPS`] steps) of the scene `build` makes,
/// stepped by `dt` on a pool of `threads` threads: the median of three batches of at least two
/// steps each, together `budget` seconds.
fn measure(
    build: Build<'_>,
    dt: f64,
    duration: usize,
    threads: usize,
    budget: f64,
) -> Result<(f64, u64), String> {
    let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().map_err(|e| e.to_string())?;
    pool.install(|| {
        let mut s = Runner::new(build()?, dt, duration);
        for _ in 0..CHECK_STEPS {
            s.step()?;
        }
        let fingerprint = s.fingerprint();
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
        if s.restarts > 0 {
            eprintln!(
                "    {threads} thread(s): restarted {} time(s) from the initial checkpoint",
                s.restarts
            );
        }
        batches.sort_by(f64::total_cmp);
        Ok((batches[1], fingerprint))
    })
}

/// The rows of one scene at each of `threads` (the first is the reference of speed-up and bits).
fn rows(
    krate: &str,
    scene: &str,
    threads: &[usize],
    measured: impl Fn(usize) -> Result<(f64, u64), String>,
) -> Vec<Row> {
    let mut rows = Vec::new();
    let mut base: Option<(f64, u64)> = None;
    for &t in threads {
        let row = match measured(t) {
            Ok((seconds, fp)) => {
                let b = *base.get_or_insert((seconds, fp));
                Row {
                    krate: krate.into(),
                    scene: scene.into(),
                    threads: t,
                    seconds,
                    speedup: b.0 / seconds,
                    identical: Some(b.1 == fp),
                    note: String::new(),
                }
            }
            Err(e) => Row {
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

/// `(crate, preset)` of every registered preset, in registry order.
pub fn preset_names() -> Vec<(&'static str, &'static str)> {
    anim::presets().into_iter().map(|(k, p)| (k.crate_name, p.name)).collect()
}

/// Times preset `index` (of [`preset_names`]) at each of `threads`.
pub fn run_preset(index: usize, quick: bool, threads: &[usize]) -> Vec<Row> {
    let Some((kind, preset)) = anim::presets().into_iter().nth(index) else { return Vec::new() };
    let t0 = Instant::now();
    let make = || build(kind, &preset, quick);
    let rows = rows(kind.crate_name, preset.name, threads, |t| {
        measure(&make, preset.run.dt, preset.run.steps(), t, budget(quick))
    });
    eprintln!("  scaling {:<13} {:<18} {:>6.1} s", kind.crate_name, preset.name, t0.elapsed().as_secs_f64());
    rows
}

/// `cargo xtask scaling`: every selected preset at each of `threads`, the table printed; true
/// when every run finished with the one-thread bits.
pub fn run(quick: bool, filter: Option<&str>, threads: &[usize]) -> bool {
    let start = Instant::now();
    eprintln!("thread scaling on {threads:?} threads{}", if quick { " (quick params)" } else { "" });
    let before = load_average();
    let mut all = Vec::new();
    for (i, (krate, name)) in preset_names().into_iter().enumerate() {
        if crate::suites::selected(filter, krate, name) {
            all.extend(run_preset(i, quick, threads));
        }
    }
    println!("{}", markdown(&all));
    if let Some((a, b)) = before.zip(load_average()) {
        println!("1-minute load average {a:.2} before, {b:.2} after ({} cores)", crate::machine::cores());
    }
    let bad = all.iter().filter(|r| r.identical != Some(true)).count();
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
            Some(true) => "yes".to_string(),
            Some(false) => "**no**".to_string(),
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

/// Parses `--threads 1,2,4`: at least one count, each at least 1; 1 is put first if missing.
pub fn parse_threads(s: &str) -> Result<Vec<usize>, String> {
    let mut v = Vec::new();
    for part in s.split(',') {
        let n: usize =
            part.trim().parse().map_err(|_| format!("--threads: `{part}` is not a thread count"))?;
        if n == 0 {
            return Err("--threads: counts start at 1".into());
        }
        if !v.contains(&n) {
            v.push(n);
        }
    }
    if !v.contains(&1) {
        v.insert(0, 1);
    }
    Ok(v)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn thread_lists_parse() {
        assert_eq!(parse_threads("1,2"), Ok(vec![1, 2]));
        assert_eq!(parse_threads("4, 8"), Ok(vec![1, 4, 8]));
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
        // Diverges at its 6th step: the run goes back to x = 0 and on.
        let mut r = Runner::new(counter(5.5, || 1.0).unwrap(), 0.1, 1000);
        let start = r.fingerprint();
        for _ in 0..5 {
            r.step().unwrap();
        }
        r.step().unwrap();
        assert_eq!((r.restarts, r.since_start), (1, 1));
        // Its nominal duration, 3 steps: the fourth starts over.
        let mut r = Runner::new(counter(f64::INFINITY, || 1.0).unwrap(), 0.1, 3);
        for _ in 0..3 {
            r.step().unwrap();
        }
        assert_ne!(r.fingerprint(), start);
        r.step().unwrap();
        assert_eq!((r.restarts, r.since_start), (1, 1));
        r.restart().unwrap();
        assert_eq!(r.fingerprint(), start);
        // A scene that fails its first step is an error, not an endless restart.
        let mut r = Runner::new(counter(0.5, || 1.0).unwrap(), 0.1, 1000);
        assert!(r.step().unwrap_err().contains("x past its limit"));
        let got = rows("anim-x", "s", &[1], |t| measure(&|| counter(0.5, || 1.0), 0.1, 1000, t, 0.01));
        assert_eq!(got[0].identical, None, "{got:?}");
        assert!(got[0].note.contains("x past its limit"), "{got:?}");
    }

    #[test]
    fn a_registered_preset_scales_bit_for_bit() {
        let Some(i) = preset_names().iter().position(|&(_, name)| name == "oscillator") else {
            panic!("no oscillator preset")
        };
        let got = run_preset(i, true, &[1, 2]);
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
