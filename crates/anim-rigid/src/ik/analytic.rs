//! Analytic inverse kinematics of 6R arms by the Paden-Kahan subproblems (Murray,
//! Li & Sastry ch. 3.3).
//!
//! The target `g_d` of the tool frame gives `g₁ = g_d M⁻¹ = e^{ξ̂₁θ₁} ··· e^{ξ̂₆θ₆}` (space
//! form, [`crate::PoeChain`]). Points on joint axes are fixed by those joints, which peels the
//! product apart.
//!
//! # Spherical wrist (PUMA-like): axes 1, 2 meet at `p_s`; axes 4, 5, 6 meet at `p_w`
//!
//! 1. `e^{ξ̂₁θ₁}e^{ξ̂₂θ₂}e^{ξ̂₃θ₃} p_w = g₁ p_w` and rotations 1, 2 keep distances to `p_s`:
//!    `‖e^{ξ̂₃θ₃} p_w - p_s‖ = ‖g₁ p_w - p_s‖` is **subproblem 3** for `θ₃` (elbow up/down).
//! 2. `e^{ξ̂₁θ₁}e^{ξ̂₂θ₂} (e^{ξ̂₃θ₃} p_w) = g₁ p_w` is **subproblem 2** for `θ₁, θ₂` (left/right
//!    shoulder).
//! 3. With `g₂ = (e^{ξ̂₁θ₁}e^{ξ̂₂θ₂}e^{ξ̂₃θ₃})⁻¹ g₁ = e^{ξ̂₄θ₄}e^{ξ̂₅θ₅}e^{ξ̂₆θ₆}` and `p` on axis
//!    6 off `p_w`: `e^{ξ̂₄θ₄}e^{ξ̂₅θ₅} p = g₂ p` is **subproblem 2** for `θ₄, θ₅` (wrist flip).
//! 4. `e^{ξ̂₆θ₆} p' = (e^{ξ̂₄θ₄}e^{ξ̂₅θ₅})⁻¹ g₂ p'` for `p'` off axis 6 is **subproblem 1**.
//!
//! # UR type: axes 2, 3, 4 parallel; axes 5 and 6 meet at `p₅₆`
//!
//! 1. Rotations 2-4 are a planar motion that keeps `ω₂ᵀx`, and 5, 6 fix `p₅₆`: so
//!    `ω₂ᵀ(e^{-ξ̂₁θ₁} g₁ p₅₆) = ω₂ᵀ p₅₆`, a point rotated onto a plane
//!    ([`crate::paden_kahan::subproblem_plane`]) for `θ₁` (shoulder left/right).
//! 2. Directions: `ω₂ᵀ R₁ᵀ R_{g₁} ω₆ = ω₂ᵀ e^{ω̂₅θ₅} ω₆`, the same plane problem for `θ₅` (wrist
//!    up/down).
//! 3. `e^{ω̂₆θ₆} (R_{g₁}ᵀ R₁ ω₂) = e^{-ω̂₅θ₅} ω₂` is **subproblem 1** (on directions) for `θ₆`.
//! 4. The planar 3R remainder `g₂₃₄ = e^{-ξ̂₁θ₁} g₁ e^{-ξ̂₆θ₆} e^{-ξ̂₅θ₅}`: **subproblem 3** on a
//!    point of axis 4 for `θ₃` (elbow), then **subproblem 1** for `θ₂` and for `θ₄`.
//!
//! This is the standard UR closed form (Hawkins 2013) written with screws, so it needs no DH
//! table: the axes come from the URDF.
//!
//! # What is returned
//!
//! Every branch that exists, up to 8, angles in `(-π, π]` (add `±2π` where the limits allow; the
//! UR5's do). Each candidate is checked by forward kinematics and kept only if it reproduces the
//! target to [`AnalyticIk::verify_tol`]. At a singularity a subproblem has infinitely many
//! solutions (wrist aligned: `θ₄ + θ₆` fixed; UR wrist: `θ₆` free; shoulder over the base):
//! the free angle is set to `0` and the solution is flagged [`IkSolution::singular`]. An
//! unreachable target gives an empty list; use [`crate::ik::NumericalIk`] for the closest pose.

