//! The soak run (`cargo xtask stability --long`): three materials (elastic, snow, fluid) in a box,
//! MLS-MPM at 64 cells, stepped for `10^5` frames or ten minutes, its kinetic plus gravitational
//! energy checked every few frames against its initial value.

use anim_core::cases::{
    Budget, ENERGY_STRIDE, Soak, drive, energy_above, energy_exceeds, finish, fmt_num, rejected,
};

/// Kinetic plus gravitational energy of the particles (their elastic energy is not negative, so
/// this sum may not exceed the initial total of a dissipative run that starts at rest shape).
fn mpm_energy<const D: usize>(p: &crate::Particles<D>, g: [f64; 3]) -> f64 {
    let mut e = 0.0;
    for i in 0..p.mass.len() {
        let m = f64::from(p.mass[i]);
        for a in 0..D {
            let v = f64::from(p.v[i * D + a]);
            e += m * (0.5 * v * v - g[a] * f64::from(p.x[i * D + a]));
        }
    }
    e
}

pub(super) fn mpm_three_materials(budget: Budget) -> Soak {
    let mut scene = match crate::scenes::three_materials(64) {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    let dt = scene.dt;
    let g = scene.sim.params().gravity;
    let e0 = mpm_energy(&scene.state, g);
    let (mut last, mut substeps) = (e0, 0usize);
    let clock = match drive(budget, dt, |k| {
        substeps += scene.sim.advance(&mut scene.state, dt).map_err(|e| e.to_string())?.substeps;
        if k.is_multiple_of(ENERGY_STRIDE) {
            last = mpm_energy(&scene.state, g);
            if energy_exceeds(last, e0) {
                return Err(energy_above(k, last, e0));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let d = format!(
        "{} particles, {substeps} substeps; kinetic + gravitational energy {} -> {} J, checked every {ENERGY_STRIDE} frames",
        scene.state.len(),
        fmt_num(e0),
        fmt_num(last)
    );
    finish(&clock, dt, true, d)
}
