//! The example-robot-data collection against Pinocchio 4.1: forward kinematics, joint
//! Jacobians, RNEA, CRBA and ABA of every robot, on a fixed and on a floating base.
//!
//! The reference is written by `crates/anim-rigid/testdata/make_pinocchio_collection_reference.py`
//! into `crates/anim-rigid/testdata/pinocchio_collection/`: `index.json` lists each robot and
//! base with Pinocchio's joint layout (names, joint types, parents, `idx_q`, `idx_v`, the
//! widths in `q` and `v`, and each joint's motion subspace `S` in its own frame), and one gzip'd
//! little-endian `f64` file per robot and base holds 20 seeded samples. Each robot is loaded from
//! its gzip'd URDF in `testdata/robots/` with [`UrdfOptions::default`] (mimic joints
//! independent, fixed joints merged, as Pinocchio builds it), its layout is checked against the
//! header (same joints in the same order, same types, parents and indices in Pinocchio's `q`
//! and in `v`), then for every sample, with `q` converted by [`crate::pinocchio::from_pinocchio`]:
//!
//! - FK: every joint's world placement `oMi` (rotation and translation) after
//!   [`compute_joint_jacobians`] against Pinocchio's `data.oMi`;
//! - Jacobians: `data.jacobian` (the world Jacobian, one column per velocity entry) against
//!   Pinocchio's `data.J` after `computeJointJacobians`. Every joint's Jacobian is these columns
//!   masked to its support, so this compares all of them at once. The file stores Pinocchio's
//!   `oMi` and the header each joint's `S`, which determine `data.J` column by column as
//!   `Ad(oMi) S` (the script checks that this reproduces `data.J` to 1e-13 before writing);
//! - RNEA `tau = ID(q, v, a)` with gravity, CRBA `H(q)` (its upper triangle, what Pinocchio's
//!   `crba` fills) and ABA `q'' = FD(q, v, tau)`.
//!
//! The floating-base samples put the fixed-base samples' joint configurations on a random base
//! placement, so their `oMi` is the stored root placement times the fixed-base `oMi`, and the
//! joint block of `H` is the fixed-base `H`; the file stores the rest (root placement, the six
//! base rows of `H`, RNEA and ABA). The script checks both identities to 1e-13.
//!
//! **Errors.** For one sample and one quantity, `e = max |ours - ref| / max(1, max |ref|)`
//! over all the entries of the quantity (all placements, all Jacobian columns, the whole vector
//! or triangle): relative to the largest reference entry, absolute when that is below 1. The
//! reported figure is the worst `e` over the samples and robots, with the robot where it
//! occurs. FK, Jacobians, RNEA and CRBA must stay within [`TOLERANCE`] (1e-13; the worst
//! measured over the collection is about 1.6e-15, a few roundings: both libraries evaluate the
//! same recursions in the same order of joints, so nothing accumulates beyond that).
//!
//! ABA solves `H q'' = tau - C` in effect; its error grows with the conditioning of `H`, so it
//! is judged per sample against `ABA_C · nv · ε · κ(H)`, with `κ(H)` the 2-norm condition number
//! of Pinocchio's `H` (cyclic Jacobi eigenvalues of the stored CRBA, [`condition_number`]). The
//! form is the first-order bound on the forward error of a backward-stable solve of an `nv x nv`
//! system, `|δx| / |x| <= c nv ε κ` (Higham, *Accuracy and Stability of Numerical Algorithms*,
//! 2002, ch. 7 and 10); [`ABA_C`] `= 2` because both libraries round, each within one such bound,
//! and the two use different recursions (world-frame here, local-frame in Pinocchio). The
//! bound is loose for ill-conditioned robots (iCub, `κ` up to 4e12, stays within 3e-3 of it) and
//! reaches 0.9 of it on the 3-joint finger_edu (`κ` = 23, error 7.6e-15). Samples where `H` is
//! numerically singular (`nv ε κ(H) >= 1`: romeo's hands, whose finger links have neither mass
//! nor inertia) have no forward dynamics; Pinocchio's ABA returns NaN there and they are
//! counted, not compared.
//!
//! The three `alex_description` models are not in the repository (CC-BY-NC-ND). Point
//! [`ROBOTS_ENV`] at the installed `example-robot-data/robots` directory and [`REFERENCE_ENV`]
//! at a reference the script wrote from there (with `--robots`, `--only alex_description` and
//! `--out`): the case and the integration test then compare those models as well.

