//! Checkpoints: a simulation's state in a versioned, self-describing file, written atomically.
//!
//! A checkpoint is two parts in one file:
//!
//! 1. a header line, JSON: `{"format":"anim-checkpoint","version":1,"kind":"springs/hanging-cloth",
//!    "payload_bytes":1234,"crc32":5678}`;
//! 2. the payload: exactly `payload_bytes` bytes of JSON, whose CRC-32 is `crc32`.
//!
//! JSON keeps the file self-describing (any JSON tool reads it) and, with `serde_json`'s
//! round-trip float formatting, every `f64` comes back bit for bit. The length and checksum make a
//! truncated or corrupted file a clear error instead of a resumed run that silently differs.
//!
//! Writes are atomic: the file is written to a temporary sibling, flushed to disk and renamed
//! over the target, so a crash mid-write leaves the previous checkpoint intact.
//!
//! ```
//! # fn main() -> Result<(), anim_io::IoError> {
//! let path = std::env::temp_dir().join(format!("anim-ckpt-doc-{}.json", std::process::id()));
//! let state = (0.25_f64, vec![1.0_f64, 0.1 + 0.2]);
//! anim_io::write_checkpoint(&path, "example/state", &state)?;
//! let (header, back): (_, (f64, Vec<f64>)) = anim_io::read_checkpoint(&path)?;
//! assert_eq!(header.kind, "example/state");
//! assert_eq!(back.1[1].to_bits(), (0.1_f64 + 0.2).to_bits());
//! # std::fs::remove_file(&path).unwrap();
//! # Ok(())
//! # }
//! ```

use crate::IoError;
use serde::de::DeserializeOwned;
use serde::{Deserialize, Serialize};
use std::io::Write;
use std::path::{Path, PathBuf};

/// The `format` field of every checkpoint header.
pub const FORMAT: &str = "anim-checkpoint";
/// The checkpoint layout this build writes and reads.
pub const VERSION: u32 = 1;
/// Header lines longer than this are not checkpoint headers (the header is a few hundred bytes).
const MAX_HEADER_BYTES: usize = 4096;

/// The first line of a checkpoint.
#[derive(Debug, Clone, PartialEq, Eq, Serialize, Deserialize)]
#[serde(deny_unknown_fields)]
pub struct CheckpointHeader {
    /// Always [`FORMAT`].
    pub format: String,
    /// The layout version ([`VERSION`] when written by this build).
    pub version: u32,
    /// What the payload is (the writer's name for its simulation, e.g. `springs/hanging-cloth`).
    pub kind: String,
    /// Length of the payload in bytes.
    pub payload_bytes: u64,
    /// CRC-32 (IEEE) of the payload.
    pub crc32: u32,
}

/// Why a checkpoint cannot be read.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
#[non_exhaustive]
pub enum CheckpointProblem {
    /// The first line is not a checkpoint header.
    #[error("not an anim checkpoint: {0}")]
    NotACheckpoint(String),
    /// Written by a layout this build does not read.
    #[error("checkpoint version {found} is not supported (this build reads version {supported})")]
    Version {
        /// The file's version.
        found: u32,
        /// The version this build reads.
        supported: u32,
    },
    /// The payload is shorter (or longer) than the header says: the file was cut or appended to.
    #[error("truncated or extended: the header announces {expected} payload bytes, the file has {found}")]
    Length {
        /// Bytes announced by the header.
        expected: u64,
        /// Bytes present.
        found: u64,
    },
    /// The payload's checksum does not match: the file was altered.
    #[error("corrupted: payload CRC-32 is {computed:#010x}, the header says {stored:#010x}")]
    Checksum {
        /// Checksum in the header.
        stored: u32,
        /// Checksum of the bytes present.
        computed: u32,
    },
    /// The payload is intact but is not what the reader expects (another kind of simulation).
    #[error("payload of kind `{kind}` does not fit: {cause}")]
    Payload {
        /// The header's kind.
        kind: String,
        /// The deserialiser's message (with line and column).
        cause: String,
    },
}

fn problem(path: &Path, problem: CheckpointProblem) -> IoError {
    IoError::Checkpoint { path: path.to_path_buf(), problem }
}

