//! The kinematic tree: joints in topological order, the rigid body each joint moves (its
//! inertia), and named frames. Built once by [`ModelBuilder`] (or [`crate::urdf`]), never
//! changed by an algorithm.
//!
//! # Layout (Pinocchio's)
//!
//! Joint `0` is the **universe**, the fixed world; it is its own parent. Every other joint `i`
//! has a parent `parent(i) < i`, so one forward sweep `i = 1, 2, ...` visits parents before
//! children (topological order) and one backward sweep visits children first, which is what
//! RNEA, CRBA and ABA need. Joint `i` moves the frame
//!
//! ```text
//! parent_M_i(q) = placement_i · X_J(q_i)          (placement: Se3 in the parent joint's frame)
//! world_M_i(q)  = world_M_parent(i)(q) · parent_M_i(q)
//! ```
//!
//! where `X_J` is the joint's own motion ([`JointType::transform`]). The rigid body attached to
//! joint `i` (every link it carries, fixed links merged) has one [`Inertia`] expressed in joint
//! `i`'s frame. A [`Frame`] is a named placement relative to a joint: the joint itself, a link,
//! a merged fixed joint, or an operational point such as a tool centre.
//!
//! # Configuration and velocity
//!
//! The configuration `q` has `nq` entries and the velocity `v` has `nv`; they differ for joints
//! whose configuration space is not a vector space:
//!
//! | joint | `nq` | `nv` | `q` | `v` |
//! | --- | --- | --- | --- | --- |
//! | revolute | 1 | 1 | angle (rad) | angular rate about the axis |
//! | prismatic | 1 | 1 | displacement (m) | rate along the axis |
//! | fixed | 0 | 0 | | |
//! | planar | 3 | 3 | `(x, y, θ)`: translation along the plane's `e₁`, `e₂` ([`Axis::plane_basis`]) and angle about its normal | `(vx, vy, ω)` in the joint (child) frame |
//! | spherical | 4 | 3 | unit quaternion `(x, y, z, w)` | angular velocity in the joint (child) frame |
//! | free | 7 | 6 | translation `(x, y, z)`, unit quaternion `(x, y, z, w)` | twist `(v, ω)` in the joint (child) frame |
//!
//! The quaternion order `(x, y, z, w)` and the local-frame velocity are Pinocchio's, so `v`
//! vectors (and accelerations, torques, Jacobian columns) can be exchanged with it. `q` vectors
//! can too, except that Pinocchio stores a revolute joint without position limits (URDF
//! `continuous`) as `(cos θ, sin θ)` where this table has the angle; [`crate::pinocchio`]
//! converts between the two layouts. Moving on this manifold is [`crate::config::integrate`]
//! and [`crate::config::difference`].

use anim_core::glam::{DMat3, DVec3};
use anim_core::lie::{Se3, so3};
use thiserror::Error;

/// Index of a joint in [`Model::joints`]; `0` is the universe.
pub type JointIndex = usize;
/// Index of a frame in [`Model::frames`]; `0` is the universe frame.
pub type FrameIndex = usize;

/// Tolerance on the orthonormality of joint and frame placements given to [`ModelBuilder`].
const PLACEMENT_TOL: f64 = 1e-9;

mod joint_type;
mod mimic;

pub use joint_type::{Axis, JointType};
pub use mimic::Mimic;

/// Position, velocity and effort limits of a one-degree-of-freedom joint. Unbounded entries are
/// infinite; multi-degree-of-freedom joints carry [`JointLimits::UNBOUNDED`].
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct JointLimits {
    /// Lowest position (rad or m); `-inf` when unbounded.
    pub lower: f64,
    /// Highest position (rad or m); `+inf` when unbounded.
    pub upper: f64,
    /// Largest speed magnitude; `+inf` when unknown.
    pub velocity: f64,
    /// Largest effort (N·m or N) magnitude; `+inf` when unknown.
    pub effort: f64,
}

