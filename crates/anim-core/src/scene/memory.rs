//! How much memory a scene will take, and whether the machine has it: every kind's builder
//! estimates the bytes its scene will allocate from the parameters alone (model, data, state,
//! solver scratch: grids, particles, matrix nonzeros and factor fill, frame buffers), before
//! allocating any of it, and refuses parameters that ask for more than is available with the
//! estimate and the available memory in the message, instead of aborting on a failed
//! allocation halfway through.
//!
//! The memory available to a scene ([`available_memory`]) is the memory free (`MemAvailable`,
//! a cgroup's limit, `ulimit -v`: [`free_memory`]) less a tenth, at least 256 MiB, kept for what
//! no estimate counts (the process's threads and allocator, its code, the writer's buffers) and
//! for the estimates' own error. The arithmetic is in `f64`, so a size of any magnitude gives a
//! finite (or infinite) estimate and never an overflow.
//!
//! ```
//! use anim_core::scene::{BuildError, MemoryNeed};
//!
//! // A 3D grid 1e9 cells across: far beyond any machine.
//! let n = 1.0e9_f64;
//! let need = MemoryNeed::new().with(n * n * n, "grid nodes", 28.0).with(8.0 * n * n * n, "particles", 120.0);
//! let e = need.check_within("resolution", "1000000000 cells across", Some(16.0 * 1024.0 * 1024.0 * 1024.0));
//! let Err(BuildError::Memory { bytes, available, .. }) = &e else { panic!("refused") };
//! assert_eq!((*bytes, *available), (need.bytes(), 16.0 * 1024.0 * 1024.0 * 1024.0));
//! assert_eq!(
//!     e.unwrap_err().to_string(),
//!     "field `resolution`: 1000000000 cells across needs about 9.88e29 B (1e27 grid nodes x 28 B, \
//!      8e27 particles x 120 B); 16.0 GiB available"
//! );
//! // A small grid fits.
//! let need = MemoryNeed::new().with(64.0 * 64.0 * 64.0, "grid nodes", 28.0);
//! assert!(need.check_within("resolution", "64 cells across", Some(1.0e9)).is_ok());
//! ```

use super::preset::BuildError;

/// The most bytes a scene may take when the available memory is unknown (not Linux, or
/// `/proc/meminfo` unreadable): 2^48 bytes (256 TiB), a bound no machine reaches, so that only
/// sizes that cannot be meant are refused.
pub const UNKNOWN_LIMIT: f64 = 281_474_976_710_656.0;

/// Bytes per point of the [`Frame`](super::Frame) a view fills: its position and velocity as
/// `f64`.
pub const FRAME_POINT_BYTES: f64 = 48.0;

/// Bytes per point a run holds to write a frame beyond the frame itself, as `anim run` writes
/// VTK: the writer's snapshot of the frame (48), its positions, velocities and vertex ids (56),
/// the cell arrays (connectivity, offsets, types, 24) and the bytes of the array being encoded
/// (24), and the file's text in memory, 88 characters of base64 a point in a string grown by
/// doubling: up to 176. (Its resident part measured 170 bytes a point: `anim run` on 1.19
/// million MPM particles peaks 200 MB higher writing `vtu` frames than writing none; the rest is
/// address space reserved by the string's growth, which `ulimit -v` counts.)
pub const WRITTEN_POINT_BYTES: f64 = 330.0;

/// Bytes per cell of the [`Frame`](super::Frame) of an image grid: its density and velocity as
/// `f64`.
pub const FRAME_CELL_BYTES: f64 = 32.0;

/// Bytes per cell a run holds to write a grid frame beyond the frame itself: the writer's
/// snapshot (32), the bytes of the array being encoded (24) and the `vti` file in memory (base64
/// of the density and velocity, 43 characters, growing by doubling: up to 86).
pub const WRITTEN_CELL_BYTES: f64 = 142.0;