use std::io::Read;
use std::path::{Path, PathBuf};

use anim_core::cases::{Check, Ctx, Judge, nan_max};
use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::{Se3, Twist};
use serde_json::Value;

use crate::pinocchio::{from_pinocchio, idx_q as pin_idx_q, is_unbounded_revolute, nq as pin_nq};
use crate::{Data, JointType, Model, UrdfOptions, aba, compute_joint_jacobians, crba, parse_urdf, rnea};

/// Environment variable: a directory of URDFs (`.urdf` or `.urdf.gz`) laid out as
/// example-robot-data's `robots/`, compared with the reference in [`REFERENCE_ENV`].
pub const ROBOTS_ENV: &str = "ANIM_ROBOT_COLLECTION";
/// Environment variable: a reference directory written by the script's `--out`.
pub const REFERENCE_ENV: &str = "ANIM_ROBOT_COLLECTION_REFERENCE";
/// Samples per robot and base in the reference.
pub const SAMPLES: usize = 20;
/// Relative tolerance of FK, Jacobians, RNEA and CRBA (module documentation).
pub const TOLERANCE: f64 = 1e-13;
/// ABA passes when `e <= ABA_C · nv · ε · κ(H)`: two libraries, each within the first-order
/// forward-error bound `nv ε κ(H)` of a backward-stable solve (module documentation).
pub const ABA_C: f64 = 2.0;

/// The base a robot is mounted on.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Base {
    /// The root link welded to the world.
    Fixed,
    /// The root link carried by a free joint named `root_joint`.
    Floating,
}

impl Base {
    /// `fixed` or `floating`.
    #[must_use]
    pub fn label(self) -> &'static str {
        match self {
            Base::Fixed => "fixed",
            Base::Floating => "floating",
        }
    }
}

/// The worst relative errors of one robot and base over its samples (module documentation).
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Errors {
    /// Joint world placements.
    pub fk: f64,
    /// World Jacobian columns.
    pub jacobian: f64,
    /// RNEA torques.
    pub rnea: f64,
    /// CRBA upper triangle.
    pub crba: f64,
    /// ABA accelerations.
    pub aba: f64,
    /// The worst ABA error in units of `nv ε κ(H)` of its sample (passes at most [`ABA_C`]).
    pub aba_per_cond: f64,
    /// The largest `κ(H)` over the samples where `H` is not numerically singular.
    pub cond: f64,
    /// Samples where `H` is numerically singular (`nv ε κ(H) >= 1`: a subtree without mass or
    /// inertia), where forward dynamics is undefined and ABA is not compared.
    pub singular: usize,
    /// Of those, the samples where this crate's ABA still returned finite numbers.
    pub singular_finite: usize,
    /// Of those, the samples where Pinocchio's ABA returned finite numbers.
    pub singular_reference_finite: usize,
}

