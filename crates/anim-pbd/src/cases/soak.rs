//! The cloth-drape soak run (`cargo xtask stability --long`): `10^5` steps or ten minutes of XPBD
//! on a 24x24 cloth draped on a sphere, its kinetic and gravitational energy checked on a fixed
//! stride.

use anim_core::cases::{
    Budget, ENERGY_STRIDE, Soak, SoakCase, drive, energy_above, energy_exceeds, finish, fmt_num, rejected,
};

/// The cloth-drape soak case.
pub(super) const DRAPE: SoakCase = SoakCase {
    crate_name: "anim-pbd",
    name: "24x24 cloth with rigid distances draped on a sphere, XPBD at dt = 1/30 s",
    bound: "kinetic + gravitational energy never above its initial value",
    run: drape,
};

fn drape(budget: Budget) -> Soak {
    let scene = crate::scenes::cloth_drape(Some(24)).map_err(|e| e.to_string());
    let (mut sim, mut state) = match scene.and_then(|s| s.into_simulation().map_err(|e| e.to_string())) {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    let dt = 1.0 / 30.0;
    let e0 = sim.model().kinetic_and_gravity_energy(&state.x, &state.v);
    let mut last = e0;
    let clock = match drive(budget, dt, |k| {
        sim.advance(&mut state, dt).map_err(|e| e.to_string())?;
        if k.is_multiple_of(ENERGY_STRIDE) {
            last = sim.model().kinetic_and_gravity_energy(&state.x, &state.v);
            if energy_exceeds(last, e0) {
                return Err(energy_above(k, last, e0));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let x = &state.x;
    let mut strain = 0.0f64;
    for c in sim.model().constraints() {
        if let crate::ConstraintFunction::Distance { particles: [i, j], rest_length } = c.function
            && rest_length > 0.0
        {
            let d = ((x[3 * i] - x[3 * j]).powi(2)
                + (x[3 * i + 1] - x[3 * j + 1]).powi(2)
                + (x[3 * i + 2] - x[3 * j + 2]).powi(2))
            .sqrt();
            strain = strain.max((d - rest_length).abs() / rest_length);
        }
    }
    let d = format!(
        "kinetic + gravitational energy {} -> {} J, checked every {ENERGY_STRIDE} steps; largest distance strain at the end {}",
        fmt_num(e0),
        fmt_num(last),
        fmt_num(strain)
    );
    finish(&clock, dt, true, d)
}
