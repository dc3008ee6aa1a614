//! The committed peer ratios, `docs/report/peers.csv`: one row per comparison that
//! `cargo xtask bench --peers` measured (date, machine, crate, case, peer, threads, our and their
//! time per step, ratio = ours / theirs). A run with `--filter` replaces only the rows of the
//! crates it measured; the report renders the file as a table.

use crate::machine::Machine;
use std::path::Path;
use std::sync::Mutex;

/// Where `bench --peers` keeps the ratios.
pub const PATH: &str = "docs/report/peers.csv";

/// One measured comparison.
#[derive(Debug, Clone, PartialEq, serde::Serialize, serde::Deserialize)]
pub struct PeerRow {
    /// UTC date of the run, `YYYY-MM-DD`.
    pub date: String,
    /// CPU model.
    pub cpu: String,
    /// Logical cores of the machine.
    pub cores: usize,
    /// Our crate (`anim-fluid`).
    pub krate: String,
    /// The problem compared.
    pub case: String,
    /// The other code.
    pub peer: String,
    /// Threads both ran with.
    pub threads: usize,
    /// Our time per step (s).
    pub ours_s: f64,
    /// Their time per step (s).
    pub theirs_s: f64,
    /// `ours_s / theirs_s`: below 1 means we are faster.
    pub ratio: f64,
}

static MEASURED: Mutex<Vec<PeerRow>> = Mutex::new(Vec::new());

/// Records a comparison measured now on this machine (kept until [`take`]).
pub fn record(krate: &str, case: &str, peer: &str, threads: usize, ours_s: f64, theirs_s: f64) {
    if !(ours_s.is_finite() && theirs_s.is_finite() && theirs_s > 0.0) {
        return;
    }
    let m = Machine::this();
    let row = PeerRow {
        date: crate::machine::today(),
        cpu: m.cpu,
        cores: m.cores,
        krate: krate.into(),
        case: case.into(),
        peer: peer.into(),
        threads,
        ours_s,
        theirs_s,
        ratio: ours_s / theirs_s,
    };
    if let Ok(mut rows) = MEASURED.lock() {
        rows.push(row);
    }
}

/// The rows recorded since the last call.
pub fn take() -> Vec<PeerRow> {
    MEASURED.lock().map(|mut rows| std::mem::take(&mut *rows)).unwrap_or_default()
}

/// Reads the file; a missing file is an empty table.
pub fn read(path: &Path) -> Result<Vec<PeerRow>, String> {
    if !path.exists() {
        return Ok(Vec::new());
    }
    let mut reader = csv::Reader::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    reader
        .deserialize()
        .enumerate()
        .map(|(i, r)| r.map_err(|e| format!("{}: row {}: {e}", path.display(), i + 1)))
        .collect()
}

/// `old` with the rows of every crate present in `new` replaced by `new`'s rows; other crates'
/// rows are kept as they were. Sorted by crate, then in measurement order.
pub fn merge(old: Vec<PeerRow>, new: Vec<PeerRow>) -> Vec<PeerRow> {
    let mut rows: Vec<PeerRow> =
        old.into_iter().filter(|r| !new.iter().any(|n| n.krate == r.krate)).collect();
    rows.extend(new);
    rows.sort_by(|a, b| a.krate.cmp(&b.krate));
    rows
}

/// Merges `new` into the file at `path` (see [`merge`]).
pub fn update(path: &Path, new: Vec<PeerRow>) -> Result<usize, String> {
    let rows = merge(read(path)?, new);
    if let Some(dir) = path.parent() {
        std::fs::create_dir_all(dir).map_err(|e| format!("{}: {e}", dir.display()))?;
    }
    let mut w = csv::Writer::from_path(path).map_err(|e| format!("{}: {e}", path.display()))?;
    for r in &rows {
        w.serialize(r).map_err(|e| format!("{}: {e}", path.display()))?;
    }
    w.flush().map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(rows.len())
}

/// The rows as a Markdown table.
pub fn markdown(rows: &[PeerRow]) -> String {
    let mut s = String::from(
        "| date | machine | crate | case | peer | threads | ours / step | theirs / step | ours / theirs |\n\
         | --- | --- | --- | --- | --- | --- | --- | --- | --- |\n",
    );
    for r in rows {
        s.push_str(&format!(
            "| {} | {}, {} cores | {} | {} | {} | {} | {} | {} | {:.3} |\n",
            r.date,
            r.cpu,
            r.cores,
            r.krate,
            r.case.replace('|', "/"),
            r.peer.replace('|', "/"),
            r.threads,
            crate::registry::seconds(r.ours_s),
            crate::registry::seconds(r.theirs_s),
            r.ratio
        ));
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    fn row(krate: &str, case: &str, ours: f64) -> PeerRow {
        PeerRow {
            date: "2026-01-02".into(),
            cpu: "Test CPU, 3 GHz".into(),
            cores: 2,
            krate: krate.into(),
            case: case.into(),
            peer: "peer \"x\"".into(),
            threads: 1,
            ours_s: ours,
            theirs_s: 2.0,
            ratio: ours / 2.0,
        }
    }

    #[test]
    fn a_filtered_run_replaces_only_its_crates_rows() {
        let old = vec![
            row("anim-fem", "beam", 1.0),
            row("anim-fluid", "N = 128", 1.0),
            row("anim-fluid", "N = 256", 1.0),
        ];
        let merged = merge(old, vec![row("anim-fluid", "N = 512", 0.5)]);
        assert_eq!(merged.len(), 2);
        assert_eq!((merged[0].krate.as_str(), merged[0].case.as_str()), ("anim-fem", "beam"));
        assert_eq!((merged[1].case.as_str(), merged[1].ratio), ("N = 512", 0.25));
    }

    #[test]
    fn the_file_round_trips_with_commas_and_quotes() {
        let dir = std::env::temp_dir().join(format!("anim-peers-{}", std::process::id()));
        let path = dir.join("peers.csv");
        std::fs::remove_dir_all(&dir).ok();
        assert_eq!(update(&path, vec![row("anim-fem", "beam, 1 step", 1.0)]), Ok(1));
        assert_eq!(update(&path, vec![row("anim-fluid", "stam", 3.0)]), Ok(2));
        let back = read(&path).unwrap();
        assert_eq!(back, vec![row("anim-fem", "beam, 1 step", 1.0), row("anim-fluid", "stam", 3.0)]);
        let md = markdown(&back);
        assert!(md.contains("| 2026-01-02 | Test CPU, 3 GHz, 2 cores | anim-fluid | stam |"), "{md}");
        assert!(md.contains("| 1.500 |"), "{md}");
        std::fs::write(&path, "date,cpu\nx,y\n").unwrap();
        assert!(read(&path).unwrap_err().contains("peers.csv: row 1"));
        std::fs::remove_dir_all(&dir).ok();
    }
}