use anim_core::glam::DVec3;
use anim_core::lie::{Se3, so3};
use thiserror::Error;

use crate::config::neutral;
use crate::data::Data;
use crate::ik::pose::pose_error;
use crate::kinematics::frames_forward_kinematics;
use crate::model::{FrameIndex, JointType, Model};
use crate::paden_kahan::{
    DEFAULT_TOL, Sp1, Sp2, Sp3, rotate_about, subproblem_plane, subproblem1, subproblem2, subproblem3,
    wrap_angle,
};
use crate::poe::PoeChain;

/// Geometry tolerance (m or unitless) for recognising intersecting and parallel axes.
const GEOMETRY_TOL: f64 = 1e-9;

/// Why an [`AnalyticIk`] cannot be built for a frame.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum IkError {
    /// The chain does not consist of exactly six revolute joints.
    #[error(
        "frame '{frame}': analytic IK needs a chain of 6 revolute joints, this one has {found} moving joints ({kinds})"
    )]
    NotSixRevolute {
        /// The frame.
        frame: String,
        /// Number of moving joints found.
        found: usize,
        /// Their kinds.
        kinds: String,
    },
    /// The axes fit neither supported geometry.
    #[error("frame '{frame}': the axes fit neither a spherical wrist ({spherical}) nor a UR-type arm ({ur})")]
    UnsupportedGeometry {
        /// The frame.
        frame: String,
        /// Why the spherical-wrist solver does not apply.
        spherical: String,
        /// Why the UR-type solver does not apply.
        ur: String,
    },
}

/// Which closed form an [`AnalyticIk`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum AnalyticIkKind {
    /// Axes 1, 2 intersect; axes 4, 5, 6 intersect (PUMA-like).
    SphericalWrist,
    /// Axes 2, 3, 4 parallel; axes 5, 6 intersect (Universal Robots).
    UrType,
}

/// One inverse-kinematics solution.
#[derive(Debug, Clone, PartialEq)]
pub struct IkSolution {
    /// The full configuration (length `nq`): the chain's joints solved, every other entry at
    /// its neutral value.
    pub q: Vec<f64>,
    /// `max(position error, rotation angle)` of `world_M_f(q)` against the target.
    pub residual: f64,
    /// Whether every joint is within its limits.
    pub within_limits: bool,
    /// Whether a subproblem had infinitely many solutions (a singular configuration); the free
    /// angle was set to `0`.
    pub singular: bool,
}

/// The rigid motion of the rotation by `theta` about the line through `r` along unit `w`.
fn rotation_about(w: DVec3, r: DVec3, theta: f64) -> Se3 {
    let rot = so3::exp(w * theta);
    Se3::new(rot, r - rot * r)
}

/// The closest points of the lines `r1 + s w1` and `r2 + t w2` (unit directions): their
/// midpoint and distance, or `None` for parallel lines.
fn line_intersection(w1: DVec3, r1: DVec3, w2: DVec3, r2: DVec3) -> Option<(DVec3, f64)> {
    let n = w1.cross(w2);
    let n2 = n.length_squared();
    if n2 < 1e-12 {
        return None;
    }
    let d = r2 - r1;
    let s = d.cross(w2).dot(n) / n2;
    let t = d.cross(w1).dot(n) / n2;
    let (a, b) = (r1 + w1 * s, r2 + w2 * t);
    Some(((a + b) * 0.5, (a - b).length()))
}

fn distance_to_line(w: DVec3, r: DVec3, p: DVec3) -> f64 {
    let d = p - r;
    (d - w * w.dot(d)).length()
}

/// A unit vector normal to the unit `w`.
fn any_normal(w: DVec3) -> DVec3 {
    let a = if w.x.abs() < 0.9 { DVec3::X } else { DVec3::Y };
    w.cross(a).normalize()
}

