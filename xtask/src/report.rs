//! `cargo xtask report`: conformance, stability and work-precision studies, thread scaling and
//! the committed peer ratios, written as Markdown tables and SVG plots to `docs/report/`, with the
//! cheapest-method table also as `docs/report/cheapest.json` (read by `anim run --tolerance`).

use crate::machine::Machine;
use crate::peers::ratios::{self, PeerRow};
use crate::registry::{Ctx, StudyResult, StudyUse, fmt_num};
use crate::report_data::{self, Data, Kind, Part};
use crate::scaling;
use crate::suites::{self, ConformanceRun, StabilityRun};
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Tolerances of the "cheapest method" tables.
pub const TOLERANCES: [f64; 6] = [1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8];

/// The tolerances of `study`'s cheapest-method tables: [`TOLERANCES`] and the extra ones its
/// crate registered for it (`StudyUse::extra_tolerances`), largest first.
pub fn tolerances(study: &StudyResult, uses: &[StudyUse]) -> Vec<f64> {
    let mut tols = TOLERANCES.to_vec();
    for u in uses.iter().filter(|u| u.study == study.slug) {
        tols.extend(u.extra_tolerances.iter().filter(|t| !TOLERANCES.contains(t)));
    }
    tols.sort_by(|a, b| b.total_cmp(a));
    tols
}

/// Tolerances of the headline table.
const HEADLINE: [f64; 3] = [1e-1, 1e-2, 1e-3];