impl JointLimits {
    /// No limits at all.
    pub const UNBOUNDED: Self = Self {
        lower: f64::NEG_INFINITY,
        upper: f64::INFINITY,
        velocity: f64::INFINITY,
        effort: f64::INFINITY,
    };

    /// Position limits `[lower, upper]`, unbounded speed and effort.
    #[must_use]
    pub const fn position(lower: f64, upper: f64) -> Self {
        Self { lower, upper, velocity: f64::INFINITY, effort: f64::INFINITY }
    }

    /// Whether both position limits are finite.
    #[must_use]
    pub fn is_bounded(&self) -> bool {
        self.lower.is_finite() && self.upper.is_finite()
    }
}

impl Default for JointLimits {
    fn default() -> Self {
        Self::UNBOUNDED
    }
}

/// The mass properties of a rigid body, expressed in some frame `F` (a joint frame in a
/// [`Model`]): mass, centre of mass and the rotational inertia about the centre of mass with
/// `F`'s axes. Pinocchio's `Inertia` (mass, lever, inertia) in the same convention.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Inertia {
    /// Mass (kg), `>= 0`.
    pub mass: f64,
    /// Centre of mass in `F` (m).
    pub com: DVec3,
    /// Rotational inertia about the centre of mass, axes of `F` (kg·m²), symmetric.
    pub rotational: DMat3,
}

impl Inertia {
    /// No mass.
    pub const ZERO: Self = Self { mass: 0.0, com: DVec3::ZERO, rotational: DMat3::ZERO };

    /// The inertia of mass `mass` at `com` with rotational inertia `rotational` about it.
    #[must_use]
    pub const fn new(mass: f64, com: DVec3, rotational: DMat3) -> Self {
        Self { mass, com, rotational }
    }

    /// The same body expressed in the frame `A` given `g = A_M_F`: `com' = g(com)`,
    /// `I' = R I Rᵀ`.
    #[must_use]
    pub fn transformed(&self, g: &Se3) -> Self {
        Self {
            mass: self.mass,
            com: g.transform_point(self.com),
            rotational: g.rotation * self.rotational * g.rotation.transpose(),
        }
    }

    /// The inertia of two bodies rigidly joined (both expressed in the same frame): masses add,
    /// the centre of mass is the mass-weighted mean, and the rotational inertia about it follows
    /// the parallel-axis theorem,
    /// `I = I₁ + I₂ - (m₁ m₂ / (m₁ + m₂)) ĉ²` with `c = c₁ - c₂`.
    #[must_use]
    pub fn merged(&self, other: &Inertia) -> Self {
        let mass = self.mass + other.mass;
        if mass <= 0.0 {
            return Self { mass: 0.0, com: DVec3::ZERO, rotational: self.rotational + other.rotational };
        }
        let com = (self.com * self.mass + other.com * other.mass) / mass;
        let d = so3::hat(self.com - other.com);
        let rotational = self.rotational + other.rotational - d * d * (self.mass * other.mass / mass);
        Self { mass, com, rotational }
    }
}

impl Default for Inertia {
    fn default() -> Self {
        Self::ZERO
    }
}

/// One joint of a [`Model`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Joint {
    /// Unique name (the URDF joint name; `universe` for joint 0).
    pub name: String,
    /// Kind and axis.
    pub kind: JointType,
    /// Parent joint; `parent < own index`, and `0` for the universe itself.
    pub parent: JointIndex,
    /// Placement of the joint frame at the neutral configuration, in the parent joint's frame.
    pub placement: Se3,
    /// Limits (meaningful for one-degree-of-freedom joints).
    pub limits: JointLimits,
    /// First index of this joint in the configuration `q`.
    pub idx_q: usize,
    /// First index of this joint in the velocity `v` (and the Jacobian's columns).
    pub idx_v: usize,
    /// When set, the joint is *coupled* to another one (URDF `<mimic>` with
    /// [`crate::urdf::UrdfOptions::couple_mimic_joints`]): it owns no entry of `q` or `v`, and
    /// [`idx_q`](Self::idx_q), [`idx_v`](Self::idx_v) are its master's, as in Pinocchio.
    #[cfg_attr(feature = "serde", serde(default))]
    pub mimic: Option<Mimic>,
}