/// One part of a scene's memory: `count` items of `each` bytes.
#[derive(Debug, Clone, PartialEq)]
struct Part {
    count: f64,
    noun: String,
    each: f64,
}

/// The bytes a scene will allocate, as a sum of parts (`count` items of `each` bytes: grid
/// nodes, particles, matrix nonzeros), estimated from its parameters before anything is
/// allocated. The parts are named in the refusal so a user sees what grows.
#[derive(Debug, Clone, Default, PartialEq)]
pub struct MemoryNeed {
    parts: Vec<Part>,
}

impl MemoryNeed {
    /// No memory.
    #[must_use]
    pub fn new() -> Self {
        Self::default()
    }

    /// This need and `count` items (`noun`, plural: `"grid nodes"`) of `each` bytes.
    #[must_use]
    pub fn with(mut self, count: f64, noun: &str, each: f64) -> Self {
        self.add(count, noun, each);
        self
    }

    /// Adds `count` items (`noun`) of `each` bytes; a part of no items is left out.
    pub fn add(&mut self, count: f64, noun: &str, each: f64) {
        if count != 0.0 && each != 0.0 {
            self.parts.push(Part { count, noun: noun.to_string(), each });
        }
    }

    /// This need and the view of `points` points: the frame ([`FRAME_POINT_BYTES`]) and what a
    /// run holds to write it ([`WRITTEN_POINT_BYTES`]), as the parts `frame points` and
    /// `written points`.
    #[must_use]
    pub fn with_frame_points(self, points: f64) -> Self {
        self.with(points, "frame points", FRAME_POINT_BYTES).with(
            points,
            "written points",
            WRITTEN_POINT_BYTES,
        )
    }

    /// This need and the view of an image grid of `cells` cells: the frame
    /// ([`FRAME_CELL_BYTES`]) and what a run holds to write it ([`WRITTEN_CELL_BYTES`]), as the
    /// parts `frame cells` and `written cells`.
    #[must_use]
    pub fn with_frame_cells(self, cells: f64) -> Self {
        self.with(cells, "frame cells", FRAME_CELL_BYTES).with(cells, "written cells", WRITTEN_CELL_BYTES)
    }

    /// The bytes of the parts named `noun` (0 when there is none): what a test that does not
    /// write frames leaves out, `written points` or `written cells`.
    #[must_use]
    pub fn bytes_of(&self, noun: &str) -> f64 {
        self.parts.iter().filter(|p| p.noun == noun).map(|p| p.count * p.each).sum()
    }

    /// The bytes apart from what a run holds to write frames (the parts `written points` and
    /// `written cells`): what a build, a step and a drawn frame hold, which the crates' estimate
    /// tests measure.
    #[must_use]
    pub fn bytes_without_writing(&self) -> f64 {
        self.bytes() - self.bytes_of("written points") - self.bytes_of("written cells")
    }

    /// Adds every part of `other`.
    pub fn extend(&mut self, other: MemoryNeed) {
        self.parts.extend(other.parts);
    }

    /// The estimate in bytes: the sum of the parts (infinite when a count is).
    #[must_use]
    pub fn bytes(&self) -> f64 {
        self.parts.iter().map(|p| p.count * p.each).sum()
    }

    /// The parts as the refusal lists them: `1e27 grid nodes x 28 B, 8e27 particles x 120 B`.
    #[must_use]
    pub fn breakdown(&self) -> String {
        let parts: Vec<String> = self
            .parts
            .iter()
            .map(|p| format!("{} {} x {} B", count(p.count), p.noun, count(p.each)))
            .collect();
        parts.join(", ")
    }

    /// Refuses the need when it exceeds the memory available to this process
    /// ([`available_memory`]), or [`UNKNOWN_LIMIT`] when that is unknown.
    ///
    /// # Errors
    /// [`BuildError::Memory`] of `field`, whose message says `what` was asked (`"2048 cells
    /// across"`), the estimate with its parts, and the memory available.
    pub fn check(&self, field: &str, what: &str) -> Result<(), BuildError> {
        self.check_within(field, what, available_memory())
    }