/// Everything the report shows.
pub struct Report {
    /// `(crate, study)` in registry order.
    pub studies: Vec<(&'static str, StudyResult)>,
    pub conformance: ConformanceRun,
    pub stability: StabilityRun,
    pub scaling: Vec<scaling::Row>,
    /// The 1-minute load average before and after the scaling runs.
    pub load: Option<(f64, f64)>,
    /// Rows of `docs/report/peers.csv` (or an error reading it).
    pub peers: Result<Vec<PeerRow>, String>,
    pub quick: bool,
    /// When the newest part was measured.
    pub date: String,
    /// When the oldest part was measured (the same as `date` after a whole run).
    pub oldest: String,
    pub machine: Machine,
    /// Wall time of all parts of the report, seconds.
    pub seconds: f64,
    /// Whether `soak.md` (from `stability --long`) is beside the index.
    pub soak: bool,
    /// What the crates registered their studies to serve (`--tolerance` scenes, extra
    /// tolerances).
    pub study_uses: Vec<StudyUse>,
    /// Every part's wall time: (kind, crate, name, seconds), in registry order.
    pub durations: Vec<(&'static str, String, String, f64)>,
    /// The roofline section (`roofline.md` beside the index), if measured.
    pub roofline: Option<String>,
}

/// Runs the report into `out`. With `filter`, only the conformance cases, hard cases, studies and
/// thread-scaling presets whose crate or name contains it are run; every other part is taken
/// from `out/data.json` (written by every run), so the index stays whole.
pub fn run(ctx: &Ctx, out: &str, threads: &[usize], filter: Option<&str>) -> bool {
    let start = Instant::now();
    let dir = Path::new(out);
    if let Err(e) = std::fs::create_dir_all(dir) {
        eprintln!("cannot create {out}: {e}");
        return false;
    }
    let data_path = dir.join("data.json");
    let mut stored = match filter {
        None => Data::new(ctx.quick, Machine::this(), Vec::new()),
        Some(_) => match Data::load(&data_path, ctx.quick) {
            Ok(d) => d,
            Err(e) => {
                eprintln!("{e}");
                return false;
            }
        },
    };
    let today = crate::machine::today();
    let mut parts = Vec::new();
    let mut missing = Vec::new();
    let mut keep = |stored: &mut Data, parts: &mut Vec<Part>, kind, krate: &str, name: &str| match stored
        .take(kind, krate, name)
    {
        Some(p) => parts.push(p),
        None => missing.push(format!("{krate}: {name}")),
    };
    let reg = crate::cases::all();
    for case in &reg.conformance {
        if !suites::selected(filter, case.crate_name, case.name) {
            keep(&mut stored, &mut parts, Kind::Conformance, case.crate_name, case.name);
            continue;
        }
        let t = Instant::now();
        let checks = (case.run)(ctx);
        let secs = t.elapsed().as_secs_f64();
        eprintln!("  {:<40} {:>4} checks  {:>7.2} s", case.name, checks.len(), secs);
        let mut p = Part::new(Kind::Conformance, case.crate_name, case.name, &today, secs);
        p.checks = report_data::store_checks(&checks);
        parts.push(p);
    }
    for case in &reg.stability {
        if !suites::selected(filter, case.crate_name, case.name) {
            keep(&mut stored, &mut parts, Kind::Stability, case.crate_name, case.name);
            continue;
        }
        let t = Instant::now();
        let outcome = (case.run)(ctx);
        let mut p = Part::new(Kind::Stability, case.crate_name, case.name, &today, t.elapsed().as_secs_f64());
        p.outcome = Some(((case.expected)(), outcome));
        parts.push(p);
    }
    for study in &reg.studies {
        if !suites::selected(filter, study.crate_name, study.name) {
            keep(&mut stored, &mut parts, Kind::Study, study.crate_name, study.name);
            continue;
        }
        let t = Instant::now();
        let result = (study.run)(ctx);
        let secs = t.elapsed().as_secs_f64();
        eprintln!("  study {:<45} {:>6.1} s", study.name, secs);
        let mut p = Part::new(Kind::Study, study.crate_name, study.name, &today, secs);
        p.study = Some(result);
        parts.push(p);
    }
    eprintln!("thread scaling on {threads:?} threads");
    for (kind, preset) in anim::presets() {
        let (krate, scene) = (kind.crate_name, preset.name);
        if !suites::selected(filter, krate, scene) {
            keep(&mut stored, &mut parts, Kind::Scaling, krate, scene);
            continue;
        }
        let t = Instant::now();
        let before = scaling::load_average();
        let rows = scaling::run_preset(kind, &preset, ctx.quick, threads);
        let mut p = Part::new(Kind::Scaling, krate, scene, &today, t.elapsed().as_secs_f64());
        p.load = before.zip(scaling::load_average());
        p.scaling = rows;
        parts.push(p);
    }
    if !missing.is_empty() {
        eprintln!(
            "{} registered part(s) are not in {} and were not selected by the filter; they are left \
             out of the index until a run selects them: {}",
            missing.len(),
            data_path.display(),
            missing.join("; ")
        );
    }
    let roofline_md = dir.join("roofline.md");
    if filter.is_none_or(|f| "roofline".contains(f)) {
        let t = Instant::now();
        let md = crate::roofline::measure(None, threads);
        if let Err(e) = std::fs::write(&roofline_md, &md) {
            eprintln!("cannot write {}: {e}", roofline_md.display());
        }
        eprintln!("  roofline {:>6.1} s", t.elapsed().as_secs_f64());
    }
    let data = Data::new(ctx.quick, Machine::this(), parts);
    let mut report =
        Report::from_data(&data, ratios::read(&dir.join("peers.csv")), dir.join("soak.md").exists());
    report.roofline = std::fs::read_to_string(&roofline_md).ok();
    let mut ok = match write(dir, &report).and_then(|()| data.write(&data_path)) {
        Ok(()) => true,
        Err(e) => {
            eprintln!("{e}");
            false
        }
    };
    ok &= missing.is_empty();
    eprintln!(
        "report{}{} finished in {:.0} s ({:.1} min); its parts took {:.0} s ({:.1} min) in all; wrote {}",
        if ctx.quick { " --quick" } else { "" },
        filter.map(|f| format!(" --filter {f}")).unwrap_or_default(),
        start.elapsed().as_secs_f64(),
        start.elapsed().as_secs_f64() / 60.0,
        report.seconds,
        report.seconds / 60.0,
        dir.join("index.md").display()
    );
    ok && report.conformance.passed()
        && report.stability.passed()
        && report.scaling.iter().all(scaling::passed)
}

impl Report {
    /// The report of the stored parts (in registry order).
    pub fn from_data(data: &Data, peers: Result<Vec<PeerRow>, String>, soak: bool) -> Self {
        let mut studies = Vec::new();
        let mut checks = Vec::new();
        let mut rows = Vec::new();
        let mut scaling_rows = Vec::new();
        let mut load: Option<(f64, f64)> = None;
        let mut conformance_seconds = 0.0;
        for p in &data.parts {
            match p.kind {
                Kind::Conformance => {
                    checks.extend(p.checks());
                    conformance_seconds += p.seconds;
                }
                Kind::Stability => {
                    if let Some((expected, outcome)) = &p.outcome {
                        rows.push((leak(&p.krate), leak(&p.name), expected.clone(), outcome.clone()));
                    }
                }
                Kind::Study => {
                    if let Some(s) = &p.study {
                        studies.push((leak(&p.krate), s.clone()));
                    }
                }
                Kind::Scaling => {
                    scaling_rows.extend(p.scaling.iter().cloned());
                    if let Some((a, b)) = p.load {
                        load = Some(load.map_or((a, b), |(x, y)| (x.min(a), y.max(b))));
                    }
                }
            }
        }
        let dates: Vec<&str> = data.parts.iter().map(|p| p.date.as_str()).collect();
        let newest = dates.iter().max().map_or_else(crate::machine::today, |d| (*d).to_string());
        let oldest = dates.iter().min().map_or_else(|| newest.clone(), |d| (*d).to_string());
        Report {
            studies,
            conformance: ConformanceRun { checks, seconds: conformance_seconds },
            stability: StabilityRun { rows },
            scaling: scaling_rows,
            load,
            peers,
            quick: data.mode == "quick",
            date: newest,
            oldest,
            machine: data.machine.clone(),
            seconds: data.parts.iter().map(|p| p.seconds).sum(),
            soak,
            study_uses: anim::cases().study_uses,
            durations: data
                .parts
                .iter()
                .map(|p| (p.kind.name(), p.krate.clone(), p.name.clone(), p.seconds))
                .collect(),
            roofline: None,
        }
    }
}

/// Registry names are `&'static str`; names read back from `data.json` are leaked to match
/// (a few kilobytes, once per run).
fn leak(s: &str) -> &'static str {
    Box::leak(s.to_owned().into_boxed_str())
}

/// Writes `index.md`, one SVG per study and `cheapest.json` into `dir`.
pub fn write(dir: &Path, r: &Report) -> Result<(), String> {
    let mut failed = Vec::new();
    for (_, study) in &r.studies {
        let svg = dir.join(format!("{}.svg", study.slug));
        if let Err(e) = plot(study, &svg) {
            failed.push(format!("cannot write {}: {e}", svg.display()));
        }
    }
    let index = dir.join("index.md");
    std::fs::write(&index, index_markdown(r))
        .map_err(|e| format!("cannot write {}: {e}", index.display()))?;
    let json = dir.join("cheapest.json");
    let text = serde_json::to_string_pretty(&cheapest_table(r)).map_err(|e| e.to_string())?;
    std::fs::write(&json, text + "\n").map_err(|e| format!("cannot write {}: {e}", json.display()))?;
    if failed.is_empty() { Ok(()) } else { Err(failed.join("\n")) }
}

/// Version of `cheapest.json`: 2 added every measured point per method (`series`) and the study
/// problem's parameters (`problem`); `scene` may name a preset (`KIND/PRESET`).
pub const FORMAT: u32 = 2;

/// `docs/report/cheapest.json`: per study, per tolerance, the cheapest measured method, and every
/// measured point per method.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct CheapestTable {
    /// Format version.
    pub format: u32,
    pub date: String,
    pub machine: Machine,
    /// `quick` or `full`.
    pub mode: String,
    /// The tolerances of every study's picks (a study may add more to its own, see
    /// [`tolerances`]).
    pub tolerances: Vec<f64>,
    pub families: Vec<Family>,
}