impl Errors {
    /// The quantities, in the order of [`Errors::values`].
    pub const NAMES: [&'static str; 6] =
        ["FK oMi", "Jacobians data.J", "RNEA tau", "CRBA H", "ABA q''", "ABA q'' / (nv eps cond(H))"];

    /// The errors named by [`Errors::NAMES`].
    #[must_use]
    pub fn values(&self) -> [f64; 6] {
        [self.fk, self.jacobian, self.rnea, self.crba, self.aba, self.aba_per_cond]
    }

    /// Whether every quantity is within its tolerance (false on NaN).
    #[must_use]
    pub fn pass(&self) -> bool {
        [self.fk, self.jacobian, self.rnea, self.crba].iter().all(|&e| e <= TOLERANCE)
            && self.aba_per_cond <= ABA_C
    }
}

/// What happened to one entry of the reference.
#[derive(Debug, Clone, PartialEq)]
pub enum Outcome {
    /// Loaded with Pinocchio's layout and compared on `samples` samples.
    Compared {
        /// Samples compared.
        samples: usize,
        /// The worst errors.
        errors: Errors,
        /// `nv` of the model.
        nv: usize,
    },
    /// Pinocchio refused the URDF (its message); `ours` is what this crate does with it: the
    /// model's `(nq, nv)` when it loads it, its error when it refuses it too.
    RefusedByPinocchio {
        /// Pinocchio's message.
        pinocchio: String,
        /// This crate's outcome.
        ours: Result<(usize, usize), String>,
    },
    /// This crate refused the URDF, built another layout, or the reference is malformed.
    Failed(String),
}

/// One robot and base of the reference.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelResult {
    /// The URDF's path in the collection (`ur_description/urdf/ur5_robot.urdf`).
    pub urdf: String,
    /// The base (`None` for a URDF Pinocchio refused).
    pub base: Option<Base>,
    /// The outcome.
    pub outcome: Outcome,
}

/// The committed URDFs (`testdata/robots`).
#[must_use]
pub fn committed_robots() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata").join("robots")
}

/// The committed reference (`testdata/pinocchio_collection`).
#[must_use]
pub fn committed_reference() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("testdata").join("pinocchio_collection")
}

/// The reference directories given by [`ROBOTS_ENV`] and [`REFERENCE_ENV`], when both are set.
#[must_use]
pub fn external() -> Option<(PathBuf, PathBuf)> {
    let robots = std::env::var_os(ROBOTS_ENV)?;
    let reference = std::env::var_os(REFERENCE_ENV)?;
    Some((PathBuf::from(robots), PathBuf::from(reference)))
}

fn gunzip(path: &Path) -> Result<Vec<u8>, String> {
    let file = std::fs::File::open(path).map_err(|e| format!("{}: {e}", path.display()))?;
    let mut out = Vec::new();
    flate2::read::GzDecoder::new(file)
        .read_to_end(&mut out)
        .map_err(|e| format!("{}: {e}", path.display()))?;
    Ok(out)
}

/// Loads `urdf` (`<dir>/<urdf>.gz`, else `<dir>/<urdf>`); errors name the file.
pub fn load_robot(robots: &Path, urdf: &str, base: Base) -> Result<Model, String> {
    let gz = robots.join(format!("{urdf}.gz"));
    let (path, text) = if gz.exists() {
        let bytes = gunzip(&gz)?;
        (gz.clone(), String::from_utf8(bytes).map_err(|e| format!("{}: {e}", gz.display()))?)
    } else {
        let path = robots.join(urdf);
        let text = std::fs::read_to_string(&path).map_err(|e| format!("{}: {e}", path.display()))?;
        (path, text)
    };
    let options = UrdfOptions::default().floating_base(base == Base::Floating);
    parse_urdf(&text, &options).map_err(|mut e| {
        e.file = path.strip_prefix(robots).unwrap_or(&path).display().to_string();
        e.to_string()
    })
}

/// Pinocchio's joint type (`JointModelRX`, `JointModelRUBZ`, ...) as a family of this crate's.
fn pinocchio_family(kind: &str) -> &'static str {
    let k = kind.strip_prefix("JointModel").unwrap_or(kind);
    if k == "FreeFlyer" {
        "free"
    } else if k == "Planar" {
        "planar"
    } else if k.starts_with("Spherical") {
        "spherical"
    } else if k.starts_with("RUB") || k.starts_with("RevoluteUnbounded") {
        "unbounded revolute"
    } else if k.starts_with('R') {
        "revolute"
    } else if k.starts_with('P') {
        "prismatic"
    } else {
        "unknown"
    }
}

fn our_family(model: &Model, j: usize) -> &'static str {
    let joint = model.joint(j);
    match joint.kind {
        JointType::Revolute(_) if is_unbounded_revolute(joint) => "unbounded revolute",
        JointType::Revolute(_) => "revolute",
        JointType::Prismatic(_) => "prismatic",
        JointType::Free => "free",
        JointType::Planar(_) => "planar",
        JointType::Spherical => "spherical",
        JointType::Fixed => "fixed",
    }
}

