//! The memory an `mpm` scene will take, estimated from its resolution and its matter before the
//! grid or the particles exist, so the `mpm` kind refuses a size the machine cannot hold
//! (anim-core's [`MemoryNeed`]) instead of aborting halfway through the build.
//!
//! The parts, per item (sizes of the buffers of the particle arrays and the sparse grid):
//!
//! | part | bytes (2D, 3D) | what |
//! | --- | --- | --- |
//! | grid blocks | 12 | the dense tables over every `4^D`-node block of the domain, `(n / 4 + 2)^D` of them: the particle and grid block slots and the particle counts (`u32` each) |
//! | particles | 210, 354 | three copies of the particle arrays (66 B, 114 B: position, velocity, affine matrix, deformation gradient, plastic state, mass, volume, material, id): the state, the step's output and the backup a substepped step restores; the sort's key, order and block (`u32` each) |
//! | frame points, written points | 48, 330 | the frame a view fills (position and velocity, `f64`) and what a run holds to write it (anim-core's `FRAME_POINT_BYTES`, `WRITTEN_POINT_BYTES`) |
//! | particle blocks | 1,024, 8,192 | the private window of `8^D` nodes (16 B each) of every block holding particles |
//! | grid blocks with matter | 256, 1,024 | the `4^D` nodes (16 B each) of every grid block the particles touch |
//!
//! The blocks with matter are counted over the bounding box of each region of matter (`L / 4 + 1`
//! and `L / 4 + 2` blocks along a side of `L` cells): what the particles occupy at the start; a
//! run that spreads its matter (a dam break) adds blocks, small beside the particles.

use crate::scenes;
use anim_core::scene::{BuildError, MemoryNeed};

/// Matter in a scene: its particles and the blocks they occupy.
#[derive(Debug, Clone, Copy, Default, PartialEq)]
pub struct Matter {
    /// Particles.
    pub particles: f64,
    /// Blocks of `4^D` nodes holding particles.
    pub blocks: f64,
    /// Grid blocks the particles' stencils touch.
    pub grid_blocks: f64,
}

impl Matter {
    /// `particles` particles in a box of `extent` cells along each of its `D` sides.
    #[must_use]
    pub fn in_box(particles: f64, extent: &[f64]) -> Self {
        let (mut blocks, mut grid_blocks) = (1.0, 1.0);
        for &l in extent {
            blocks *= l / 4.0 + 1.0;
            grid_blocks *= l / 4.0 + 2.0;
        }
        Self { particles, blocks, grid_blocks }
    }

    /// A box of `extent` cells along each side filled with `per_cell` particles per cell and
    /// axis.
    #[must_use]
    pub fn filled_box(extent: &[f64], per_cell: f64) -> Self {
        let particles = extent.iter().map(|l| (l * per_cell).floor().max(0.0)).product();
        Self::in_box(particles, extent)
    }

    /// This matter and `other`.
    #[must_use]
    pub fn and(self, other: Self) -> Self {
        Self {
            particles: self.particles + other.particles,
            blocks: self.blocks + other.blocks,
            grid_blocks: self.grid_blocks + other.grid_blocks,
        }
    }
}

/// The memory of a scene of `dim` dimensions at `n` cells per axis holding `matter`.
#[must_use]
pub fn need(dim: usize, n: f64, matter: &Matter) -> MemoryNeed {
    let three = dim >= 3;
    let table = (n / 4.0).floor() + 2.0;
    MemoryNeed::new()
        .with(table.powi(dim as i32), "grid blocks", 12.0)
        .with(matter.particles, "particles", if three { 354.0 } else { 210.0 })
        .with_frame_points(matter.particles)
        .with(matter.blocks, "particle blocks", if three { 8192.0 } else { 1024.0 })
        .with(matter.grid_blocks, "grid blocks with matter", if three { 1024.0 } else { 256.0 })
}

