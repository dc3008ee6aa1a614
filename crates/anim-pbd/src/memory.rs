//! The memory a scene of [`scenes`] will take, estimated from its name and resolution before
//! anything is built, so the `pbd` kind refuses a size the machine cannot hold (anim-core's
//! [`MemoryNeed`]) instead of aborting halfway through the build.
//!
//! The parts, per item (sizes of the types of `model`, `constraint` and the
//! solver's scratch):
//!
//! | part | bytes | what |
//! | --- | --- | --- |
//! | particles | 210, + 104 per collider | the particle, inverse mass and rest position, the state, the solver's positions, velocities and predictions, the external forces; a contact slot reserved per collider |
//! | constraints | 360 (sequential Gauss-Seidel), 420 (coloured Gauss-Seidel) | the builder's and the model's constraint (112 B each), the compiled copy (112 B), the multiplier and the incidences; the coloured sweep's buffered corrections |
//! | frame points, written points | 48, 330 | the frame a view fills (position and velocity, `f64`) and what a run holds to write it (anim-core's `FRAME_POINT_BYTES`, `WRITTEN_POINT_BYTES`) |
//! | triangles | 84 (48 more in a global volume) | the triangle and its incidences; in the view's context and the drawing's copy |
//! | edges | 32 | a rope's link in the view's context and the drawing's copy |
//! | tetrahedra | 72 | the tetrahedron and its lattice cell's share while the blob is made; in the view's context |

use crate::scenes;
use anim_core::scene::{BuildError, MemoryNeed};

/// The counts of a model as the scenes build it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ModelSize {
    /// Particles.
    pub particles: f64,
    /// Constraints.
    pub constraints: f64,
    /// Triangles (drawn; of a global volume as well for the balloon).
    pub triangles: f64,
    /// Edges drawn (a rope's links).
    pub edges: f64,
    /// Tetrahedra.
    pub tets: f64,
    /// Shape colliders (a contact slot each per particle).
    pub colliders: f64,
    /// Whether the solver sweeps colours (buffered corrections per constraint).
    pub coloured: bool,
    /// Whether the triangles also make a global volume constraint.
    pub volume: bool,
}

impl ModelSize {
    /// The counts of the scene `name` at resolution `n` (in `f64`, so no size overflows);
    /// `None` for an unknown name. The blob's are estimated from the volume of its union of
    /// spheres (about `4.6 r^3`: 0.575 lattice cells per `cells^3`) and the lattice's vertices
    /// and edges per cell, within 10% of its mesh; the others are exact.
    #[must_use]
    pub fn of_scene(name: &str, n: usize) -> Option<Self> {
        let n = n as f64;
        // An nx x ny grid of particles cut into triangles: 3 (nx-1)(ny-1) + (nx-1) + (ny-1) edges
        // (distances) and 3 (nx-1)(ny-1) - (nx-1) - (ny-1) interior ones (bending).
        let cloth = |nx: f64, ny: f64, colliders: f64, coloured: bool| {
            let cells = (nx - 1.0) * (ny - 1.0);
            Self {
                particles: nx * ny,
                constraints: 6.0 * cells,
                triangles: 2.0 * cells,
                tets: 0.0,
                edges: 0.0,
                colliders,
                coloured,
                volume: false,
            }
        };
        Some(match name {
            "cloth-drape" => cloth(n, n, 2.0, true),
            "flag" => {
                let nz = (2.0 * n / 3.0).ceil().max(2.0);
                let mut flag = cloth(n, nz, 1.0, true);
                flag.constraints += nz;
                flag
            }
            "hanging-cloth" | "benchmark-cloth" => cloth(n, n, 0.0, false),
            "rope" => Self {
                particles: n + 1.0,
                constraints: n,
                triangles: 0.0,
                tets: 0.0,
                edges: n,
                colliders: 3.0,
                coloured: false,
                volume: false,
            },
            "soft-blob" => {
                // 0.575 cells^3 lattice cells C, 6 tetrahedra each (a volume constraint each);
                // 7 edges per cell (a distance each) and C + 4.1 C^(2/3) vertices, with the
                // surface's share (11.8 C^(2/3) edges) measured on the blob from 6 to 48 cells.
                let cells = 0.575 * n * n * n;
                let surface = cells.powf(2.0 / 3.0);
                Self {
                    particles: cells + 4.1 * surface,
                    constraints: 13.0 * cells + 11.8 * surface,
                    triangles: 0.0,
                    tets: 6.0 * cells,
                    edges: 0.0,
                    colliders: 1.0,
                    coloured: true,
                    volume: false,
                }
            }
            "balloon" => {
                // An icosphere subdivided n times: 10 4^n + 2 vertices, 30 4^n edges, 20 4^n
                // triangles; a distance and a bending constraint per edge, one global volume.
                let k = 4f64.powf(n);
                Self {
                    particles: 10.0 * k + 2.0,
                    constraints: 60.0 * k + 1.0,
                    triangles: 20.0 * k,
                    tets: 0.0,
                    edges: 0.0,
                    colliders: 2.0,
                    coloured: true,
                    volume: true,
                }
            }
            _ => return None,
        })
    }