fn usize_of(v: &Value) -> Option<usize> {
    v.as_u64().and_then(|x| usize::try_from(x).ok())
}

/// The motion subspace columns of every joint, from the header, after checking that `model`
/// has Pinocchio's layout.
fn check_layout(model: &Model, entry: &Value) -> Result<Vec<Vec<Twist>>, String> {
    let joints = entry["joints"].as_array().ok_or("no joints in the header")?;
    let (nq, nv) = (usize_of(&entry["nq"]), usize_of(&entry["nv"]));
    if joints.len() + 1 != model.njoints() || nq != Some(pin_nq(model)) || nv != Some(model.nv()) {
        return Err(format!(
            "layout differs: Pinocchio has {} joints, nq = {nq:?}, nv = {nv:?}; here {} joints, nq = {} (Pinocchio layout), nv = {}",
            joints.len() + 1,
            model.njoints(),
            pin_nq(model),
            model.nv()
        ));
    }
    let mut subspaces = Vec::with_capacity(joints.len());
    for (k, h) in joints.iter().enumerate() {
        let j = k + 1;
        let ours = model.joint(j);
        let name = h[0].as_str().unwrap_or("");
        let kind = h[1].as_str().unwrap_or("");
        let expected = [usize_of(&h[2]), usize_of(&h[3]), usize_of(&h[4]), usize_of(&h[6])];
        let got = [Some(ours.parent), Some(pin_idx_q(model, j)), Some(ours.idx_v), Some(ours.nv())];
        if ours.name != name || pinocchio_family(kind) != our_family(model, j) || expected != got {
            return Err(format!(
                "joint {j}: Pinocchio has '{name}' ({kind}, parent, idx_q, idx_v, nv = {expected:?}), here '{}' ({}, {got:?})",
                ours.name,
                our_family(model, j)
            ));
        }
        let mut columns = Vec::new();
        for s in h[7].as_array().into_iter().flatten() {
            let s: Vec<f64> = s.as_array().into_iter().flatten().filter_map(Value::as_f64).collect();
            if s.len() != 6 {
                return Err(format!("joint {j}: a motion subspace column of {} entries", s.len()));
            }
            columns.push(Twist::new(DVec3::new(s[0], s[1], s[2]), DVec3::new(s[3], s[4], s[5])));
        }
        if columns.len() != ours.nv() {
            return Err(format!(
                "joint {j}: {} motion subspace columns for nv = {}",
                columns.len(),
                ours.nv()
            ));
        }
        subspaces.push(columns);
    }
    Ok(subspaces)
}

/// Reads consecutive runs of a sample file.
struct Cursor {
    values: Vec<f64>,
    at: usize,
}

impl Cursor {
    fn take(&mut self, n: usize) -> Result<&[f64], String> {
        let run = self.values.get(self.at..self.at + n).ok_or("the data file is too short")?;
        self.at += n;
        Ok(run)
    }
}

/// A placement stored as the rotation row by row, then the translation.
fn se3(a: &[f64]) -> Se3 {
    let r = DMat3::from_cols(
        DVec3::new(a[0], a[3], a[6]),
        DVec3::new(a[1], a[4], a[7]),
        DVec3::new(a[2], a[5], a[8]),
    );
    Se3::new(r, DVec3::new(a[9], a[10], a[11]))
}

/// `max |ours - reference| / max(1, max |reference|)` (NaN on a NaN entry).
fn rel_err(ours: &[f64], reference: &[f64]) -> f64 {
    if ours.len() != reference.len() {
        return f64::NAN;
    }
    let scale = reference.iter().fold(1.0_f64, |m, x| nan_max(m, x.abs()));
    ours.iter().zip(reference).fold(0.0_f64, |m, (a, b)| nan_max(m, (a - b).abs())) / scale
}

fn push_se3(out: &mut Vec<f64>, m: &Se3) {
    out.extend_from_slice(&m.rotation.transpose().to_cols_array());
    out.extend_from_slice(&m.translation.to_array());
}

