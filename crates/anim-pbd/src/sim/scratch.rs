//! The solver's scratch: every buffer a step writes (positions `x`, velocities `v`, predictions
//! `p`, the compiled constraints and their multipliers, the sweep order, buffered corrections,
//! contacts, body poses, wind forces), sized once from the model. Contacts with colliders are
//! reserved for every particle against every collider, so they never grow. The contacts between
//! contact bodies are reserved for every particle of a contact body against at most four other
//! bodies, and their grid's table for two cells per axis of every surface triangle: a step
//! allocates nothing unless a particle touches more than four other bodies at once or the scene
//! is so wide that rounding spreads a triangle over a third cell (`sim/body_contacts.rs`).

use super::body_contacts::BodyContactData;
use crate::collide::{Contact, Pose};
use crate::model::PbdModel;
use crate::project::Compiled;
use anim_core::glam::DVec3;
use std::ops::Range;
use std::sync::Mutex;
use std::sync::atomic::AtomicUsize;

/// The solver's scratch, sized once from the model.
#[derive(Debug)]
pub(super) struct Data {
    pub(super) x: Vec<DVec3>,
    pub(super) v: Vec<DVec3>,
    pub(super) p: Vec<DVec3>,
    pub(super) compiled: Vec<Compiled>,
    pub(super) lambda: Vec<f64>,
    /// Ranges of `compiled` swept in sequence (one for Gauss-Seidel and Jacobi, one per colour).
    pub(super) groups: Vec<Range<usize>>,
    /// Per colour: whether it holds a global volume (then it is swept sequentially).
    pub(super) group_has_volume: Vec<bool>,
    /// Per colour: its split by particle ranges (`sim/colour_split.rs`).
    pub(super) splits: Vec<super::colour_split::Split>,
    /// The Jacobi gather's incidences as flat correction indices `4 c + slot` (empty when a
    /// global volume is among them).
    pub(super) jacobi_inc: Vec<u32>,
    /// Buffered corrections per constraint (coloured and Jacobi sweeps).
    pub(super) corr: Vec<[DVec3; 4]>,
    pub(super) scratch: Vec<Mutex<Vec<DVec3>>>,
    /// Copies of the volume meshes' buffered corrections (Jacobi gather).
    pub(super) volume_corr: Vec<Vec<DVec3>>,
    pub(super) contacts: Vec<Contact>,
    pub(super) contact_groups: Vec<Range<usize>>,
    /// The contacts between contact bodies and their search buffers.
    pub(super) bodies: BodyContactData,
    pub(super) pose_start: Vec<Pose>,
    pub(super) pose_end: Vec<Pose>,
    pub(super) pose_sub: Vec<Pose>,
    pub(super) pose_sub_prev: Vec<Pose>,
    pub(super) tri_force: Vec<DVec3>,
    pub(super) ext: Vec<DVec3>,
    pub(super) bad: AtomicUsize,
}

impl Data {
    /// Buffers sized for `model`; the sweep order is left empty for the solver to fill, and the
    /// bodies stand at their poses at time 0.
    pub(super) fn new(model: &PbdModel) -> Self {
        let n = model.num_particles();
        let nb = model.bodies.len();
        let nc = model.colliders.len() + model.mesh_colliders.len();
        let scratch =
            model.volume_meshes.iter().map(|m| Mutex::new(vec![DVec3::ZERO; m.vertices.len()])).collect();
        let mut data = Data {
            x: vec![DVec3::ZERO; n],
            v: vec![DVec3::ZERO; n],
            p: vec![DVec3::ZERO; n],
            compiled: Vec::new(),
            lambda: Vec::new(),
            groups: Vec::new(),
            group_has_volume: Vec::new(),
            splits: Vec::new(),
            jacobi_inc: Vec::new(),
            corr: Vec::new(),
            scratch,
            volume_corr: model.volume_meshes.iter().map(|m| vec![DVec3::ZERO; m.vertices.len()]).collect(),
            contacts: Vec::with_capacity(n * nc),
            contact_groups: Vec::with_capacity(nc),
            bodies: BodyContactData::new(model),
            pose_start: vec![Pose::IDENTITY; nb],
            pose_end: vec![Pose::IDENTITY; nb],
            pose_sub: vec![Pose::IDENTITY; nb],
            pose_sub_prev: vec![Pose::IDENTITY; nb],
            tri_force: vec![DVec3::ZERO; if model.wind.is_some() { model.triangles.len() } else { 0 }],
            ext: vec![DVec3::ZERO; n],
            bad: AtomicUsize::new(usize::MAX),
        };
        for (b, body) in model.bodies.iter().enumerate() {
            data.pose_sub[b] = body.pose_at(0.0);
        }
        data
    }
}
