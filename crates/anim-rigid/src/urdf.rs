//! URDF loading: `<robot>` files of links and joints into a [`Model`].
//!
//! What is read: every `<link>` (its `<inertial>`: `origin`, `mass`, `inertia`) and every
//! `<joint>` (`type`, `parent`, `child`, `origin` `xyz`/`rpy`, `axis`, `limit`). Joint types:
//! `revolute` and `continuous` become [`JointType::Revolute`] (continuous without position
//! limits; Pinocchio represents it by `(cos θ, sin θ)`, here it is the angle itself, see
//! [`crate::pinocchio`]),
//! `prismatic`, `fixed`, `floating` ([`JointType::Free`]) and `planar` ([`JointType::Planar`],
//! its `axis` the plane's normal, its `<limit>` ignored; Pinocchio ignores that axis and uses `+z`,
//! so the two agree on planar joints whose axis is `0 0 1`). What is
//! ignored without failing: `<visual>`, `<collision>`, `<material>`, `<mimic>` unless
//! [`UrdfOptions::couple_mimic_joints`] is set (by default the mimicking joint stays an
//! independent joint, as in Pinocchio's default), `<dynamics>`,
//! `<safety_controller>`, `<transmission>`, `<gazebo>` and anything else, and, as urdfdom does,
//! the `<axis>` of fixed and floating joints (it may be `0 0 0` there; on a revolute, continuous
//! or prismatic joint a zero or non-finite axis is an error).
//!
//! The tree is built as Pinocchio's URDF parser builds it, so that joint indices, frames and
//! `v` vectors can be exchanged, and `q` vectors through [`crate::pinocchio::to_pinocchio`] and
//! [`crate::pinocchio::from_pinocchio`] (continuous joints differ):
//!
//! - the root link (the one link that is no joint's child) is fixed to the universe, or carried
//!   by a free joint named `root_joint` ([`UrdfOptions::floating_base`]);
//! - children are visited depth first, the joints below a link in the byte order of their names
//!   (urdfdom keeps joints in a `std::map`), which fixes the order of `q`;
//! - with [`UrdfOptions::merge_fixed_joints`] (the default, and Pinocchio's behaviour) a fixed
//!   joint becomes a [`FrameKind::FixedJoint`] frame, its child link a [`FrameKind::Body`] frame,
//!   and the child's inertia is merged into the body of the nearest moving ancestor;
//! - [`UrdfOptions::locked_joints`] turns named moving joints into fixed ones at a given
//!   position first (Pinocchio's `buildReducedModel`; e.g. the Panda's finger joints);
//! - with [`UrdfOptions::couple_mimic_joints`], a revolute, continuous or prismatic joint with
//!   `<mimic joint="J" multiplier="m" offset="o"/>` (defaults `m = 1`, `o = 0`, as urdfdom)
//!   follows `J`: `q = m · q_J + o`, no entry of its own in `q` and `v`
//!   ([`crate::model::Mimic`]), as Pinocchio's `buildModelFromUrdf(..., mimic=True)`. The rules
//!   are Pinocchio's: `J` must be a moving joint earlier in the depth-first order (romeo and
//!   talos_full_v2 break this and are refused, by Pinocchio too), not itself a mimic, and a
//!   continuous joint only follows a continuous one; `<mimic>` on a fixed or floating joint is
//!   ignored; a locked `J` is refused unless the mimicking joint is locked too;
//! - every moving joint gets a [`FrameKind::Joint`] frame, every link a [`FrameKind::Body`]
//!   frame, and joint `0`'s frame is named `universe`.
//!
//! `rpy` is the URDF's fixed-axis roll-pitch-yaw, `R = Rz(yaw) Ry(pitch) Rx(roll)`, converted
//! through a quaternion exactly as urdfdom does. Errors name the file, the line, the element and
//! the cause ([`UrdfError`]).

use std::collections::HashMap;
use std::path::Path;