/// One study's picks.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct Family {
    /// The study's slug (its SVG's name).
    pub study: String,
    #[serde(rename = "crate")]
    pub krate: String,
    pub title: String,
    /// What the error measures.
    pub error: String,
    /// What the swept parameter is (dt, iterations, resolution).
    pub param: String,
    /// The scene of `anim run` this study's problem is (`KIND` or `KIND/PRESET`), if any.
    pub scene: Option<String>,
    /// Simulated time the study measured over (for scene families with a trajectory error).
    pub horizon: Option<f64>,
    /// The study problem's parameters the picker scales by (scene families only).
    #[serde(default, skip_serializing_if = "std::collections::BTreeMap::is_empty")]
    pub problem: std::collections::BTreeMap<String, f64>,
    /// The cheapest point of any method per tolerance.
    pub picks: Vec<Pick>,
    /// Every measured point, per method: `anim run --tolerance` picks among the methods that
    /// keep the scene's physics, which need not include the overall cheapest.
    pub series: Vec<TableSeries>,
}

/// One method's measured points.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct TableSeries {
    /// The method label.
    pub method: String,
    /// Its points (only those with a finite error and wall time).
    pub points: Vec<TablePoint>,
}

/// One measured point.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct TablePoint {
    /// The swept parameter.
    pub param: f64,
    /// Median wall time of one run of the study's problem, seconds.
    pub seconds: f64,
    /// The study's error.
    pub error: f64,
}