impl Joint {
    /// Number of configuration entries it owns (`0` for a coupled joint).
    #[inline]
    #[must_use]
    pub fn nq(&self) -> usize {
        if self.mimic.is_some() { 0 } else { self.kind.nq() }
    }

    /// Number of velocity entries it owns (`0` for a coupled joint).
    #[inline]
    #[must_use]
    pub fn nv(&self) -> usize {
        if self.mimic.is_some() { 0 } else { self.kind.nv() }
    }
}

/// What a [`Frame`] marks.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub enum FrameKind {
    /// The frame of a movable joint (identity placement on it).
    Joint,
    /// A fixed joint merged into its parent body (and the universe frame).
    FixedJoint,
    /// A link (URDF `<link>`).
    Body,
    /// An operational point added by the user (a tool centre, a marker).
    Operational,
}

/// A named frame rigidly attached to a joint.
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Frame {
    /// Name (URDF link or joint name). Names are unique within one [`FrameKind`].
    pub name: String,
    /// What it marks.
    pub kind: FrameKind,
    /// The joint whose motion carries it.
    pub parent_joint: JointIndex,
    /// Placement in the parent joint's frame.
    pub placement: Se3,
}

/// Bad input to [`ModelBuilder`].
#[derive(Debug, Clone, PartialEq, Error)]
pub enum ModelError {
    /// The parent joint index does not exist (yet).
    #[error("joint '{joint}': parent joint index {parent} does not exist (the model has {count} joints)")]
    UnknownParent {
        /// The joint being added.
        joint: String,
        /// The parent index given.
        parent: usize,
        /// Number of joints so far.
        count: usize,
    },
    /// Two joints with the same name.
    #[error("joint name '{0}' is used twice")]
    DuplicateJoint(String),
    /// Two frames of the same kind with the same name.
    #[error("{kind:?} frame name '{name}' is used twice")]
    DuplicateFrame {
        /// The name.
        name: String,
        /// Its kind.
        kind: FrameKind,
    },
    /// A placement with non-finite entries or a rotation block that is not a rotation.
    #[error("{what} '{name}': placement is not a rigid motion (non-finite or non-orthonormal rotation)")]
    BadPlacement {
        /// `joint`, `frame` or `body`.
        what: &'static str,
        /// Its name.
        name: String,
    },
    /// Limits with `lower > upper` or NaN, or negative speed/effort limits.
    #[error(
        "joint '{joint}': invalid limits (lower {lower}, upper {upper}, velocity {velocity}, effort {effort})"
    )]
    BadLimits {
        /// The joint.
        joint: String,
        /// Lower position limit.
        lower: f64,
        /// Upper position limit.
        upper: f64,
        /// Speed limit.
        velocity: f64,
        /// Effort limit.
        effort: f64,
    },
    /// A coupled joint that cannot follow the joint it names.
    #[error("joint '{joint}' cannot mimic joint '{master}': {reason}")]
    BadMimic {
        /// The coupled joint.
        joint: String,
        /// The joint it names.
        master: String,
        /// Why not.
        reason: String,
    },
    /// A gravity vector with a non-finite component.
    #[error("gravity {0:?} is not finite")]
    BadGravity([f64; 3]),
    /// A negative or non-finite mass, or a non-finite centre of mass or inertia.
    #[error("body on joint '{joint}': invalid inertia (mass {mass})")]
    BadInertia {
        /// The joint the body is attached to.
        joint: String,
        /// Its mass.
        mass: f64,
    },
}