fn push_twist(out: &mut Vec<f64>, t: &Twist) {
    out.extend_from_slice(&t.v.to_array());
    out.extend_from_slice(&t.w.to_array());
}

/// The 2-norm condition number of the symmetric positive definite `h` (n x n, row-major),
/// from its eigenvalues by cyclic Jacobi rotations (Golub & Van Loan, sec. 8.5). `h` is
/// overwritten.
#[must_use]
pub fn condition_number(h: &mut [f64], n: usize) -> f64 {
    for _ in 0..64 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| h[i * n + j].powi(2))
            .sum();
        let diag: f64 = (0..n).map(|i| h[i * n + i].powi(2)).sum();
        if off <= 1e-32 * diag {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = h[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let theta = (h[q * n + q] - h[p * n + p]) / (2.0 * apq);
                let t = if theta == 0.0 {
                    1.0
                } else {
                    theta.signum() / (theta.abs() + theta.mul_add(theta, 1.0).sqrt())
                };
                let c = 1.0 / t.mul_add(t, 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (kp, kq) = (h[k * n + p], h[k * n + q]);
                    h[k * n + p] = c * kp - s * kq;
                    h[k * n + q] = s * kp + c * kq;
                }
                for k in 0..n {
                    let (pk, qk) = (h[p * n + k], h[q * n + k]);
                    h[p * n + k] = c * pk - s * qk;
                    h[q * n + k] = s * pk + c * qk;
                }
            }
        }
    }
    let (lo, hi) = (0..n).fold((f64::INFINITY, 0.0_f64), |(lo, hi), i| {
        let e = h[i * n + i];
        (lo.min(e), hi.max(e))
    });
    if n == 0 {
        1.0
    } else if lo > 0.0 {
        hi / lo
    } else {
        f64::INFINITY
    }
}

/// What the floating-base samples of the same robot take from its fixed-base samples: `oMi`
/// of every joint and the upper triangle of `H`, per sample.
#[derive(Default)]
struct FixedReference {
    urdf: String,
    placements: Vec<Vec<Se3>>,
    triangles: Vec<Vec<f64>>,
}