use anim_core::glam::{DMat3, DQuat, DVec3};
use anim_core::lie::Se3;
use roxmltree::{Document, Node};
use thiserror::Error;

use crate::model::{
    Axis, FrameKind, Inertia, JointIndex, JointLimits, JointType, Model, ModelBuilder, ModelError,
};

/// How a URDF becomes a [`Model`].
#[derive(Debug, Clone, PartialEq)]
#[non_exhaustive]
pub struct UrdfOptions {
    /// Merge fixed joints into their parent body as frames (Pinocchio's behaviour). Default
    /// `true`. When `false`, every fixed joint stays a [`JointType::Fixed`] joint with its own
    /// body.
    pub merge_fixed_joints: bool,
    /// Carry the root link by a free joint named `root_joint` (a floating base). Default `false`:
    /// the root link is fixed to the world.
    pub floating_base: bool,
    /// Moving joints to lock, with the position each is locked at: they are treated as fixed
    /// joints whose origin includes the joint motion at that position. Default: none.
    pub locked_joints: Vec<(String, f64)>,
    /// Couple the joints that carry a `<mimic joint="J" multiplier="m" offset="o"/>` to `J`:
    /// `q = m · q_J + o`, with no entry of their own in `q` and `v` ([`crate::model::Mimic`];
    /// Pinocchio's `buildModelFromUrdf(..., mimic=True)`). Default `false`: `<mimic>` is
    /// ignored and every such joint is independent (Pinocchio's default).
    pub couple_mimic_joints: bool,
}

impl Default for UrdfOptions {
    fn default() -> Self {
        Self {
            merge_fixed_joints: true,
            floating_base: false,
            locked_joints: Vec::new(),
            couple_mimic_joints: false,
        }
    }
}

impl UrdfOptions {
    /// The defaults with the joints `names` locked at `0`.
    #[must_use]
    pub fn with_locked_joints(names: &[&str]) -> Self {
        Self { locked_joints: names.iter().map(|n| ((*n).to_string(), 0.0)).collect(), ..Self::default() }
    }

    /// These options with joint `name` locked at `position`.
    #[must_use]
    pub fn lock_joint(mut self, name: &str, position: f64) -> Self {
        self.locked_joints.push((name.to_string(), position));
        self
    }

    /// These options with [`merge_fixed_joints`](Self::merge_fixed_joints) set to `merge`.
    #[must_use]
    pub fn merge_fixed_joints(mut self, merge: bool) -> Self {
        self.merge_fixed_joints = merge;
        self
    }

    /// These options with [`couple_mimic_joints`](Self::couple_mimic_joints) set to `couple`.
    #[must_use]
    pub fn couple_mimic_joints(mut self, couple: bool) -> Self {
        self.couple_mimic_joints = couple;
        self
    }

    /// These options with [`floating_base`](Self::floating_base) set to `floating`.
    #[must_use]
    pub fn floating_base(mut self, floating: bool) -> Self {
        self.floating_base = floating;
        self
    }
}