/// An articulated rigid-body model: the kinematic tree, its limits, the bodies' inertias and
/// named frames. Immutable; every algorithm takes `&Model` and writes into a [`crate::Data`].
#[derive(Debug, Clone, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Model {
    name: String,
    joints: Vec<Joint>,
    inertias: Vec<Inertia>,
    frames: Vec<Frame>,
    children: Vec<Vec<JointIndex>>,
    nq: usize,
    nv: usize,
    lower: Vec<f64>,
    upper: Vec<f64>,
    #[cfg_attr(feature = "serde", serde(default = "default_gravity"))]
    gravity: DVec3,
    #[cfg_attr(feature = "serde", serde(default))]
    mimic_joints: Vec<JointIndex>,
}

/// Standard gravity along `-z`, `(0, 0, -9.81)` m/s² (Pinocchio's default).
pub const DEFAULT_GRAVITY: DVec3 = DVec3::new(0.0, 0.0, -9.81);

#[cfg(feature = "serde")]
fn default_gravity() -> DVec3 {
    DEFAULT_GRAVITY
}

impl Model {
    /// The model's name (the URDF robot name).
    #[must_use]
    pub fn name(&self) -> &str {
        &self.name
    }

    /// Number of joints including the universe (Pinocchio's `njoints`).
    #[inline]
    #[must_use]
    pub fn njoints(&self) -> usize {
        self.joints.len()
    }

    /// Size of the configuration vector `q`.
    #[inline]
    #[must_use]
    pub fn nq(&self) -> usize {
        self.nq
    }

    /// Size of the velocity vector `v` (degrees of freedom, Jacobian columns).
    #[inline]
    #[must_use]
    pub fn nv(&self) -> usize {
        self.nv
    }

    /// The coupled joints ([`Joint::mimic`]), in increasing index order; empty unless the model
    /// was built with coupled mimic joints.
    #[inline]
    #[must_use]
    pub fn mimic_joints(&self) -> &[JointIndex] {
        &self.mimic_joints
    }

    /// Number of columns of [`crate::Data::jacobian`]: `nv`, plus one per coupled joint
    /// (Pinocchio's `nvExtended`).
    #[inline]
    #[must_use]
    pub fn nv_extended(&self) -> usize {
        self.nv + self.mimic_joints.len()
    }

    /// Every joint in topological order; index `0` is the universe.
    #[inline]
    #[must_use]
    pub fn joints(&self) -> &[Joint] {
        &self.joints
    }

    /// Joint `i`.
    ///
    /// # Panics
    /// When `i >= njoints()`.
    #[inline]
    #[must_use]
    #[track_caller]
    pub fn joint(&self, i: JointIndex) -> &Joint {
        &self.joints[i]
    }

    /// The parent of joint `i` (`0` for the universe itself).
    #[inline]
    #[must_use]
    #[track_caller]
    pub fn parent(&self, i: JointIndex) -> JointIndex {
        self.joints[i].parent
    }

    /// The children of joint `i`, in increasing index order.
    #[inline]
    #[must_use]
    #[track_caller]
    pub fn children(&self, i: JointIndex) -> &[JointIndex] {
        &self.children[i]
    }

    /// The inertia of the body carried by each joint, in that joint's frame (index `0`: the
    /// links fixed to the world).
    #[inline]
    #[must_use]
    pub fn inertias(&self) -> &[Inertia] {
        &self.inertias
    }

    /// Every frame; index `0` is the universe.
    #[inline]
    #[must_use]
    pub fn frames(&self) -> &[Frame] {
        &self.frames
    }

    /// Frame `f`.
    ///
    /// # Panics
    /// When `f >= frames().len()`.
    #[inline]
    #[must_use]
    #[track_caller]
    pub fn frame(&self, f: FrameIndex) -> &Frame {
        &self.frames[f]
    }

    /// The index of the joint named `name`.
    #[must_use]
    pub fn joint_id(&self, name: &str) -> Option<JointIndex> {
        self.joints.iter().position(|j| j.name == name)
    }