    /// The memory of a simulation of this model.
    #[must_use]
    pub fn need(&self) -> MemoryNeed {
        let per_constraint = if self.coloured { 420.0 } else { 360.0 };
        let per_triangle = if self.volume { 132.0 } else { 84.0 };
        MemoryNeed::new()
            .with(self.particles, "particles", 210.0 + 104.0 * self.colliders)
            .with_frame_points(self.particles)
            .with(self.constraints, "constraints", per_constraint)
            .with(self.triangles, "triangles", per_triangle)
            .with(self.edges, "edges", 32.0)
            .with(self.tets, "tetrahedra", 72.0)
    }

    /// Refuses counts beyond the model's `u32` indices.
    ///
    /// # Errors
    /// [`BuildError::Invalid`] of `field` naming the count and its bound.
    pub fn check_indices(&self, field: &str) -> Result<(), BuildError> {
        let max = f64::from(u32::MAX - 1);
        for (what, count) in [("particles", self.particles), ("constraints", self.constraints)] {
            if count > max {
                return Err(BuildError::invalid(
                    field,
                    format!("makes {count:.3e} {what}, more than the {max} a model indexes"),
                ));
            }
        }
        Ok(())
    }
}

/// What a scene's resolution counts, for the refusal.
fn unit(name: &str) -> &'static str {
    match name {
        "flag" => "particles across",
        "rope" => "links",
        "soft-blob" => "cells across",
        "balloon" => "subdivisions",
        _ => "particles per side",
    }
}

/// The memory of the scene `name` at `resolution` (its default when `None`); `None` for an
/// unknown name.
#[must_use]
pub fn scene_need(name: &str, resolution: Option<usize>) -> Option<MemoryNeed> {
    let (default, _) = scenes::resolution_range(name)?;
    Some(ModelSize::of_scene(name, resolution.unwrap_or(default))?.need())
}

/// Refuses the scene `name` at `resolution` when its memory ([`scene_need`]) exceeds what is
/// available, or its counts the model's indices. Unknown names and resolutions below the
/// scene's smallest pass (the scene's builder names them).
///
/// # Errors
/// [`BuildError::Memory`] or [`BuildError::Invalid`] of `resolution`.
pub fn check_scene(name: &str, resolution: Option<usize>) -> Result<(), BuildError> {
    let Some((default, min)) = scenes::resolution_range(name) else { return Ok(()) };
    let n = resolution.unwrap_or(default);
    let Some(size) = ModelSize::of_scene(name, n).filter(|_| n >= min) else { return Ok(()) };
    size.need().check("resolution", &format!("{n} {}", unit(name)))?;
    size.check_indices("resolution")
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_counts_are_those_the_scenes_build() {
        for (name, n) in [
            ("cloth-drape", 5),
            ("flag", 7),
            ("rope", 9),
            ("balloon", 2),
            ("hanging-cloth", 4),
            ("benchmark-cloth", 3),
        ] {
            let scene = scenes::by_name(name, Some(n)).expect("known").expect("builds");
            let size = ModelSize::of_scene(name, n).expect("known");
            let m = &scene.model;
            assert_eq!(size.particles, m.num_particles() as f64, "{name}");
            assert_eq!(size.constraints, m.num_constraints() as f64, "{name}");
            assert_eq!(size.triangles, m.triangles().len() as f64, "{name}");
            assert_eq!(size.edges, m.edges().len() as f64, "{name}");
            assert_eq!(size.colliders, m.colliders().len() as f64, "{name}");
            assert_eq!(size.coloured, scene.params.solver == crate::SolverKind::ColoredGaussSeidel, "{name}");
        }
        // The blob's counts come from the volume of its spheres: within 15% of the mesh's.
        for n in [6, 24] {
            let scene = scenes::by_name("soft-blob", Some(n)).expect("known").expect("builds");
            let size = ModelSize::of_scene("soft-blob", n).expect("known");
            let m = &scene.model;
            for (what, estimate, built) in [
                ("particles", size.particles, m.num_particles()),
                ("constraints", size.constraints, m.num_constraints()),
                ("tets", size.tets, m.tets().len()),
            ] {
                let ratio = estimate / built as f64;
                assert!((0.85..=1.15).contains(&ratio), "blob {n}: {what} {estimate} against {built}");
            }
        }
    }

    #[test]
    fn a_size_beyond_the_memory_or_the_indices_is_refused_before_building() {
        let e = check_scene("cloth-drape", Some(1_000_000_000)).expect_err("refused");
        let BuildError::Memory { bytes, .. } = &e else { panic!("{e:?}") };
        assert!(*bytes > 1e20, "{bytes}");
        assert!(
            e.to_string().starts_with("field `resolution`: 1000000000 particles per side needs about "),
            "{e}"
        );
        let e = check_scene("balloon", Some(40)).expect_err("refused");
        assert!(e.to_string().starts_with("field `resolution`: 40 subdivisions needs about "), "{e}");
        let size = ModelSize::of_scene("rope", 5_000_000_000).expect("known");
        let e = size.check_indices("resolution").expect_err("refused");
        assert_eq!(
            e.to_string(),
            "field `resolution`: makes 5.000e9 particles, more than the 4294967294 a model indexes"
        );
        assert!(check_scene("rope", Some(1000)).is_ok());
        assert!(check_scene("flag", Some(1)).is_ok(), "the scene names it");
    }
}
