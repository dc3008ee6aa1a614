//! Building models: particles and constraints by hand, or whole shapes (a chain, a cloth grid,
//! any triangle mesh, any tetrahedral mesh, a closed balloon), all checked before a
//! [`PbdModel`](crate::PbdModel) exists.
//!
//! Every input is validated by [`PbdBuilder::build`] (or by the shape method, for the shape's own
//! parameters), and a problem is a [`BuildError`] naming the element: the particle, constraint,
//! triangle, tetrahedron or collider index and the offending value. Nothing here panics on user
//! data.
//!
//! ```
//! use anim_pbd::{Chain, ConstraintParams, PbdBuilder};
//!
//! let mut b = PbdBuilder::new();
//! b.gravity([0.0, 0.0, -9.81]);
//! let rope = b.chain(&Chain {
//!     count: 11,
//!     start: [0.0, 0.0, 1.0],
//!     end: [1.0, 0.0, 1.0],
//!     mass: 0.01,
//!     stretch: ConstraintParams::with_compliance(1e-6),
//! })?;
//! b.pin(rope.start);
//! let model = b.build()?;
//! assert_eq!((model.num_particles(), model.num_constraints()), (11, 10));
//! # Ok::<(), anim_pbd::BuildError>(())
//! ```
//!
//! The builder and its constraints by hand are in `build/builder.rs`, the shapes in
//! `build/rope.rs` ([`Chain`]), `build/cloth.rs` ([`Cloth`] and any triangle mesh) and
//! `build/tet.rs` (any tetrahedral mesh), the contact bodies in `build/contact.rs`, the check of
//! a closed surface oriented outward in `build/closed.rs`; the checks that turn a builder into a
//! model in `build/validate.rs`, and [`BuildError`] in `build/error.rs`.

mod builder;
mod closed;
mod cloth;
mod contact;
mod error;
mod rope;
mod tet;
mod validate;

pub use builder::{EARTH_GRAVITY, MeshMass, PbdBuilder};
#[cfg(feature = "serde")]
pub(crate) use closed::{NotClosed, closed_outward};
pub use cloth::{Bending, Cloth, ClothHandle, MeshParams};
pub use error::{BuildError, InputError};
pub use rope::Chain;
pub use tet::TetMeshParams;