#[derive(Debug, Clone, PartialEq)]
enum Geometry {
    Spherical { shoulder: DVec3, wrist: DVec3 },
    Ur { p56: DVec3 },
}

/// Closed-form inverse kinematics for one frame of a 6R arm (see the [module docs](self)).
#[derive(Debug, Clone, PartialEq)]
pub struct AnalyticIk {
    geometry: Geometry,
    home_inv: Se3,
    w: [DVec3; 6],
    r: [DVec3; 6],
    idx_q: [usize; 6],
    limits: [(f64, f64); 6],
    neutral: Vec<f64>,
    chain: PoeChain,
    tol: f64,
    /// Largest residual (m or rad) of a returned solution: `1e-9` by default.
    pub verify_tol: f64,
}

impl AnalyticIk {
    /// The solver for frame `frame` of `model`.
    ///
    /// # Errors
    /// When the chain to the frame is not six revolute joints, or its axes fit neither
    /// geometry.
    ///
    /// # Panics
    /// When `frame` is out of range.
    #[track_caller]
    pub fn new(model: &Model, frame: FrameIndex) -> Result<Self, IkError> {
        let frame_name = model.frame(frame).name.clone();
        let chain_joints: Vec<usize> = model
            .support(model.frame(frame).parent_joint)
            .into_iter()
            .filter(|&j| model.joint(j).kind.nv() > 0)
            .collect();
        // Six independent revolute joints: a coupled one does not count as its own.
        let revolute = chain_joints.iter().all(|&j| {
            matches!(model.joint(j).kind, JointType::Revolute(_)) && model.joint(j).mimic.is_none()
        });
        if chain_joints.len() != 6 || !revolute {
            return Err(IkError::NotSixRevolute {
                frame: frame_name,
                found: chain_joints.len(),
                kinds: chain_joints
                    .iter()
                    .map(|&j| model.joint(j).kind.name())
                    .collect::<Vec<_>>()
                    .join(", "),
            });
        }
        let mut data = Data::new(model);
        let q0 = neutral(model);
        frames_forward_kinematics(model, &mut data, &q0);
        let mut w = [DVec3::ZERO; 6];
        let mut r = [DVec3::ZERO; 6];
        let mut idx_q = [0; 6];
        let mut limits = [(0.0, 0.0); 6];
        for (k, &j) in chain_joints.iter().enumerate() {
            limits[k] = (model.joint(j).limits.lower, model.joint(j).limits.upper);
            let JointType::Revolute(axis) = model.joint(j).kind else { unreachable!("checked above") };
            let g = data.world_placements[j];
            w[k] = (g.rotation * axis.vector()).normalize();
            r[k] = g.translation;
            idx_q[k] = model.joint(j).idx_q;
        }
        let spherical = Self::spherical_geometry(&w, &r);
        let geometry = match spherical {
            Ok(g) => g,
            Err(why_not_spherical) => match Self::ur_geometry(&w, &r) {
                Ok(g) => g,
                Err(why_not_ur) => {
                    return Err(IkError::UnsupportedGeometry {
                        frame: frame_name,
                        spherical: why_not_spherical,
                        ur: why_not_ur,
                    });
                }
            },
        };
        Ok(Self {
            geometry,
            home_inv: data.frame_placements[frame].inverse(),
            w,
            r,
            idx_q,
            limits,
            neutral: q0,
            chain: PoeChain::new(model, frame),
            tol: DEFAULT_TOL,
            verify_tol: 1e-9,
        })
    }

