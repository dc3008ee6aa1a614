//! Tests of the report: its parts, tables and the cheapest-method data.

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
    let md = study_markdown("anim-core", &r, &[]);
    assert!(md.contains("| 1e-2 | fast-rough |"), "{md}");
    assert!(md.contains("| 1e-8 | none in the sweep |"), "{md}");
    assert!(md.contains("| 1e-1 | fast-rough |"), "{md}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_study_with_extra_tolerances_gets_their_rows_in_order() {
    // tiny(): fast-rough has error 1e-3, so it meets 5e-2 as well.
    // The extra 5e-2 is what anim-flip registers for its dam-break study.
    let uses = anim::cases().study_uses;
    let r = StudyResult { slug: anim_flip::cases::DAM_BREAK_SLUG.into(), ..tiny() };
    assert_eq!(tolerances(&r, &uses), [1e-1, 5e-2, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8]);
    assert_eq!(tolerances(&tiny(), &uses), TOLERANCES);
    let md = study_markdown("anim-flip", &r, &uses);
    let rows: Vec<&str> =
        md.lines().filter(|l| l.starts_with("| 1e-1 |") || l.starts_with("| 5e-2 |")).collect();
    assert_eq!(rows.len(), 2, "{md}");
    assert!(rows[1].starts_with("| 5e-2 | fast-rough | 0.1 |"), "{md}");
    let mut report = tiny_report();
    report.studies.push(("anim-flip", r));
    let table = cheapest_table(&report);
    let picks: Vec<f64> = table.families[2].picks.iter().map(|p| p.tolerance).collect();
    assert_eq!(picks, [1e-1, 5e-2, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8]);
    assert_eq!(table.families[2].picks[1].method.as_deref(), Some("fast-rough"));
    assert_eq!(table.families[0].picks.len(), TOLERANCES.len());
}

fn tiny_report() -> Report {
    use crate::registry::{Check, Judge, Outcome};
    let oscillator = StudyResult { slug: "core-oscillator".into(), ..tiny() };
    Report {
        studies: vec![
            ("anim-core", oscillator),
            ("anim-x", StudyResult { slug: "x-study".into(), ..tiny() }),
        ],
        conformance: ConformanceRun {
            checks: vec![Check {
                crate_name: "anim-x",
                case: "case".into(),
                metric: "error".into(),
                measured: 1e-3,
                reference: 0.0,
                tolerance: 1e-2,
                judge: Judge::AtMost,
                source: "a book",
            }],
            seconds: 0.1,
        },
        stability: StabilityRun {
            rows: vec![("anim-x", "hard", Outcome::Stable("ok".into()), Outcome::Stable("ran".into()))],
        },
        scaling: vec![scaling::Row {
            krate: "anim-x".into(),
            scene: "scene".into(),
            threads: 2,
            seconds: 1e-3,
            speedup: 1.8,
            identical: Some(true),
            note: String::new(),
        }],
        load: Some((0.5, 1.5)),
        peers: Ok(vec![PeerRow {
            date: "2026-11-25".into(),
            cpu: "CPU".into(),
            cores: 2,
            krate: "anim-x".into(),
            case: "case".into(),
            peer: "other".into(),
            threads: 1,
            ours_s: 1e-3,
            theirs_s: 2e-3,
            ratio: 0.5,
        }]),
        quick: true,
        date: "2026-11-25".into(),
        oldest: "2026-11-25".into(),
        machine: Machine { cpu: "CPU".into(), cores: 2 },
        seconds: 12.0,
        soak: false,
        study_uses: anim::cases().study_uses,
        durations: vec![
            ("conformance", "anim-x".into(), "case".into(), 0.1),
            ("study", "anim-x".into(), "a | study".into(), 11.0),
            ("scaling", "anim-x".into(), "scene".into(), 0.9),
        ],
        roofline: None,
    }
}