/// Compares one robot and base on its first `samples` samples.
fn compare_model(
    model: &Model,
    entry: &Value,
    reference: &Path,
    samples: usize,
    base: Base,
    fixed: &mut FixedReference,
) -> Result<(usize, Errors), String> {
    let subspaces = check_layout(model, entry)?;
    let file = entry["data"].as_str().ok_or("no data file in the header")?;
    let bytes = gunzip(&reference.join(file))?;
    if bytes.len() % 8 != 0 {
        return Err(format!("{file}: {} bytes is not a whole number of f64", bytes.len()));
    }
    let values = bytes
        .chunks_exact(8)
        .map(|b| f64::from_le_bytes([b[0], b[1], b[2], b[3], b[4], b[5], b[6], b[7]]))
        .collect();
    let mut cur = Cursor { values, at: 0 };
    let (nqp, nv, nj) = (pin_nq(model), model.nv(), model.njoints());
    let stored = usize_of(&entry["samples"]).ok_or("no sample count in the header")?;
    let samples = samples.min(stored);
    if base == Base::Floating
        && (fixed.urdf != entry["urdf"].as_str().unwrap_or("") || fixed.placements.len() < samples)
    {
        return Err("the floating-base entry does not follow its fixed-base entry".into());
    }
    if base == Base::Fixed {
        *fixed = FixedReference {
            urdf: entry["urdf"].as_str().unwrap_or("").to_string(),
            ..FixedReference::default()
        };
    }
    let mut data = Data::new(model);
    let mut e = Errors::default();
    let (mut ours, mut refs) = (Vec::new(), Vec::new());
    for s in 0..samples {
        let q_pin = cur.take(nqp)?.to_vec();
        let v = cur.take(nv)?.to_vec();
        let a = cur.take(nv)?.to_vec();
        let tau = cur.take(nv)?.to_vec();
        let q = from_pinocchio(model, &q_pin).map_err(|x| format!("sample {s}: {x}"))?;
        // Reference placements and the upper triangle of H.
        let (placements, triangle, rnea_ref, aba_ref);
        match base {
            Base::Fixed => {
                placements = (1..nj).map(|_| cur.take(12).map(se3)).collect::<Result<Vec<_>, _>>()?;
                rnea_ref = cur.take(nv)?.to_vec();
                triangle = cur.take(nv * (nv + 1) / 2)?.to_vec();
                aba_ref = cur.take(nv)?.to_vec();
                fixed.placements.push(placements.clone());
                fixed.triangles.push(triangle.clone());
            }
            Base::Floating => {
                let root = se3(cur.take(12)?);
                placements =
                    std::iter::once(root).chain(fixed.placements[s].iter().map(|m| root * *m)).collect();
                rnea_ref = cur.take(nv)?.to_vec();
                let rows = cur.take((0..6.min(nv)).map(|r| nv - r).sum())?.to_vec();
                let mut t = rows;
                t.extend_from_slice(&fixed.triangles[s]);
                triangle = t;
                aba_ref = cur.take(nv)?.to_vec();
            }
        }
        if placements.len() + 1 != nj || triangle.len() != nv * (nv + 1) / 2 {
            return Err("the floating base does not extend the fixed base".into());
        }
        compute_joint_jacobians(model, &mut data, &q);
        // FK.
        ours.clear();
        refs.clear();
        for (j, m) in placements.iter().enumerate() {
            push_se3(&mut ours, &data.world_placements[j + 1]);
            push_se3(&mut refs, m);
        }
        e.fk = nan_max(e.fk, rel_err(&ours, &refs));
        // Jacobian columns: Ad(oMi) S of Pinocchio's oMi and S.
        ours.clear();
        refs.clear();
        for (j, m) in placements.iter().enumerate() {
            for (k, s) in subspaces[j].iter().enumerate() {
                push_twist(&mut ours, &data.jacobian.column(model.joint(j + 1).idx_v + k));
                push_twist(&mut refs, &m.adjoint(*s));
            }
        }
        e.jacobian = nan_max(e.jacobian, rel_err(&ours, &refs));
        e.rnea = nan_max(e.rnea, rel_err(rnea(model, &mut data, &q, &v, &a), &rnea_ref));
        let h = crba(model, &mut data, &q);
        ours.clear();
        for i in 0..nv {
            ours.extend_from_slice(&h.row(i)[i..]);
        }
        e.crba = nan_max(e.crba, rel_err(&ours, &triangle));
        let mut full = vec![0.0; nv * nv];
        let mut k = 0;
        for i in 0..nv {
            for j in i..nv {
                full[i * nv + j] = triangle[k];
                full[j * nv + i] = triangle[k];
                k += 1;
            }
        }
        let cond = condition_number(&mut full, nv);
        let ddq = aba(model, &mut data, &q, &v, &tau);
        if cond * nv as f64 * f64::EPSILON >= 1.0 {
            // Numerically singular H: forward dynamics is not defined, nothing to compare.
            e.singular += 1;
            e.singular_finite += usize::from(ddq.iter().all(|x| x.is_finite()));
            e.singular_reference_finite += usize::from(aba_ref.iter().all(|x| x.is_finite()));
            continue;
        }
        let err = rel_err(ddq, &aba_ref);
        e.aba = nan_max(e.aba, err);
        e.cond = nan_max(e.cond, cond);
        if nv > 0 {
            e.aba_per_cond = nan_max(e.aba_per_cond, err / (nv as f64 * f64::EPSILON * cond));
        }
    }
    if base == Base::Fixed {
        // The floating base reads the rest of the fixed-base samples too.
        for _ in samples..stored {
            let _ = cur.take(nqp + 3 * nv)?;
            let p = (1..nj).map(|_| cur.take(12).map(se3)).collect::<Result<Vec<_>, _>>()?;
            let _ = cur.take(nv)?;
            let t = cur.take(nv * (nv + 1) / 2)?.to_vec();
            let _ = cur.take(nv)?;
            fixed.placements.push(p);
            fixed.triangles.push(t);
        }
    }
    Ok((samples, e))
}

