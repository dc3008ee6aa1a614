//! The pendulum-chain soak run (`cargo xtask stability --long`): `10^5` steps or ten minutes of
//! RK4 on a 32-link chain falling from horizontal, its energy checked on a fixed stride.

use anim_core::cases::{Budget, ENERGY_STRIDE, Soak, SoakCase, drive, finish, fmt_num, rejected};
use anim_core::solver::Solver;

/// The pendulum-chain soak case.
pub(super) const CHAIN: SoakCase = SoakCase {
    crate_name: "anim-rigid",
    name: "32-link pendulum chain falling from horizontal, RK4 at dt = 5e-4 s",
    bound: "energy never gains 1% of the chain's potential drop m g L (loss reported)",
    run: chain,
};

fn chain(budget: Budget) -> Soak {
    let scene = match crate::scenes::pendulum_chain(None) {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    let dt = scene.dt;
    let (mut sim, mut state) = match scene.into_simulation() {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    // 32 links of 0.1 kg and 0.1 m: total mass 3.2 kg, the centre of mass can fall 1.6 m at most.
    let scale = 3.2 * 9.81 * 1.6;
    let e0 = sim.energy(&state);
    let (mut gain, mut loss) = (0.0f64, 0.0f64);
    let clock = match drive(budget, dt, |k| {
        sim.step(&mut state, dt).map_err(|e| e.to_string())?;
        if k.is_multiple_of(ENERGY_STRIDE) {
            let de = sim.energy(&state) - e0;
            gain = gain.max(de);
            loss = loss.max(-de);
            if !(de < 0.01 * scale) {
                return Err(format!("step {k}: energy gain {de} J against m g L = {scale} J"));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let d = format!(
        "largest energy gain {} J ({} of m g L = {} J), largest loss {} J ({}; RK4 is not symplectic and dissipates slowly), checked every {ENERGY_STRIDE} steps",
        fmt_num(gain),
        fmt_num(gain / scale),
        fmt_num(scale),
        fmt_num(loss),
        fmt_num(loss / scale)
    );
    finish(&clock, dt, true, d)
}