    /// The index of the first frame named `name` (any kind). Link and joint names may coincide
    /// in a URDF; [`frame_id_of_kind`](Self::frame_id_of_kind) disambiguates.
    #[must_use]
    pub fn frame_id(&self, name: &str) -> Option<FrameIndex> {
        self.frames.iter().position(|f| f.name == name)
    }

    /// The index of the frame named `name` of kind `kind`.
    #[must_use]
    pub fn frame_id_of_kind(&self, name: &str, kind: FrameKind) -> Option<FrameIndex> {
        self.frames.iter().position(|f| f.name == name && f.kind == kind)
    }

    /// Lower position limit per configuration entry (`-inf` where unbounded, `-1` on
    /// quaternion entries).
    #[inline]
    #[must_use]
    pub fn lower_limits(&self) -> &[f64] {
        &self.lower
    }

    /// Upper position limit per configuration entry (`+inf` where unbounded, `1` on quaternion
    /// entries).
    #[inline]
    #[must_use]
    pub fn upper_limits(&self) -> &[f64] {
        &self.upper
    }

    /// The joints from the first one below the universe down to `joint` itself (its *support*),
    /// root first. Empty for the universe.
    #[must_use]
    pub fn support(&self, joint: JointIndex) -> Vec<JointIndex> {
        let mut chain = Vec::new();
        let mut j = joint;
        while j != 0 {
            chain.push(j);
            j = self.joints[j].parent;
        }
        chain.reverse();
        chain
    }

    /// Whether joint `ancestor` is `joint` or one of its ancestors (the universe is an ancestor
    /// of every joint).
    #[must_use]
    pub fn is_ancestor(&self, ancestor: JointIndex, joint: JointIndex) -> bool {
        let mut j = joint;
        loop {
            if j == ancestor {
                return true;
            }
            if j == 0 {
                return false;
            }
            j = self.joints[j].parent;
        }
    }

    /// Total mass of every body.
    #[must_use]
    pub fn total_mass(&self) -> f64 {
        self.inertias.iter().map(|i| i.mass).sum()
    }

    /// The gravitational acceleration in the world frame (m/s²); default [`DEFAULT_GRAVITY`].
    /// The dynamics algorithms ([`crate::dynamics`]) include it.
    #[inline]
    #[must_use]
    pub fn gravity(&self) -> DVec3 {
        self.gravity
    }

    /// Sets the gravitational acceleration (a parameter, changed between queries by the caller,
    /// never by an algorithm). `DVec3::ZERO` switches gravity off.
    ///
    /// # Panics
    /// When `g` is not finite.
    #[track_caller]
    pub fn set_gravity(&mut self, g: DVec3) {
        assert!(g.is_finite(), "gravity must be finite, got {g}");
        self.gravity = g;
    }

    /// Whether every joint's configuration is a vector space (revolute, prismatic and fixed
    /// joints only), so that `nq == nv` and `q` moves by plain addition (a planar joint has
    /// `nq == nv` but its `v` is in the moving frame).
    #[must_use]
    pub fn is_euclidean(&self) -> bool {
        self.joints
            .iter()
            .all(|j| matches!(j.kind, JointType::Revolute(_) | JointType::Prismatic(_) | JointType::Fixed))
    }
}

/// Builds a [`Model`] joint by joint, in topological order (a parent before its children).
///
/// ```
/// use anim_core::glam::DVec3;
/// use anim_core::lie::Se3;
/// use anim_rigid::{Axis, FrameKind, Inertia, JointLimits, JointType, ModelBuilder};
///
/// let mut b = ModelBuilder::new("two-link");
/// let j1 = b.add_joint(0, "shoulder", JointType::Revolute(Axis::Z), Se3::IDENTITY, JointLimits::UNBOUNDED)?;
/// let j2 = b.add_joint(j1, "elbow", JointType::Revolute(Axis::Z),
///     Se3::from_translation(DVec3::X), JointLimits::position(-2.0, 2.0))?;
/// b.append_body(j2, &Inertia::new(1.0, DVec3::X * 0.5, Default::default()), &Se3::IDENTITY)?;
/// b.add_frame("tip", FrameKind::Operational, j2, Se3::from_translation(DVec3::X))?;
/// let model = b.build();
/// assert_eq!((model.njoints(), model.nq(), model.nv()), (3, 2, 2));
/// # Ok::<(), anim_rigid::ModelError>(())
/// ```
#[derive(Debug, Clone)]
pub struct ModelBuilder {
    model: Model,
}

