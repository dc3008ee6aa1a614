//! Soak cases (`cargo xtask stability --long`): one hard case per crate that steps in time, run
//! for `10^5` steps or ten minutes, with its bound checked on a fixed stride. anim-material has no
//! time stepping of its own (its models run inside the FEM and MPM soaks); anim-io has none.

use crate::registry::fmt_num;
use crate::registry::{Budget, Soak, SoakCase, drive, finish, rejected};

/// Registers the soak cases, in crate order.
pub fn register(r: &mut crate::registry::Registry) {
    r.soak.extend([
        SoakCase {
            crate_name: "anim-core",
            name: "Kepler orbit e = 0.9, velocity Verlet, 2000 steps per orbit",
            bound: "energy error no larger than twice its first-tenth amplitude (no secular drift); angular momentum to 1e-9",
            run: core_kepler,
        },
        SoakCase {
            crate_name: "anim-springs",
            name: "cloth k = 1e6, m = 1e-3, linearised backward Euler at dt = 1/30 s",
            bound: "energy excess over its initial value no larger after the first tenth than within it, and final energy below initial; max stretch ratio < 1.01",
            run: springs_stiff_cloth,
        },
        SoakCase {
            crate_name: "anim-pbd",
            name: "24x24 cloth with rigid distances draped on a sphere, XPBD at dt = 1/30 s",
            bound: "kinetic + gravitational energy never above its initial value",
            run: pbd_drape,
        },
        SoakCase {
            crate_name: "anim-rigid",
            name: "32-link pendulum chain falling from horizontal, RK4 at dt = 5e-4 s",
            bound: "energy never gains 1% of the chain's potential drop m g L (loss reported)",
            run: rigid_chain,
        },
        SoakCase {
            crate_name: "anim-fem",
            name: "E = 1e8 Pa stable Neo-Hookean cantilever, backward Euler at dt = 1/24 s",
            bound: "total energy never above its initial value",
            run: fem_stiff_beam,
        },
        SoakCase {
            crate_name: "anim-mpm",
            name: "three materials (elastic, snow, fluid) in a box, MLS-MPM, 64 cells",
            bound: "kinetic + gravitational energy never above its initial value",
            run: mpm_three_materials,
        },
    ]);
}

/// Energy-stride shared by the cases.
const STRIDE: u64 = 10;

/// Whether `e` is above `e0` beyond rounding.
fn exceeds(e: f64, e0: f64) -> bool {
    !(e <= e0 + 1e-9 * e0.abs().max(1e-12))
}

/// The error text of a bound broken at step `k`.
fn above(k: u64, e: f64, e0: f64) -> String {
    format!("step {k}: energy {e} J above its initial value {e0} J")
}