/// The matter of the preset `name` at `n` cells per axis and `per_cell` particles per cell and
/// axis (the dam break's; the others place their own): the regions its scene fills, in cells;
/// `None` for an unknown name.
#[must_use]
pub fn preset_matter(name: &str, n: usize, per_cell: usize) -> Option<Matter> {
    let n = n as f64;
    let cells = |side: f64| side * n;
    Some(match name {
        "three-materials" => Matter::filled_box(&[cells(0.2), cells(0.2)], 2.0)
            .and(Matter::filled_box(&[cells(0.2), cells(0.2)], 2.0))
            .and(Matter::filled_box(&[cells(0.25), cells(0.35)], 2.0)),
        "dam-break-2d" => Matter::filled_box(&[cells(0.2), cells(0.4)], per_cell as f64),
        "dam-break-3d" => Matter::filled_box(&[cells(0.3), cells(0.6), cells(0.4)], 2.0),
        "snowball" => {
            // A ball of radius 0.1 m: its volume in lattice points (2 per cell and axis).
            let r = cells(0.1) * 2.0;
            Matter::in_box(4.0 / 3.0 * std::f64::consts::PI * r * r * r, &[cells(0.2); 3])
        }
        "benchmark-2d" => Matter::in_box(n * n / 2.0, &[cells(0.4); 2]),
        "benchmark-3d" => Matter::in_box(n * n * n / 4.0, &[cells(0.4); 3]),
        _ => return None,
    })
}

/// The memory of the preset `name` at `resolution` (its default when `None`) with `per_cell`
/// particles per cell and axis (2 when `None`); `None` for an unknown name.
#[must_use]
pub fn preset_need(name: &str, resolution: Option<usize>, per_cell: Option<usize>) -> Option<MemoryNeed> {
    let n = resolution.or_else(|| scenes::resolution_default(name))?;
    let matter = preset_matter(name, n, per_cell.unwrap_or(2))?;
    Some(need(scenes::dim(name)?, n as f64, &matter))
}

/// Refuses the preset `name` at `resolution` when its memory ([`preset_need`]) exceeds what is
/// available. Unknown names pass (the kind names them).
///
/// # Errors
/// [`BuildError::Memory`] of `resolution`.
pub fn check_preset(
    name: &str,
    resolution: Option<usize>,
    per_cell: Option<usize>,
) -> Result<(), BuildError> {
    let Some(n) = resolution.or_else(|| scenes::resolution_default(name)) else { return Ok(()) };
    let Some(need) = preset_need(name, Some(n), per_cell) else { return Ok(()) };
    need.check("resolution", &format!("{n} cells per axis"))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::scenes::MpmScene;

    #[test]
    fn the_particle_counts_are_those_the_presets_seed() {
        for (name, n, per_cell) in [
            ("three-materials", 32, None),
            ("dam-break-2d", 40, Some(3)),
            ("dam-break-3d", 16, None),
            ("snowball", 32, None),
            ("benchmark-2d", 16, None),
            ("benchmark-3d", 16, None),
        ] {
            let scene = scenes::by_name_with(name, Some(n), per_cell).expect("known").expect("builds");
            let built = match &scene {
                MpmScene::Two(s) => s.state.len(),
                MpmScene::Three(s) => s.state.len(),
            } as f64;
            let estimate = preset_matter(name, n, per_cell.unwrap_or(2)).expect("known").particles;
            // Exact for boxes; the ball's lattice points within 5% of its volume's.
            let ratio = estimate / built;
            assert!((0.95..=1.05).contains(&ratio), "{name}: {estimate} against {built}");
            if name != "snowball" {
                assert_eq!(estimate, built, "{name}");
            }
        }
    }

    #[test]
    fn a_resolution_beyond_the_memory_is_refused_before_the_grid() {
        let start = std::time::Instant::now();
        let e = check_preset("dam-break-3d", Some(1_000_000_000), None).expect_err("refused");
        assert!(start.elapsed().as_secs_f64() < 1.0);
        let BuildError::Memory { bytes, .. } = &e else { panic!("{e:?}") };
        // 1e27 cells' worth of tables alone: (2.5e8)^3 blocks of 12 B.
        assert!(*bytes > 12.0 * 2.5e8f64.powi(3), "{bytes}");
        assert!(
            e.to_string().starts_with("field `resolution`: 1000000000 cells per axis needs about "),
            "{e}"
        );
        assert!(check_preset("snowball", Some(16), None).is_ok());
        assert!(check_preset("warp-field", Some(1_000_000_000), None).is_ok());
    }
}
