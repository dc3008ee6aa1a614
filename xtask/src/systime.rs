//! `cargo xtask systime`: the operating system's share of every registered preset's run.
//!
//! Each preset (`anim::presets()`, so a newly registered one gets its rows without an edit here)
//! runs as `anim run NAME --frames N` at its default size, with no frame files, preview or
//! viewer, in a child process of its own (this program again, `xtask systime-child`, which runs
//! the `anim` command's own code), on `RAYON_NUM_THREADS` = 1 and 2 threads. The child's user and
//! system CPU time and its voluntary context switches come from the kernel's accounting of
//! waited-for children (`getrusage(RUSAGE_CHILDREN)` before and after the child). A row fails when
//! the system time exceeds [`LIMIT`] of the user time: a solver's parallel loops too small to pay
//! for the thread pool's wake-ups show as system time (futex and `sched_yield` calls) and
//! voluntary context switches, not as work. System time below [`FLOOR`] (what starting a process
//! and touching its memory costs) is not judged.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::Instant;

/// The largest system time a run may take, as a fraction of its user time.
pub const LIMIT: f64 = 0.10;

/// System time (s) too small to judge: a process's start, exit and first touch of its memory.
pub const FLOOR: f64 = 0.02;

/// Frames each preset runs for unless `--frames` says otherwise.
pub const FRAMES: usize = 10;

/// The subcommand a child runs under.
pub const CHILD: &str = "systime-child";

/// The CPU accounting of a process, from `getrusage`.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Usage {
    /// User CPU time, s.
    pub user: f64,
    /// System CPU time, s.
    pub system: f64,
    /// Voluntary context switches (the process waited: a lock, a sleep, a read).
    pub voluntary: i64,
    /// Involuntary context switches (the scheduler took the core away).
    pub involuntary: i64,
}

impl Usage {
    /// `self - before`.
    fn since(self, before: Usage) -> Usage {
        Usage {
            user: self.user - before.user,
            system: self.system - before.system,
            voluntary: self.voluntary - before.voluntary,
            involuntary: self.involuntary - before.involuntary,
        }
    }
}

/// The accumulated usage of this process's terminated, waited-for children.
#[cfg(unix)]
#[allow(unsafe_code)]
fn children() -> Result<Usage, String> {
    // SAFETY: `rusage` is a plain C struct of integers, valid when zeroed; `getrusage` writes one
    // into the pointer it is given, which points to `ru`, alive for the call.
    let (rc, ru) = unsafe {
        let mut ru: libc::rusage = std::mem::zeroed();
        (libc::getrusage(libc::RUSAGE_CHILDREN, &mut ru), ru)
    };
    if rc != 0 {
        return Err(format!("getrusage: {}", std::io::Error::last_os_error()));
    }
    let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    Ok(Usage {
        user: secs(ru.ru_utime),
        system: secs(ru.ru_stime),
        voluntary: ru.ru_nvcsw,
        involuntary: ru.ru_nivcsw,
    })
}

#[cfg(not(unix))]
fn children() -> Result<Usage, String> {
    Err("the CPU accounting of child processes is read with getrusage, which needs Unix".into())
}

/// One measured run.
#[derive(Debug, Clone, PartialEq)]
pub struct Row {
    /// The crate that registers the preset.
    pub krate: String,
    /// The preset's name.
    pub scene: String,
    /// `RAYON_NUM_THREADS` of the child.
    pub threads: usize,
    /// Wall time of the child, s.
    pub wall: f64,
    /// What the kernel counted for it.
    pub usage: Usage,
    /// Why the child failed, if it did.
    pub error: Option<String>,
}

impl Row {
    /// System time over user time.
    pub fn ratio(&self) -> f64 {
        self.usage.system / self.usage.user
    }

    /// Whether the run finished with its system time within [`LIMIT`] of its user time (or below
    /// [`FLOOR`]).
    pub fn passed(&self) -> bool {
        self.error.is_none() && (self.usage.system <= LIMIT * self.usage.user || self.usage.system < FLOOR)
    }
}

/// Runs `xtask systime-child NAME FRAMES OUT` on `threads` threads and measures it.
fn measure(exe: &Path, krate: &str, scene: &str, frames: usize, threads: usize, out: &Path) -> Row {
    let mut row = Row {
        krate: krate.into(),
        scene: scene.into(),
        threads,
        wall: f64::NAN,
        usage: Usage::default(),
        error: None,
    };
    let log = out.with_extension("log");
    let result = (|| -> Result<(), String> {
        let stderr = std::fs::File::create(&log).map_err(|e| format!("{}: {e}", log.display()))?;
        let before = children()?;
        let start = Instant::now();
        let status = Command::new(exe)
            .args([CHILD, scene, &frames.to_string()])
            .arg(out)
            .env("RAYON_NUM_THREADS", threads.to_string())
            .stdin(Stdio::null())
            .stdout(Stdio::null())
            .stderr(stderr)
            .status()
            .map_err(|e| format!("could not start {}: {e}", exe.display()))?;
        row.wall = start.elapsed().as_secs_f64();
        row.usage = children()?.since(before);
        if status.success() {
            Ok(())
        } else {
            let text = std::fs::read_to_string(&log).unwrap_or_default();
            let last = text.lines().rev().find(|l| !l.trim().is_empty()).unwrap_or("no message");
            Err(format!("{status}: {last}"))
        }
    })();
    row.error = result.err();
    row
}

