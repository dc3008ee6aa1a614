//! The memory a scene of [`scenes`] will take, estimated from its name, resolution and method
//! before anything is built, so the `springs` kind refuses a size the machine cannot hold
//! (anim-core's [`MemoryNeed`]) instead of aborting halfway through the build.
//!
//! The parts, per item (sizes from the types of `network` and anim-core's integrators):
//!
//! | part | bytes | what |
//! | --- | --- | --- |
//! | particles | 320 (velocity Verlet, symplectic Euler), 400 (implicit), + 144 with a ground or collider | the model (mass, pin, rest position, inverse mass, incidence offsets), the state, the integrator's vectors, the contact Jacobians |
//! | frame points, written points | 48, 330 | the frame a view fills (position and velocity, `f64`) and what a run holds to write it (anim-core's `FRAME_POINT_BYTES`, `WRITTEN_POINT_BYTES`) |
//! | springs | 216 | the spring, its compact ends and `[l, k, c]`, two incidences, the force and linearisation scratch, the pattern slots; its line in the view's context and the drawing's copy |
//! | triangles | 72 | the triangles drawn (the cloth, the jelly's faces), in the model, the view's context and the drawing's copy |
//! | matrix blocks | 144 | a 3x3 block of the assembled Jacobian (values and column indices), one per particle and two per spring, with an implicit integrator and a solver on the assembled matrix |
//! | factor blocks | 144 | a 3x3 block of the sparse Cholesky factor (anim-core's [`cholesky_factor_blocks`] of the lattice: the cloth's 2D grid, the jelly's 3D one) |

use crate::network::{MAX_PARTICLES, MAX_SPRINGS};
use crate::scenes;
use anim_core::integrate::IntegratorKind;
use anim_core::linalg::LinearSolverKind;
use anim_core::scene::{BuildError, MemoryNeed, cholesky_factor_blocks};

/// The counts of a network as the builders make them.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct NetworkSize {
    /// Particles.
    pub particles: f64,
    /// Springs.
    pub springs: f64,
    /// Triangles (cloth).
    pub triangles: f64,
    /// The particles along each side of the lattice the springs connect (one side for a
    /// chain, two for a cloth, three for a lattice): how a Cholesky factor fills.
    pub sides: [f64; 3],
    /// Whether the network has a collider (contact Jacobians per particle).
    pub contact: bool,
}

impl NetworkSize {
    /// The counts of the scene `name` at `n` particles per side (particles of the rope), in
    /// `f64` so that no size overflows; `None` for an unknown name.
    #[must_use]
    pub fn of_scene(name: &str, n: usize) -> Option<Self> {
        let n = n as f64;
        Some(match name {
            // Structural 2 n (n - 1), shear 2 (n - 1)^2, bending 2 n (n - 2); 2 (n - 1)^2 triangles.
            "hanging-cloth" | "benchmark-cloth" => Self {
                particles: n * n,
                springs: 2.0 * n * (n - 1.0) + 2.0 * (n - 1.0) * (n - 1.0) + 2.0 * n * (n - 2.0).max(0.0),
                triangles: 2.0 * (n - 1.0) * (n - 1.0),
                sides: [n, n, 1.0],
                contact: false,
            },
            "swinging-rope" => {
                Self { particles: n, springs: n - 1.0, triangles: 0.0, sides: [n, 1.0, 1.0], contact: false }
            }
            // Edges 3 n^2 (n - 1), face diagonals 6 n (n - 1)^2, body diagonals 4 (n - 1)^3;
            // two triangles per cell of the six faces.
            "jelly-drop" => Self {
                particles: n * n * n,
                springs: 3.0 * n * n * (n - 1.0) + 6.0 * n * (n - 1.0).powi(2) + 4.0 * (n - 1.0).powi(3),
                triangles: 12.0 * (n - 1.0) * (n - 1.0),
                sides: [n, n, n],
                contact: true,
            },
            _ => return None,
        })
    }

    /// The memory of a simulation of this network stepped by `integrator` with `linear`.
    #[must_use]
    pub fn need(&self, integrator: IntegratorKind, linear: LinearSolverKind) -> MemoryNeed {
        let implicit = integrator.is_implicit();
        let per_particle = if implicit { 400.0 } else { 320.0 } + if self.contact { 144.0 } else { 0.0 };
        let mut need = MemoryNeed::new()
            .with(self.particles, "particles", per_particle)
            .with_frame_points(self.particles)
            .with(self.springs, "springs", 216.0)
            .with(self.triangles, "triangles", 72.0);
        let assembled = !matches!(linear, LinearSolverKind::Cg | LinearSolverKind::JacobiPcg);
        if implicit && assembled {
            need.add(self.particles + 2.0 * self.springs, "matrix blocks", 144.0);
            if linear == LinearSolverKind::Cholesky {
                let sides: Vec<f64> = self.sides.into_iter().filter(|&s| s > 1.0).collect();
                // The stencil's constant, faer's factor measured against the law: 8.1 to 9.7 on
                // the cloth from 48 to 384 particles a side (George's count for nested
                // dissection is 7.75), 14 to 15.4 on the jelly from 16 to 36, 2 on the chain.
                let c = match sides.len() {
                    0 | 1 => 2.0,
                    2 => 9.5,
                    _ => 15.0,
                };
                need.add(cholesky_factor_blocks(&sides, c), "Cholesky factor blocks", 144.0);
            }
        }
        need
    }