/// Compares every robot and base of the reference in `reference` (its `index.json`), loading
/// the URDFs from `robots`, on the first `samples` samples of each.
///
/// # Errors
/// When `index.json` cannot be read; a robot that fails is a [`Outcome::Failed`] entry.
pub fn compare(robots: &Path, reference: &Path, samples: usize) -> Result<Vec<ModelResult>, String> {
    let index = reference.join("index.json");
    let text = std::fs::read_to_string(&index).map_err(|e| format!("{}: {e}", index.display()))?;
    let json: Value = serde_json::from_str(&text).map_err(|e| format!("{}: {e}", index.display()))?;
    let models = json["models"].as_array().ok_or_else(|| format!("{}: no models", index.display()))?;
    let mut fixed = FixedReference::default();
    let mut out = Vec::new();
    for entry in models {
        let urdf = entry["urdf"].as_str().unwrap_or("").to_string();
        if let Some(message) = entry["refused"].as_str() {
            let ours = load_robot(robots, &urdf, Base::Fixed).map(|m| (m.nq(), m.nv()));
            out.push(ModelResult {
                urdf,
                base: None,
                outcome: Outcome::RefusedByPinocchio { pinocchio: message.to_string(), ours },
            });
            continue;
        }
        let base = if entry["base"].as_str() == Some("floating") { Base::Floating } else { Base::Fixed };
        let outcome = match load_robot(robots, &urdf, base).and_then(|model| {
            compare_model(&model, entry, reference, samples, base, &mut fixed).map(|r| (r, model.nv()))
        }) {
            Ok(((samples, errors), nv)) => Outcome::Compared { samples, errors, nv },
            Err(e) => Outcome::Failed(e),
        };
        out.push(ModelResult { urdf, base: Some(base), outcome });
    }
    Ok(out)
}

const SOURCE: &str = "Pinocchio 4.1.0 via crates/anim-rigid/testdata/make_pinocchio_collection_reference.py";

/// The conformance case: the committed collection (and the external one when [`ROBOTS_ENV`]
/// and [`REFERENCE_ENV`] are set), all [`SAMPLES`] samples, also with `--quick` (about 2 s in the
/// test profile).
pub(super) fn pinocchio_collection(_: &Ctx) -> Vec<Check> {
    let samples = SAMPLES;
    let mut sets = vec![("example-robot-data collection", committed_robots(), committed_reference())];
    if let Some((robots, reference)) = external() {
        sets.push(("external collection", robots, reference));
    }
    let mut out = Vec::new();
    for (set, robots, reference) in sets {
        match compare(&robots, &reference, samples) {
            Ok(results) => out.extend(checks(set, &results)),
            Err(e) => out.push(Check::could_not_run(super::CRATE, set, &e)),
        }
    }
    out
}