/// The cheapest method meeting one tolerance; `method` is `None` when none in the sweep does.
#[derive(Debug, serde::Serialize, serde::Deserialize)]
pub struct Pick {
    pub tolerance: f64,
    pub method: Option<String>,
    pub param: Option<f64>,
    /// Median wall time of one run of the study's problem, seconds.
    pub seconds: Option<f64>,
    pub error: Option<f64>,
}

pub fn cheapest_table(r: &Report) -> CheapestTable {
    let families = r
        .studies
        .iter()
        .map(|(krate, s)| {
            let scene = r.study_uses.iter().find(|u| u.study == s.slug && u.scene.is_some());
            Family {
                study: s.slug.clone(),
                krate: (*krate).into(),
                title: s.title.clone(),
                error: s.error_label.clone(),
                param: s.param_label.clone(),
                scene: scene.and_then(|u| u.scene).map(str::to_string),
                horizon: scene.and_then(|u| u.horizon),
                problem: scene
                    .map(|u| (u.problem)(r.quick).into_iter().map(|(k, v)| (k.to_string(), v)).collect())
                    .unwrap_or_default(),
                series: s
                    .series
                    .iter()
                    .map(|series| TableSeries {
                        method: series.label.clone(),
                        points: series
                            .points
                            .iter()
                            .filter(|p| p.error.is_finite() && p.seconds.is_finite())
                            .map(|p| TablePoint { param: p.param, seconds: p.seconds, error: p.error })
                            .collect(),
                    })
                    .collect(),
                picks: tolerances(s, &r.study_uses)
                    .into_iter()
                    .map(|tol| match cheapest(s, tol) {
                        Some((method, param, seconds, error)) => Pick {
                            tolerance: tol,
                            method: Some(method),
                            param: Some(param),
                            seconds: Some(seconds),
                            error: Some(error),
                        },
                        None => {
                            Pick { tolerance: tol, method: None, param: None, seconds: None, error: None }
                        }
                    })
                    .collect(),
            }
        })
        .collect();
    CheapestTable {
        format: FORMAT,
        date: r.date.clone(),
        machine: r.machine.clone(),
        mode: if r.quick { "quick" } else { "full" }.into(),
        tolerances: TOLERANCES.to_vec(),
        families,
    }
}