    /// As [`check`](Self::check), against `available` bytes (`None`: unknown, the bound is
    /// [`UNKNOWN_LIMIT`]).
    ///
    /// # Errors
    /// [`BuildError::Memory`] when the estimate is above the bound (or not a number).
    pub fn check_within(&self, field: &str, what: &str, available: Option<f64>) -> Result<(), BuildError> {
        let bytes = self.bytes();
        let limit = available.unwrap_or(UNKNOWN_LIMIT);
        if bytes <= limit {
            return Ok(());
        }
        let have = match available {
            Some(a) => format!("{} available", format_bytes(a)),
            None => format!(
                "more than the {} a scene may take when the available memory is unknown",
                format_bytes(UNKNOWN_LIMIT)
            ),
        };
        let parts = self.breakdown();
        let parts = if parts.is_empty() { String::new() } else { format!(" ({parts})") };
        Err(BuildError::Memory {
            field: field.to_string(),
            message: format!("{what} needs about {}{parts}; {have}", format_bytes(bytes)),
            bytes,
            available: limit,
        })
    }
}

/// The nonzero blocks of the sparse Cholesky factor (faer's, AMD ordering) of a matrix whose
/// graph is a mesh filling a lattice of `dims` nodes (1, 2 or 3 of them; a block row per node,
/// edges between near neighbours), for estimating a direct solver's memory before the matrix
/// exists. With `N` the nodes and `a <= b` the smallest sides:
///
/// - 1D (a chain): `c N`, the band;
/// - 2D: `c N min(log2 N, a)`: nested dissection's `N log2 N` on a square (George 1973: `c =
///   31/4` on a 5-point grid; faer's AMD ordering fills a little more), the band `N a` on a
///   strip;
/// - 3D: `c N sqrt(a b)`: nested dissection's `N^(4/3)` on a cube (Lipton, Rose & Tarjan 1979),
///   `N a` on a bar of side `a`;
///
/// at most the dense triangle `N (N + 1) / 2`. The constant `c` depends on the stencil and is
/// measured by the caller against faer's factor (anim-springs' cloth: 9.5 in 2D, its jelly's
/// 27-point lattice: 15; anim-fem's tetrahedra of six per cube: 10). A scalar factor has `k^2`
/// times as many nonzeros for blocks of `k` unknowns.
#[must_use]
pub fn cholesky_factor_blocks(dims: &[f64], c: f64) -> f64 {
    let mut sides: Vec<f64> = dims.iter().map(|d| d.max(1.0)).collect();
    sides.sort_by(f64::total_cmp);
    let n: f64 = sides.iter().product();
    let fill = match sides.as_slice() {
        [] | [_] => c * n,
        [a, _] => c * n * n.log2().max(1.0).min(*a),
        [a, b, ..] => c * n * (a * b).sqrt(),
    };
    fill.min(0.5 * n * (n + 1.0))
}

/// Refuses `need` when it exceeds the memory available ([`MemoryNeed::check`]).
///
/// # Errors
/// [`BuildError::Memory`] of `field`, naming `what` was asked, the estimate and the memory
/// available.
pub fn check_memory(field: &str, what: &str, need: &MemoryNeed) -> Result<(), BuildError> {
    need.check(field, what)
}

/// A count as a message shows it: whole below a million (`4096`), else with three significant
/// digits at most and a power of ten (`8.59e9`, `1e27`).
fn count(x: f64) -> String {
    if !x.is_finite() {
        return "more than 1e308".into();
    }
    if x.abs() < 1.0e6 {
        return format!("{}", x.round());
    }
    let text = format!("{x:.2e}");
    match text.split_once('e') {
        Some((mantissa, exponent)) => {
            let mantissa = mantissa.trim_end_matches('0').trim_end_matches('.');
            format!("{mantissa}e{exponent}")
        }
        None => text,
    }
}

