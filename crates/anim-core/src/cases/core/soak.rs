//! The Kepler soak run (`cargo xtask stability --long`): an eccentric orbit stepped for `10^5`
//! steps or ten minutes, its energy and angular momentum checked every step.

use crate::cases::{Budget, Soak, SoakCase, drive, finish, fmt_num};
use crate::integrate::systems::KeplerOrbit;
use crate::integrate::{IntegratorKind, NewtonParams, State};
use crate::linalg::LinearSolverKind;

/// The Kepler orbit soak case.
pub(super) const KEPLER: SoakCase = SoakCase {
    crate_name: "anim-core",
    name: "Kepler orbit e = 0.9, velocity Verlet, 2000 steps per orbit",
    bound: "energy error no larger than twice its first-tenth amplitude (no secular drift); angular momentum to 1e-9",
    run: core_kepler,
};

fn core_kepler(budget: Budget) -> Soak {
    let mut sys = KeplerOrbit::ellipse(0.9);
    let (x0, v0) = sys.initial();
    let mut state = State::new(x0.to_vec(), v0.to_vec());
    let mut integ = IntegratorKind::VelocityVerlet.build_with::<KeplerOrbit>(
        2,
        NewtonParams::with_tolerance(1e-13),
        LinearSolverKind::Cg,
    );
    let dt = sys.period() / 2000.0;
    let e0 = sys.energy_of(&state.x, &state.v);
    let l0 = KeplerOrbit::angular_momentum(&state.x, &state.v);
    let tenth = budget.steps / 10;
    let (mut early, mut worst, mut worst_l) = (0.0f64, 0.0f64, 0.0f64);
    let clock = match drive(budget, dt, |k| {
        integ.step(&mut sys, &mut state, dt).map_err(|e| e.to_string())?;
        let de = (sys.energy_of(&state.x, &state.v) - e0).abs();
        worst = worst.max(de);
        if k <= tenth {
            early = early.max(de);
        }
        worst_l = worst_l.max((KeplerOrbit::angular_momentum(&state.x, &state.v) - l0).abs());
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let detail = format!(
        "{} orbits; |E - E0| at most {} in the first tenth, {} overall (E0 = {}); |L - L0| at most {}",
        fmt_num(clock.steps as f64 * dt / sys.period()),
        fmt_num(early),
        fmt_num(worst),
        fmt_num(e0),
        fmt_num(worst_l)
    );
    finish(&clock, dt, worst.is_finite() && worst <= 2.0 * early && worst_l <= 1e-9 * l0.abs(), detail)
}