/// The whole `index.md`.
pub fn index_markdown(r: &Report) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "# anim: work-precision report\n");
    let _ = writeln!(
        md,
        "Written by `cargo xtask report{}` on {} ({}); its parts took {:.0} s ({:.1} min) to run.{} \
         Wall times are medians of repeated runs on that machine; compare methods within one table, \
         not across machines.\n",
        if r.quick { " --quick" } else { "" },
        r.date,
        r.machine.describe(),
        r.seconds,
        r.seconds / 60.0,
        if r.oldest == r.date {
            String::new()
        } else {
            format!(
                " The parts were measured between {} and {} (`cargo xtask report --filter TEXT` re-runs \
                 the parts of matching crates and keeps the others from [data.json](data.json)).",
                r.oldest, r.date
            )
        }
    );
    let _ = writeln!(md, "## Cheapest method meeting a tolerance\n");
    let _ = writeln!(
        md,
        "Measured: for each study and tolerance, the fastest point of any method whose error is at \
         most the tolerance (method, its {{dt, iterations, resolution}}, wall time of one run, error). \
         Each study's error measure is given below its plot; relative unless it says otherwise. The \
         same table is in [cheapest.json](cheapest.json), which `anim run SCENE --tolerance TOL` reads.\n"
    );
    let _ = write!(md, "| study | crate | error measure |");
    for tol in HEADLINE {
        let _ = write!(md, " {tol:.0e} |");
    }
    let _ = writeln!(md, "\n| --- | --- | --- |{}", " --- |".repeat(HEADLINE.len()));
    for (krate, s) in &r.studies {
        let _ = write!(md, "| [{}](#{}) | {krate} | {} |", s.slug, s.slug, s.error_label.replace('|', "\\|"));
        for tol in HEADLINE {
            match cheapest(s, tol) {
                Some((label, param, secs, err)) => {
                    let _ = write!(
                        md,
                        " {label}, {} = {}: {} (error {}) |",
                        s.param_label,
                        fmt_num(param),
                        seconds(secs),
                        fmt_num(err)
                    );
                }
                None => {
                    let _ = write!(md, " none in the sweep |");
                }
            }
        }
        let _ = writeln!(md);
    }
    let _ = writeln!(md, "\n## Work-precision studies\n");
    for (krate, s) in &r.studies {
        let _ = writeln!(md, "<a id=\"{}\"></a>\n", s.slug);
        md.push_str(&study_markdown(krate, s, &r.study_uses));
    }
    let _ = writeln!(md, "## Thread scaling\n");
    let _ = writeln!(
        md,
        "Every registered preset ({} parameters) stepped on rayon pools of 1 to {} threads \
         (`cargo xtask report --threads 1,2,4,...` for more; `cargo xtask scaling` for this table \
         alone); time per step is the median of three batches after {} steps whose checkpoints \
         are compared bit for bit with the one-thread run. A preset that ends before the timing \
         does (its divergence guard, its duration) restarts from its initial checkpoint, untimed.\n",
        if r.quick { "its quick" } else { "its full" },
        r.scaling.iter().map(|s| s.threads).max().unwrap_or(1),
        scaling::CHECK_STEPS
    );
    if let Some((before, after)) = r.load {
        let _ = writeln!(
            md,
            "The machine's 1-minute load average was {before:.2} before these runs and {after:.2} after \
             ({} cores): with other work on the cores, a second thread may find no free core and the \
             speed-up falls below what an idle machine gives.\n",
            r.machine.cores
        );
    }
    md.push_str(&scaling::markdown(&r.scaling));
    md.push_str(SCALING_LIMITS);
    if let Some(roofline) = &r.roofline {
        let _ = writeln!(md, "\n## Distance to the machine's limits\n");
        md.push_str(roofline);
    }
    let _ = writeln!(md, "\n## Peer comparisons\n");
    match &r.peers {
        Ok(rows) if rows.is_empty() => {
            let _ = writeln!(
                md,
                "No peer ratios recorded yet: `cargo xtask bench --peers [--filter CRATE]` measures them \
                 and writes [peers.csv](peers.csv).\n"
            );
        }
        Ok(rows) => {
            let _ = writeln!(
                md,
                "From [peers.csv](peers.csv), written by `cargo xtask bench --peers [--filter CRATE]` (each \
                 row with the date and machine it was measured on; a filtered run replaces only its crate's \
                 rows). Ratio = our time per step over theirs: below 1 means faster.\n"
            );
            md.push_str(&ratios::markdown(rows));
            md.push('\n');
        }
        Err(e) => {
            let _ = writeln!(md, "peers.csv could not be read: {e}\n");
        }
    }
    let conf = &r.conformance;
    let _ = writeln!(md, "## Conformance\n\n{}", suites::conformance_table(&conf.checks));
    let _ = writeln!(md, "{} passed, {} failed.\n", conf.checks.len() - conf.failures(), conf.failures());
    let _ = writeln!(md, "## Stability (hard cases)\n\n{}", suites::stability_table(&r.stability));
    let _ = writeln!(
        md,
        "{} as expected, {} unexpected.\n",
        r.stability.rows.len() - r.stability.unexpected(),
        r.stability.unexpected()
    );
    if r.soak {
        let _ = writeln!(
            md,
            "Long runs of each crate's hard case and of every registered preset (`cargo xtask stability --long`): [soak.md](soak.md).\n"
        );
    }
    md.push_str(&durations_markdown(r));
    md
}

