//! Constraints as position based dynamics defines them (Müller et al. 2007): a cardinality `n_j`, a function
//! `C_j: R^{3 n_j} -> R`, an index set `{i_1, ..., i_{n_j}}`, a stiffness `k_j` in `[0, 1]` and a
//! type, equality (`C_j = 0`) or inequality (`C_j >= 0`); plus, for XPBD (Macklin et al. 2016), a compliance
//! `alpha_j >= 0` (the inverse stiffness, in SI units of `C^2 / J`) and a damping `beta_j >= 0`.
//!
//! # The functions
//!
//! | function | `C(x)` | cardinality | source |
//! | --- | --- | --- | --- |
//! | [`Distance`](ConstraintFunction::Distance) | `\|x_i - x_j\| - l` | 2 | Müller et al. 2007, eq. (10) |
//! | [`DihedralBending`](ConstraintFunction::DihedralBending) | `theta(x) - theta_0`, the signed angle between the two triangle normals | 4 | Müller et al. 2007, section 4.2; gradients of Bridson et al. 2003 |
//! | [`IsometricBending`](ConstraintFunction::IsometricBending) | `\|sum_i K_i x_i\| - r_0` with the cotangent weights `K_i` of Bergou et al. 2006 | 4 | Bergou et al. 2006; Bender, Müller and Macklin 2014 |
//! | [`TetVolume`](ConstraintFunction::TetVolume) | `V(x) - V_0`, `V = (x_1 - x_0) . ((x_2 - x_0) x (x_3 - x_0)) / 6` | 4 | Müller et al. 2007 (tetrahedral volume) |
//! | [`GlobalVolume`](ConstraintFunction::GlobalVolume) | `sum_t x_a . (x_b x x_c) / 6 - k_pressure V_0` over a closed mesh | all mesh vertices | Müller et al. 2007, section 4.4 (balloons) |
//! | [`Attachment`](ConstraintFunction::Attachment) | `\|x_i - t\| - d`, `t` a fixed point or a point of a moving kinematic body | 1 | Müller et al. 2007, section 3.3 (attachment) |
//!
//! Contacts (section 3.4 of Müller et al., line (8) of the loop) are generated each step by the
//! solver from the [colliders](crate::collide); they are inequality constraints
//! `C(p) = n . (p - q) - thickness >= 0` with the surface point `q` and normal `n` fixed when they
//! are generated.
//!
//! Every function here is invariant under rigid motions of its particles, except
//! [`Attachment`](ConstraintFunction::Attachment), whose target is external. So
//! `sum_i grad_i C = 0` and `sum_i x_i x grad_i C = 0`, and a projection
//! `dx_i = -s w_i grad_i C` changes neither linear nor angular momentum (Müller et al.'s remark on
//! ghost forces; checked in the tests and by `cargo xtask conformance`).
//!
//! # Isometric bending as one scalar constraint
//!
//! Bergou et al.'s energy for an inextensible surface with a flat rest shape is
//! `E = (1/2) k x^T Q x` with `Q = 3 / (A_0 + A_1) K K^T` on the stencil of an interior edge,
//! i.e. `E = (1/2) k |sum_i s K_i x_i|^2` with `s^2 = 3 / (A_0 + A_1)`. We write it as the scalar
//! constraint `C = |v| - |v_0|`, `v = sum_i s K_i x_i` ([`IsometricBending::weights`] holds
//! `s K_i`), with compliance `alpha = 1/k`: for a flat rest shape (`v_0 = 0`)
//! `(1/2) alpha^-1 C^2 = E` exactly. Unlike the library of Bender et al., which uses `C = E`
//! (whose gradient vanishes at the rest state), this `C` is linear along every ray from the rest
//! state, so one projection of an isolated stencil is exact, and it is rotation invariant, so it
//! conserves angular momentum. For a curved rest shape it keeps the magnitude of the rest
//! curvature vector (our extension; use dihedral bending when the rest shape is curved).
//!
//! # Degenerate configurations
//!
//! When a gradient is undefined (coincident distance endpoints, a zero-area triangle in a bending
//! stencil, a zero curvature vector), [`Constraint::evaluate`] reports it: a distance constraint
//! falls back to its rest direction (so coincident particles separate instead of producing NaN),
//! the others return a zero gradient and the solver skips them for that projection. Degenerate
//! *rest* shapes are rejected when the model is built ([`BuildError`](crate::BuildError)).

