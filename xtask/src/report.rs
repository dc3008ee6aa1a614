//! `cargo xtask report`: conformance, stability and work-precision studies written as Markdown
//! tables and SVG plots.

use crate::registry::{self, Ctx, StudyResult, fmt_num};
use crate::suites;
use plotters::prelude::*;
use std::fmt::Write as _;
use std::path::Path;
use std::time::Instant;

/// Tolerances of the "cheapest method" tables.
const TOLERANCES: [f64; 5] = [1e-2, 1e-3, 1e-4, 1e-6, 1e-8];

pub fn run(ctx: &Ctx, out: &str) -> bool {
    let start = Instant::now();
    let dir = Path::new(out);
    if let Err(e) = std::fs::create_dir_all(dir) {
        eprintln!("cannot create {out}: {e}");
        return false;
    }
    let conf = suites::conformance(ctx, None);
    let stab = suites::stability(ctx, None);
    let mut md = String::new();
    let _ = writeln!(md, "# anim: work-precision report\n");
    let _ = writeln!(
        md,
        "Written by `cargo xtask report{}`. Wall times are medians of repeated runs on the machine \
         that ran the report ({} logical cores); compare methods within one table, not across machines.\n",
        if ctx.quick { " --quick" } else { "" },
        std::thread::available_parallelism().map(|n| n.get()).unwrap_or(1)
    );
    let _ = writeln!(md, "## Work-precision studies\n");
    let mut ok = true;
    for study in registry::all().studies {
        let t = Instant::now();
        let result = (study.run)(ctx);
        eprintln!("  study {:<45} {:>6.1} s", study.name, t.elapsed().as_secs_f64());
        let svg = dir.join(format!("{}.svg", result.slug));
        if let Err(e) = plot(&result, &svg) {
            eprintln!("cannot write {}: {e}", svg.display());
            ok = false;
        }
        md.push_str(&study_markdown(study.crate_name, &result));
    }
    let _ = writeln!(md, "## Conformance\n\n{}", suites::conformance_table(&conf.checks));
    let _ = writeln!(md, "{} passed, {} failed.\n", conf.checks.len() - conf.failures(), conf.failures());
    let _ = writeln!(md, "## Stability (hard cases)\n\n{}", suites::stability_table(&stab));
    if dir.join("soak.md").exists() {
        let _ = writeln!(
            md,
            "Long runs of each crate's hard case (`cargo xtask stability --long`): [soak.md](soak.md).\n"
        );
    }
    let index = dir.join("index.md");
    if let Err(e) = std::fs::write(&index, md) {
        eprintln!("cannot write {}: {e}", index.display());
        return false;
    }
    eprintln!("wrote {} in {:.0} s", index.display(), start.elapsed().as_secs_f64());
    ok && conf.passed() && stab.passed()
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

fn study_markdown(crate_name: &str, r: &StudyResult) -> String {
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
    for tol in TOLERANCES {
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

fn seconds(s: f64) -> String {
    if s < 1e-3 {
        format!("{:.2} us", s * 1e6)
    } else if s < 1.0 {
        format!("{:.2} ms", s * 1e3)
    } else {
        format!("{s:.2} s")
    }
}

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
        .build_cartesian_2d((tmin / 1.5..tmax * 1.5).log_scale(), (emin / 3.0..emax * 3.0).log_scale())?;
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registry::{Point, Series};

    fn tiny() -> StudyResult {
        StudyResult {
            title: "t".into(),
            slug: "t".into(),
            error_label: "e".into(),
            param_label: "dt".into(),
            series: vec![
                Series {
                    label: "slow-accurate".into(),
                    points: vec![
                        Point { param: 0.1, seconds: 1.0, error: 1e-7 },
                        Point { param: 0.2, seconds: 0.5, error: 1e-5 },
                    ],
                },
                Series {
                    label: "fast-rough".into(),
                    points: vec![Point { param: 0.1, seconds: 0.01, error: 1e-3 }],
                },
            ],
        }
    }

    #[test]
    fn many_series_get_distinct_styles() {
        let series: Vec<Series> = (0..25)
            .map(|i| Series {
                label: format!("method-{i}"),
                points: vec![
                    Point { param: 0.1, seconds: 1e-3 * (i + 1) as f64, error: 1e-2 / (i + 1) as f64 },
                    Point { param: 0.05, seconds: 2e-3 * (i + 1) as f64, error: 1e-3 / (i + 1) as f64 },
                ],
            })
            .collect();
        let r = StudyResult { series, ..tiny() };
        let dir = std::env::temp_dir().join(format!("anim-report-many-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("many.svg");
        plot(&r, &path).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.contains("method-24"));
        // Series 10..19 are dashed (many short segments), series 20.. carry square markers.
        assert!(svg.matches("<rect").count() > 2 * 5, "square markers expected");
        std::fs::remove_dir_all(&dir).ok();
    }

    #[test]
    fn cheapest_picks_the_fastest_point_under_the_tolerance() {
        let r = tiny();
        assert_eq!(cheapest(&r, 1e-2).map(|c| c.0), Some("fast-rough".into()));
        assert_eq!(cheapest(&r, 1e-4).map(|c| (c.0, c.2)), Some(("slow-accurate".into(), 0.5)));
        assert_eq!(cheapest(&r, 1e-6).map(|c| c.2), Some(1.0));
        assert!(cheapest(&r, 1e-9).is_none());
    }

    #[test]
    fn writes_an_svg_and_a_table() {
        let r = tiny();
        let dir = std::env::temp_dir().join(format!("anim-report-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("t.svg");
        plot(&r, &path).unwrap();
        let svg = std::fs::read_to_string(&path).unwrap();
        assert!(svg.starts_with("<svg") && svg.contains("slow-accurate") && svg.contains("fast-rough"));
        let md = study_markdown("anim-core", &r);
        assert!(md.contains("| 1e-2 | fast-rough |"), "{md}");
        assert!(md.contains("| 1e-8 | none in the sweep |"), "{md}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
