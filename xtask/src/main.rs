//! Workspace automation for anim: `cargo xtask <suite>`. What CI runs is `cargo ci`
//! (`xtask/ci`), which runs the quick conformance and stability suites through
//! `xtask/tests/suites.rs`.
//!
//! | suite | what it does |
//! | --- | --- |
//! | `conformance [--quick] [--filter S]` | every reference case with metric, error, tolerance and verdict; exit 1 on any failure |
//! | `stability [--quick] [--filter S]` | the named hard cases of every crate with their outcomes; exit 1 on an unexpected outcome |
//! | `stability --long [--quick] [--filter S] [--out DIR]` | soak: each crate's hard case for `10^5` steps or ten minutes with its energy bound, then every registered preset for the same budget (its solver's guard at every step, frame and checkpoint finite on a stride; `--quick`: quick params, 200 steps or 3 s); written to `docs/report/soak.md` |
//! | `scaling [--quick] [--filter S] [--threads 1,2,...]` | thread scaling of every registered preset (quick params with `--quick`): time per step, speed-up over one thread and the same checkpoint bits as one thread, on 1 and all cores unless `--threads`; exit 1 on a failure or a thread-count dependence |
//! | `systime [--filter S] [--threads 1,2,...] [--frames N]` | every registered preset run as `anim run NAME --frames N` (10 unless given; no frame files, preview or viewer) at its default size in a child process per thread count (1 and 2 unless `--threads`): the child's user and system CPU time and voluntary context switches (`getrusage`), printed as a table; exit 1 when a run's system time exceeds 10% of its user time (`xtask/src/systime.rs`) |
//! | `bench [--filter S]` | the criterion benches under `benches/` (with `presets`: one step of every registered preset), printed as a table and written to `target/xtask/bench.csv`; `--peers [--filter S]`: the peer comparisons (springs, rigid, pbd, fem, mpm, fluid, flip), their ratios merged into `docs/report/peers.csv` (a filtered run replaces only its crates' rows) |
//! | `roofline [--filter S] [--threads 1,2,...]` | this machine's memory bandwidth and peak flop rates (1 and all cores unless `--threads`), then every registered hot kernel's time per item, achieved GB/s and GFLOP/s against its roofline bound, and its distance from it (`xtask/src/roofline.rs`); also a section of `report` |
//! | `viewer [--out DIR]` | runs a cloth, a 3D MPM scene and a 2D grid fluid, opens each run's `viewer.html` in headless Chromium at the first and the last frame, and checks the screenshots are not blank and differ (`xtask/src/viewer.rs`); skipped with a note where Chromium is absent |
//! | `consumer` | a fresh Cargo project outside the workspace depending on anim-pbd and anim-rigid by path with default features off and its own glam 0.34, its lockfile resolved afresh (the newest versions the ranges allow): drops a cloth and poses a robot, passing its own `glam::DVec3` values in and reading ours out, checked against closed forms, with no serde crate in its `cargo tree`; run again with anim-pbd's `parallel` on, the cloth bit for bit the same (`xtask/src/consumer.rs`) |
//! | `packaged` | every publishable crate from its `.crate` archive (`cargo package --workspace --no-verify`), unpacked into a workspace of its own whose lockfile takes the lowest versions our direct requirements allow (`-Z direct-minimal-versions`), its libraries and programs checked with every feature: a file a crate needs but does not package, or a lower bound below the API we use, fails (`xtask/src/packaged.rs`) |
//! | `report [--quick] [--filter S] [--out DIR] [--threads 1,2,...]` | conformance, stability and work-precision studies, the cheapest method per tolerance (also `cheapest.json`), thread scaling (1 and all cores unless `--threads`) and the peer ratios of `docs/report/peers.csv`, written to `docs/report/` (Markdown + SVG, and every measured part in `data.json`); `--filter` re-runs only the parts of matching crates or names and keeps the rest from `data.json`; prints its duration |

mod architecture;
mod bench;
mod cases;
mod consumer;
mod machine;
mod packaged;
mod peers;
mod python;
mod registry;
mod report;
mod report_data;
mod roofline;
mod scaling;
mod soak;
mod suites;
mod systime;
mod viewer;