impl ModelBuilder {
    /// A model with only the universe joint and the `universe` frame.
    #[must_use]
    pub fn new(name: &str) -> Self {
        let universe = Joint {
            name: "universe".into(),
            kind: JointType::Fixed,
            parent: 0,
            placement: Se3::IDENTITY,
            limits: JointLimits::UNBOUNDED,
            idx_q: 0,
            idx_v: 0,
            mimic: None,
        };
        let frame = Frame {
            name: "universe".into(),
            kind: FrameKind::FixedJoint,
            parent_joint: 0,
            placement: Se3::IDENTITY,
        };
        Self {
            model: Model {
                name: name.to_string(),
                joints: vec![universe],
                inertias: vec![Inertia::ZERO],
                frames: vec![frame],
                children: vec![Vec::new()],
                nq: 0,
                nv: 0,
                lower: Vec::new(),
                upper: Vec::new(),
                gravity: DEFAULT_GRAVITY,
                mimic_joints: Vec::new(),
            },
        }
    }

    /// Sets the model's gravity (default [`DEFAULT_GRAVITY`]).
    ///
    /// # Errors
    /// [`ModelError::BadGravity`] when `g` is not finite.
    pub fn gravity(&mut self, g: DVec3) -> Result<&mut Self, ModelError> {
        if !g.is_finite() {
            return Err(ModelError::BadGravity(g.to_array()));
        }
        self.model.gravity = g;
        Ok(self)
    }

    /// The model built so far (to look up indices while building).
    #[must_use]
    pub fn model(&self) -> &Model {
        &self.model
    }

    /// Adds joint `name` of type `kind` under `parent`, at `placement` in the parent joint's
    /// frame, with `limits` (ignored for joints that are not one-degree-of-freedom), and a
    /// [`FrameKind::Joint`] frame on it. Returns its index.
    ///
    /// # Errors
    /// An unknown parent, a name already used, a placement that is not a rigid motion, or bad
    /// limits.
    pub fn add_joint(
        &mut self,
        parent: JointIndex,
        name: &str,
        kind: JointType,
        placement: Se3,
        limits: JointLimits,
    ) -> Result<JointIndex, ModelError> {
        let m = &mut self.model;
        if parent >= m.joints.len() {
            return Err(ModelError::UnknownParent { joint: name.into(), parent, count: m.joints.len() });
        }
        if m.joints.iter().any(|j| j.name == name) {
            return Err(ModelError::DuplicateJoint(name.into()));
        }
        check_placement(&placement, "joint", name)?;
        let one_dof = kind.nq() == 1;
        let limits = if one_dof { limits } else { JointLimits::UNBOUNDED };
        if limits.lower.is_nan()
            || limits.upper.is_nan()
            || limits.lower > limits.upper
            || limits.lower == f64::INFINITY
            || limits.upper == f64::NEG_INFINITY
            || !(limits.velocity >= 0.0)
            || !(limits.effort >= 0.0)
        {
            return Err(ModelError::BadLimits {
                joint: name.into(),
                lower: limits.lower,
                upper: limits.upper,
                velocity: limits.velocity,
                effort: limits.effort,
            });
        }
        let index = m.joints.len();
        m.joints.push(Joint {
            name: name.into(),
            kind,
            parent,
            placement,
            limits,
            idx_q: m.nq,
            idx_v: m.nv,
            mimic: None,
        });
        m.inertias.push(Inertia::ZERO);
        m.children.push(Vec::new());
        m.children[parent].push(index);
        match kind {
            JointType::Revolute(_) | JointType::Prismatic(_) => {
                m.lower.push(limits.lower);
                m.upper.push(limits.upper);
            }
            JointType::Fixed => {}
            JointType::Spherical => {
                m.lower.extend([-1.0; 4]);
                m.upper.extend([1.0; 4]);
            }
            JointType::Free => {
                m.lower.extend([f64::NEG_INFINITY; 3]);
                m.upper.extend([f64::INFINITY; 3]);
                m.lower.extend([-1.0; 4]);
                m.upper.extend([1.0; 4]);
            }
            JointType::Planar(_) => {
                m.lower.extend([f64::NEG_INFINITY; 3]);
                m.upper.extend([f64::INFINITY; 3]);
            }
        }
        m.nq += kind.nq();
        m.nv += kind.nv();
        m.frames.push(Frame {
            name: name.into(),
            kind: FrameKind::Joint,
            parent_joint: index,
            placement: Se3::IDENTITY,
        });
        Ok(index)
    }