/// Why a URDF could not be loaded.
#[derive(Debug, Clone, PartialEq, Error)]
pub enum UrdfCause {
    /// The file could not be read.
    #[error("cannot read the file: {0}")]
    Io(String),
    /// The text is not well-formed XML.
    #[error("malformed XML: {0}")]
    Xml(String),
    /// The root element is not `<robot>`.
    #[error("the root element is <{0}>, expected <robot>")]
    NotARobot(String),
    /// A required attribute is missing.
    #[error("missing attribute '{0}'")]
    MissingAttribute(&'static str),
    /// A required child element is missing.
    #[error("missing element <{0}>")]
    MissingElement(&'static str),
    /// A number that does not parse or is not finite, or the wrong count of numbers.
    #[error("attribute '{attribute}' = \"{value}\": {reason}")]
    BadNumber {
        /// The attribute.
        attribute: &'static str,
        /// Its text.
        value: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A joint axis of zero length or with non-finite entries.
    #[error("axis xyz=\"{0}\" has zero length or is not finite")]
    BadAxis(String),
    /// A `type` this loader does not know.
    #[error(
        "joint type '{0}' is not supported (revolute, continuous, prismatic, fixed, floating and planar are)"
    )]
    UnsupportedJointType(String),
    /// Two links with the same name.
    #[error("link '{0}' is defined twice")]
    DuplicateLink(String),
    /// Two joints with the same name.
    #[error("joint '{0}' is defined twice")]
    DuplicateJoint(String),
    /// A joint names a parent or child link that does not exist.
    #[error("the {role} link '{link}' does not exist")]
    MissingLink {
        /// `parent` or `child`.
        role: &'static str,
        /// The link name.
        link: String,
    },
    /// A link is the child of two joints.
    #[error("link '{link}' is the child of two joints ('{first}' and '{second}')")]
    TwoParents {
        /// The link.
        link: String,
        /// The first joint.
        first: String,
        /// The second joint.
        second: String,
    },
    /// The joints form a cycle.
    #[error("the joints form a cycle through the links {0:?}")]
    Cycle(Vec<String>),
    /// More than one link is no joint's child.
    #[error("the tree has {} roots ({:?}); a URDF must have exactly one", .0.len(), .0)]
    MultipleRoots(Vec<String>),
    /// The robot has no link.
    #[error("the robot has no <link>")]
    NoLinks,
    /// A joint named in [`UrdfOptions::locked_joints`] does not exist or cannot be locked.
    #[error("cannot lock joint '{0}': no such revolute, continuous or prismatic joint")]
    BadLockedJoint(String),
    /// A `<mimic>` that cannot be coupled ([`UrdfOptions::couple_mimic_joints`]).
    #[error("cannot couple to joint '{master}': {reason}")]
    BadMimic {
        /// The joint named by `<mimic joint=...>`.
        master: String,
        /// Why not.
        reason: String,
    },
    /// The model builder refused an element (bad limits, non-rotation placement, bad inertia).
    #[error(transparent)]
    Model(#[from] ModelError),
}

/// A URDF loading error: the file, line and element where it happened, and the cause.
#[derive(Debug, Clone, PartialEq, Error)]
#[error("{file}:{line}: <{element}>: {cause}")]
pub struct UrdfError {
    /// The file name (`<string>` for [`parse_urdf`]).
    pub file: String,
    /// 1-based line of the element (`0` when the error is not tied to an element).
    pub line: u32,
    /// The element, with its name when it has one (`joint panda_joint1`).
    pub element: String,
    /// What is wrong (boxed to keep `Result<_, UrdfError>` small).
    pub cause: Box<UrdfCause>,
}

/// Loads the URDF file at `path`.
///
/// # Errors
/// A [`UrdfError`] naming the file, line, element and cause: unreadable file, malformed XML or
/// number, zero or non-finite axis, missing parent or child link, a cycle, several roots,
/// unsupported joint type.
pub fn load_urdf(path: impl AsRef<Path>, options: &UrdfOptions) -> Result<Model, UrdfError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|e| UrdfError {
        file: file.clone(),
        line: 0,
        element: "robot".into(),
        cause: Box::new(UrdfCause::Io(e.to_string())),
    })?;
    parse_with_name(&text, &file, options)
}

/// Parses URDF text (errors name the file `<string>`).
///
/// # Errors
/// As [`load_urdf`].
pub fn parse_urdf(xml: &str, options: &UrdfOptions) -> Result<Model, UrdfError> {
    parse_with_name(xml, "<string>", options)
}

/// A parsed `<joint>`.
struct UJoint<'a> {
    name: &'a str,
    node: Node<'a, 'a>,
    kind: JointType,
    parent: &'a str,
    child: &'a str,
    origin: Se3,
    limits: JointLimits,
    continuous: bool,
    /// `<mimic>` (read only when coupling): the master's name, multiplier, offset and element.
    mimic: Option<(&'a str, f64, f64, Node<'a, 'a>)>,
}