/// Bytes in human units: `B` below a KiB, then KiB, MiB, GiB and TiB with one decimal, and
/// bytes with a power of ten from 1024 TiB on (`3.2e30 B`).
///
/// ```
/// use anim_core::scene::format_bytes;
///
/// assert_eq!(format_bytes(512.0), "512 B");
/// assert_eq!(format_bytes(1536.0), "1.5 KiB");
/// assert_eq!(format_bytes(3.0 * 1024.0 * 1024.0), "3.0 MiB");
/// assert_eq!(format_bytes(18.2 * 1024.0 * 1024.0 * 1024.0), "18.2 GiB");
/// assert_eq!(format_bytes(2.0f64.powi(48)), "256.0 TiB");
/// assert_eq!(format_bytes(3.2e30), "3.2e30 B");
/// ```
#[must_use]
pub fn format_bytes(bytes: f64) -> String {
    const UNITS: [&str; 4] = ["KiB", "MiB", "GiB", "TiB"];
    if !bytes.is_finite() {
        return "more than 1e308 B".into();
    }
    if bytes < 1024.0 {
        return format!("{} B", bytes.round());
    }
    let mut value = bytes;
    for unit in UNITS {
        value /= 1024.0;
        if value < 1023.95 {
            return format!("{value:.1} {unit}");
        }
    }
    format!("{} B", count(bytes))
}

/// What the memory check keeps back from the memory free, for what no scene's estimate
/// counts: the process's threads (their stacks and allocator arenas), its code, the writer's
/// file buffers and the estimates' own error: a tenth of it, at least 256 MiB.
fn reserve(free: f64) -> f64 {
    (0.1 * free).max(256.0 * 1024.0 * 1024.0)
}

/// The memory a scene of this process may take, in bytes: the memory free ([`free_memory`])
/// less a tenth of it (at least 256 MiB) kept for the process itself and the estimates' error;
/// `None` when the memory free is unknown.
#[must_use]
pub fn available_memory() -> Option<f64> {
    free_memory().map(|free| (free - reserve(free)).max(0.0))
}

/// The memory this process may still allocate, in bytes: on Linux the least of the system's
/// `MemAvailable` (`/proc/meminfo`), the room left under the cgroup's limit
/// (`/sys/fs/cgroup/memory.max` less `memory.current`, when the limit is a number) and the room
/// left under the address-space limit (`ulimit -v`: `Max address space` of `/proc/self/limits`
/// less `VmSize` of `/proc/self/status`); `None` elsewhere or when `/proc/meminfo` cannot be
/// read.
#[must_use]
pub fn free_memory() -> Option<f64> {
    let meminfo = std::fs::read_to_string("/proc/meminfo").ok()?;
    let mut available = kib_field(&meminfo, "MemAvailable:")?;
    if let Some(max) = read_number("/sys/fs/cgroup/memory.max") {
        let used = read_number("/sys/fs/cgroup/memory.current").unwrap_or(0.0);
        available = available.min((max - used).max(0.0));
    }
    if let Some(limit) = address_space_limit() {
        let used = std::fs::read_to_string("/proc/self/status")
            .ok()
            .and_then(|s| kib_field(&s, "VmSize:"))
            .unwrap_or(0.0);
        available = available.min((limit - used).max(0.0));
    }
    Some(available)
}

/// The value in bytes of the line of `text` starting with `key`, given in kB (`MemAvailable:
/// 18874368 kB`).
fn kib_field(text: &str, key: &str) -> Option<f64> {
    let line = text.lines().find(|l| l.starts_with(key))?;
    let kib: f64 = line[key.len()..].split_whitespace().next()?.parse().ok()?;
    Some(kib * 1024.0)
}

/// The number a file holds (a cgroup's `memory.max`: `max` when unlimited gives `None`).
fn read_number(path: &str) -> Option<f64> {
    std::fs::read_to_string(path).ok()?.trim().parse::<u64>().ok().map(|n| n as f64)
}

