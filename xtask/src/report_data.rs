//! `docs/report/data.json`: every measured part of the report (a conformance case's checks, a
//! hard case's outcome, a study's points, a thread-scaling preset's rows), each with the date it
//! was measured and how long it took. `cargo xtask report --filter TEXT` re-runs only the parts of
//! matching crates or names and keeps the others from this file, so one crate's section can be
//! brought up to date without the whole run (over half an hour in full mode).

use crate::machine::Machine;
use crate::registry::{Check, Judge, Outcome, StudyResult};
use crate::scaling;
use serde::{Deserialize, Serialize};
use std::path::Path;

/// Format version of `data.json`.
const FORMAT: u32 = 1;

/// What kind of report part a [`Part`] is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "kebab-case")]
pub enum Kind {
    Conformance,
    Stability,
    Study,
    Scaling,
}

impl Kind {
    /// The kind's name in tables.
    #[must_use]
    pub fn name(self) -> &'static str {
        match self {
            Kind::Conformance => "conformance",
            Kind::Stability => "stability",
            Kind::Study => "study",
            Kind::Scaling => "scaling",
        }
    }
}

/// A conformance check as stored (owned strings).
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct StoredCheck {
    pub case: String,
    pub metric: String,
    #[serde(with = "float")]
    pub measured: f64,
    #[serde(with = "float")]
    pub reference: f64,
    #[serde(with = "float")]
    pub tolerance: f64,
    pub judge: Judge,
    pub source: String,
}

/// One measured part of the report.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Part {
    pub kind: Kind,
    #[serde(rename = "crate")]
    pub krate: String,
    /// The case, study or scaling scene name as registered.
    pub name: String,
    /// When it was measured (`YYYY-MM-DD`).
    pub date: String,
    /// Wall time of the part, seconds.
    pub seconds: f64,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub checks: Vec<StoredCheck>,
    /// `(expected, outcome)` of a hard case.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub outcome: Option<(Outcome, Outcome)>,
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub study: Option<StudyResult>,
    #[serde(default, skip_serializing_if = "Vec::is_empty")]
    pub scaling: Vec<scaling::Row>,
    /// The 1-minute load average before and after a scaling part.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub load: Option<(f64, f64)>,
}

impl Part {
    pub fn new(kind: Kind, krate: &str, name: &str, date: &str, seconds: f64) -> Self {
        Self {
            kind,
            krate: krate.into(),
            name: name.into(),
            date: date.into(),
            seconds,
            checks: Vec::new(),
            outcome: None,
            study: None,
            scaling: Vec::new(),
            load: None,
        }
    }

    /// Whether this part is the registered item `(kind, crate, name)`.
    pub fn is(&self, kind: Kind, krate: &str, name: &str) -> bool {
        self.kind == kind && self.krate == krate && self.name == name
    }

    /// The stored checks as [`Check`]s. `Check` borrows its crate name and source for the
    /// program's lifetime (they are literals in the registry), so stored strings are leaked:
    /// a few kilobytes, once per report run.
    pub fn checks(&self) -> Vec<Check> {
        let krate = leak(&self.krate);
        self.checks
            .iter()
            .map(|c| Check {
                crate_name: krate,
                case: c.case.clone(),
                metric: c.metric.clone(),
                measured: c.measured,
                reference: c.reference,
                tolerance: c.tolerance,
                judge: c.judge,
                source: leak(&c.source),
            })
            .collect()
    }
}

fn leak(s: &str) -> &'static str {
    Box::leak(s.to_owned().into_boxed_str())
}

/// Converts checks for storing.
pub fn store_checks(checks: &[Check]) -> Vec<StoredCheck> {
    checks
        .iter()
        .map(|c| StoredCheck {
            case: c.case.clone(),
            metric: c.metric.clone(),
            measured: c.measured,
            reference: c.reference,
            tolerance: c.tolerance,
            judge: c.judge,
            source: c.source.into(),
        })
        .collect()
}

/// The whole file.
#[derive(Debug, Clone, Serialize, Deserialize)]
pub struct Data {
    pub format: u32,
    /// `quick` or `full`: parts of both modes are never mixed.
    pub mode: String,
    pub machine: Machine,
    pub parts: Vec<Part>,
}

impl Data {
    pub fn new(quick: bool, machine: Machine, parts: Vec<Part>) -> Self {
        Self { format: FORMAT, mode: mode(quick).into(), machine, parts }
    }

