//! [`BodyScene`]: a fluid of bodies in its tank, stepped and checkpointed as the
//! [`FlipSimulation`] it holds, drawn in the scene file's frame (the tank's inside from the
//! origin, y up like every view's frames), with its obstacles.

use crate::kind::{widened, widened_box};
use crate::particles::Particles;
use crate::sim::FlipSimulation;
use anim_core::geometry::Shape;
use anim_core::scene::{Checkpoint, CheckpointError, Context, Frame, MeshProp, Prop, View};
use anim_core::solver::{Solver, StepReport};

/// A fluid of bodies: the simulation, whose grid starts at the outer corner of the walls, and
/// what drawing it needs.
#[derive(Debug, Clone)]
pub struct BodyScene<const D: usize> {
    /// The simulation (obstacle cells solid).
    pub sim: FlipSimulation<D>,
    /// The tank's inside corner in the simulation's frame: a particle at `x` there is at
    /// `x - origin` in the scene file's frame.
    pub origin: [f64; D],
    /// The obstacle shapes, in the scene file's frame (drawn as props).
    pub obstacles: Vec<Shape>,
    /// The mesh obstacles as drawn (the scene file's frame).
    pub meshes: Vec<MeshProp>,
}

impl<const D: usize> BodyScene<D> {
    pub(crate) fn new(
        sim: FlipSimulation<D>,
        origin: [f64; D],
        obstacles: Vec<Shape>,
        meshes: Vec<MeshProp>,
    ) -> Self {
        Self { sim, origin, obstacles, meshes }
    }

    /// A point of the simulation's frame in the scene file's frame.
    #[must_use]
    pub fn to_scene(&self, x: &[f64; D]) -> [f64; D] {
        std::array::from_fn(|a| x[a] - self.origin[a])
    }
}

/// The prop an obstacle shape of a `D`-dimensional scene is drawn as; planes none.
fn prop<const D: usize>(shape: &Shape) -> Option<Prop> {
    // The first `D` components (in 2D the plane z = 0).
    let cut = |v: [f64; 3]| -> [f64; D] { std::array::from_fn(|k| v[k]) };
    match *shape {
        Shape::Sphere { center, radius } => Some(Prop::Sphere { center: widened(&cut(center)), radius }),
        Shape::Capsule { a, b, radius } => {
            Some(Prop::Capsule { a: widened(&cut(a)), b: widened(&cut(b)), radius })
        }
        Shape::Box { center, half_extents: e } => {
            let (lo, hi) = widened_box::<D>(
                &std::array::from_fn(|k| center[k] - e[k]),
                &std::array::from_fn(|k| center[k] + e[k]),
            );
            Some(Prop::Cuboid { lo, hi })
        }
        Shape::Plane { .. } => None,
    }
}

impl<const D: usize> Solver for BodyScene<D> {
    type State = Particles<D>;
    type Error = crate::FlipError;

    fn step(&mut self, state: &mut Particles<D>, dt: f64) -> Result<StepReport, crate::FlipError> {
        self.sim.step(state, dt)
    }
}

/// The simulation's checkpoint ([`FlipSimulation`]'s, positions in its frame).
impl<const D: usize> Checkpoint for BodyScene<D> {
    const VERSION: u32 = <FlipSimulation<D> as Checkpoint>::VERSION;

    fn time(&self, _: &Particles<D>) -> f64 {
        self.sim.time()
    }

    fn save(&self, particles: &Particles<D>) -> serde_json::Value {
        Checkpoint::save(&self.sim, particles)
    }

    fn restore(
        &mut self,
        particles: &mut Particles<D>,
        saved: &serde_json::Value,
    ) -> Result<(), CheckpointError> {
        Checkpoint::restore(&mut self.sim, particles, saved)
    }

    fn provoke_overflow(&mut self, particles: &mut Particles<D>) -> Option<String> {
        self.sim.provoke_overflow(particles)
    }
}

impl<const D: usize> View for BodyScene<D> {
    fn method(&self) -> String {
        View::method(&self.sim)
    }

    /// Particles drawn as discs of a quarter cell, the tank's inner walls (from the origin to
    /// 1 m; they are also the bounds) and the obstacle shapes but planes.
    fn context(&self, _: &Particles<D>) -> Context {
        let (lo, hi) = self.sim.fluid_box();
        let tank = widened_box(&self.to_scene(&lo), &self.to_scene(&hi));
        let mut context = Context::default();
        context.point_dim = 3;
        context.planar = D == 2;
        context.point_radius = 0.25 * self.sim.grid().h();
        context.props.push(Prop::Tank { lo: tank.0, hi: tank.1 });
        context.props.extend(self.obstacles.iter().filter_map(prop::<D>));
        context.mesh_props.clone_from(&self.meshes);
        context.bounds = Some(tank);
        context
    }

    fn frame(&self, particles: &Particles<D>, out: &mut Frame) {
        out.time = self.sim.time();
        out.points.clear();
        for x in &particles.x {
            out.points.extend(widened(&self.to_scene(x)));
        }
        let velocity = out.field_mut("velocity", 3);
        for v in &particles.v {
            velocity.extend(widened(v));
        }
    }
}