/// Writes `bytes` to `path` atomically: a temporary sibling is written, flushed to disk and
/// renamed over `path`. A crash at any point leaves either the old file or the new one.
///
/// # Errors
/// [`IoError::Io`] naming the file the operating system refused.
pub fn write_atomic(path: &Path, bytes: &[u8]) -> Result<(), IoError> {
    let name = path.file_name().map_or_else(|| "checkpoint".into(), |n| n.to_string_lossy().into_owned());
    let tmp: PathBuf = path.with_file_name(format!(".{name}.tmp-{}", std::process::id()));
    let result = (|| {
        let mut file = std::fs::File::create(&tmp).map_err(|e| IoError::io(&tmp, e))?;
        file.write_all(bytes).map_err(|e| IoError::io(&tmp, e))?;
        file.sync_all().map_err(|e| IoError::io(&tmp, e))?;
        std::fs::rename(&tmp, path).map_err(|e| IoError::io(path, e))
    })();
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result?;
    // Make the rename itself durable where the platform allows syncing a directory.
    if let Some(dir) = path.parent().filter(|d| !d.as_os_str().is_empty())
        && let Ok(d) = std::fs::File::open(dir)
    {
        let _ = d.sync_all();
    }
    Ok(())
}

/// Serialises `payload` as a checkpoint of `kind` and writes it atomically to `path`.
///
/// # Errors
/// [`IoError::Encode`] if `payload` cannot be serialised, [`IoError::Io`] if the file cannot be
/// written.
///
/// JSON has no NaN or infinity (`serde_json` writes them as `null`): checkpoint only finite
/// states. The workspace's simulations never hold a non-finite state (a step that would produce
/// one fails and leaves the state as it was), and a `null` where a number belongs makes
/// [`read_checkpoint`] fail with a [`CheckpointProblem::Payload`] naming line and column.
pub fn write_checkpoint<T: Serialize + ?Sized>(path: &Path, kind: &str, payload: &T) -> Result<(), IoError> {
    let body = serde_json::to_vec(payload).map_err(|e| IoError::encode(path, e))?;
    let header = CheckpointHeader {
        format: FORMAT.into(),
        version: VERSION,
        kind: kind.into(),
        payload_bytes: body.len() as u64,
        crc32: crc32fast::hash(&body),
    };
    let mut bytes = serde_json::to_vec(&header).map_err(|e| IoError::encode(path, e))?;
    bytes.push(b'\n');
    bytes.extend_from_slice(&body);
    write_atomic(path, &bytes)
}

/// Reads a checkpoint written by [`write_checkpoint`], checking its format, version, length and
/// checksum before deserialising the payload.
///
/// # Errors
/// [`IoError::Io`] if the file cannot be read; [`IoError::Checkpoint`] naming the file and the
/// [`CheckpointProblem`] otherwise.
pub fn read_checkpoint<T: DeserializeOwned>(path: &Path) -> Result<(CheckpointHeader, T), IoError> {
    let bytes = std::fs::read(path).map_err(|e| IoError::io(path, e))?;
    parse_checkpoint(&bytes, path)
}