use std::process::ExitCode;

/// The system allocator with a counter: the scene-contract suite counts the allocations of a
/// step (`cases/presets.rs`).
#[global_allocator]
pub static ALLOC: anim_core::alloc_count::CountingAllocator =
    anim_core::alloc_count::CountingAllocator::new();

const USAGE: &str = "usage: cargo xtask <conformance|stability|scaling|systime|bench|roofline|report|viewer|consumer|packaged> [--quick] [--long] [--filter TEXT] [--out DIR] [--threads 1,2,...] [--frames N]";

#[derive(Debug, Default)]
struct Args {
    quick: bool,
    long: bool,
    filter: Option<String>,
    out: Option<String>,
    threads: Option<Vec<usize>>,
    frames: Option<usize>,
}

fn parse(args: &[String]) -> Result<Args, String> {
    let mut parsed = Args::default();
    let mut it = args.iter();
    while let Some(a) = it.next() {
        match a.as_str() {
            "--quick" => parsed.quick = true,
            "--long" => parsed.long = true,
            "--filter" => parsed.filter = Some(it.next().ok_or("--filter needs a value")?.clone()),
            "--out" => parsed.out = Some(it.next().ok_or("--out needs a value")?.clone()),
            "--threads" => {
                parsed.threads = Some(scaling::parse_threads(it.next().ok_or("--threads needs a value")?)?)
            }
            "--frames" => {
                let v = it.next().ok_or("--frames needs a value")?;
                parsed.frames = Some(
                    v.parse()
                        .ok()
                        .filter(|&n: &usize| n > 0)
                        .ok_or(format!("--frames: `{v}` is not a count >= 1"))?,
                )
            }
            // `bench --peers`: read by bench.rs from the process arguments.
            "--peers" => {}
            other => return Err(format!("unknown argument '{other}'")),
        }
    }
    Ok(parsed)
}

/// The `--threads` counts, or 1 and all cores.
fn threads(given: Option<Vec<usize>>) -> Vec<usize> {
    given.unwrap_or_else(|| {
        let n = machine::cores();
        if n > 1 { vec![1, n] } else { vec![1] }
    })
}

fn main() -> ExitCode {
    let argv: Vec<String> = std::env::args().skip(1).collect();
    let Some((cmd, rest)) = argv.split_first() else {
        eprintln!("{USAGE}");
        return ExitCode::from(2);
    };
    if cmd == systime::CHILD {
        return if systime::child(rest) { ExitCode::SUCCESS } else { ExitCode::FAILURE };
    }
    let args = match parse(rest) {
        Ok(a) => a,
        Err(e) => {
            eprintln!("error: {e}\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    let ctx = registry::Ctx { quick: args.quick };
    let ok = match cmd.as_str() {
        "conformance" => suites::conformance(&ctx, args.filter.as_deref()).passed(),
        "stability" if args.long => {
            soak::run(args.quick, args.filter.as_deref(), args.out.as_deref().unwrap_or("docs/report"))
        }
        "stability" => suites::stability(&ctx, args.filter.as_deref()).passed(),
        "scaling" => scaling::run(args.quick, args.filter.as_deref(), &threads(args.threads)),
        "systime" => {
            systime::run(args.filter.as_deref(), &args.threads.unwrap_or_else(|| vec![1, 2]), args.frames)
        }
        "bench" => bench::run(args.filter.as_deref()),
        "roofline" => roofline::run(args.filter.as_deref(), &threads(args.threads)),
        "report" => report::run(
            &ctx,
            args.out.as_deref().unwrap_or("docs/report"),
            &threads(args.threads),
            args.filter.as_deref(),
        ),
        "consumer" => consumer::run_check(),
        "packaged" => packaged::run_check(),
        "viewer" => viewer::run(std::path::Path::new(args.out.as_deref().unwrap_or("target/xtask/viewer"))),
        "help" | "--help" | "-h" => {
            println!("{USAGE}");
            true
        }
        other => {
            eprintln!("error: unknown suite '{other}'\n{USAGE}");
            return ExitCode::from(2);
        }
    };
    if ok { ExitCode::SUCCESS } else { ExitCode::FAILURE }
}
