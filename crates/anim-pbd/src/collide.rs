//! Obstacles: kinematic bodies (moved by a prescribed motion, not by the simulation) and the
//! colliders, shapes (plane, sphere, box, capsule: [`Collider`]) and closed triangle meshes
//! ([`MeshCollider`], the signed distance field of the surface), from which line (8) of the PBD
//! loop, `generateCollisionConstraints(x_i -> p_i)`, makes inequality constraints every step.
//!
//! # Contacts
//!
//! For every free particle and every collider, the signed distance `phi(p)` of the predicted
//! position `p` to the shape is evaluated; if `phi(p) < thickness + margin + |p - x|` (a
//! speculative margin, [`PbdParams::contact_margin`](crate::PbdParams::contact_margin)), a
//! contact constraint
//!
//! ```text
//! C(p) = n . (p - q) - thickness >= 0
//! ```
//!
//! is generated with `q` the closest surface point and `n` the outward normal at `q`, both frozen
//! for the step (Müller et al. 2007, section 3.4, the "static" case; the shapes are solid, so the
//! closest point also resolves a particle that crossed the surface during the step, unless it
//! passed through a shape thinner than its motion: a box of half-thickness `b` is crossed by a
//! particle whose substep motion exceeds `b + thickness` when the substep ends past its middle).
//! A contact is always rigid (compliance 0) and inactive while `C >= 0`; the margin lets it catch
//! a particle that the internal constraints push into the shape during the iterations.
//!
//! A mesh collider reads `phi` and `n` from its distance field (trilinear between the lattice's
//! nodes, `n` the normalised gradient) and takes `q = p - phi n`; it is solid too, and a particle
//! outside the field's lattice gets no contact. The model's normal is frozen for the substep, so
//! no derivative of `n` (no curvature term) enters the projection. Its contact is **continuous**:
//! a particle whose motion over the substep is longer than its distance to the surface has its
//! path from `x` to `p` marched through the field by conservative advancement, and where the
//! path first comes within the thickness, at `y`, the contact takes `q = y - phi(y) n(y)` and
//! `n(y)` (a speculative contact from the start of the motion, as Bridson et al. 2002 stop cloth
//! before a collision rather than after it; `collide/sweep.rs`). A plate thinner than the motion
//! then stops the particle on its near side: particles and a cloth thrown at a 1 cm mesh plate
//! stay on it at 20 to 50 m/s and, measured by `cargo xtask stability`, at every speed tried up
//! to 10 km/s (the analytic box of the same plate lets particles through from 2 m/s at a
//! substep of 1/240 s). The field still has to see the plate: a plate thinner than the field's
//! spacing may have no node inside it and read as a dip of the distance, caught only within the
//! thickness of its top.
//!
//! **Friction** is positional (Macklin et al. 2014, "Unified particle physics", eq. 24): after a
//! projection that pushed the particle out by `d`, its tangential motion relative to the obstacle
//! over the step, `dx_t`, is removed entirely when `|dx_t| < mu_s d` (static friction) and
//! shortened by `min(mu_k d, |dx_t|)` otherwise (kinetic friction). A particle resting on a
//! surface under gravity `g` therefore sticks while its tangential speed is below
//! `mu_s g h` and slides with deceleration `mu_k g`.
//!
//! Limitation: the friction test runs in every iteration against that iteration's normal
//! correction. When a large step is solved by many iterations of one substep, internal
//! constraints that keep pulling a particle into a curved surface can keep it inside the static
//! cone, and a stretched cloth can stay locked on a frictional sphere (measured by
//! `cargo xtask stability`: 54% to 76% stretch at dt = 1/30 with 10 iterations and 1 substep,
//! 11% to 12% with 1 iteration and 10 substeps). Use substeps for such scenes (the drape scene
//! uses 4 and ends below 3%); friction from accumulated multipliers (Müller et al. 2020) would
//! remove this and is not implemented.
//!
//! **Restitution** is applied in the loop's `velocityUpdate` (line 16) as in Müller et al. 2020
//! ("Detailed rigid body simulation with extended position based dynamics", eq. 34): a contact
//! whose normal velocity before the solve, `v_n^-`, was approaching faster than `2 |g| h` leaves
//! with `v_n = -e v_n^-`; slower contacts get `v_n = 0` (no jitter at rest).
//!
//! # Moving obstacles
//!
//! A collider or an attachment may belong to a [`KinematicBody`], whose pose follows a
//! [`BodyMotion`] of time (or a target set between steps with
//! [`PbdSimulation::set_body_target`](crate::PbdSimulation::set_body_target)). Within a step the
//! pose moves linearly from its start to its end; substeps see the interpolated pose and friction
//! acts relative to the body's velocity at the contact point (`x^obs, v^obs`).
//!
//! # Contacts between bodies
//!
//! Particles do not collide with each other, except across **contact bodies**
//! ([`PbdBuilder::contact_body`](crate::PbdBuilder::contact_body)): a range of particles with the
//! triangles of its surface. Every particle of a contact body is tested against the surface
//! triangles of the other contact bodies (not its own: there is no self-collision), with the
//! thickness and friction of [`BodyContact`]; `sim/body_contacts.rs` has the constraint.