use anim_core::glam::DVec3;

/// Below this length a direction is undefined (about `1.5e-154`, `sqrt(f64::MIN_POSITIVE)`).
pub const MIN_LENGTH: f64 = 1.491_668_146_240_041_3e-154;

/// Equality (`C = 0`) or inequality (`C >= 0`), a constraint's "type" in PBD.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash, Default)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum ConstraintType {
    /// `C(x) = 0`.
    #[default]
    Equality,
    /// `C(x) >= 0`: projected only while violated; an XPBD multiplier stays `>= 0`.
    Inequality,
}

/// The stiffness, compliance and damping of a constraint.
///
/// PBD uses `stiffness` (Müller et al.'s `k` in `[0, 1]`); XPBD uses `compliance` and `damping`.
/// Both are stored so that one model runs under either method.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
#[non_exhaustive]
pub struct ConstraintParams {
    /// PBD stiffness `k` in `[0, 1]`. Default `1`.
    pub stiffness: f64,
    /// XPBD compliance `alpha >= 0`, the inverse stiffness in units of `C^2 / J` (m/N for a
    /// distance, rad^2/J for an angle, m^6/J for a volume). Default `0` (rigid).
    pub compliance: f64,
    /// XPBD damping `beta >= 0` (Macklin et al. 2016, eq. 26): the damping coefficient of the
    /// constraint's rate, force = `-beta dC/dt` along the gradient (N s/m for a distance); it
    /// acts through `gamma = alpha beta / h`, so a rigid constraint (`alpha = 0`) is undamped.
    /// Default `0`.
    pub damping: f64,
    /// Equality or inequality. Default equality.
    pub kind: ConstraintType,
}

impl Default for ConstraintParams {
    fn default() -> Self {
        Self { stiffness: 1.0, compliance: 0.0, damping: 0.0, kind: ConstraintType::Equality }
    }
}

impl ConstraintParams {
    /// A rigid equality constraint: `k = 1`, `alpha = 0`, no damping.
    #[must_use]
    pub fn rigid() -> Self {
        Self::default()
    }

    /// PBD stiffness `k` (compliance 0).
    #[must_use]
    pub fn with_stiffness(k: f64) -> Self {
        Self { stiffness: k, ..Self::default() }
    }

    /// XPBD compliance `alpha` (stiffness 1).
    #[must_use]
    pub fn with_compliance(alpha: f64) -> Self {
        Self { compliance: alpha, ..Self::default() }
    }

    /// Sets the PBD stiffness `k`.
    #[must_use]
    pub fn stiffness(mut self, k: f64) -> Self {
        self.stiffness = k;
        self
    }

    /// Sets the XPBD compliance `alpha`.
    #[must_use]
    pub fn compliance(mut self, alpha: f64) -> Self {
        self.compliance = alpha;
        self
    }

    /// Sets the XPBD damping `beta`.
    #[must_use]
    pub fn damping(mut self, beta: f64) -> Self {
        self.damping = beta;
        self
    }

    /// Makes the constraint an inequality `C >= 0`.
    #[must_use]
    pub fn inequality(mut self) -> Self {
        self.kind = ConstraintType::Inequality;
        self
    }
}

/// What an attachment holds its particle to.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum AttachTarget {
    /// A fixed point in world space.
    Point([f64; 3]),
    /// A point given in the local frame of a kinematic body; it moves with the body.
    Body {
        /// Kinematic body index.
        body: usize,
        /// The point in the body's frame.
        local: [f64; 3],
    },
}

/// The isometric bending stencil (see the module docs).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct IsometricBending {
    /// `[p0, p1, p2, p3]`: `p2, p3` the shared edge, `p0` and `p1` the opposite vertices.
    pub particles: [usize; 4],
    /// `s K_i` for the four particles: the cotangent weights of Bergou et al. scaled by
    /// `s = sqrt(3 / (A_0 + A_1))`; they sum to zero.
    pub weights: [f64; 4],
    /// `|v_0|`, the rest curvature magnitude (0 for a flat rest shape).
    pub rest: f64,
}

