//! Per-step metrics as CSV (one row per step, a header from the row type's field names) and
//! summaries as JSON, through serde. Numbers are written in the shortest form that reads back to
//! the same `f64`.

use crate::IoError;
use serde::Serialize;
use std::fs::File;
use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

/// Writes `value` as pretty-printed JSON with a trailing newline.
pub fn write_json<T: Serialize + ?Sized>(path: impl AsRef<Path>, value: &T) -> Result<(), IoError> {
    let path = path.as_ref();
    let mut text = serde_json::to_string_pretty(value).map_err(|e| IoError::encode(path, e))?;
    text.push('\n');
    crate::vtk::write_file(path, &text)
}

/// A CSV file written row by row. Rows are flat serde structs (numbers, strings, booleans,
/// options; `None` is an empty cell); the header is the first row's field names.
///
/// ```
/// # fn main() -> Result<(), anim_io::IoError> {
/// #[derive(serde::Serialize)]
/// struct Step { step: usize, t: f64, energy: f64 }
///
/// let path = std::env::temp_dir().join(format!("anim-io-doc-{}.csv", std::process::id()));
/// let mut csv = anim_io::metrics::CsvWriter::create(&path)?;
/// csv.row(&Step { step: 0, t: 0.0, energy: 1.5 })?;
/// csv.row(&Step { step: 1, t: 0.01, energy: 1.25 })?;
/// csv.finish()?;
/// assert_eq!(std::fs::read_to_string(&path).unwrap(), "step,t,energy\n0,0.0,1.5\n1,0.01,1.25\n");
/// # std::fs::remove_file(&path).unwrap();
/// # Ok(())
/// # }
/// ```
pub struct CsvWriter {
    path: PathBuf,
    inner: csv::Writer<BufWriter<File>>,
}

impl std::fmt::Debug for CsvWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("CsvWriter").field("path", &self.path).finish_non_exhaustive()
    }
}

impl CsvWriter {
    /// Creates (truncates) the file.
    pub fn create(path: impl AsRef<Path>) -> Result<Self, IoError> {
        let path = path.as_ref().to_path_buf();
        let file = File::create(&path).map_err(|e| IoError::io(&path, e))?;
        Ok(CsvWriter { inner: csv::Writer::from_writer(BufWriter::new(file)), path })
    }

    /// Appends one row (the first row also writes the header).
    pub fn row<T: Serialize>(&mut self, row: &T) -> Result<(), IoError> {
        self.inner.serialize(row).map_err(|e| csv_error(&self.path, e))
    }

    /// Flushes the file.
    pub fn finish(mut self) -> Result<(), IoError> {
        self.inner.flush().map_err(|e| IoError::io(&self.path, e))?;
        match self.inner.into_inner() {
            Ok(mut w) => w.flush().map_err(|e| IoError::io(&self.path, e)),
            Err(e) => Err(IoError::io(&self.path, std::io::Error::other(e.to_string()))),
        }
    }
}

fn csv_error(path: &Path, e: csv::Error) -> IoError {
    match e.into_kind() {
        csv::ErrorKind::Io(io) => IoError::io(path, io),
        other => IoError::encode(path, format!("{other:?}")),
    }
}

/// Writes all `rows` as CSV.
pub fn write_csv<T: Serialize>(path: impl AsRef<Path>, rows: &[T]) -> Result<(), IoError> {
    let mut w = CsvWriter::create(path)?;
    for r in rows {
        w.row(r)?;
    }
    w.finish()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize, serde::Deserialize, Debug, PartialEq)]
    struct Row {
        step: u64,
        t: f64,
        energy: Option<f64>,
        solver: String,
    }

    fn tmp(name: &str) -> PathBuf {
        std::env::temp_dir().join(format!("anim-io-metrics-{}-{name}", std::process::id()))
    }

    #[test]
    fn csv_and_json_read_back_bit_for_bit() {
        let rows = vec![
            Row { step: 0, t: 0.0, energy: Some(1.0 / 3.0), solver: "cg".into() },
            Row { step: 1, t: 1e-300, energy: None, solver: "a,b".into() },
            Row { step: 2, t: -2.5e17, energy: Some(f64::MIN_POSITIVE), solver: "x\"y".into() },
        ];
        let path = tmp("rows.csv");
        write_csv(&path, &rows).unwrap();
        let back: Vec<Row> =
            csv::Reader::from_path(&path).unwrap().deserialize().collect::<Result<_, _>>().unwrap();
        assert_eq!(back, rows);
        let json = tmp("rows.json");
        write_json(&json, &rows).unwrap();
        let back: Vec<Row> = serde_json::from_str(&std::fs::read_to_string(&json).unwrap()).unwrap();
        assert_eq!(back, rows);
        std::fs::remove_file(path).unwrap();
        std::fs::remove_file(json).unwrap();
    }

    #[test]
    fn nested_rows_are_an_error_not_a_panic() {
        #[derive(Serialize)]
        struct Nested {
            v: Vec<Vec<f64>>,
        }
        let path = tmp("nested.csv");
        let e = write_csv(&path, &[Nested { v: vec![vec![1.0]] }]).unwrap_err();
        assert!(matches!(e, IoError::Encode { .. }), "{e}");
        let _ = std::fs::remove_file(path);
    }
}
