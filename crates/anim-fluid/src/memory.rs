//! The memory a `fluid` scene will take, estimated from its grid before any field exists, so
//! the `fluid` kind refuses a resolution or a domain the machine cannot hold (anim-core's
//! [`MemoryNeed`]) instead of aborting halfway through the build.
//!
//! Per cell of the grid (faces count as cells: each axis has about as many):
//!
//! | solver | bytes | what |
//! | --- | --- | --- |
//! | Stam's | 48 per cell of the `(n + 2)^2` grid | six `f32` fields and their backup |
//! | MAC | 235 + 24 D | the solid flags; the velocity, density and temperature with their backup, `2 (D + 2)` `f64`s; the pressure's backup; the transport's old velocity and its three scratch fields and old scalar; vorticity confinement's seven fields; the implicit viscosity's five CG vectors; the projection's pressure and right-hand side; the Poisson operator (diagonal, labels, neighbour counts) and CG's five vectors |
//! | MAC, MGPCG | + 32 + 42 / (2^D - 1) | the finest level's four vectors; the coarser levels' four vectors and operators |
//! | MAC, other pressure solvers | + 8 | the one scratch vector |
//! | MAC, advection-reflection | + 8 D | the reflected velocity |
//! | MAC with obstacles | + the pressure solver again | the solver rebuilt on the obstacles' labels while the first one lives |
//! | both: frame cells, written cells | 32, 142 per cell drawn | the frame a view fills (density and velocity, `f64`) and what a run holds to write it (anim-core's `FRAME_CELL_BYTES`, `WRITTEN_CELL_BYTES`) |
//!
//! The counts are those of `MacFluid::new` (329.5 bytes a cell measured in 2D, 349 in 3D, with
//! MGPCG) and of `set_solid` (97 and 89 more).

use crate::advection::Splitting;
use crate::pressure::PressureMethod;
use anim_core::scene::{BuildError, MemoryNeed};

/// What sets the memory of a MAC grid beside its cells.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MacLayout {
    /// 2 or 3.
    pub dim: usize,
    /// The pressure solver.
    pub pressure: PressureMethod,
    /// How a step splits advection from projection (advection-reflection keeps a reflected
    /// velocity).
    pub splitting: Splitting,
    /// Whether obstacles mark solid cells (the pressure solver is rebuilt on their labels).
    pub obstacles: bool,
}

impl MacLayout {
    /// The bytes of the pressure solver per cell.
    fn solver(&self) -> f64 {
        let coarse = 42.0 / (2f64.powi(self.dim as i32) - 1.0);
        50.0 + if self.pressure == PressureMethod::Mgpcg { 32.0 + coarse } else { 8.0 }
    }

    /// The bytes per cell of a MAC fluid of this layout (see the module's table).
    #[must_use]
    pub fn per_cell(&self) -> f64 {
        let d = self.dim as f64;
        // Solid flags 1; state and backup 2 (D + 2) 8; pressure backup 8; transport 8 D + 32;
        // confinement 56; viscosity 40; projection 16.
        let fields = 1.0 + 16.0 * (d + 2.0) + 8.0 + (8.0 * d + 32.0) + 56.0 + 40.0 + 16.0;
        let reflect = if self.splitting == Splitting::Reflection { 8.0 * d } else { 0.0 };
        let rebuilt = if self.obstacles { self.solver() } else { 0.0 };
        fields + self.solver() + reflect + rebuilt
    }

    /// The memory of a MAC fluid of `cells` cells, with `masks` bytes per cell of sources' and
    /// obstacles' masks.
    #[must_use]
    pub fn need(&self, cells: f64, masks: f64) -> MemoryNeed {
        MemoryNeed::new().with(cells, "grid cells", self.per_cell() + masks).with_frame_cells(cells)
    }
}

/// The memory of Stam's solver on an `n x n` grid (its fields are `(n + 2)^2`).
#[must_use]
pub fn stam_need(n: f64) -> MemoryNeed {
    MemoryNeed::new().with((n + 2.0) * (n + 2.0), "grid cells", 48.0).with_frame_cells(n * n)
}