    /// Refuses counts beyond the network's `u32` indices ([`MAX_PARTICLES`], [`MAX_SPRINGS`]).
    ///
    /// # Errors
    /// [`BuildError::Invalid`] of `field` naming the count and its bound.
    pub fn check_indices(&self, field: &str) -> Result<(), BuildError> {
        for (what, count, max) in
            [("particles", self.particles, MAX_PARTICLES), ("springs", self.springs, MAX_SPRINGS)]
        {
            if count > max as f64 {
                return Err(BuildError::invalid(
                    field,
                    format!("makes {count:.3e} {what}, more than the {max} a network indexes"),
                ));
            }
        }
        Ok(())
    }
}

/// The memory of the scene `name` at `resolution` (its default when `None`), stepped by
/// `integrator` and `linear` (the scene's own when `None`); `None` for an unknown name.
#[must_use]
pub fn scene_need(
    name: &str,
    resolution: Option<usize>,
    integrator: Option<IntegratorKind>,
    linear: Option<LinearSolverKind>,
) -> Option<MemoryNeed> {
    let (default, _) = scenes::resolution_range(name)?;
    let (own_integrator, own_linear) = scenes::method(name)?;
    let size = NetworkSize::of_scene(name, resolution.unwrap_or(default))?;
    Some(size.need(integrator.unwrap_or(own_integrator), linear.unwrap_or(own_linear)))
}

/// Refuses the scene `name` at `resolution` when its memory ([`scene_need`]) exceeds what is
/// available, or its counts the network's indices. Unknown names and resolutions below the
/// scene's smallest pass (the scene's builder names them).
///
/// # Errors
/// [`BuildError::Memory`] or [`BuildError::Invalid`] of `resolution`.
pub fn check_scene(
    name: &str,
    resolution: Option<usize>,
    integrator: Option<IntegratorKind>,
    linear: Option<LinearSolverKind>,
) -> Result<(), BuildError> {
    let (Some((default, min)), Some(need)) =
        (scenes::resolution_range(name), scene_need(name, resolution, integrator, linear))
    else {
        return Ok(());
    };
    let n = resolution.unwrap_or(default);
    if n < min {
        return Ok(());
    }
    let unit = if name == "swinging-rope" { "particles" } else { "particles per side" };
    need.check("resolution", &format!("{n} {unit}"))?;
    match NetworkSize::of_scene(name, n) {
        Some(size) => size.check_indices("resolution"),
        None => Ok(()),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_counts_are_those_the_scenes_build() {
        for (name, n) in
            [("hanging-cloth", 5), ("swinging-rope", 7), ("jelly-drop", 4), ("benchmark-cloth", 3)]
        {
            let scene = scenes::by_name(name, Some(n)).expect("known").expect("builds");
            let size = NetworkSize::of_scene(name, n).expect("known");
            assert_eq!(size.particles, (scene.state.x.len() / 3) as f64, "{name}");
            assert_eq!(size.springs, scene.network.num_springs() as f64, "{name}");
            assert_eq!(size.triangles, scene.network.triangles().len() as f64, "{name}");
            assert_eq!(size.contact, !scene.network.model().colliders().is_empty(), "{name}");
            assert_eq!(scenes::method(name), Some((scene.integrator, scene.linear_solver)), "{name}");
        }
    }

    #[test]
    fn the_matrix_and_factor_count_only_where_the_method_assembles_or_factors() {
        let size = NetworkSize::of_scene("hanging-cloth", 10).expect("known");
        let explicit = size.need(IntegratorKind::VelocityVerlet, LinearSolverKind::Cholesky).bytes();
        let cg = size.need(IntegratorKind::BackwardEuler, LinearSolverKind::Cg).bytes();
        let jacobi = size.need(IntegratorKind::BackwardEuler, LinearSolverKind::Jacobi).bytes();
        let cholesky = size.need(IntegratorKind::BackwardEuler, LinearSolverKind::Cholesky).bytes();
        assert_eq!(cg - explicit, 80.0 * 100.0, "only the implicit integrator's vectors");
        assert_eq!(jacobi - cg, 144.0 * (100.0 + 2.0 * size.springs));
        assert_eq!(cholesky - jacobi, 144.0 * cholesky_factor_blocks(&[10.0, 10.0], 9.5));
    }

    #[test]
    fn a_size_beyond_the_indices_or_the_memory_is_refused_before_building() {
        let size = NetworkSize::of_scene("hanging-cloth", 1 << 17).expect("known");
        let e = size.check_indices("resolution").expect_err("refused");
        assert_eq!(
            e.to_string(),
            "field `resolution`: makes 1.718e10 particles, more than the 4294967295 a network indexes"
        );
        let size = NetworkSize::of_scene("jelly-drop", 600).expect("known");
        let e = size.check_indices("resolution").expect_err("refused");
        assert!(e.to_string().contains("springs, more than the 2147483647 a network indexes"), "{e}");
        assert!(NetworkSize::of_scene("jelly-drop", 500).expect("known").check_indices("r").is_ok());
        let e = check_scene("jelly-drop", Some(2000), None, None).expect_err("refused");
        let BuildError::Memory { bytes, .. } = &e else { panic!("{e:?}") };
        assert!(*bytes > 1e15, "{bytes}");
        assert!(e.to_string().starts_with("field `resolution`: 2000 particles per side needs about "), "{e}");
        assert!(check_scene("swinging-rope", Some(1000), None, None).is_ok());
        assert!(check_scene("swinging-rope", Some(1), None, None).is_ok(), "the scene names it");
        assert!(check_scene("flying-carpet", Some(1), None, None).is_ok(), "the kind names it");
    }
}