    /// Reads `path` for a filtered run in `quick` or full mode.
    ///
    /// # Errors
    /// A message naming the file when it is missing, unreadable, of another format or mode.
    pub fn load(path: &Path, quick: bool) -> Result<Self, String> {
        let text = std::fs::read_to_string(path).map_err(|e| {
            format!(
                "{}: {e}; a filtered report keeps the other parts from this file, so run the whole \
                 report once first",
                path.display()
            )
        })?;
        let data: Data = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", path.display()))?;
        if data.format != FORMAT {
            return Err(format!("{}: format {} (this xtask writes {FORMAT})", path.display(), data.format));
        }
        if data.mode != mode(quick) {
            return Err(format!(
                "{}: its parts were measured in {} mode; a filtered run in {} mode would mix them",
                path.display(),
                data.mode,
                mode(quick)
            ));
        }
        Ok(data)
    }

    /// Takes the stored part `(kind, crate, name)` out of the file, if it is there.
    pub fn take(&mut self, kind: Kind, krate: &str, name: &str) -> Option<Part> {
        let i = self.parts.iter().position(|p| p.is(kind, krate, name))?;
        Some(self.parts.remove(i))
    }

    /// Writes the file (pretty JSON).
    ///
    /// # Errors
    /// A message naming the file.
    pub fn write(&self, path: &Path) -> Result<(), String> {
        let text = serde_json::to_string_pretty(self).map_err(|e| e.to_string())?;
        std::fs::write(path, text + "\n").map_err(|e| format!("cannot write {}: {e}", path.display()))
    }
}

fn mode(quick: bool) -> &'static str {
    if quick { "quick" } else { "full" }
}

pub use anim_core::cases::float;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::registry::{Point, Series};

    #[test]
    fn parts_round_trip_with_non_finite_values() {
        let check = Check {
            crate_name: "anim-x",
            case: "case".into(),
            metric: "m".into(),
            measured: f64::NAN,
            reference: f64::INFINITY,
            tolerance: 1e-3,
            judge: Judge::AtMost,
            source: "a table",
        };
        let mut conf = Part::new(Kind::Conformance, "anim-x", "case", "2026-11-25", 1.5);
        conf.checks = store_checks(&[check]);
        let mut study = Part::new(Kind::Study, "anim-x", "study", "2026-11-25", 2.0);
        study.study = Some(StudyResult {
            title: "t".into(),
            slug: "s".into(),
            error_label: "e".into(),
            param_label: "p".into(),
            series: vec![Series {
                label: "a".into(),
                points: vec![Point { param: 0.1, seconds: 1e-3, error: f64::NEG_INFINITY }],
            }],
        });
        let mut hard = Part::new(Kind::Stability, "anim-x", "hard", "2026-11-24", 0.5);
        hard.outcome = Some((Outcome::Stable(String::new()), Outcome::Diverged("step 3".into())));
        let data = Data::new(false, Machine { cpu: "CPU".into(), cores: 2 }, vec![conf, study, hard]);
        let text = serde_json::to_string(&data).unwrap();
        let mut back: Data = serde_json::from_str(&text).unwrap();
        let checks = back.parts[0].checks();
        assert!(checks[0].measured.is_nan() && checks[0].reference == f64::INFINITY);
        assert_eq!((checks[0].crate_name, checks[0].source), ("anim-x", "a table"));
        let p = back.parts[1].study.as_ref().unwrap().series[0].points[0];
        assert_eq!((p.param, p.error), (0.1, f64::NEG_INFINITY));
        let hard = back.take(Kind::Stability, "anim-x", "hard").unwrap();
        assert_eq!(hard.outcome.unwrap().1, Outcome::Diverged("step 3".into()));
        assert!(back.take(Kind::Stability, "anim-x", "hard").is_none());
        assert_eq!(back.parts.len(), 2);
    }

    #[test]
    fn a_filtered_run_refuses_a_file_of_the_other_mode() {
        let dir = std::env::temp_dir().join(format!("anim-report-data-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("data.json");
        Data::new(true, Machine { cpu: "CPU".into(), cores: 2 }, Vec::new()).write(&path).unwrap();
        let e = Data::load(&path, false).unwrap_err();
        assert!(e.contains("quick mode") && e.contains("full mode"), "{e}");
        assert!(Data::load(&path, true).is_ok());
        let e = Data::load(&dir.join("missing.json"), true).unwrap_err();
        assert!(e.contains("missing.json") && e.contains("run the whole report once"), "{e}");
        std::fs::remove_dir_all(&dir).ok();
    }
}