/// The function `C_j` and its index set.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum ConstraintFunction {
    /// `C = |x_i - x_j| - rest_length`.
    Distance {
        /// The two particles.
        particles: [usize; 2],
        /// Rest length `l >= 0`.
        rest_length: f64,
    },
    /// `C = theta - rest_angle`, `theta` in `(-pi, pi]` the signed dihedral angle of the
    /// triangles `(p0, p2, p3)` and `(p1, p3, p2)` across the edge `(p2, p3)` (0 when flat).
    DihedralBending {
        /// `[p0, p1, p2, p3]`: `p2, p3` the shared edge, `p0, p1` the opposite vertices.
        particles: [usize; 4],
        /// Rest angle `theta_0` (rad).
        rest_angle: f64,
    },
    /// Bergou et al.'s quadratic bending as `C = |sum_i w_i x_i| - rest`.
    IsometricBending(IsometricBending),
    /// `C = V - rest_volume` with the signed volume
    /// `V = (x_1 - x_0) . ((x_2 - x_0) x (x_3 - x_0)) / 6`.
    TetVolume {
        /// The tetrahedron's four particles.
        particles: [usize; 4],
        /// Signed rest volume `V_0` (its sign is the orientation kept).
        rest_volume: f64,
    },
    /// `C = V(x) - pressure * rest_volume` for a closed triangle mesh of the model
    /// ([`PbdModel::volume_mesh`](crate::PbdModel::volume_mesh)).
    GlobalVolume {
        /// Index of the volume mesh.
        mesh: usize,
        /// Rest volume `V_0` (> 0).
        rest_volume: f64,
        /// Over-pressure `k_pressure` (1 keeps the rest volume, > 1 inflates).
        pressure: f64,
    },
    /// `C = |x_i - t| - distance`.
    Attachment {
        /// The attached particle.
        particle: usize,
        /// The target point.
        target: AttachTarget,
        /// Allowed distance `d >= 0` (0 pins the particle to the target).
        distance: f64,
    },
}

impl ConstraintFunction {
    /// Short name for reports ("distance", "dihedral", ...).
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            ConstraintFunction::Distance { .. } => "distance",
            ConstraintFunction::DihedralBending { .. } => "dihedral bending",
            ConstraintFunction::IsometricBending(_) => "isometric bending",
            ConstraintFunction::TetVolume { .. } => "tetrahedral volume",
            ConstraintFunction::GlobalVolume { .. } => "global volume",
            ConstraintFunction::Attachment { .. } => "attachment",
        }
    }
}

/// A constraint: the function with its index set, and its parameters.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Constraint {
    /// `C_j` and its particles.
    pub function: ConstraintFunction,
    /// Stiffness, compliance, damping and type.
    pub params: ConstraintParams,
}

/// The gradient of a constraint of cardinality up to 4 (the global volume writes into a slice).
pub type Grad4 = [DVec3; 4];

#[inline]
pub(crate) fn load(x: &[f64], i: usize) -> DVec3 {
    DVec3::new(x[3 * i], x[3 * i + 1], x[3 * i + 2])
}

/// `C` and its gradient for a distance constraint; `fallback` is the direction used when the
/// endpoints coincide.
#[inline]
pub(crate) fn distance(a: DVec3, b: DVec3, rest: f64, fallback: DVec3) -> (f64, DVec3) {
    let d = a - b;
    let len = d.length();
    let n = if len > MIN_LENGTH { d * (1.0 / len) } else { fallback };
    (len - rest, n)
}

/// Signed dihedral angle and its gradient for `[p0, p1, p2, p3]` (edge `p2, p3`); `None` when a
/// triangle or the edge is degenerate.
#[inline(always)]
pub(crate) fn dihedral(p: [DVec3; 4]) -> Option<(f64, Grad4)> {
    let (s, c, g) = dihedral_parts(p)?;
    Some((crate::angle::atan2(s, c), g))
}