use anim_core::glam::{DQuat, DVec3};

mod mesh;
#[cfg(test)]
mod mesh_tests;
mod sweep;

pub use mesh::MeshCollider;
pub(crate) use sweep::first_touch;

/// A rigid pose: `world = position + rotation * local`.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct Pose {
    /// Translation.
    pub position: DVec3,
    /// Rotation (unit quaternion).
    pub rotation: DQuat,
}

impl Default for Pose {
    fn default() -> Self {
        Self::IDENTITY
    }
}

impl Pose {
    /// No translation, no rotation.
    pub const IDENTITY: Pose = Pose { position: DVec3::ZERO, rotation: DQuat::IDENTITY };

    /// A translation.
    #[must_use]
    pub fn from_translation(p: [f64; 3]) -> Self {
        Self { position: DVec3::from_array(p), rotation: DQuat::IDENTITY }
    }

    /// Maps a local point to world space.
    #[inline]
    #[must_use]
    pub fn apply(&self, local: DVec3) -> DVec3 {
        self.position + self.rotation * local
    }

    /// Maps a world point to the local frame.
    #[inline]
    #[must_use]
    pub fn inverse_apply(&self, world: DVec3) -> DVec3 {
        self.rotation.inverse() * (world - self.position)
    }

    /// Linear interpolation of the position and spherical interpolation of the rotation.
    #[must_use]
    pub fn lerp(&self, other: &Pose, s: f64) -> Pose {
        Pose {
            position: self.position.lerp(other.position, s),
            rotation: self.rotation.slerp(other.rotation, s),
        }
    }
}

/// How a kinematic body moves: a function of time from its initial pose.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(rename_all = "kebab-case"))]
pub enum BodyMotion {
    /// It stays where it is.
    Fixed,
    /// Constant linear velocity (m/s) and angular velocity (rad/s, about its own origin).
    Constant {
        /// Linear velocity.
        velocity: [f64; 3],
        /// Angular velocity.
        angular_velocity: [f64; 3],
    },
    /// Translation `amplitude * sin(2 pi frequency t)`.
    Oscillate {
        /// Amplitude (m) per axis.
        amplitude: [f64; 3],
        /// Frequency (Hz).
        frequency: f64,
    },
}

/// A body that moves by prescription and carries colliders and attachment points.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
pub struct KinematicBody {
    /// Pose at time 0.
    pub pose: Pose,
    /// Motion from that pose.
    pub motion: BodyMotion,
    /// What the body looks like in pictures, in its own frame (the flag's pole): drawn where
    /// the body is at each frame, never collided with (give the body a [`Collider`] for that).
    #[cfg_attr(feature = "serde", serde(default))]
    pub look: Option<Shape>,
}

impl KinematicBody {
    /// A body at `pose` following `motion`, with no look.
    #[must_use]
    pub fn new(pose: Pose, motion: BodyMotion) -> Self {
        Self { pose, motion, look: None }
    }

    /// The body drawn as `shape` (in its own frame) wherever it moves; see
    /// [`KinematicBody::look`].
    #[must_use]
    pub fn with_look(mut self, shape: Shape) -> Self {
        self.look = Some(shape);
        self
    }

    /// The body's look placed at its pose at time `t`, in the world frame: a sphere or capsule
    /// moved and turned with the body, a box moved (drawn axis-aligned: a box look is kept only
    /// by a body that does not turn). `None` without a look, for a plane, or for a box on a
    /// turned body.
    #[must_use]
    pub fn look_at(&self, t: f64) -> Option<Shape> {
        let pose = self.pose_at(t);
        let at = |p: [f64; 3]| pose.apply(DVec3::from_array(p)).to_array();
        match self.look? {
            Shape::Sphere { center, radius } => Some(Shape::Sphere { center: at(center), radius }),
            Shape::Capsule { a, b, radius } => Some(Shape::Capsule { a: at(a), b: at(b), radius }),
            Shape::Box { center, half_extents } if pose.rotation.angle_between(DQuat::IDENTITY) < 1e-12 => {
                Some(Shape::Box { center: at(center), half_extents })
            }
            Shape::Box { .. } | Shape::Plane { .. } => None,
        }
    }