/// The soft address-space limit of this process in bytes, `None` when unlimited or unknown.
fn address_space_limit() -> Option<f64> {
    let limits = std::fs::read_to_string("/proc/self/limits").ok()?;
    let line = limits.lines().find(|l| l.starts_with("Max address space"))?;
    let soft = line["Max address space".len()..].split_whitespace().next()?;
    soft.parse::<u64>().ok().map(|n| n as f64)
}

#[cfg(test)]
mod tests {
    use super::*;

    const GIB: f64 = 1024.0 * 1024.0 * 1024.0;

    #[test]
    fn counts_and_bytes_read_as_people_write_them() {
        assert_eq!(count(0.0), "0");
        assert_eq!(count(4096.0), "4096");
        assert_eq!(count(999_999.0), "999999");
        assert_eq!(count(1.0e6), "1e6");
        assert_eq!(count(8_589_934_592.0), "8.59e9");
        assert_eq!(count(1.0e27), "1e27");
        assert_eq!(count(2.7e28), "2.7e28");
        assert_eq!(count(f64::INFINITY), "more than 1e308");
        assert_eq!(format_bytes(0.0), "0 B");
        assert_eq!(format_bytes(1023.0), "1023 B");
        assert_eq!(format_bytes(1024.0), "1.0 KiB");
        assert_eq!(format_bytes(1024.0 * 1024.0 - 1.0), "1.0 MiB");
        assert_eq!(format_bytes(7.3 * GIB), "7.3 GiB");
        assert_eq!(format_bytes(1023.0 * 1024.0 * GIB), "1023.0 TiB");
        assert_eq!(format_bytes(1024.0 * 1024.0 * GIB), "1.13e15 B");
        assert_eq!(format_bytes(f64::INFINITY), "more than 1e308 B");
    }

    #[test]
    fn a_need_above_the_available_memory_is_refused_with_both() {
        // 2048^3 nodes of 28 B and 8 particles of 120 B per cell: 3D MPM at 2048.
        let n = 2048.0f64;
        let need =
            MemoryNeed::new().with(n * n * n, "grid nodes", 28.0).with(8.0 * n * n * n, "particles", 120.0);
        assert_eq!(need.bytes(), n * n * n * (28.0 + 960.0));
        let e = need.check_within("resolution", "2048 cells across", Some(18.2 * GIB)).expect_err("refused");
        assert_eq!(
            e.to_string(),
            "field `resolution`: 2048 cells across needs about 7.7 TiB (8.59e9 grid nodes x 28 B, 6.87e10 \
             particles x 120 B); 18.2 GiB available"
        );
        match e {
            BuildError::Memory { field, bytes, available, .. } => {
                assert_eq!(field, "resolution");
                assert_eq!(bytes, need.bytes());
                assert_eq!(available, 18.2 * GIB);
            }
            other => panic!("{other:?}"),
        }
        // Within a table, the field is prefixed and the numbers kept.
        let e = need.check_within("resolution", "2048 cells across", Some(GIB)).expect_err("refused");
        let BuildError::Memory { field, bytes, .. } = e.within("bodies[1]") else { panic!("memory") };
        assert_eq!((field.as_str(), bytes), ("bodies[1].resolution", need.bytes()));
    }