/// How long each part of the report took: the total per kind, then every part, longest first.
fn durations_markdown(r: &Report) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "## How long each part took\n");
    let mut kinds: Vec<(&str, f64, usize)> = Vec::new();
    for (kind, _, _, secs) in &r.durations {
        match kinds.iter_mut().find(|k| k.0 == *kind) {
            Some(k) => {
                k.1 += secs;
                k.2 += 1;
            }
            None => kinds.push((kind, *secs, 1)),
        }
    }
    let totals: Vec<String> =
        kinds.iter().map(|(kind, secs, n)| format!("{kind} {secs:.0} s ({n} parts)")).collect();
    let _ = writeln!(md, "Wall time of each part, {:.0} s in all: {}.\n", r.seconds, totals.join(", "));
    let _ = writeln!(md, "| part | crate | name | wall time |\n| --- | --- | --- | --- |");
    let mut parts: Vec<&(&str, String, String, f64)> = r.durations.iter().collect();
    parts.sort_by(|a, b| b.3.total_cmp(&a.3));
    for (kind, krate, name, secs) in parts {
        let _ = writeln!(md, "| {kind} | {krate} | {} | {} |", name.replace('|', "\\|"), seconds(*secs));
    }
    md.push('\n');
    md
}

/// The cheapest point of any series whose error is at most `tol`: (label, param, seconds, error).
pub fn cheapest(result: &StudyResult, tol: f64) -> Option<(String, f64, f64, f64)> {
    result
        .series
        .iter()
        .flat_map(|s| s.points.iter().map(move |p| (s, p)))
        .filter(|(_, p)| p.error <= tol && p.error.is_finite())
        .min_by(|a, b| a.1.seconds.total_cmp(&b.1.seconds))
        .map(|(s, p)| (s.label.clone(), p.param, p.seconds, p.error))
}

fn study_markdown(crate_name: &str, r: &StudyResult, uses: &[StudyUse]) -> String {
    let mut md = String::new();
    let _ = writeln!(md, "### {} ({crate_name})\n", r.title);
    let _ = writeln!(md, "![{}]({}.svg)\n", r.title, r.slug);
    let _ = writeln!(md, "Error: {}.\n", r.error_label);
    let _ = writeln!(md, "Cheapest method meeting each tolerance (measured):\n");
    let _ = writeln!(
        md,
        "| tolerance | method | {} | wall time | error |\n| --- | --- | --- | --- | --- |",
        r.param_label
    );
    for tol in tolerances(r, uses) {
        match cheapest(r, tol) {
            Some((label, param, secs, err)) => {
                let _ = writeln!(
                    md,
                    "| {tol:.0e} | {label} | {} | {} | {} |",
                    fmt_num(param),
                    seconds(secs),
                    fmt_num(err)
                );
            }
            None => {
                let _ = writeln!(md, "| {tol:.0e} | none in the sweep | | | |");
            }
        }
    }
    let _ = writeln!(md, "\n<details><summary>All points</summary>\n");
    let _ = writeln!(md, "| method | {} | wall time | error |\n| --- | --- | --- | --- |", r.param_label);
    for s in &r.series {
        for p in &s.points {
            let _ = writeln!(
                md,
                "| {} | {} | {} | {} |",
                s.label,
                fmt_num(p.param),
                seconds(p.seconds),
                fmt_num(p.error)
            );
        }
    }
    let _ = writeln!(md, "\n</details>\n");
    md
}

pub use crate::registry::seconds;

const PALETTE: [RGBColor; 10] = [
    RGBColor(31, 119, 180),
    RGBColor(255, 127, 14),
    RGBColor(44, 160, 44),
    RGBColor(214, 39, 40),
    RGBColor(148, 103, 189),
    RGBColor(140, 86, 75),
    RGBColor(227, 119, 194),
    RGBColor(127, 127, 127),
    RGBColor(188, 189, 34),
    RGBColor(23, 190, 207),
];

/// The power of ten at or below `x` (positive): a time axis spans whole decades (a hair
/// wider, so that both ends are ticks), so it always has labelled ticks (a span inside one
/// decade would have none).
fn decade_below(x: f64) -> f64 {
    10f64.powf(x.log10().floor())
}

/// The power of ten at or above `x` (positive).
fn decade_above(x: f64) -> f64 {
    10f64.powf(x.log10().ceil())
}