    fn spherical_geometry(w: &[DVec3; 6], r: &[DVec3; 6]) -> Result<Geometry, String> {
        let (shoulder, d12) = line_intersection(w[0], r[0], w[1], r[1]).ok_or("axes 1 and 2 are parallel")?;
        if d12 > GEOMETRY_TOL {
            return Err(format!("axes 1 and 2 miss each other by {d12:.3e} m"));
        }
        let (wrist, d45) = line_intersection(w[3], r[3], w[4], r[4]).ok_or("axes 4 and 5 are parallel")?;
        if d45 > GEOMETRY_TOL {
            return Err(format!("axes 4 and 5 miss each other by {d45:.3e} m"));
        }
        let d6 = distance_to_line(w[5], r[5], wrist);
        if d6 > GEOMETRY_TOL {
            return Err(format!("axis 6 misses the wrist point by {d6:.3e} m"));
        }
        if w[4].cross(w[5]).length() < 1e-6 {
            return Err("axes 5 and 6 are parallel".into());
        }
        Ok(Geometry::Spherical { shoulder, wrist })
    }

    fn ur_geometry(w: &[DVec3; 6], r: &[DVec3; 6]) -> Result<Geometry, String> {
        for k in [2, 3] {
            let s = w[1].cross(w[k]).length();
            if s > GEOMETRY_TOL {
                return Err(format!("axes 2 and {} are not parallel (sin = {s:.3e})", k + 1));
            }
        }
        if w[0].cross(w[1]).length() < 1e-6 {
            return Err("axes 1 and 2 are parallel".into());
        }
        let (p56, d56) = line_intersection(w[4], r[4], w[5], r[5]).ok_or("axes 5 and 6 are parallel")?;
        if d56 > GEOMETRY_TOL {
            return Err(format!("axes 5 and 6 miss each other by {d56:.3e} m"));
        }
        if w[4].cross(w[1]).length() < 1e-6 {
            return Err("axis 5 is parallel to axes 2-4".into());
        }
        Ok(Geometry::Ur { p56 })
    }

    /// Which closed form this solver uses.
    #[must_use]
    pub fn kind(&self) -> AnalyticIkKind {
        match self.geometry {
            Geometry::Spherical { .. } => AnalyticIkKind::SphericalWrist,
            Geometry::Ur { .. } => AnalyticIkKind::UrType,
        }
    }

    /// Whether this is the spherical-wrist solver.
    #[must_use]
    pub fn is_spherical_wrist(&self) -> bool {
        matches!(self.geometry, Geometry::Spherical { .. })
    }

    fn e(&self, k: usize, theta: f64) -> Se3 {
        rotation_about(self.w[k], self.r[k], theta)
    }

    /// Every solution for the frame's world placement `target` (see the [module docs](self)).
    /// Empty when the target is out of reach.
    #[must_use]
    pub fn solve(&self, target: &Se3) -> Vec<IkSolution> {
        let g1 = *target * self.home_inv;
        let mut candidates: Vec<([f64; 6], bool)> = Vec::with_capacity(8);
        match self.geometry {
            Geometry::Spherical { shoulder, wrist } => {
                self.solve_spherical(&g1, shoulder, wrist, &mut candidates)
            }
            Geometry::Ur { p56 } => self.solve_ur(&g1, p56, &mut candidates),
        }
        let mut out: Vec<IkSolution> = Vec::with_capacity(candidates.len());
        for (angles, singular) in candidates {
            let mut q = self.neutral.clone();
            for k in 0..6 {
                q[self.idx_q[k]] = wrap_angle(angles[k]);
            }
            let (dp, dr) = pose_error(&self.chain.forward_space(&q), target);
            let residual = dp.max(dr);
            if !(residual <= self.verify_tol) {
                continue;
            }
            let duplicate =
                out.iter().any(|s| self.idx_q.iter().all(|&i| wrap_angle(s.q[i] - q[i]).abs() < 1e-9));
            if duplicate {
                continue;
            }
            let within = (0..6).all(|k| {
                let x = q[self.idx_q[k]];
                x >= self.limits[k].0 && x <= self.limits[k].1
            });
            out.push(IkSolution { q, residual, within_limits: within, singular });
        }
        out
    }