/// The dihedral angle's sine and cosine up to a common positive factor, `(s, c)` with
/// `theta = atan2(s, c)`, and the angle's gradient (Bridson et al. 2003), each computed once;
/// `None` when a triangle or the edge is degenerate.
#[inline(always)]
pub(crate) fn dihedral_parts(p: [DVec3; 4]) -> Option<(f64, f64, Grad4)> {
    let [p0, p1, p2, p3] = p;
    let e = p3 - p2;
    let elen2 = e.length_squared();
    let n1 = (p2 - p0).cross(p3 - p0);
    let n2 = (p3 - p1).cross(p2 - p1);
    let (l1, l2) = (n1.length_squared(), n2.length_squared());
    // Relative degeneracy test: |N|^2 against |E|^2 times the squared extent of the triangle.
    let tiny = 1e-24;
    let s1 = elen2 * (p0 - p2).length_squared().max((p0 - p3).length_squared());
    let s2 = elen2 * (p1 - p2).length_squared().max((p1 - p3).length_squared());
    if !(elen2 > MIN_LENGTH * MIN_LENGTH) || !(l1 > tiny * s1) || !(l2 > tiny * s2) {
        return None;
    }
    let inv_elen = 1.0 / elen2.sqrt();
    let elen = elen2 * inv_elen;
    let (m1, m2) = (n1 * (1.0 / l1), n2 * (1.0 / l2));
    let g0 = elen * m1;
    let g1 = elen * m2;
    let g2 = ((p0 - p3).dot(e) * inv_elen) * m1 + ((p1 - p3).dot(e) * inv_elen) * m2;
    let g3 = ((p2 - p0).dot(e) * inv_elen) * m1 + ((p2 - p1).dot(e) * inv_elen) * m2;
    // atan2 is invariant under a common positive scale: no need to normalise n1, n2 or e.
    Some((n2.cross(n1).dot(e), n1.dot(n2) * elen, [g0, g1, g2, g3]))
}

/// Wraps an angle difference into `(-pi, pi]`.
#[inline]
pub(crate) fn wrap_angle(a: f64) -> f64 {
    use std::f64::consts::{PI, TAU};
    if a > PI {
        a - TAU
    } else if a <= -PI {
        a + TAU
    } else {
        a
    }
}

/// Whether a tetrahedron of signed volume `v` is flat: `|v|` at most `1e-12` of the cube of its
/// longest edge (a relative test, whatever the mesh's size), or not a number.
pub(crate) fn tet_is_flat(p: [DVec3; 4], v: f64) -> bool {
    let mut l2 = 0.0f64;
    for a in 0..4 {
        for b in a + 1..4 {
            l2 = l2.max((p[a] - p[b]).length_squared());
        }
    }
    !(v.abs() > 1e-12 * l2 * l2.sqrt())
}

/// Signed volume of a tetrahedron and its gradient.
#[inline]
pub(crate) fn tet_volume(p: [DVec3; 4]) -> (f64, Grad4) {
    let [p0, p1, p2, p3] = p;
    let (a, b, c) = (p1 - p0, p2 - p0, p3 - p0);
    let g1 = b.cross(c) / 6.0;
    let g2 = c.cross(a) / 6.0;
    let g3 = a.cross(b) / 6.0;
    (a.dot(g1), [-(g1 + g2 + g3), g1, g2, g3])
}

/// `v = sum_i w_i x_i`, `C = |v| - rest`, gradient `w_i v / |v|`; `None` when `v = 0`.
#[inline]
pub(crate) fn isometric(p: [DVec3; 4], w: [f64; 4], rest: f64) -> Option<(f64, Grad4)> {
    let v = w[0] * p[0] + w[1] * p[1] + w[2] * p[2] + w[3] * p[3];
    let len = v.length();
    if !(len > MIN_LENGTH) {
        return None;
    }
    let n = v / len;
    Some((len - rest, [w[0] * n, w[1] * n, w[2] * n, w[3] * n]))
}