/// `cargo xtask systime [--filter S] [--threads 1,2] [--frames N]`: every selected preset's run
/// measured on each thread count, the table printed; true when every row passed.
pub fn run(filter: Option<&str>, threads: &[usize], frames: Option<usize>) -> bool {
    let start = Instant::now();
    let frames = frames.unwrap_or(FRAMES);
    let exe = match std::env::current_exe() {
        Ok(e) => e,
        Err(e) => {
            eprintln!("could not find this program to run its children: {e}");
            return false;
        }
    };
    let dir = PathBuf::from("target/xtask/systime");
    if let Err(e) = std::fs::create_dir_all(&dir) {
        eprintln!("{}: {e}", dir.display());
        return false;
    }
    eprintln!("system time of every preset, {frames} frames, on {threads:?} threads");
    let mut rows = Vec::new();
    for (kind, preset) in anim::presets() {
        if !crate::suites::selected(filter, kind.crate_name, preset.name) {
            continue;
        }
        for &t in threads {
            let out = dir.join(format!("{}-{t}", preset.name));
            let row = measure(&exe, kind.crate_name, preset.name, frames, t, &out);
            eprintln!(
                "  {:<13} {:<22} {t} thread(s): {:>6.2} s user, {:>6.2} s system{}",
                row.krate,
                row.scene,
                row.usage.user,
                row.usage.system,
                row.error.as_deref().map(|e| format!(", failed: {e}")).unwrap_or_default()
            );
            rows.push(row);
        }
    }
    println!("{}", markdown(&rows, frames));
    let bad = rows.iter().filter(|r| !r.passed()).count();
    let (user, system) = rows.iter().fold((0.0, 0.0), |(u, s), r| (u + r.usage.user, s + r.usage.system));
    println!(
        "systime: {} rows, {bad} over {:.0}% or failed; {user:.1} s user, {system:.1} s system in all; {:.0} s",
        rows.len(),
        LIMIT * 100.0,
        start.elapsed().as_secs_f64()
    );
    bad == 0
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[Row], frames: usize) -> String {
    let mut s = format!(
        "`anim run NAME --frames {frames}` (no frame files, preview or viewer) in a child process per row\n\n\
         | crate | preset | threads | wall | user | system | system / user | voluntary switches | verdict |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n"
    );
    for r in rows {
        let verdict = match &r.error {
            Some(e) => format!("**failed**: {e}"),
            None if r.usage.system < FLOOR && r.usage.system > LIMIT * r.usage.user => {
                "ok (below floor)".into()
            }
            None if r.passed() => "ok".into(),
            None => format!("**over {:.0}%**", LIMIT * 100.0),
        };
        let _ = writeln!(
            s,
            "| {} | {} | {} | {:.2} s | {:.2} s | {:.2} s | {:.1}% | {} | {verdict} |",
            r.krate,
            r.scene,
            r.threads,
            r.wall,
            r.usage.user,
            r.usage.system,
            100.0 * r.ratio(),
            r.usage.voluntary
        );
    }
    s
}

/// What a child runs: `anim run NAME --frames FRAMES --out OUT --format none --no-preview
/// --no-viewer --quiet`, through the `anim` command's own code.
#[derive(clap::Parser)]
struct Anim {
    #[command(flatten)]
    run: anim_cli::run::RunArgs,
}

/// `xtask systime-child NAME FRAMES OUT`: runs the preset as `anim run` does; true on success.
pub fn child(args: &[String]) -> bool {
    use clap::Parser as _;
    let [name, frames, out] = args else {
        eprintln!("usage: xtask {CHILD} NAME FRAMES OUT");
        return false;
    };
    let argv = [
        "anim",
        name,
        "--frames",
        frames,
        "--out",
        out,
        "--format",
        "none",
        "--no-preview",
        "--no-viewer",
        "--quiet",
    ];
    match Anim::try_parse_from(argv) {
        Ok(a) => match anim_cli::run::run(&a.run) {
            Ok(()) => true,
            Err(e) => {
                eprintln!("{name}: {e}");
                false
            }
        },
        Err(e) => {
            eprintln!("{e}");
            false
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(user: f64, system: f64) -> Row {
        Row {
            krate: "anim-x".into(),
            scene: "s".into(),
            threads: 1,
            wall: user,
            usage: Usage { user, system, voluntary: 10, involuntary: 0 },
            error: None,
        }
    }

    #[test]
    fn system_time_over_the_limit_fails() {
        assert!(row(1.0, 0.09).passed());
        assert!(!row(1.0, 0.2).passed());
        // Too little to judge: a process's own start.
        assert!(row(0.01, 0.015).passed());
        let failed = Row { error: Some("exit status: 1".into()), ..row(1.0, 0.0) };
        assert!(!failed.passed());
        let md = markdown(&[row(1.0, 0.2), row(1.0, 0.05), row(0.01, 0.015)], 3);
        assert!(
            md.contains("| anim-x | s | 1 | 1.00 s | 1.00 s | 0.20 s | 20.0% | 10 | **over 10%** |"),
            "{md}"
        );
        assert!(md.contains("| 5.0% | 10 | ok |"), "{md}");
        assert!(md.contains("ok (below floor)"), "{md}");
    }

    #[cfg(unix)]
    #[test]
    fn a_childs_cpu_time_is_counted() {
        // A child that spins for about 0.2 s of user time: the difference of the children's
        // accounting holds it (the kernel counts in ticks, hence the margin).
        let before = children().unwrap();
        let status = Command::new("sh")
            .args(["-c", "i=0; while [ $i -lt 200000 ]; do i=$((i+1)); done"])
            .status()
            .unwrap();
        assert!(status.success());
        let used = children().unwrap().since(before);
        assert!(used.user > 0.01, "{used:?}");
        assert!(used.system >= 0.0 && used.voluntary >= 0, "{used:?}");
    }
}