/// A parsed `<link>`.
struct ULink<'a> {
    node: Node<'a, 'a>,
    inertia: Inertia,
    /// Inertial frame in the link frame.
    inertial_origin: Se3,
}

struct Ctx<'a> {
    file: &'a str,
    doc: &'a Document<'a>,
}

impl Ctx<'_> {
    fn err(&self, node: Node<'_, '_>, cause: UrdfCause) -> UrdfError {
        let line = self.doc.text_pos_at(node.range().start).row;
        let tag = node.tag_name().name();
        let element = match node.attribute("name") {
            Some(n) => format!("{tag} {n}"),
            None => tag.to_string(),
        };
        UrdfError { file: self.file.to_string(), line, element, cause: Box::new(cause) }
    }

    fn attr<'n>(&self, node: Node<'n, 'n>, name: &'static str) -> Result<&'n str, UrdfError> {
        node.attribute(name).ok_or_else(|| self.err(node, UrdfCause::MissingAttribute(name)))
    }

    fn numbers<const N: usize>(
        &self,
        node: Node<'_, '_>,
        attribute: &'static str,
        text: &str,
    ) -> Result<[f64; N], UrdfError> {
        let bad =
            |reason: String| self.err(node, UrdfCause::BadNumber { attribute, value: text.into(), reason });
        let parts: Vec<&str> = text.split_whitespace().collect();
        if parts.len() != N {
            return Err(bad(format!("expected {N} numbers, found {}", parts.len())));
        }
        let mut out = [0.0; N];
        for (o, p) in out.iter_mut().zip(parts) {
            let x: f64 = p.parse().map_err(|_| bad(format!("'{p}' is not a number")))?;
            if !x.is_finite() {
                return Err(bad(format!("'{p}' is not finite")));
            }
            *o = x;
        }
        Ok(out)
    }

    fn number(&self, node: Node<'_, '_>, attribute: &'static str) -> Result<Option<f64>, UrdfError> {
        match node.attribute(attribute) {
            None => Ok(None),
            Some(text) => Ok(Some(self.numbers::<1>(node, attribute, text)?[0])),
        }
    }

    /// `<origin xyz rpy>` of `parent`'s child element `origin` (identity when absent).
    fn origin(&self, parent: Node<'_, '_>) -> Result<Se3, UrdfError> {
        let Some(o) = child(parent, "origin") else {
            return Ok(Se3::IDENTITY);
        };
        let xyz = match o.attribute("xyz") {
            Some(t) => self.numbers::<3>(o, "xyz", t)?,
            None => [0.0; 3],
        };
        let rpy = match o.attribute("rpy") {
            Some(t) => self.numbers::<3>(o, "rpy", t)?,
            None => [0.0; 3],
        };
        Ok(Se3::new(rpy_to_matrix(rpy[0], rpy[1], rpy[2]), DVec3::from_array(xyz)))
    }
}

/// The first child element of `node` named `name`.
fn child<'a>(node: Node<'a, 'a>, name: &str) -> Option<Node<'a, 'a>> {
    node.children().find(|c| c.is_element() && c.tag_name().name() == name)
}

/// URDF roll-pitch-yaw to a rotation matrix, through the quaternion urdfdom computes
/// (`Rotation::setFromRPY`), normalised.
#[must_use]
pub fn rpy_to_matrix(roll: f64, pitch: f64, yaw: f64) -> DMat3 {
    let (sp, cp) = (roll / 2.0).sin_cos();
    let (st, ct) = (pitch / 2.0).sin_cos();
    let (ss, cs) = (yaw / 2.0).sin_cos();
    let q = DQuat::from_xyzw(
        sp * ct * cs - cp * st * ss,
        cp * st * cs + sp * ct * ss,
        cp * ct * ss - sp * st * cs,
        cp * ct * cs + sp * st * ss,
    );
    DMat3::from_quat(q.normalize())
}