    /// Pose at time `t`.
    #[must_use]
    pub fn pose_at(&self, t: f64) -> Pose {
        match self.motion {
            BodyMotion::Fixed => self.pose,
            BodyMotion::Constant { velocity, angular_velocity } => {
                let w = DVec3::from_array(angular_velocity);
                let angle = w.length() * t;
                let rot =
                    if angle > 0.0 { DQuat::from_axis_angle(w.normalize(), angle) } else { DQuat::IDENTITY };
                Pose {
                    position: self.pose.position + t * DVec3::from_array(velocity),
                    rotation: (rot * self.pose.rotation).normalize(),
                }
            }
            BodyMotion::Oscillate { amplitude, frequency } => Pose {
                position: self.pose.position
                    + DVec3::from_array(amplitude) * (std::f64::consts::TAU * frequency * t).sin(),
                rotation: self.pose.rotation,
            },
        }
    }
}

/// A collider's geometry, in the frame of its body (or in world space): anim-core's shared
/// [`Shape`] (plane, sphere, box, capsule), re-exported here.
pub use anim_core::geometry::Shape;

/// A collider: a geometry on an optional kinematic body, with its contact parameters. The
/// geometry is a [`Shape`] (the default, `Collider`), or the signed distance field of a closed
/// triangle mesh ([`MeshCollider`], `Collider<DistanceField>`); the contact parameters, their
/// setters and their checks are the same for both.
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields))]
pub struct Collider<G = Shape> {
    /// The geometry (in the body's frame when `body` is set): a [`Shape`], or a mesh's
    /// [`DistanceField`](anim_core::surface::DistanceField).
    pub shape: G,
    /// The kinematic body carrying it, if any.
    pub body: Option<usize>,
    /// Distance kept between particle centres and the surface (m, >= 0; a particle radius).
    pub thickness: f64,
    /// Static friction coefficient `mu_s >= 0`.
    pub static_friction: f64,
    /// Kinetic friction coefficient `0 <= mu_k` (at most `mu_s` is physical but not required).
    pub kinetic_friction: f64,
    /// Coefficient of restitution `e` in `[0, 1]`.
    pub restitution: f64,
}

impl<G> Collider<G> {
    /// A collider of the geometry `shape`, fixed in world space, with no thickness, no friction
    /// and no restitution.
    #[must_use]
    pub fn new(shape: G) -> Self {
        Self {
            shape,
            body: None,
            thickness: 0.0,
            static_friction: 0.0,
            kinetic_friction: 0.0,
            restitution: 0.0,
        }
    }

    /// Sets the thickness.
    #[must_use]
    pub fn with_thickness(mut self, thickness: f64) -> Self {
        self.thickness = thickness;
        self
    }

    /// Sets static and kinetic friction.
    #[must_use]
    pub fn with_friction(mut self, static_friction: f64, kinetic_friction: f64) -> Self {
        self.static_friction = static_friction;
        self.kinetic_friction = kinetic_friction;
        self
    }

    /// Sets the restitution.
    #[must_use]
    pub fn with_restitution(mut self, e: f64) -> Self {
        self.restitution = e;
        self
    }

    /// Puts the collider on kinematic body `body` (the geometry is then in the body's frame).
    #[must_use]
    pub fn on_body(mut self, body: usize) -> Self {
        self.body = Some(body);
        self
    }

    /// The coefficients `(mu_s, mu_k, e)`.
    #[inline]
    pub(crate) fn coefficients(&self) -> (f64, f64, f64) {
        (self.static_friction, self.kinetic_friction, self.restitution)
    }

    /// Checks the contact parameters: thickness and friction non-negative and finite,
    /// restitution in `[0, 1]`, the body among `bodies`; the reason on failure.
    pub(crate) fn check_contact(&self, bodies: usize) -> Result<(), String> {
        let nonneg = |v: f64| v >= 0.0 && v.is_finite();
        if !nonneg(self.thickness) {
            return Err(format!("thickness must be non-negative and finite, got {}", self.thickness));
        }
        if !nonneg(self.static_friction) || !nonneg(self.kinetic_friction) {
            return Err(format!(
                "friction coefficients must be non-negative and finite, got {} and {}",
                self.static_friction, self.kinetic_friction
            ));
        }
        if !(0.0..=1.0).contains(&self.restitution) {
            return Err(format!("restitution must lie in [0, 1], got {}", self.restitution));
        }
        if let Some(b) = self.body
            && b >= bodies
        {
            return Err(format!("body {b} does not exist (the model has {bodies} kinematic bodies)"));
        }
        Ok(())
    }
}

