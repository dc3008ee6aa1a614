//! The memory a `flip` scene will take, estimated from its tank and its water before the grid
//! or the particles exist, so the `flip` kind refuses a resolution the machine cannot hold
//! (anim-core's [`MemoryNeed`]) instead of aborting halfway through the build.
//!
//! The parts, per item (sizes of the buffers of `sim`, the MAC grid, the particles
//! and anim-fluid's pressure solver):
//!
//! | part | bytes (2D, 3D) | what |
//! | --- | --- | --- |
//! | grid cells | 214, 240 | the solid flags and labels, the cell bins' offsets, the pressure's right-hand side, solution and the volume correction's fields (50); per face axis the velocity, its copy before forces, the transfer's weights and the extrapolation's scratch and flags (34 D); the pressure solver, MGPCG: the operator, CG's vectors, the finest level's and the coarser levels' vectors (96, 88) |
//! | particles | 212, 380 | position, velocity and APIC's matrix (64 B, 120 B), their backup for a substepped step and their copy in cell order for the transfers, the bins' cell, order and rank |
//! | frame points, written points | 48, 330 | the frame a view fills (position and velocity, `f64`) and what a run holds to write it (anim-core's `FRAME_POINT_BYTES`, `WRITTEN_POINT_BYTES`) |
//! | lattice points | 1 | a scene of bodies marks the particle lattice of the whole tank as taken or not |

use crate::scenes;
use anim_core::scene::{BuildError, MemoryNeed};

/// The memory of a scene of `dim` dimensions of `cells` grid cells and `particles` particles.
#[must_use]
pub fn need(dim: usize, cells: f64, particles: f64) -> MemoryNeed {
    let three = dim >= 3;
    MemoryNeed::new()
        .with(cells, "grid cells", if three { 240.0 } else { 214.0 })
        .with(particles, "particles", if three { 380.0 } else { 212.0 })
        .with_frame_points(particles)
}

/// The grid cells and particles of the preset `name` at `n` cells across its 1 m tank (in
/// `f64`: a size of any magnitude counts); `None` for an unknown name. The particles are
/// those of the presets' lattice (2 per cell and axis) over the water's volume.
#[must_use]
pub fn preset_counts(name: &str, n: usize) -> Option<(usize, f64, f64)> {
    let n = n as f64;
    // The inside of the tank along an axis of `c` cells, one solid cell each side, in lattice
    // points.
    let inside = |c: f64| 2.0 * (c - 2.0);
    Some(match name {
        "dam-break-2d" => (2, n * ((0.8 * n).ceil() + 2.0), (0.5 * n) * n),
        "dam-break-3d" => (3, n * ((0.8 * n).ceil() + 2.0) * ((0.5 * n).ceil() + 2.0), 0.25 * n * n * n),
        "drop-2d" => {
            let disk = std::f64::consts::PI * (0.3 * n).powi(2);
            (2, n * n, inside(n) * (0.6 * n) + disk)
        }
        "drop-3d" => {
            let ball = 4.0 / 3.0 * std::f64::consts::PI * (0.3 * n).powi(3);
            (3, n * n * n, inside(n) * inside(n) * (0.6 * n) + ball)
        }
        "sloshing-tank" => {
            let ny = (0.5 * n).ceil() + 2.0;
            (2, n * ny, inside(n) * (0.5 * n))
        }
        _ => return None,
    })
}

/// The memory of the preset `name` at `resolution` cells across (its default when `None`);
/// `None` for an unknown name.
#[must_use]
pub fn preset_need(name: &str, resolution: Option<usize>) -> Option<MemoryNeed> {
    let n = resolution.or_else(|| scenes::resolution_default(name))?;
    let (dim, cells, particles) = preset_counts(name, n)?;
    Some(need(dim, cells, particles))
}

/// Refuses the preset `name` at `resolution` when its memory ([`preset_need`]) exceeds what is
/// available. Unknown names pass (the kind names them).
///
/// # Errors
/// [`BuildError::Memory`] of `resolution`.
pub fn check_preset(name: &str, resolution: Option<usize>) -> Result<(), BuildError> {
    let Some(n) = resolution.or_else(|| scenes::resolution_default(name)) else { return Ok(()) };
    let Some(need) = preset_need(name, Some(n)) else { return Ok(()) };
    need.check("resolution", &format!("{n} cells across"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::FlipScene;

    #[test]
    fn the_counts_are_those_the_presets_build() {
        for (name, n) in [
            ("dam-break-2d", 24),
            ("dam-break-3d", 12),
            ("drop-2d", 40),
            ("drop-3d", 24),
            ("sloshing-tank", 32),
        ] {
            let scene = scenes::by_name(name, Some(n), None).expect("known").expect("builds");
            let (cells, particles) = match &scene {
                FlipScene::Two(p) => (p.sim.grid().cells().iter().product::<usize>(), p.particles.len()),
                FlipScene::Three(p) => (p.sim.grid().cells().iter().product::<usize>(), p.particles.len()),
            };
            let (dim, c, q) = preset_counts(name, n).expect("known");
            assert_eq!(dim, scene.dim(), "{name}");
            assert_eq!(c, cells as f64, "{name}");
            // Exact for boxes; the drop's disk or ball within its lattice error.
            let ratio = q / particles as f64;
            assert!((0.95..=1.05).contains(&ratio), "{name}: {q} against {particles}");
        }
    }

    #[test]
    fn a_resolution_beyond_the_memory_is_refused_before_the_grid() {
        let start = std::time::Instant::now();
        let e = check_preset("drop-3d", Some(1_000_000_000)).expect_err("refused");
        assert!(start.elapsed().as_secs_f64() < 1.0);
        let BuildError::Memory { bytes, .. } = &e else { panic!("{e:?}") };
        assert!(*bytes > 240.0 * 1e27, "{bytes}");
        assert!(e.to_string().starts_with("field `resolution`: 1000000000 cells across needs about "), "{e}");
        assert!(check_preset("sloshing-tank", Some(64)).is_ok());
        assert!(check_preset("dam-break-4d", Some(1_000_000_000)).is_ok());
    }
}
