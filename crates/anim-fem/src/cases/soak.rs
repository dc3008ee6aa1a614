//! The soak run (`cargo xtask stability --long`): the E = 1e8 Pa stable Neo-Hookean cantilever
//! under backward Euler at dt = 1/24 s, stepped for `10^5` steps or ten minutes, its total energy
//! checked every few steps against its initial value.

use crate::FemError;
use crate::generate;
use crate::material::{Material, MaterialModel};
use crate::model::{EARTH_GRAVITY, FemModel};
use crate::sim::{FemParams, FemSimulation};
use anim_core::cases::{
    Budget, ENERGY_STRIDE, Soak, drive, energy_above, energy_exceeds, finish, fmt_num, rejected,
};
use anim_core::solver::Solver;

pub(super) fn fem_stiff_beam(budget: Budget) -> Soak {
    let setup = || -> Result<FemSimulation, FemError> {
        let mesh = generate::box_mesh([0.0; 3], [1.0, 0.1, 0.1], [20, 2, 2])?;
        let mut m = FemModel::new(mesh, Material::new(MaterialModel::StableNeoHookean, 1e8, 0.3, 1000.0)?)?
            .with_gravity(EARTH_GRAVITY);
        let clamp = m.vertices_where(|p| p[0] < 1e-9);
        m.pin_vertices(&clamp)?;
        FemSimulation::new(m, FemParams::default())
    };
    let mut sim = match setup() {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    let mut state = sim.rest_state();
    let dt = 1.0 / 24.0;
    let e0 = sim.total_energy(&state);
    let mut last = e0;
    let clock = match drive(budget, dt, |k| {
        sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        if k.is_multiple_of(ENERGY_STRIDE) {
            last = sim.total_energy(&state);
            if energy_exceeds(last, e0) {
                return Err(energy_above(k, last, e0));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let tip = state.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
    let d = format!(
        "20x2x2 cells (240 tets); total energy {} -> {} J, checked every {ENERGY_STRIDE} steps; lowest point z = {} m",
        fmt_num(e0),
        fmt_num(last),
        fmt_num(tip)
    );
    finish(&clock, dt, true, d)
}