    fn solve_spherical(&self, g1: &Se3, shoulder: DVec3, wrist: DVec3, out: &mut Vec<([f64; 6], bool)>) {
        let (w, r, tol) = (&self.w, &self.r, self.tol);
        let q_w = g1.transform_point(wrist);
        let delta = (q_w - shoulder).length();
        let Some(sp3) = subproblem3(w[2], r[2], wrist, shoulder, delta, tol) else { return };
        let singular3 = sp3 == Sp3::Any;
        for t3 in sp3.solutions() {
            let p3 = rotate_about(w[2], r[2], t3, wrist);
            let Some(sp2) = subproblem2(w[0], w[1], shoulder, p3, q_w, tol) else { continue };
            let singular12 = matches!(sp2, Sp2::Degenerate { .. });
            for (t1, t2) in sp2.solutions() {
                let g123 = self.e(0, t1) * self.e(1, t2) * self.e(2, t3);
                let g2 = g123.inverse() * *g1;
                let p6 = wrist + w[5];
                let Some(sp2w) = subproblem2(w[3], w[4], wrist, p6, g2.transform_point(p6), tol) else {
                    continue;
                };
                let singular45 = matches!(sp2w, Sp2::Degenerate { .. });
                for (t4, t5) in sp2w.solutions() {
                    let g3 = (self.e(3, t4) * self.e(4, t5)).inverse() * g2;
                    let pp = wrist + any_normal(w[5]);
                    let Some(sp1) = subproblem1(w[5], wrist, pp, g3.transform_point(pp), tol) else {
                        continue;
                    };
                    let singular = singular3 || singular12 || singular45 || sp1 == Sp1::Any;
                    out.push(([t1, t2, t3, t4, t5, sp1.angle()], singular));
                }
            }
        }
    }

    fn solve_ur(&self, g1: &Se3, p56: DVec3, out: &mut Vec<([f64; 6], bool)>) {
        let (w, r, tol) = (&self.w, &self.r, self.tol);
        let q56 = g1.transform_point(p56);
        // θ₁: rotating q56 by φ = -θ₁ about axis 1 brings it onto the plane ω₂ᵀx = ω₂ᵀp56.
        let Some(sp_1) = subproblem_plane(w[0], r[0], q56, w[1], w[1].dot(p56), tol) else { return };
        let singular1 = sp_1 == Sp3::Any;
        for phi in sp_1.solutions() {
            let t1 = -phi;
            let r1 = so3::exp(w[0] * t1);
            let d5 = w[1].dot(r1.transpose() * (g1.rotation * w[5]));
            let Some(sp_5) = subproblem_plane(w[4], DVec3::ZERO, w[5], w[1], d5, tol) else { continue };
            let singular5 = sp_5 == Sp3::Any;
            for t5 in sp_5.solutions() {
                let a = g1.rotation.transpose() * (r1 * w[1]);
                let b = so3::exp(w[4] * -t5) * w[1];
                let Some(sp_6) = subproblem1(w[5], DVec3::ZERO, a, b, tol) else { continue };
                let t6 = sp_6.angle();
                let g234 = self.e(0, t1).inverse() * *g1 * self.e(5, t6).inverse() * self.e(4, t5).inverse();
                let q4 = g234.transform_point(r[3]);
                let delta = (q4 - r[1]).length();
                let Some(sp_3) = subproblem3(w[2], r[2], r[3], r[1], delta, tol) else { continue };
                for t3 in sp_3.solutions() {
                    let p4 = rotate_about(w[2], r[2], t3, r[3]);
                    let Some(sp_2) = subproblem1(w[1], r[1], p4, q4, tol) else { continue };
                    let t2 = sp_2.angle();
                    let g4 = (self.e(1, t2) * self.e(2, t3)).inverse() * g234;
                    let pp = r[3] + any_normal(w[3]);
                    let Some(sp_4) = subproblem1(w[3], r[3], pp, g4.transform_point(pp), tol) else {
                        continue;
                    };
                    let singular = singular1
                        || singular5
                        || sp_6 == Sp1::Any
                        || sp_3 == Sp3::Any
                        || sp_2 == Sp1::Any
                        || sp_4 == Sp1::Any;
                    out.push(([t1, t2, t3, sp_4.angle(), t5, t6], singular));
                }
            }
        }
    }
}