fn parse_with_name(xml: &str, file: &str, options: &UrdfOptions) -> Result<Model, UrdfError> {
    let doc = Document::parse(xml).map_err(|e| UrdfError {
        file: file.to_string(),
        line: e.pos().row,
        element: "xml".into(),
        cause: Box::new(UrdfCause::Xml(e.to_string())),
    })?;
    let cx = Ctx { file, doc: &doc };
    let robot = doc.root_element();
    if robot.tag_name().name() != "robot" {
        return Err(cx.err(robot, UrdfCause::NotARobot(robot.tag_name().name().to_string())));
    }
    let robot_name = robot.attribute("name").unwrap_or("robot");

    // Links.
    let mut links: HashMap<&str, ULink<'_>> = HashMap::new();
    let mut link_order: Vec<&str> = Vec::new();
    for node in robot.children().filter(|n| n.is_element() && n.tag_name().name() == "link") {
        let name = cx.attr(node, "name")?;
        let (inertia, inertial_origin) = match child(node, "inertial") {
            None => (Inertia::ZERO, Se3::IDENTITY),
            Some(inertial) => {
                let origin = cx.origin(inertial)?;
                let mass_node = child(inertial, "mass")
                    .ok_or_else(|| cx.err(inertial, UrdfCause::MissingElement("mass")))?;
                let mass = cx.numbers::<1>(mass_node, "value", cx.attr(mass_node, "value")?)?[0];
                let i_node = child(inertial, "inertia")
                    .ok_or_else(|| cx.err(inertial, UrdfCause::MissingElement("inertia")))?;
                let mut v = [0.0; 6];
                for (slot, key) in v.iter_mut().zip(["ixx", "ixy", "ixz", "iyy", "iyz", "izz"]) {
                    *slot = cx.number(i_node, key)?.unwrap_or(0.0);
                }
                let [ixx, ixy, ixz, iyy, iyz, izz] = v;
                let tensor = DMat3::from_cols(
                    DVec3::new(ixx, ixy, ixz),
                    DVec3::new(ixy, iyy, iyz),
                    DVec3::new(ixz, iyz, izz),
                );
                if mass < 0.0 {
                    return Err(cx.err(
                        mass_node,
                        UrdfCause::BadNumber {
                            attribute: "value",
                            value: mass.to_string(),
                            reason: "negative mass".into(),
                        },
                    ));
                }
                (Inertia::new(mass, DVec3::ZERO, tensor), origin)
            }
        };
        if links.insert(name, ULink { node, inertia, inertial_origin }).is_some() {
            return Err(cx.err(node, UrdfCause::DuplicateLink(name.into())));
        }
        link_order.push(name);
    }
    if links.is_empty() {
        return Err(cx.err(robot, UrdfCause::NoLinks));
    }

    // Joints.
    let mut joints: Vec<UJoint<'_>> = Vec::new();
    for node in robot.children().filter(|n| n.is_element() && n.tag_name().name() == "joint") {
        let name = cx.attr(node, "name")?;
        if joints.iter().any(|j| j.name == name) {
            return Err(cx.err(node, UrdfCause::DuplicateJoint(name.into())));
        }
        let type_name = cx.attr(node, "type")?;
        let parent_node =
            child(node, "parent").ok_or_else(|| cx.err(node, UrdfCause::MissingElement("parent")))?;
        let child_node =
            child(node, "child").ok_or_else(|| cx.err(node, UrdfCause::MissingElement("child")))?;
        let parent = cx.attr(parent_node, "link")?;
        let child_link = cx.attr(child_node, "link")?;
        for (role, link, n) in [("parent", parent, parent_node), ("child", child_link, child_node)] {
            if !links.contains_key(link) {
                return Err(cx.err(n, UrdfCause::MissingLink { role, link: link.into() }));
            }
        }
        let origin = cx.origin(node)?;
        // urdfdom reads `<axis>` only for joints that have one: on fixed and floating joints it
        // is ignored, whatever it says (several published robots give fixed joints `0 0 0`).
        let has_axis = !matches!(type_name, "fixed" | "floating");
        let axis = match child(node, "axis").filter(|_| has_axis) {
            None => Axis::X,
            Some(a) => {
                let text = a.attribute("xyz").unwrap_or("1 0 0");
                let parts: Vec<&str> = text.split_whitespace().collect();
                let values: Vec<Option<f64>> = parts.iter().map(|p| p.parse::<f64>().ok()).collect();
                if parts.len() != 3 || values.iter().any(Option::is_none) {
                    // Not three numbers at all: a malformed number.
                    cx.numbers::<3>(a, "xyz", text)?;
                }
                let v = DVec3::new(
                    values[0].unwrap_or(f64::NAN),
                    values[1].unwrap_or(f64::NAN),
                    values[2].unwrap_or(f64::NAN),
                );
                Axis::from_vector(v).ok_or_else(|| cx.err(a, UrdfCause::BadAxis(text.into())))?
            }
        };
        let limit_node = child(node, "limit");
        let read_limits = |require_position: bool| -> Result<JointLimits, UrdfError> {
            match limit_node {
                None if require_position => Err(cx.err(node, UrdfCause::MissingElement("limit"))),
                None => Ok(JointLimits::UNBOUNDED),
                Some(l) => {
                    let (lower, upper) = if require_position {
                        (cx.number(l, "lower")?.unwrap_or(0.0), cx.number(l, "upper")?.unwrap_or(0.0))
                    } else {
                        (f64::NEG_INFINITY, f64::INFINITY)
                    };
                    Ok(JointLimits {
                        lower,
                        upper,
                        velocity: cx.number(l, "velocity")?.unwrap_or(f64::INFINITY),
                        effort: cx.number(l, "effort")?.unwrap_or(f64::INFINITY),
                    })
                }
            }
        };
        let (kind, limits) = match type_name {
            "revolute" => (JointType::Revolute(axis), read_limits(true)?),
            "continuous" => (JointType::Revolute(axis), read_limits(false)?),
            "prismatic" => (JointType::Prismatic(axis), read_limits(true)?),
            "fixed" => (JointType::Fixed, JointLimits::UNBOUNDED),
            "floating" => (JointType::Free, JointLimits::UNBOUNDED),
            "planar" => (JointType::Planar(axis), JointLimits::UNBOUNDED),
            other => return Err(cx.err(node, UrdfCause::UnsupportedJointType(other.into()))),
        };
        let mimic = match child(node, "mimic").filter(|_| options.couple_mimic_joints) {
            None => None,
            Some(m) => Some((
                cx.attr(m, "joint")?,
                cx.number(m, "multiplier")?.unwrap_or(1.0),
                cx.number(m, "offset")?.unwrap_or(0.0),
                m,
            )),
        };
        let continuous = type_name == "continuous";
        joints.push(UJoint {
            name,
            node,
            kind,
            parent,
            child: child_link,
            origin,
            limits,
            continuous,
            mimic,
        });
    }

    // Locked joints become fixed joints at their locked position.
    for (name, value) in &options.locked_joints {
        let Some(j) = joints.iter_mut().find(|j| j.name == name) else {
            return Err(UrdfError {
                file: file.into(),
                line: 0,
                element: "robot".into(),
                cause: Box::new(UrdfCause::BadLockedJoint(name.clone())),
            });
        };
        if j.kind.nq() != 1 {
            return Err(cx.err(j.node, UrdfCause::BadLockedJoint(name.clone())));
        }
        j.origin *= j.kind.transform(&[*value]);
        j.kind = JointType::Fixed;
    }

    // Topology: one parent per link, exactly one root, no cycle.
    let mut parent_joint: HashMap<&str, usize> = HashMap::new();
    let mut children_of: HashMap<&str, Vec<usize>> = HashMap::new();
    for (k, j) in joints.iter().enumerate() {
        if let Some(&first) = parent_joint.get(j.child) {
            return Err(cx.err(
                j.node,
                UrdfCause::TwoParents {
                    link: j.child.into(),
                    first: joints[first].name.into(),
                    second: j.name.into(),
                },
            ));
        }
        parent_joint.insert(j.child, k);
        children_of.entry(j.parent).or_default().push(k);
    }
    for list in children_of.values_mut() {
        list.sort_by(|&a, &b| joints[a].name.as_bytes().cmp(joints[b].name.as_bytes()));
    }
    let roots: Vec<&str> = link_order.iter().copied().filter(|l| !parent_joint.contains_key(l)).collect();
    if roots.is_empty() {
        // Every link has a parent: follow parents from the first link until one repeats.
        let cycle = find_cycle(link_order[0], &joints, &parent_joint);
        let node = joints[parent_joint[cycle[0].as_str()]].node;
        return Err(cx.err(node, UrdfCause::Cycle(cycle)));
    }
    if roots.len() > 1 {
        return Err(cx.err(
            links[roots[1]].node,
            UrdfCause::MultipleRoots(roots.iter().map(|r| r.to_string()).collect()),
        ));
    }
    let root = roots[0];

    // Build depth first from the root.
    let mut b = ModelBuilder::new(robot_name);
    let model_err = |node: Node<'_, '_>, e: ModelError| cx.err(node, UrdfCause::Model(e));
    let root_joint: JointIndex = if options.floating_base {
        b.add_joint(0, "root_joint", JointType::Free, Se3::IDENTITY, JointLimits::UNBOUNDED)
            .map_err(|e| model_err(robot, e))?
    } else {
        0
    };
    let root_link = &links[root];
    b.add_frame(root, FrameKind::Body, root_joint, Se3::IDENTITY)
        .map_err(|e| model_err(root_link.node, e))?;
    b.append_body(root_joint, &root_link.inertia, &root_link.inertial_origin)
        .map_err(|e| model_err(root_link.node, e))?;

    // Pre-order depth first, like Pinocchio's recursive parser: a joint, then everything below
    // its child link, then the joint's next sibling (siblings in name order). Each stack entry
    // is a URDF joint, the model joint carrying its parent link and that link's placement on it.
    let mut visited = 1usize;
    let push_children =
        |stack: &mut Vec<(usize, JointIndex, Se3)>, link: &str, carrier: JointIndex, at: Se3| {
            if let Some(kids) = children_of.get(link) {
                stack.extend(kids.iter().rev().map(|&k| (k, carrier, at)));
            }
        };
    let mut stack: Vec<(usize, JointIndex, Se3)> = Vec::new();
    push_children(&mut stack, root, root_joint, Se3::IDENTITY);
    while let Some((k, carrier, link_placement)) = stack.pop() {
        let j = &joints[k];
        let child_link = &links[j.child];
        let placement = link_placement * j.origin;
        visited += 1;
        if matches!(j.kind, JointType::Fixed) && options.merge_fixed_joints {
            b.add_frame(j.name, FrameKind::FixedJoint, carrier, placement)
                .map_err(|e| model_err(j.node, e))?;
            b.add_frame(j.child, FrameKind::Body, carrier, placement)
                .map_err(|e| model_err(child_link.node, e))?;
            b.append_body(carrier, &child_link.inertia, &(placement * child_link.inertial_origin))
                .map_err(|e| model_err(child_link.node, e))?;
            push_children(&mut stack, j.child, carrier, placement);
        } else {
            let index = match j
                .mimic
                .filter(|_| matches!(j.kind, JointType::Revolute(_) | JointType::Prismatic(_)))
            {
                None => b.add_joint(carrier, j.name, j.kind, placement, j.limits),
                Some((master, multiplier, offset, node)) => {
                    let id = mimic_master(&cx, &b, &joints, j, master, node)?;
                    b.add_mimic_joint(carrier, j.name, j.kind, placement, j.limits, id, multiplier, offset)
                }
            }
            .map_err(|e| model_err(j.node, e))?;
            b.add_frame(j.child, FrameKind::Body, index, Se3::IDENTITY)
                .map_err(|e| model_err(child_link.node, e))?;
            b.append_body(index, &child_link.inertia, &child_link.inertial_origin)
                .map_err(|e| model_err(child_link.node, e))?;
            push_children(&mut stack, j.child, index, Se3::IDENTITY);
        }
    }
    if visited != link_order.len() {
        // Links not reachable from the root each have a parent: they sit on a cycle.
        let reached: std::collections::HashSet<&str> = {
            let mut set = std::collections::HashSet::new();
            let mut todo = vec![root];
            while let Some(l) = todo.pop() {
                if set.insert(l)
                    && let Some(kids) = children_of.get(l)
                {
                    todo.extend(kids.iter().map(|&k| joints[k].child));
                }
            }
            set
        };
        let start = link_order.iter().copied().find(|l| !reached.contains(l)).unwrap_or(root);
        let cycle = find_cycle(start, &joints, &parent_joint);
        let node =
            cycle.first().and_then(|l| parent_joint.get(l.as_str())).map_or(robot, |&k| joints[k].node);
        return Err(cx.err(node, UrdfCause::Cycle(cycle)));
    }
    Ok(b.build())
}