/// Parses the bytes of a checkpoint file; errors name `path`. See [`read_checkpoint`].
///
/// # Errors
/// [`IoError::Checkpoint`] naming `path` and the [`CheckpointProblem`].
pub fn parse_checkpoint<T: DeserializeOwned>(
    bytes: &[u8],
    path: &Path,
) -> Result<(CheckpointHeader, T), IoError> {
    let header_end = bytes
        .iter()
        .take(MAX_HEADER_BYTES)
        .position(|&b| b == b'\n')
        .ok_or_else(|| problem(path, CheckpointProblem::NotACheckpoint("no header line".into())))?;
    let header: CheckpointHeader = serde_json::from_slice(&bytes[..header_end])
        .map_err(|e| problem(path, CheckpointProblem::NotACheckpoint(format!("header: {e}"))))?;
    if header.format != FORMAT {
        return Err(problem(
            path,
            CheckpointProblem::NotACheckpoint(format!("format is `{}`, expected `{FORMAT}`", header.format)),
        ));
    }
    if header.version != VERSION {
        return Err(problem(path, CheckpointProblem::Version { found: header.version, supported: VERSION }));
    }
    let body = &bytes[header_end + 1..];
    if body.len() as u64 != header.payload_bytes {
        return Err(problem(
            path,
            CheckpointProblem::Length { expected: header.payload_bytes, found: body.len() as u64 },
        ));
    }
    let computed = crc32fast::hash(body);
    if computed != header.crc32 {
        return Err(problem(path, CheckpointProblem::Checksum { stored: header.crc32, computed }));
    }
    let payload = serde_json::from_slice(body).map_err(|e| {
        problem(path, CheckpointProblem::Payload { kind: header.kind.clone(), cause: e.to_string() })
    })?;
    Ok((header, payload))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn temp(name: &str) -> PathBuf {
        let dir = std::env::temp_dir().join(format!("anim-ckpt-{}-{name}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        dir.join("run.ckpt")
    }

    fn checkpoint_problem(e: IoError) -> CheckpointProblem {
        match e {
            IoError::Checkpoint { problem, .. } => problem,
            other => panic!("expected a checkpoint problem, got {other}"),
        }
    }

    #[derive(Debug, PartialEq, Serialize, Deserialize)]
    struct Payload {
        t: f64,
        x: Vec<f64>,
        name: String,
    }

    fn payload() -> Payload {
        // Values whose shortest decimal forms are long: they must come back bit for bit.
        Payload {
            t: 0.1 + 0.2,
            x: vec![1.0 / 3.0, -2.0e-310, f64::MAX, 5e-324, -0.0],
            name: "a \"null\"".into(),
        }
    }

    #[test]
    fn round_trip_is_bit_exact() {
        let path = temp("roundtrip");
        write_checkpoint(&path, "test/payload", &payload()).unwrap();
        let (header, back): (_, Payload) = read_checkpoint(&path).unwrap();
        assert_eq!(header.kind, "test/payload");
        assert_eq!(header.version, VERSION);
        let p = payload();
        assert_eq!(back.t.to_bits(), p.t.to_bits());
        assert!(back.x.iter().zip(&p.x).all(|(a, b)| a.to_bits() == b.to_bits()));
        assert_eq!(back.name, p.name);
    }

    #[test]
    fn truncated_corrupted_and_foreign_files_are_clear_errors() {
        let path = temp("damaged");
        write_checkpoint(&path, "test/payload", &payload()).unwrap();
        let good = std::fs::read(&path).unwrap();

        std::fs::write(&path, &good[..good.len() - 7]).unwrap();
        let e = read_checkpoint::<Payload>(&path).unwrap_err();
        assert!(e.to_string().contains("run.ckpt"), "{e}");
        assert!(
            matches!(checkpoint_problem(e), CheckpointProblem::Length { found, expected } if found + 7 == expected)
        );

        // One digit changed in the payload: still valid JSON, caught by the checksum.
        let mut flipped = good.clone();
        let digit = flipped.iter().rposition(u8::is_ascii_digit).unwrap();
        flipped[digit] = if flipped[digit] == b'1' { b'2' } else { b'1' };
        std::fs::write(&path, &flipped).unwrap();
        assert!(matches!(
            checkpoint_problem(read_checkpoint::<Payload>(&path).unwrap_err()),
            CheckpointProblem::Checksum { .. }
        ));

        std::fs::write(&path, b"frame,t,x0\n0,0.0,1.0\n").unwrap();
        assert!(matches!(
            checkpoint_problem(read_checkpoint::<Payload>(&path).unwrap_err()),
            CheckpointProblem::NotACheckpoint(_)
        ));
        std::fs::write(&path, b"").unwrap();
        assert!(matches!(
            checkpoint_problem(read_checkpoint::<Payload>(&path).unwrap_err()),
            CheckpointProblem::NotACheckpoint(_)
        ));
    }

    #[test]
    fn another_version_or_kind_is_refused_with_both_named() {
        let path = temp("version");
        write_checkpoint(&path, "test/payload", &payload()).unwrap();
        let text = String::from_utf8(std::fs::read(&path).unwrap()).unwrap();
        std::fs::write(&path, text.replacen("\"version\":1", "\"version\":2", 1)).unwrap();
        let e = read_checkpoint::<Payload>(&path).unwrap_err();
        assert!(e.to_string().contains("version 2") && e.to_string().contains("version 1"), "{e}");

        write_checkpoint(&path, "test/other", &vec![1.0_f64, 2.0]).unwrap();
        let e = read_checkpoint::<Payload>(&path).unwrap_err();
        assert!(e.to_string().contains("test/other"), "{e}");
    }

    #[test]
    fn a_null_where_a_number_belongs_is_a_payload_error() {
        let path = temp("nan");
        write_checkpoint(&path, "test/nan", &vec![1.0, f64::NAN]).unwrap();
        let e = read_checkpoint::<Vec<f64>>(&path).unwrap_err();
        assert!(
            matches!(checkpoint_problem(e), CheckpointProblem::Payload { cause, .. } if cause.contains("column"))
        );
    }

    #[test]
    fn a_failed_write_keeps_the_previous_checkpoint() {
        let path = temp("atomic");
        write_checkpoint(&path, "test/payload", &payload()).unwrap();
        // A write that fails (here: the target is a directory, so the rename fails) leaves
        // the previous checkpoint and no temporary file.
        let blocked = path.with_file_name("blocked");
        std::fs::create_dir_all(blocked.join("inner")).unwrap();
        assert!(write_checkpoint(&blocked, "test/payload", &payload()).is_err());
        std::fs::remove_dir_all(&blocked).unwrap();
        let (_, back): (_, Payload) = read_checkpoint(&path).unwrap();
        assert_eq!(back, payload());
        // No temporary files are left behind.
        let dir = path.parent().unwrap();
        assert_eq!(std::fs::read_dir(dir).unwrap().count(), 1);
    }
}