/// Log-log plot of error against wall time, one line per method.
pub fn plot(r: &StudyResult, path: &Path) -> Result<(), Box<dyn std::error::Error>> {
    let pts =
        || r.series.iter().flat_map(|s| s.points.iter()).filter(|p| p.error > 0.0 && p.error.is_finite());
    let (mut tmin, mut tmax, mut emin, mut emax) = (f64::MAX, f64::MIN, f64::MAX, f64::MIN);
    for p in pts() {
        tmin = tmin.min(p.seconds);
        tmax = tmax.max(p.seconds);
        emin = emin.min(p.error);
        emax = emax.max(p.error);
    }
    if tmin > tmax {
        return Err("no finite points to plot".into());
    }
    let root = SVGBackend::new(path, (900, 600)).into_drawing_area();
    root.fill(&WHITE)?;
    let mut chart = ChartBuilder::on(&root)
        .caption(&r.title, ("sans-serif", if r.title.len() > 90 { 12 } else { 18 }))
        .margin(12)
        .x_label_area_size(45)
        .y_label_area_size(70)
        .build_cartesian_2d(
            (0.999 * decade_below(tmin / 1.5)..1.001 * decade_above(tmax * 1.5)).log_scale(),
            (emin / 3.0..emax * 3.0).log_scale(),
        )?;
    chart
        .configure_mesh()
        .x_desc("wall time per run [s]")
        .y_desc(r.error_label.as_str())
        .x_label_formatter(&|v| format!("{v:.0e}"))
        .y_label_formatter(&|v| format!("{v:.0e}"))
        .draw()?;
    for (i, s) in r.series.iter().enumerate() {
        // Ten colours; beyond them the same colours come back dashed, then with square markers.
        let color = PALETTE[i % PALETTE.len()];
        let round = i / PALETTE.len();
        let line: Vec<(f64, f64)> = s
            .points
            .iter()
            .filter(|p| p.error > 0.0 && p.error.is_finite())
            .map(|p| (p.seconds, p.error))
            .collect();
        let style = color.stroke_width(2);
        let legend_len = if round == 1 { 7 } else { 20 };
        let legend = move |(x, y): (i32, i32)| PathElement::new(vec![(x, y), (x + legend_len, y)], style);
        if round == 1 {
            chart
                .draw_series(DashedLineSeries::new(line.clone(), 6, 4, style))?
                .label(s.label.as_str())
                .legend(legend);
        } else {
            chart.draw_series(LineSeries::new(line.clone(), style))?.label(s.label.as_str()).legend(legend);
        }
        if round >= 2 {
            chart.draw_series(line.into_iter().map(|(x, y)| {
                Rectangle::new([(x / 1.04, y / 1.15), (x * 1.04, y * 1.15)], color.filled())
            }))?;
        } else {
            chart.draw_series(line.into_iter().map(|p| Circle::new(p, 3, color.filled())))?;
        }
    }
    chart
        .configure_series_labels()
        .background_style(WHITE.mix(0.9))
        .border_style(BLACK)
        .position(SeriesLabelPosition::LowerRight)
        .draw()?;
    root.present()?;
    Ok(())
}

/// Where two threads stay below 1.6x, and why, as measured.
const SCALING_LIMITS: &str = "\nWhere two threads stay below 1.6x: anim-springs' `cloth` and `jelly` \
factor the backward-Euler matrix with faer's sparse Cholesky, sequential so that the bits do not \
depend on the thread count; only the spring forces and the matrix's assembly run in parallel, so \
the step scales by Amdahl's law with the factorisation's share. `anim run cloth --resolution N \
--frames 5` on 1 and 2 threads, interleaved, three rounds (2 cores under a load average of 20 to \
24): 0.97x at 32 (0.74-1.11), 1.03x at 64 (0.74-1.31), 1.08x at 128 (0.83-1.12); no measured size \
reaches 1.6x. The presets whose step takes well under a millisecond (the rope, the rigid bodies, \
the 2D grids of 64 cells) run their loops on one thread by design: a loop splits only into tasks \
of at least `anim_core::par::TASK_NS` (50 us) of work, below which waking the second thread costs \
more than its half of the work. `cargo xtask systime` checks the other side of that rule: every \
preset's system time within 10% of its user time on 1 and 2 threads.\n";

#[cfg(test)]
mod tests;