fn core_kepler(budget: Budget) -> Soak {
    use anim_core::integrate::systems::KeplerOrbit;
    use anim_core::integrate::{IntegratorKind, NewtonParams, State};
    use anim_core::linalg::LinearSolverKind;
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

fn springs_stiff_cloth(budget: Budget) -> Soak {
    // The seed's linearised backward Euler is not a minimiser of the incremental potential, so it
    // may raise the energy while the cloth swings through large rotations; the bound is that it
    // never does so after the first tenth of the run. (Newton to convergence stalls here: with the
    // residual-norm line search it stops near a relative residual of 1e-5 at omega dt = 1000.)
    let (mut sim, mut state) = match super::springs::stiff_cloth() {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    let dt = 1.0 / 30.0;
    let e0 = sim.network_mut().energy_parts(&state.x, &state.v).total();
    let tenth = budget.steps / 10;
    let (mut last, mut stretch, mut early, mut late) = (e0, 0.0f64, 0.0f64, 0.0f64);
    let clock = match drive(budget, dt, |k| {
        sim.advance(&mut state, dt).map_err(|e| e.to_string())?;
        if k.is_multiple_of(STRIDE) {
            last = sim.network_mut().energy_parts(&state.x, &state.v).total();
            stretch = stretch.max(sim.network().max_stretch(&state.x).map_or(f64::NAN, |s| s.ratio));
            let excess = (last - e0).max(0.0);
            if k <= tenth {
                early = early.max(excess);
            } else {
                late = late.max(excess);
            }
            if !last.is_finite() || !(stretch < 1.01) {
                return Err(format!("step {k}: energy {last} J, max stretch ratio {stretch}"));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let d = format!(
        "energy {} -> {} J, checked every {STRIDE} steps; largest excess over the initial energy {} J in the first tenth, {} J after it; max stretch ratio {}",
        fmt_num(e0),
        fmt_num(last),
        fmt_num(early),
        fmt_num(late),
        fmt_num(stretch)
    );
    finish(&clock, dt, late <= early && last <= e0, d)
}

fn pbd_drape(budget: Budget) -> Soak {
    let scene = anim_pbd::scenes::cloth_drape(Some(24)).map_err(|e| e.to_string());
    let (mut sim, mut state) = match scene.and_then(|s| s.into_simulation().map_err(|e| e.to_string())) {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    let dt = 1.0 / 30.0;
    let e0 = sim.model().kinetic_and_gravity_energy(&state.x, &state.v);
    let mut last = e0;
    let clock = match drive(budget, dt, |k| {
        sim.advance(&mut state, dt).map_err(|e| e.to_string())?;
        if k.is_multiple_of(STRIDE) {
            last = sim.model().kinetic_and_gravity_energy(&state.x, &state.v);
            if exceeds(last, e0) {
                return Err(above(k, last, e0));
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
        if let anim_pbd::ConstraintFunction::Distance { particles: [i, j], rest_length } = c.function
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
        "kinetic + gravitational energy {} -> {} J, checked every {STRIDE} steps; largest distance strain at the end {}",
        fmt_num(e0),
        fmt_num(last),
        fmt_num(strain)
    );
    finish(&clock, dt, true, d)
}

fn rigid_chain(budget: Budget) -> Soak {
    use anim_core::solver::Solver;
    let scene = match anim_rigid::scenes::pendulum_chain(None) {
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
        if k.is_multiple_of(STRIDE) {
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
        "largest energy gain {} J ({} of m g L = {} J), largest loss {} J ({}; RK4 is not symplectic and dissipates slowly), checked every {STRIDE} steps",
        fmt_num(gain),
        fmt_num(gain / scale),
        fmt_num(scale),
        fmt_num(loss),
        fmt_num(loss / scale)
    );
    finish(&clock, dt, true, d)
}

fn fem_stiff_beam(budget: Budget) -> Soak {
    use anim_core::solver::Solver;
    use anim_fem::generate;
    use anim_fem::material::{Material, MaterialModel};
    use anim_fem::model::{EARTH_GRAVITY, FemModel};
    use anim_fem::sim::{FemParams, FemSimulation};
    let setup = || -> Result<FemSimulation, anim_fem::FemError> {
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
        if k.is_multiple_of(STRIDE) {
            last = sim.total_energy(&state);
            if exceeds(last, e0) {
                return Err(above(k, last, e0));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let tip = state.x.chunks(3).map(|p| p[2]).fold(f64::INFINITY, f64::min);
    let d = format!(
        "20x2x2 cells (240 tets); total energy {} -> {} J, checked every {STRIDE} steps; lowest point z = {} m",
        fmt_num(e0),
        fmt_num(last),
        fmt_num(tip)
    );
    finish(&clock, dt, true, d)
}

/// Kinetic plus gravitational energy of the particles (their elastic energy is not negative, so
/// this sum may not exceed the initial total of a dissipative run that starts at rest shape).
fn mpm_energy<const D: usize>(p: &anim_mpm::Particles<D>, g: [f64; 3]) -> f64 {
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

fn mpm_three_materials(budget: Budget) -> Soak {
    let mut scene = match anim_mpm::scenes::three_materials(64) {
        Ok(s) => s,
        Err(e) => return rejected(budget, e),
    };
    let dt = scene.dt;
    let g = scene.sim.params().gravity;
    let e0 = mpm_energy(&scene.state, g);
    let (mut last, mut substeps) = (e0, 0usize);
    let clock = match drive(budget, dt, |k| {
        substeps += scene.sim.advance(&mut scene.state, dt).map_err(|e| e.to_string())?.substeps;
        if k.is_multiple_of(STRIDE) {
            last = mpm_energy(&scene.state, g);
            if exceeds(last, e0) {
                return Err(above(k, last, e0));
            }
        }
        Ok(())
    }) {
        Ok(c) => c,
        Err(s) => return s,
    };
    let d = format!(
        "{} particles, {substeps} substeps; kinetic + gravitational energy {} -> {} J, checked every {STRIDE} frames",
        scene.state.len(),
        fmt_num(e0),
        fmt_num(last)
    );
    finish(&clock, dt, true, d)
}