/// The model joint that the coupled URDF joint `j` follows (`<mimic joint="master">` at
/// `node`), or why it cannot: Pinocchio's rules, which need the master already in the model
/// (earlier in the depth-first order), moving, of the same configuration size (a continuous
/// joint only follows a continuous one, in Pinocchio's `(cos, sin)` layout) and not itself
/// coupled.
fn mimic_master(
    cx: &Ctx<'_>,
    b: &ModelBuilder,
    joints: &[UJoint<'_>],
    j: &UJoint<'_>,
    master: &str,
    node: Node<'_, '_>,
) -> Result<JointIndex, UrdfError> {
    let bad = |reason: &str| {
        cx.err(
            node,
            UrdfCause::BadMimic { master: master.into(), reason: format!("joint '{}': {reason}", j.name) },
        )
    };
    let Some(m) = joints.iter().find(|u| u.name == master) else {
        return Err(bad("no such joint"));
    };
    if !matches!(m.kind, JointType::Revolute(_) | JointType::Prismatic(_)) {
        return Err(bad("it is not a revolute, continuous or prismatic joint (or it is locked)"));
    }
    if m.continuous != j.continuous {
        return Err(bad(
            "a continuous joint can only mimic a continuous one (Pinocchio's configuration sizes differ)",
        ));
    }
    if m.mimic.is_some() {
        return Err(bad("it is itself a mimic joint (chains of mimic joints are not supported)"));
    }
    b.model()
        .joint_id(master)
        .ok_or_else(|| bad("it comes later in the depth-first joint order (Pinocchio refuses this too)"))
}

/// The links of the cycle reached by following parent joints from `start`.
fn find_cycle(start: &str, joints: &[UJoint<'_>], parent_joint: &HashMap<&str, usize>) -> Vec<String> {
    let mut path: Vec<&str> = vec![start];
    let mut link = start;
    while let Some(&k) = parent_joint.get(link) {
        link = joints[k].parent;
        if let Some(pos) = path.iter().position(|l| *l == link) {
            return path[pos..].iter().map(|l| l.to_string()).collect();
        }
        path.push(link);
    }
    path.iter().map(|l| l.to_string()).collect()
}