/// The time section sums each kind and lists every part, longest first, with `|` escaped.
#[test]
fn the_report_says_how_long_each_part_took() {
    let md = index_markdown(&tiny_report());
    let section = &md[md.find("## How long each part took").expect("the section")..];
    assert!(
        section
            .contains("12 s in all: conformance 0 s (1 parts), study 11 s (1 parts), scaling 1 s (1 parts)"),
        "{section}"
    );
    let study = section.find("| study | anim-x | a \\| study | 11.00 s |").expect("the study's row");
    let scaling = section.find("| scaling | anim-x | scene |").expect("the scaling row");
    let conformance = section.find("| conformance | anim-x | case |").expect("the conformance row");
    assert!(study < scaling && scaling < conformance, "{section}");
}

#[test]
fn index_has_every_section_table_and_plot() {
    let dir = std::env::temp_dir().join(format!("anim-report-index-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    write(&dir, &tiny_report()).unwrap();
    let md = std::fs::read_to_string(dir.join("index.md")).unwrap();
    let headings: Vec<&str> = md.lines().filter(|l| l.starts_with('#')).collect();
    assert_eq!(
        headings,
        [
            "# anim: work-precision report",
            "## Cheapest method meeting a tolerance",
            "## Work-precision studies",
            "### t (anim-core)",
            "### t (anim-x)",
            "## Thread scaling",
            "## Peer comparisons",
            "## Conformance",
            "## Stability (hard cases)",
            "## How long each part took",
        ]
    );
    assert!(
        md.contains("`cargo xtask report --quick` on 2026-11-25 (CPU, 2 cores); its parts took 12 s"),
        "{md}"
    );
    // The headline table: one row per study, the cheapest point under 1e-1, 1e-2 and 1e-3.
    assert!(
        md.contains(
            "| study | crate | error measure | 1e-1 | 1e-2 | 1e-3 |\n| --- | --- | --- | --- | --- | --- |"
        ),
        "{md}"
    );
    assert!(
        md.contains("| [x-study](#x-study) | anim-x | e | fast-rough, dt = 0.1: 10.00 ms (error 0.001) | fast-rough, dt = 0.1: 10.00 ms (error 0.001) | fast-rough, dt = 0.1: 10.00 ms (error 0.001) |"),
        "{md}"
    );
    assert!(md.contains("![t](core-oscillator.svg)") && md.contains("![t](x-study.svg)"), "{md}");
    assert!(md.contains("| anim-x | scene | 2 | 1.00 ms | 1.80 | yes |"), "{md}");
    assert!(md.contains("load average was 0.50 before these runs and 1.50 after (2 cores)"), "{md}");
    assert!(
        md.contains("| 2026-11-25 | CPU, 2 cores | anim-x | case | other | 1 | 1.00 ms | 2.00 ms | 0.500 |"),
        "{md}"
    );
    assert!(md.contains("| anim-x | case | error | 0.001 | <= 0.01 | pass | a book |"), "{md}");
    assert!(md.contains("1 passed, 0 failed.") && md.contains("1 as expected, 0 unexpected."), "{md}");
    assert!(!md.contains("soak.md"), "no soak.md beside this index");
    for svg in ["core-oscillator.svg", "x-study.svg"] {
        let text = std::fs::read_to_string(dir.join(svg)).unwrap();
        assert!(text.starts_with("<svg") && text.contains("fast-rough"), "{svg}");
    }
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn stored_parts_give_the_report_in_order_with_their_date_range() {
    use crate::registry::{Judge, Outcome};
    use crate::report_data::{Data, Kind, Part, StoredCheck};
    let mut conf = Part::new(Kind::Conformance, "anim-x", "case", "2026-11-20", 4.0);
    conf.checks = vec![StoredCheck {
        case: "c".into(),
        metric: "m".into(),
        measured: 2.0,
        reference: 0.0,
        tolerance: 1.0,
        judge: Judge::AtMost,
        source: "s".into(),
    }];
    let mut a = Part::new(Kind::Study, "anim-x", "first", "2026-11-25", 10.0);
    a.study = Some(StudyResult { slug: "first".into(), ..tiny() });
    let mut b = Part::new(Kind::Study, "anim-y", "second", "2026-11-21", 20.0);
    b.study = Some(StudyResult { slug: "second".into(), ..tiny() });
    let mut hard = Part::new(Kind::Stability, "anim-y", "hard", "2026-11-21", 1.0);
    hard.outcome = Some((Outcome::Stable(String::new()), Outcome::Stable("ok".into())));
    let data = Data::new(false, Machine { cpu: "CPU".into(), cores: 2 }, vec![conf, a, b, hard]);
    let r = Report::from_data(&data, Ok(Vec::new()), false);
    let slugs: Vec<&str> = r.studies.iter().map(|(_, s)| s.slug.as_str()).collect();
    assert_eq!(slugs, ["first", "second"]);
    assert_eq!((r.seconds, r.date.as_str(), r.oldest.as_str()), (35.0, "2026-11-25", "2026-11-20"));
    assert_eq!(r.conformance.failures(), 1);
    assert!(r.stability.passed() && !r.quick);
    let md = index_markdown(&r);
    assert!(md.contains("its parts took 35 s"), "{md}");
    assert!(md.contains("measured between 2026-11-20 and 2026-11-25"), "{md}");
}

#[test]
fn cheapest_json_lists_every_tolerance_with_the_measured_pick() {
    let dir = std::env::temp_dir().join(format!("anim-report-json-{}", std::process::id()));
    std::fs::remove_dir_all(&dir).ok();
    std::fs::create_dir_all(&dir).unwrap();
    write(&dir, &tiny_report()).unwrap();
    let text = std::fs::read_to_string(dir.join("cheapest.json")).unwrap();
    std::fs::remove_dir_all(&dir).ok();
    // A report with the FEM, spring and cavity studies too, and a point that failed (NaN).
    let mut r = tiny_report();
    r.studies[0].1.series[1].points.push(Point { param: 0.05, seconds: f64::NAN, error: f64::NAN });
    for (krate, slug) in [
        ("anim-fem", "fem-beam"),
        ("anim-springs", "springs-cloth"),
        ("anim-fluid", "fluid_cavity_ghia"),
        ("anim-pbd", "pbd-cloth-position"),
        ("anim-mpm", "mpm_dam_break"),
    ] {
        r.studies.push((krate, StudyResult { slug: slug.into(), ..tiny() }));
    }
    let text_all = serde_json::to_string_pretty(&cheapest_table(&r)).unwrap();
    assert!(text.contains("\"format\": 2"));
    let text = text_all;
    let v: serde_json::Value = serde_json::from_str(&text).unwrap();
    assert_eq!(v["format"], 2);
    assert_eq!(v["date"], "2026-11-25");
    assert_eq!(v["machine"]["cpu"], "CPU");
    assert_eq!(v["machine"]["cores"], 2);
    assert_eq!(v["mode"], "quick");
    assert_eq!(v["tolerances"], serde_json::json!([1e-1, 1e-2, 1e-3, 1e-4, 1e-6, 1e-8]));
    let families = v["families"].as_array().unwrap();
    assert_eq!(families.len(), 7);
    let osc = &families[0];
    assert_eq!(osc["study"], "core-oscillator");
    assert_eq!(osc["crate"], "anim-core");
    assert_eq!(osc["scene"], "harmonic-oscillator");
    // 10.3 periods of the unit oscillator, `m = k = 1`.
    assert_eq!(osc["horizon"], 10.3 * 2.0 * std::f64::consts::PI);
    assert_eq!(osc["param"], "dt");
    assert_eq!(families[1]["scene"], serde_json::Value::Null);
    let picks = osc["picks"].as_array().unwrap();
    assert_eq!(picks.len(), TOLERANCES.len());
    // tiny(): fast-rough (0.01 s, error 1e-3) meets 1e-1..1e-3; slow-accurate at dt 0.2
    // (0.5 s, 1e-5) meets 1e-4; at dt 0.1 (1 s, 1e-7) meets 1e-6; nothing meets 1e-8.
    let expect = [
        (1e-1, Some(("fast-rough", 0.1, 0.01, 1e-3))),
        (1e-2, Some(("fast-rough", 0.1, 0.01, 1e-3))),
        (1e-3, Some(("fast-rough", 0.1, 0.01, 1e-3))),
        (1e-4, Some(("slow-accurate", 0.2, 0.5, 1e-5))),
        (1e-6, Some(("slow-accurate", 0.1, 1.0, 1e-7))),
        (1e-8, None),
    ];
    for (p, (tol, want)) in picks.iter().zip(expect) {
        assert_eq!(p["tolerance"], tol);
        match want {
            Some((m, param, secs, err)) => {
                assert_eq!(p["method"], m, "{tol}");
                assert_eq!(p["param"], param, "{tol}");
                assert_eq!(p["seconds"], secs, "{tol}");
                assert_eq!(p["error"], err, "{tol}");
            }
            None => assert!(p["method"].is_null() && p["param"].is_null(), "{tol}"),
        }
    }
    // Every finite point of every method, in the study's order (the NaN point is left out).
    let series = osc["series"].as_array().unwrap();
    let methods: Vec<&str> = series.iter().map(|s| s["method"].as_str().unwrap()).collect();
    assert_eq!(methods, ["slow-accurate", "fast-rough"]);
    assert_eq!(
        series[0]["points"],
        serde_json::json!([
            { "param": 0.1, "seconds": 1.0, "error": 1e-7 },
            { "param": 0.2, "seconds": 0.5, "error": 1e-5 },
        ])
    );
    assert_eq!(series[1]["points"], serde_json::json!([{ "param": 0.1, "seconds": 0.01, "error": 1e-3 }]));
    assert!(osc.get("problem").is_none(), "the oscillator study has no problem parameters");
    let beam = &families[2];
    assert_eq!(beam["study"], "fem-beam");
    assert_eq!(beam["scene"], "fem/cantilever-beam");
    assert_eq!(beam["horizon"], 0.5);
    assert_eq!(beam["problem"], serde_json::json!({ "young": 1e6, "density": 1000.0, "cell": 0.05 }));
    let cloth = &families[3];
    assert_eq!(cloth["problem"]["n"], 6.0, "quick mode's cloth is 6 x 6");
    assert!(families[4]["horizon"].is_null() && families[4]["scene"] == "fluid/lid-driven-cavity");
    let pbd = &families[5];
    assert_eq!(pbd["scene"], "pbd/hanging-cloth");
    assert_eq!(pbd["horizon"], 0.5);
    assert_eq!(
        pbd["problem"],
        serde_json::json!({ "n": 8.0, "dt": 1.0 / 60.0 }),
        "quick mode's cloth is 8 x 8"
    );
    let mpm = &families[6];
    assert_eq!(mpm["scene"], "mpm/dam-break-2d");
    assert!(mpm["horizon"].is_null() && mpm.get("problem").is_none());
    // And it reads back into the typed form.
    let table: CheapestTable = serde_json::from_str(&text).unwrap();
    assert_eq!(table.families[0].picks[3].method.as_deref(), Some("slow-accurate"));
    std::fs::remove_dir_all(&dir).ok();
}

/// Times that all lie inside one decade (17 to 64 ms) still get labelled ticks on the time
/// axis: it spans the decades around them (1e-2 and 1e-1 labelled).
#[test]
fn a_time_axis_inside_one_decade_is_labelled() {
    let r = StudyResult {
        series: vec![Series {
            label: "field".into(),
            points: vec![
                Point { param: 0.2, seconds: 0.0174, error: 0.011 },
                Point { param: 0.1, seconds: 0.028, error: 0.003 },
                Point { param: 0.05, seconds: 0.064, error: 0.0011 },
            ],
        }],
        ..tiny()
    };
    let dir = std::env::temp_dir().join(format!("anim-report-decade-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("decade.svg");
    plot(&r, &path).unwrap();
    let svg = std::fs::read_to_string(&path).unwrap();
    // The time axis's labels are centred under their ticks (the error axis's are not).
    let centred: Vec<&str> = svg
        .split("<text")
        .filter(|t| t.contains("text-anchor=\"middle\""))
        .filter_map(|t| t.split('>').nth(1))
        .map(|t| t.split('<').next().unwrap_or("").trim())
        .collect();
    assert!(centred.contains(&"1e-2") && centred.contains(&"1e-1"), "time ticks: {centred:?}");
    std::fs::remove_dir_all(&dir).ok();
}