/// The cotangent weights `s K_i` of Bergou et al. for the stencil `[p0, p1, p2, p3]` (edge
/// `p2, p3`), and the rest value `|sum s K_i x_i|`; `None` if a triangle has zero area.
#[must_use]
pub fn isometric_weights(p: [[f64; 3]; 4]) -> Option<([f64; 4], f64)> {
    let [p0, p1, p2, p3] = p.map(DVec3::from_array);
    // Bender et al.'s labelling: x0 = p2, x1 = p3 (the edge), x2 = p0, x3 = p1.
    let e0 = p3 - p2;
    let e1 = p0 - p2;
    let e2 = p1 - p2;
    let e3 = p0 - p3;
    let e4 = p1 - p3;
    let cot = |a: DVec3, b: DVec3| {
        let s = a.cross(b).length();
        if s > 0.0 { Some(a.dot(b) / s) } else { None }
    };
    let c01 = cot(e0, e1)?;
    let c02 = cot(e0, e2)?;
    let c03 = cot(-e0, e3)?;
    let c04 = cot(-e0, e4)?;
    let a0 = 0.5 * e0.cross(e1).length();
    let a1 = 0.5 * e0.cross(e2).length();
    let area = a0 + a1;
    // Relative test: a sliver with area far below its edge lengths squared is degenerate.
    let scale = e0.length_squared().max(e1.length_squared()).max(e2.length_squared());
    if !(a0 > 1e-12 * scale) || !(a1 > 1e-12 * scale) || !area.is_finite() {
        return None;
    }
    let s = (3.0 / area).sqrt();
    // K for (x0, x1, x2, x3) = (c03 + c04, c01 + c02, -c01 - c03, -c02 - c04).
    let w = [s * (-c01 - c03), s * (-c02 - c04), s * (c03 + c04), s * (c01 + c02)];
    let v = w[0] * p0 + w[1] * p1 + w[2] * p2 + w[3] * p3;
    Some((w, v.length()))
}

impl Constraint {
    /// The cardinality `n_j` (for a global volume: the number of vertices of its mesh,
    /// which needs the model: see [`PbdModel::cardinality`](crate::PbdModel::cardinality); this
    /// returns 0 for it).
    #[must_use]
    pub fn cardinality(&self) -> usize {
        match &self.function {
            ConstraintFunction::Distance { .. } => 2,
            ConstraintFunction::DihedralBending { .. }
            | ConstraintFunction::IsometricBending(_)
            | ConstraintFunction::TetVolume { .. } => 4,
            ConstraintFunction::GlobalVolume { .. } => 0,
            ConstraintFunction::Attachment { .. } => 1,
        }
    }

    /// The index set `{i_1, ..., i_{n_j}}` of a constraint of cardinality at most 4 (empty for a
    /// global volume, whose particles are its mesh's vertices).
    #[must_use]
    pub fn particles(&self) -> &[usize] {
        match &self.function {
            ConstraintFunction::Distance { particles, .. } => particles,
            ConstraintFunction::DihedralBending { particles, .. }
            | ConstraintFunction::TetVolume { particles, .. } => particles,
            ConstraintFunction::IsometricBending(b) => &b.particles,
            ConstraintFunction::GlobalVolume { .. } => &[],
            ConstraintFunction::Attachment { particle, .. } => std::slice::from_ref(particle),
        }
    }

    /// Evaluates `C_j` and its gradient at positions `x = [x0, y0, z0, x1, ...]` for a constraint
    /// of cardinality at most 4 (`grad[k]` is `dC/dx_{i_k}`), with an attachment's target at
    /// `target` (ignored by the others). Returns `None` where the gradient is undefined (see the
    /// module docs; a distance constraint with coincident endpoints returns its value with the
    /// gradient along `+x`), and for a global volume (use
    /// [`PbdModel::evaluate`](crate::PbdModel::evaluate)).
    ///
    /// # Panics
    /// If an index is out of range for `x`.
    #[must_use]
    pub fn evaluate(&self, x: &[f64], target: DVec3) -> Option<(f64, Grad4)> {
        let z = DVec3::ZERO;
        match &self.function {
            ConstraintFunction::Distance { particles: [i, j], rest_length } => {
                let (c, n) = distance(load(x, *i), load(x, *j), *rest_length, DVec3::X);
                Some((c, [n, -n, z, z]))
            }
            ConstraintFunction::DihedralBending { particles, rest_angle } => {
                let (theta, g) = dihedral(particles.map(|i| load(x, i)))?;
                Some((wrap_angle(theta - rest_angle), g))
            }
            ConstraintFunction::IsometricBending(b) => {
                isometric(b.particles.map(|i| load(x, i)), b.weights, b.rest)
            }
            ConstraintFunction::TetVolume { particles, rest_volume } => {
                let (v, g) = tet_volume(particles.map(|i| load(x, i)));
                Some((v - rest_volume, g))
            }
            ConstraintFunction::GlobalVolume { .. } => None,
            ConstraintFunction::Attachment { particle, distance: d, .. } => {
                let (c, n) = distance(load(x, *particle), target, *d, DVec3::X);
                if (load(x, *particle) - target).length() > MIN_LENGTH {
                    Some((c, [n, z, z, z]))
                } else {
                    None
                }
            }
        }
    }
}