/// The cells of the preset `name` at `n` cells across, with its layout (`None` for Stam's
/// solver); `None` for an unknown name.
fn preset_grid(name: &str, n: f64) -> Option<(f64, Option<MacLayout>)> {
    let mac = |dim, obstacles| MacLayout {
        dim,
        pressure: PressureMethod::Mgpcg,
        splitting: Splitting::AdvectProject,
        obstacles,
    };
    Some(match name {
        "smoke-box-2d" => (n * n, None),
        "smoke-plume-3d" => (n * (1.5 * n).ceil() * n, Some(mac(3, true))),
        "lid-driven-cavity" => (n * n, Some(mac(2, false))),
        _ => return None,
    })
}

/// The memory of the preset `name` at `resolution` cells across (its default when `None`),
/// with the file's `splitting` (the preset's when `None`; a pressure solver other than the
/// preset's MGPCG is built beside it and the MGPCG estimate covers both); `None` for an
/// unknown name.
#[must_use]
pub fn preset_need(
    name: &str,
    resolution: Option<usize>,
    splitting: Option<Splitting>,
) -> Option<MemoryNeed> {
    let n = resolution.or_else(|| crate::scenes::resolution_default(name))? as f64;
    Some(match preset_grid(name, n)? {
        (_, None) => stam_need(n),
        (cells, Some(layout)) => {
            let layout = MacLayout { splitting: splitting.unwrap_or(layout.splitting), ..layout };
            layout.need(cells, 0.0)
        }
    })
}

/// Refuses the preset `name` at `resolution` when its memory ([`preset_need`]) exceeds what is
/// available. Unknown names pass (the kind names them).
///
/// # Errors
/// [`BuildError::Memory`] of `resolution`.
pub fn check_preset(
    name: &str,
    resolution: Option<usize>,
    splitting: Option<Splitting>,
) -> Result<(), BuildError> {
    let Some(n) = resolution.or_else(|| crate::scenes::resolution_default(name)) else { return Ok(()) };
    let Some(need) = preset_need(name, Some(n), splitting) else { return Ok(()) };
    need.check("resolution", &format!("{n} cells across"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_bytes_per_cell_are_those_the_fluid_allocates() {
        // MacFluid::new measured 329.5 B a cell in 2D, 349 in 3D (faces a little more than
        // cells), with MGPCG; set_solid 97 and 89 more.
        let mac = |dim, obstacles| MacLayout {
            dim,
            pressure: PressureMethod::Mgpcg,
            splitting: Splitting::AdvectProject,
            obstacles,
        };
        assert_eq!(mac(2, false).per_cell(), 329.0);
        assert_eq!(mac(3, false).per_cell(), 345.0);
        assert_eq!(mac(2, true).per_cell() - mac(2, false).per_cell(), 96.0);
        assert_eq!(mac(3, true).per_cell() - mac(3, false).per_cell(), 88.0);
        let jacobi = MacLayout { pressure: PressureMethod::Jacobi, ..mac(2, false) };
        assert_eq!(mac(2, false).per_cell() - jacobi.per_cell(), 38.0);
        let reflect = MacLayout { splitting: Splitting::Reflection, ..mac(3, false) };
        assert_eq!(reflect.per_cell() - mac(3, false).per_cell(), 24.0);
    }

    #[test]
    fn the_grids_are_those_the_presets_build() {
        for (name, n) in [("smoke-box-2d", 10), ("smoke-plume-3d", 5), ("lid-driven-cavity", 6)] {
            let scene = crate::scenes::by_name(name, Some(n)).expect("known").expect("builds");
            let [nx, ny, nz] = scene.dims();
            let (cells, _) = preset_grid(name, n as f64).expect("known");
            assert_eq!(cells, (nx * ny * nz) as f64, "{name}");
        }
    }

    #[test]
    fn a_resolution_beyond_the_memory_is_refused_before_the_grid() {
        let start = std::time::Instant::now();
        let e = check_preset("smoke-plume-3d", Some(1_000_000_000), None).expect_err("refused");
        assert!(start.elapsed().as_secs_f64() < 1.0);
        let BuildError::Memory { bytes, .. } = &e else { panic!("{e:?}") };
        assert!(*bytes > 1.5e27 * 400.0, "{bytes}");
        assert!(e.to_string().starts_with("field `resolution`: 1000000000 cells across needs about "), "{e}");
        assert!(check_preset("lid-driven-cavity", Some(64), None).is_ok());
        assert!(check_preset("smoke-box-2d", Some(1_000_000_000), None).is_err());
        assert!(check_preset("vortex-street", Some(1_000_000_000), None).is_ok());
    }
}