    #[test]
    fn a_need_within_the_bound_is_accepted_and_unknown_memory_bounds_at_2_to_the_48() {
        let need = MemoryNeed::new().with(1000.0, "particles", 1000.0);
        assert_eq!(need.bytes(), 1.0e6);
        assert!(need.check_within("resolution", "10 cells", Some(1.0e6)).is_ok(), "equal fits");
        assert!(need.check_within("resolution", "10 cells", Some(0.999e6)).is_err());
        assert!(need.check_within("resolution", "10 cells", None).is_ok());
        let big = MemoryNeed::new().with(2.0f64.powi(40), "cells", 256.0);
        assert!(big.check_within("resolution", "x", None).is_ok(), "exactly 2^48");
        let over = MemoryNeed::new().with(2.0f64.powi(40) + 1.0, "cells", 256.0);
        let e = over.check_within("resolution", "x", None).expect_err("above 2^48");
        assert!(
            e.to_string()
                .ends_with("; more than the 256.0 TiB a scene may take when the available memory is unknown"),
            "{e}"
        );
        // No overflow: a size beyond f64's range is infinite, and refused.
        let inf = MemoryNeed::new().with(f64::MAX, "cells", 1.0e10);
        assert!(inf.bytes().is_infinite());
        assert!(inf.check_within("resolution", "x", Some(1.0e12)).is_err());
        // A part's bytes by name, the view's two parts.
        let view = MemoryNeed::new().with(10.0, "particles", 100.0).with_frame_points(10.0);
        assert_eq!(view.bytes_of("written points"), 10.0 * WRITTEN_POINT_BYTES);
        assert_eq!(view.bytes() - view.bytes_of("written points"), 10.0 * (100.0 + FRAME_POINT_BYTES));
        assert_eq!(view.bytes_without_writing(), 10.0 * (100.0 + FRAME_POINT_BYTES));
        assert_eq!(view.bytes_of("cells"), 0.0);
        // Empty parts are left out; no parts at all print no parentheses.
        let empty = MemoryNeed::new().with(0.0, "cells", 8.0);
        assert_eq!(empty.breakdown(), "");
        assert!(empty.check_within("f", "x", Some(0.0)).is_ok());
    }

    #[test]
    fn the_factor_fill_follows_nested_dissection_and_never_passes_the_dense_triangle() {
        // A square: c N log2 N; a strip: the band c N a; a cube: c N^(4/3); a bar: c N a.
        assert_eq!(cholesky_factor_blocks(&[64.0, 64.0], 7.75), 7.75 * 4096.0 * 12.0);
        assert_eq!(cholesky_factor_blocks(&[1000.0, 4.0], 7.75), 7.75 * 4000.0 * 4.0);
        assert_eq!(cholesky_factor_blocks(&[16.0, 16.0, 16.0], 14.0), 14.0 * 4096.0 * 16.0);
        assert_eq!(cholesky_factor_blocks(&[81.0, 9.0, 9.0], 9.0), 9.0 * 6561.0 * 9.0);
        assert_eq!(cholesky_factor_blocks(&[100.0], 2.0), 200.0);
        assert_eq!(cholesky_factor_blocks(&[3.0, 3.0, 3.0], 14.0), 27.0 * 28.0 / 2.0, "dense");
        assert!(cholesky_factor_blocks(&[1e9, 1e9, 1e9], 14.0).is_finite());
    }

    #[test]
    fn the_machine_reports_some_memory_on_linux() {
        let available = free_memory();
        if cfg!(target_os = "linux") {
            let a = available.expect("/proc/meminfo");
            assert!(a > 0.0 && a.is_finite() && a.fract() == 0.0, "{a}");
            // A scene gets the free memory less a tenth, at least 256 MiB.
            let mib = 1024.0 * 1024.0;
            assert_eq!(reserve(10_000.0 * mib), 1000.0 * mib);
            assert_eq!(reserve(1000.0 * mib), 256.0 * mib);
            let scene = available_memory().expect("known");
            assert!(scene < a && scene >= 0.0, "{scene} of {a}");
            let meminfo = std::fs::read_to_string("/proc/meminfo").expect("meminfo");
            let total = kib_field(&meminfo, "MemTotal:").expect("MemTotal");
            assert!(a <= total, "{a} > {total}");
        }
        assert_eq!(kib_field("MemTotal: 10 kB\nMemAvailable:    7 kB\n", "MemAvailable:"), Some(7168.0));
        assert_eq!(kib_field("MemTotal: 10 kB\n", "MemAvailable:"), None);
    }
}