impl Collider {
    /// The ground plane `z = height` (z up, the scenes' convention).
    #[must_use]
    pub fn ground(height: f64) -> Self {
        Self::new(Shape::ground(height))
    }

    /// A sphere.
    #[must_use]
    pub fn sphere(center: [f64; 3], radius: f64) -> Self {
        Self::new(Shape::Sphere { center, radius })
    }

    /// An axis-aligned box (rotate it by putting it on a body).
    #[must_use]
    pub fn cuboid(center: [f64; 3], half_extents: [f64; 3]) -> Self {
        Self::new(Shape::Box { center, half_extents })
    }

    /// A capsule around the segment `a b`.
    #[must_use]
    pub fn capsule(a: [f64; 3], b: [f64; 3], radius: f64) -> Self {
        Self::new(Shape::Capsule { a, b, radius })
    }

    /// Checks the parameters; the collider with its shape normalised, or the reason.
    pub(crate) fn validate(&self, bodies: usize) -> Result<Collider, String> {
        self.shape.check()?;
        let mut c = *self;
        c.shape = c.shape.normalized();
        c.check_contact(bodies)?;
        Ok(c)
    }
}

/// The coefficients `(mu_s, mu_k, e)` of contact collider `ci`: the shape colliders are numbered
/// first, the mesh colliders after them.
#[inline]
pub(crate) fn coefficients(colliders: &[Collider], meshes: &[MeshCollider], ci: usize) -> (f64, f64, f64) {
    match colliders.get(ci) {
        Some(c) => c.coefficients(),
        None => meshes[ci - colliders.len()].coefficients(),
    }
}

/// The contact parameters between contact bodies
/// ([`PbdBuilder::contact_body`](crate::PbdBuilder::contact_body)), set with
/// [`PbdBuilder::body_contact`](crate::PbdBuilder::body_contact).
#[derive(Debug, Clone, Copy, PartialEq)]
#[cfg_attr(feature = "serde", derive(serde::Serialize, serde::Deserialize))]
#[cfg_attr(feature = "serde", serde(deny_unknown_fields, default))]
pub struct BodyContact {
    /// Distance kept between a particle of one body and the surface of another (m, > 0).
    /// Default `0.005`, as a scene's (`kind::DEFAULT_THICKNESS`).
    pub thickness: f64,
    /// Static friction coefficient `mu_s >= 0` between bodies. Default 0.
    pub static_friction: f64,
    /// Kinetic friction coefficient `mu_k >= 0` between bodies. Default 0.
    pub kinetic_friction: f64,
}

impl Default for BodyContact {
    fn default() -> Self {
        Self { thickness: DEFAULT_THICKNESS, static_friction: 0.0, kinetic_friction: 0.0 }
    }
}

/// The default contact thickness between bodies (m), a scene's as well.
pub(crate) const DEFAULT_THICKNESS: f64 = 0.005;

impl BodyContact {
    /// Checks the parameters; the reason on failure.
    pub(crate) fn validate(&self) -> Result<(), String> {
        if !(self.thickness > 0.0 && self.thickness.is_finite()) {
            return Err(format!("thickness must be positive and finite, got {}", self.thickness));
        }
        let nonneg = |v: f64| v >= 0.0 && v.is_finite();
        if !nonneg(self.static_friction) || !nonneg(self.kinetic_friction) {
            return Err(format!(
                "friction coefficients must be non-negative and finite, got {} and {}",
                self.static_friction, self.kinetic_friction
            ));
        }
        Ok(())
    }
}

/// A contact generated at line (8) of the loop; lives for one (sub)step.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(crate) struct Contact {
    /// The particle.
    pub particle: u32,
    /// The collider: a shape collider's index, or the number of shape colliders plus a mesh
    /// collider's index.
    pub collider: u32,
    /// Outward normal at the contact point.
    pub normal: DVec3,
    /// `n . q + thickness`: the constraint is `n . p - offset >= 0`.
    pub offset: f64,
    /// Obstacle displacement at the contact point over the substep.
    pub obstacle_dx: DVec3,
    /// Normal velocity relative to the obstacle before the solve.
    pub vn_pre: f64,
    /// Accumulated normal correction (PBD) or multiplier (XPBD) this substep.
    pub lambda: f64,
    /// The last correction (parallel sweeps compute it, then apply it).
    pub dx: DVec3,
}