fn checks(set: &str, results: &[ModelResult]) -> Vec<Check> {
    let mut out = Vec::new();
    let mut worst: [(f64, String); 6] = std::array::from_fn(|_| (0.0, String::new()));
    let (mut compared, mut max_cond) = (0, (0.0_f64, String::new()));
    let (mut singular, mut singular_finite, mut singular_models) = (0, [0, 0], Vec::new());
    for r in results {
        let who = format!("{} ({})", r.urdf, r.base.map_or("", Base::label));
        match &r.outcome {
            Outcome::Compared { errors, .. } => {
                compared += 1;
                for (w, e) in worst.iter_mut().zip(errors.values()) {
                    if e.is_nan() || e > w.0 {
                        *w = (e, who.clone());
                    }
                }
                if errors.cond > max_cond.0 {
                    max_cond = (errors.cond, who.clone());
                }
                if errors.singular > 0 {
                    singular += errors.singular;
                    singular_finite[0] += errors.singular_finite;
                    singular_finite[1] += errors.singular_reference_finite;
                    singular_models.push(who.clone());
                }
            }
            Outcome::RefusedByPinocchio { pinocchio, ours } => {
                let ours = match ours {
                    Ok((nq, nv)) => format!("anim-rigid loads it (nq = {nq}, nv = {nv})"),
                    Err(e) => format!("anim-rigid refuses it too: {e}"),
                };
                out.push(super::check(
                    &format!("{set}: {}", r.urdf),
                    &format!("Pinocchio refuses it ({}); {ours}", pinocchio.lines().next().unwrap_or("")),
                    0.0,
                    0.0,
                    Judge::AtMost,
                    SOURCE,
                ));
            }
            Outcome::Failed(e) => out.push(Check::could_not_run(super::CRATE, format!("{set}: {who}"), e)),
        }
    }
    let case = format!("{set}: {compared} models (robots x bases) vs Pinocchio");
    for (k, (name, (e, who))) in Errors::NAMES.iter().zip(&worst).enumerate() {
        let (metric, tolerance) = if k == 5 {
            (
                format!(
                    "worst {name} (at {who}; ABA tolerance {ABA_C} nv eps cond(H); largest cond(H) {:.2e} at {})",
                    max_cond.0, max_cond.1
                ),
                ABA_C,
            )
        } else if k == 4 {
            (
                format!(
                    "worst relative error of {name} (at {who}), judged against cond(H) below; not compared on {singular} samples with a singular H (massless subtrees: {}), where ABA is finite on {} of them here and on {} in Pinocchio",
                    singular_models.join(", "),
                    singular_finite[0],
                    singular_finite[1]
                ),
                f64::INFINITY,
            )
        } else {
            (format!("worst relative error of {name} (at {who})"), TOLERANCE)
        };
        out.push(super::check(&case, &metric, *e, tolerance, Judge::AtMost, SOURCE));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::{
        Base, FixedReference, committed_reference, committed_robots, compare_model, condition_number,
        load_robot,
    };
    use crate::{UrdfOptions, load_urdf};
    use serde_json::Value;

    /// The comparison catches a model that differs from Pinocchio's: gravity off by 1e-3
    /// relative (RNEA), and another joint layout (fixed joints kept as joints).
    #[test]
    fn a_different_model_fails() {
        let reference = committed_reference();
        let text = std::fs::read_to_string(reference.join("index.json")).unwrap();
        let json: Value = serde_json::from_str(&text).unwrap();
        let urdf = "ur_description/urdf/ur5_robot.urdf";
        let entry = json["models"]
            .as_array()
            .unwrap()
            .iter()
            .find(|e| e["urdf"] == urdf && e["base"] == "fixed")
            .unwrap();
        let mut model = load_robot(&committed_robots(), urdf, Base::Fixed).unwrap();
        let mut fixed = FixedReference::default();
        let (_, e) = compare_model(&model, entry, &reference, 3, Base::Fixed, &mut fixed).unwrap();
        assert!(e.pass(), "{e:?}");
        model.set_gravity(anim_core::glam::DVec3::new(0.0, 0.0, -9.8));
        let (_, e) = compare_model(&model, entry, &reference, 3, Base::Fixed, &mut fixed).unwrap();
        assert!(e.rnea > 1e-4 && e.fk == 0.0 && !e.pass(), "{e:?}");
        let path = committed_robots().join("../ur5_robot.urdf");
        let unmerged = load_urdf(path, &UrdfOptions::default().merge_fixed_joints(false)).unwrap();
        let err = compare_model(&unmerged, entry, &reference, 3, Base::Fixed, &mut fixed).unwrap_err();
        assert!(err.contains("layout differs"), "{err}");
    }

    #[test]
    fn jacobi_condition_number_of_a_rotated_diagonal() {
        // Q diag(1, 4, 100) Q^T with Q a rotation about (1, 1, 1)/sqrt(3) by 0.7 rad.
        let r = anim_core::lie::so3::exp(anim_core::glam::DVec3::splat(0.7 / 3f64.sqrt()));
        let d = anim_core::glam::DMat3::from_diagonal(anim_core::glam::DVec3::new(1.0, 4.0, 100.0));
        let m = r * d * r.transpose();
        let mut h: Vec<f64> = (0..9).map(|k| m.col(k % 3)[k / 3]).collect();
        let c = condition_number(&mut h, 3);
        assert!((c - 100.0).abs() < 1e-11, "{c}");
    }
}