    /// Adds the body `inertia`, given in a frame `B` with `placement = joint_M_B`, to the body
    /// carried by `joint` (Pinocchio's `appendBodyToJoint`).
    ///
    /// # Errors
    /// An unknown joint, a negative or non-finite mass, non-finite inertia, or a bad placement.
    pub fn append_body(
        &mut self,
        joint: JointIndex,
        inertia: &Inertia,
        placement: &Se3,
    ) -> Result<(), ModelError> {
        let m = &mut self.model;
        let Some(j) = m.joints.get(joint) else {
            return Err(ModelError::UnknownParent {
                joint: "(body)".into(),
                parent: joint,
                count: m.joints.len(),
            });
        };
        check_placement(placement, "body", &j.name)?;
        if !(inertia.mass >= 0.0)
            || !inertia.mass.is_finite()
            || !inertia.com.is_finite()
            || !inertia.rotational.is_finite()
        {
            return Err(ModelError::BadInertia { joint: j.name.clone(), mass: inertia.mass });
        }
        let moved = inertia.transformed(placement);
        m.inertias[joint] = m.inertias[joint].merged(&moved);
        Ok(())
    }

    /// Adds frame `name` of kind `kind` on `parent_joint` at `placement` (in the joint's
    /// frame). Returns its index.
    ///
    /// # Errors
    /// An unknown joint, a name already used by a frame of the same kind, or a bad placement.
    pub fn add_frame(
        &mut self,
        name: &str,
        kind: FrameKind,
        parent_joint: JointIndex,
        placement: Se3,
    ) -> Result<FrameIndex, ModelError> {
        let m = &mut self.model;
        if parent_joint >= m.joints.len() {
            return Err(ModelError::UnknownParent {
                joint: name.into(),
                parent: parent_joint,
                count: m.joints.len(),
            });
        }
        if m.frames.iter().any(|f| f.name == name && f.kind == kind) {
            return Err(ModelError::DuplicateFrame { name: name.into(), kind });
        }
        check_placement(&placement, "frame", name)?;
        m.frames.push(Frame { name: name.into(), kind, parent_joint, placement });
        Ok(m.frames.len() - 1)
    }

    /// The finished model.
    #[must_use]
    pub fn build(self) -> Model {
        let mut model = self.model;
        // Coupled joints' own Jacobian columns follow the `nv` columns of `v`.
        let nv = model.nv;
        for (k, &i) in model.mimic_joints.iter().enumerate() {
            if let Some(m) = model.joints[i].mimic.as_mut() {
                m.column = nv + k;
            }
        }
        model
    }
}

fn check_placement(g: &Se3, what: &'static str, name: &str) -> Result<(), ModelError> {
    if g.translation.is_finite() && so3::is_rotation(g.rotation, PLACEMENT_TOL) {
        Ok(())
    } else {
        Err(ModelError::BadPlacement { what, name: name.into() })
    }
}

#[cfg(test)]
mod tests;
