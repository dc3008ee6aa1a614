//! Reference scenes: particle seeding, still water, the dam break of Martin & Moyce (1952) in 2D
//! and 3D, a rotating disk, a drop falling into a pool and a sloshing tank; and the presets the
//! command line runs by name ([`NAMES`], [`by_name`]).
//!
//! Every fluid starts on the regular lattice of [`fill_box`] / [`fill_region`] (2 particles per
//! cell and axis) at rest, in a box of cells of size `1/n` m whose outermost cells are walls.

use crate::error::{FlipError, positive};
use crate::particles::Particles;
use crate::sim::{FlipParams, FlipSimulation};
use crate::tank::TankMotion;
use crate::transfer::Transfer;

/// Adds particles on a regular lattice of `per_axis` particles per cell and axis (at offsets
/// `(k + 1/2) / per_axis` of the cells of size `h`) in the box `[lo, hi)`, with velocity `v(x)`.
pub fn fill_box<const D: usize>(
    particles: &mut Particles<D>,
    h: f64,
    per_axis: usize,
    lo: [f64; D],
    hi: [f64; D],
    v: impl Fn([f64; D]) -> [f64; D],
) {
    fill_region(particles, h, per_axis, lo, hi, |_| true, v);
}

/// The lattice of [`fill_box`] in the box `[lo, hi)`, keeping the points where `inside(x)`: a
/// ball, a pool under a tilted surface, any region seeded on the same lattice as a box.
pub fn fill_region<const D: usize>(
    particles: &mut Particles<D>,
    h: f64,
    per_axis: usize,
    lo: [f64; D],
    hi: [f64; D],
    inside: impl Fn([f64; D]) -> bool,
    v: impl Fn([f64; D]) -> [f64; D],
) {
    let spacing = h / per_axis as f64;
    let counts: [usize; D] = std::array::from_fn(|a| ((hi[a] - lo[a]) / spacing).round().max(0.0) as usize);
    let total: usize = counts.iter().product();
    let point = |f: usize| -> [f64; D] {
        let idx = crate::mac::unflatten(counts, f);
        std::array::from_fn(|a| lo[a] + (idx[a] as f64 + 0.5) * spacing)
    };
    // Room for exactly the points kept: pushed one by one, the arrays would grow up to twice
    // what they hold.
    let kept = (0..total).filter(|&f| inside(point(f))).count();
    reserve(particles, kept);
    for f in 0..total {
        let x = point(f);
        if inside(x) {
            particles.push(x, v(x));
        }
    }
}

/// Room for `additional` more particles in each of `particles`' arrays.
pub(crate) fn reserve<const D: usize>(particles: &mut Particles<D>, additional: usize) {
    particles.x.reserve_exact(additional);
    particles.v.reserve_exact(additional);
    particles.c.reserve_exact(additional);
}

/// Still water: a box of `n` cells per axis of size `1/n` m, filled to half its inner height
/// with 2 particles per cell and axis, at rest.
///
/// # Errors
/// As [`FlipSimulation::new`].
pub fn still_water<const D: usize>(
    n: usize,
    params: FlipParams<D>,
) -> Result<(FlipSimulation<D>, Particles<D>), FlipError> {
    let h = 1.0 / n as f64;
    let sim = FlipSimulation::new([n; D], h, params)?;
    let (lo, mut hi) = sim.fluid_box();
    hi[1] = lo[1] + 0.5 * (hi[1] - lo[1]);
    let mut p = Particles::new();
    fill_box(&mut p, h, 2, lo, hi, |_| [0.0; D]);
    Ok((sim, p))
}

/// A 2D dam break: a column `a x 2a` against the left wall and floor of a tank `4a + ...` long
/// (`n` cells across `1 m`; the column starts at the fluid box corner). Returns the simulation,
/// the particles and the column's left edge (where the surge front is measured from).
///
/// # Errors
/// As [`FlipSimulation::new`].
pub fn dam_break(
    n: usize,
    a: f64,
    params: FlipParams<2>,
) -> Result<(FlipSimulation<2>, Particles<2>, f64), FlipError> {
    let h = 1.0 / n as f64;
    let ny = ((2.0 * a + 0.3) / h).ceil() as usize + 2;
    let sim = FlipSimulation::new([n, ny], h, params)?;
    let (lo, _) = sim.fluid_box();
    let mut p = Particles::new();
    fill_box(&mut p, h, 2, lo, [lo[0] + a, lo[1] + 2.0 * a], |_| [0.0; 2]);
    Ok((sim, p, lo[0]))
}

/// A disk of radius `r` at the centre of the unit square rotating rigidly at `omega` rad/s
/// (no gravity): `v = omega (-(y - c), x - c)`, APIC matrices set to the rotation's gradient.
///
/// # Errors
/// As [`FlipSimulation::new`].
pub fn rotating_disk(
    n: usize,
    r: f64,
    omega: f64,
    mut params: FlipParams<2>,
) -> Result<(FlipSimulation<2>, Particles<2>), FlipError> {
    params.gravity = [0.0; 2];
    let h = 1.0 / n as f64;
    let sim = FlipSimulation::new([n, n], h, params)?;
    let mut all = Particles::new();
    fill_box(&mut all, h, 2, [0.5 - r; 2], [0.5 + r; 2], |x| [-omega * (x[1] - 0.5), omega * (x[0] - 0.5)]);
    let mut p = Particles::new();
    for (x, v) in all.x.iter().zip(&all.v) {
        if (x[0] - 0.5).powi(2) + (x[1] - 0.5).powi(2) < r * r {
            p.push(*x, *v);
            if params.transfer == crate::transfer::Transfer::Apic
                && let Some(c) = p.c.last_mut()
            {
                *c = [[0.0, -omega], [omega, 0.0]];
            }
        }
    }
    Ok((sim, p))
}

/// Checks a length parameter of a scene: positive, finite, at most `max` (m).
fn length(name: &'static str, value: f64, max: f64, requirement: &'static str) -> Result<(), FlipError> {
    positive(name, value)?;
    if value > max {
        return Err(FlipError::BadParameter { name, requirement, value: value.to_string() });
    }
    Ok(())
}

/// A 3D dam break: a column `a` long (x), `2a` tall (y) and `a` wide (z) standing in the corner
/// `x = 0, z = 0` of a tank on its floor; the tank is `1 m` long (`n` cells), `2a + 0.3 m` tall
/// and `2a` wide inside (so the column fills half its width and the surge runs along x, as the 2D
/// [`dam_break`] does, with a side wall at `z = 0` and the free width beside it). Returns the
/// simulation, the particles and the column's left edge (where the surge front is measured
/// from).
///
/// # Errors
/// [`FlipError::BadParameter`] for `a` not in `(0, 0.45]` m (the column and its surge must fit
/// the 1 m tank); otherwise as [`FlipSimulation::new`].
pub fn dam_break_3d(
    n: usize,
    a: f64,
    params: FlipParams<3>,
) -> Result<(FlipSimulation<3>, Particles<3>, f64), FlipError> {
    length("a", a, 0.45, "must be at most 0.45 m (the column in a 1 m tank)")?;
    let h = 1.0 / n as f64;
    let ny = ((2.0 * a + 0.3) / h).ceil() as usize + 2;
    let nz = (2.0 * a / h).ceil() as usize + 2;
    let sim = FlipSimulation::new([n, ny, nz], h, params)?;
    let (lo, _) = sim.fluid_box();
    let mut p = Particles::new();
    fill_box(&mut p, h, 2, lo, [lo[0] + a, lo[1] + 2.0 * a, lo[2] + a], |_| [0.0; 3]);
    Ok((sim, p, lo[0]))
}

/// The benchmark dam break (`cargo xtask bench --peers --filter flip`): a cube of `n` cells per
/// axis of size `1/n` m (`n` a multiple of 4, at least 8) and a block of `n/4 x n/2 x n/2`
/// cells (x, y up, z) in the corner of the fluid box, seeded with 2 particles per cell and axis
/// (8 per cell), at rest: `n^3 / 2` particles, 1 048 576 at `n = 128`. The block fills 1/16 of
/// the box and collapses along x.
///
/// # Errors
/// [`FlipError::BadParameter`] for `n` not a multiple of 4 or below 8; otherwise as
/// [`FlipSimulation::new`].
pub fn benchmark_dam_break_3d(
    n: usize,
    params: FlipParams<3>,
) -> Result<(FlipSimulation<3>, Particles<3>), FlipError> {
    if n < 8 || !n.is_multiple_of(4) {
        return Err(FlipError::BadParameter {
            name: "n",
            requirement: "must be a multiple of 4 and at least 8",
            value: n.to_string(),
        });
    }
    let h = 1.0 / n as f64;
    let sim = FlipSimulation::new([n; 3], h, params)?;
    let (lo, _) = sim.fluid_box();
    let q = (n / 4) as f64 * h;
    let mut p = Particles::new();
    fill_box(&mut p, h, 2, lo, [lo[0] + q, lo[1] + 2.0 * q, lo[2] + 2.0 * q], |_| [0.0; 3]);
    Ok((sim, p))
}

/// Depth of the pool of [`drop_into_pool`], m.
pub const POOL_DEPTH: f64 = 0.3;
/// Radius of the drop of [`drop_into_pool`], m.
pub const DROP_RADIUS: f64 = 0.15;
/// Height of the drop's centre above the floor of the fluid box in [`drop_into_pool`], m.
pub const DROP_HEIGHT: f64 = 0.65;

/// A drop falling into a pool: a box of `n` cells per axis of size `1/n` m, a pool
/// [`POOL_DEPTH`] deep over its floor and a disk (2D) or ball (3D) of radius [`DROP_RADIUS`]
/// centred [`DROP_HEIGHT`] above the floor in the middle of the box, all at rest. Both are cut
/// from one lattice (that of [`fill_box`] over the whole fluid box), so the drop and the pool
/// have the same particle spacing. The drop falls `DROP_HEIGHT - DROP_RADIUS - POOL_DEPTH =
/// 0.2 m` before it touches the pool, at about 2 m/s.
///
/// # Errors
/// As [`FlipSimulation::new`] (`n` at least 4 for the quadratic kernel).
pub fn drop_into_pool<const D: usize>(
    n: usize,
    params: FlipParams<D>,
) -> Result<(FlipSimulation<D>, Particles<D>), FlipError> {
    let h = 1.0 / n as f64;
    let sim = FlipSimulation::new([n; D], h, params)?;
    let (lo, hi) = sim.fluid_box();
    let mut centre: [f64; D] = std::array::from_fn(|_| 0.5);
    centre[1] = lo[1] + DROP_HEIGHT;
    let surface = lo[1] + POOL_DEPTH;
    let mut p = Particles::new();
    fill_region(
        &mut p,
        h,
        2,
        lo,
        hi,
        |x| {
            let r2: f64 = (0..D).map(|a| (x[a] - centre[a]).powi(2)).sum();
            x[1] < surface || r2 < DROP_RADIUS * DROP_RADIUS
        },
        |_| [0.0; D],
    );
    Ok((sim, p))
}

/// Sloshing in a tank moved horizontally, `x_tank(t) = amplitude sin(2 pi frequency t)`: a tank
/// `1 m` long (`n` cells along x), `depth + max(depth, 0.25)` m tall inside and, in 3D, `0.25 m`
/// wide (z), filled `depth` m deep with water at rest. The simulation runs in the tank's frame
/// (`params.tank_motion` is set to the oscillation along x, [`TankMotion`]); add
/// [`TankMotion::displacement`] to the x of the positions for the world frame.
///
/// The linear natural frequencies of the water are `omega_m^2 = g k_m tanh(k_m d)`,
/// `k_m = m pi / L` (`L` the tank's inner length, `d` the depth); driving near `omega_1` makes
/// the first mode grow.
///
/// # Errors
/// [`FlipError::BadParameter`] for a depth not in `(0, 1]` m, or a negative or non-finite
/// amplitude or frequency (named `tank_motion.amplitude`, `tank_motion.frequency`); otherwise as
/// [`FlipSimulation::new`].
pub fn sloshing_tank<const D: usize>(
    n: usize,
    depth: f64,
    amplitude: f64,
    frequency: f64,
    mut params: FlipParams<D>,
) -> Result<(FlipSimulation<D>, Particles<D>), FlipError> {
    length("depth", depth, 1.0, "must be at most 1 m")?;
    params.tank_motion = Some(TankMotion::oscillation(0, amplitude, frequency));
    let h = 1.0 / n as f64;
    let mut cells = [n; D];
    cells[1] = ((depth + depth.max(0.25)) / h).ceil() as usize + 2;
    if D == 3 {
        cells[D - 1] = (0.25 / h).ceil() as usize + 2;
    }
    let sim = FlipSimulation::new(cells, h, params)?;
    let (lo, mut hi) = sim.fluid_box();
    hi[1] = lo[1] + depth;
    let mut p = Particles::new();
    fill_box(&mut p, h, 2, lo, hi, |_| [0.0; D]);
    Ok((sim, p))
}

/// The cells across the 1 m tank of a preset when none is given: 64 in 2D, 32 in 3D; `None`
/// for an unknown name.
#[must_use]
pub fn resolution_default(name: &str) -> Option<usize> {
    match name {
        "dam-break-3d" | "drop-3d" => Some(32),
        _ if NAMES.contains(&name) => Some(64),
        _ => None,
    }
}

/// The presets [`by_name`] builds, as the command line names them.
pub const NAMES: [&str; 5] = ["dam-break-2d", "dam-break-3d", "drop-2d", "drop-3d", "sloshing-tank"];

/// A preset: its name, simulation and particles.
#[derive(Debug, Clone)]
pub struct Preset<const D: usize> {
    /// The preset's name (one of [`NAMES`]).
    pub name: &'static str,
    /// The simulation.
    pub sim: FlipSimulation<D>,
    /// The particles (in the tank's frame when the tank moves).
    pub particles: Particles<D>,
}

/// A preset in 2D or 3D.
#[derive(Debug, Clone)]
pub enum FlipScene {
    /// A 2D preset.
    Two(Preset<2>),
    /// A 3D preset.
    Three(Preset<3>),
}

impl FlipScene {
    /// The preset's name.
    #[must_use]
    pub fn name(&self) -> &'static str {
        match self {
            FlipScene::Two(s) => s.name,
            FlipScene::Three(s) => s.name,
        }
    }

    /// 2 or 3.
    #[must_use]
    pub fn dim(&self) -> usize {
        match self {
            FlipScene::Two(_) => 2,
            FlipScene::Three(_) => 3,
        }
    }
}

/// Depth of the `sloshing-tank` preset's water, m.
pub const SLOSHING_DEPTH: f64 = 0.25;
/// Amplitude of the `sloshing-tank` preset's tank motion, m.
pub const SLOSHING_AMPLITUDE: f64 = 0.01;

/// The linear natural frequency of the first sloshing mode of water `depth` deep in a tank
/// `length` long under gravity `g`: `f_1 = omega_1 / (2 pi)`, `omega_1^2 = g k tanh(k d)`,
/// `k = pi / length`, Hz.
#[must_use]
pub fn sloshing_frequency(length: f64, depth: f64, g: f64) -> f64 {
    let k = std::f64::consts::PI / length;
    (g * k * (k * depth).tanh()).sqrt() / (2.0 * std::f64::consts::PI)
}

/// Builds a preset by name (see [`NAMES`]); `None` for an unknown name. `resolution` is the
/// cells across the 1 m tank (`None`: the preset's default), `transfer` overrides the default
/// APIC.
///
/// - `dam-break-2d`: [`dam_break`] with a 0.25 x 0.5 m column, 64 cells, volume correction 0.5;
/// - `dam-break-3d`: [`dam_break_3d`] with `a = 0.25` m, 32 cells, volume correction 0.5;
/// - `drop-2d`, `drop-3d`: [`drop_into_pool`], 64 and 32 cells, volume correction 0.5;
/// - `sloshing-tank`: [`sloshing_tank`] in 2D, [`SLOSHING_DEPTH`] deep, the tank moved by
///   [`SLOSHING_AMPLITUDE`] at the first mode's linear natural frequency
///   ([`sloshing_frequency`]) so that the first mode grows by resonance; 64 cells.
#[must_use]
pub fn by_name(
    name: &str,
    resolution: Option<usize>,
    transfer: Option<Transfer>,
) -> Option<Result<FlipScene, FlipError>> {
    fn params<const D: usize>(transfer: Option<Transfer>, volume_correction: f64) -> FlipParams<D> {
        let mut p = FlipParams::<D>::default();
        if let Some(t) = transfer {
            p.transfer = t;
        }
        p.volume_correction = volume_correction;
        p
    }
    let name: &'static str = NAMES.iter().find(|n| **n == name)?;
    let two = |r: Result<(FlipSimulation<2>, Particles<2>), FlipError>| {
        r.map(|(sim, particles)| FlipScene::Two(Preset { name, sim, particles }))
    };
    let three = |r: Result<(FlipSimulation<3>, Particles<3>), FlipError>| {
        r.map(|(sim, particles)| FlipScene::Three(Preset { name, sim, particles }))
    };
    let n = resolution.or_else(|| resolution_default(name))?;
    Some(match name {
        "dam-break-2d" => two(dam_break(n, 0.25, params(transfer, 0.5)).map(|(s, p, _)| (s, p))),
        "dam-break-3d" => three(dam_break_3d(n, 0.25, params(transfer, 0.5)).map(|(s, p, _)| (s, p))),
        "drop-2d" => two(drop_into_pool(n, params(transfer, 0.5))),
        "drop-3d" => three(drop_into_pool(n, params(transfer, 0.5))),
        _ => {
            let params = params::<2>(transfer, 0.0);
            // The tank's inner length, from the tank itself, for the resonant frequency.
            let at_rest = sloshing_tank(n, SLOSHING_DEPTH, 0.0, 0.0, params);
            two(at_rest.and_then(|(sim, _)| {
                let (lo, hi) = sim.fluid_box();
                let f = sloshing_frequency(hi[0] - lo[0], SLOSHING_DEPTH, -params.gravity[1]);
                sloshing_tank(n, SLOSHING_DEPTH, SLOSHING_AMPLITUDE, f, params)
            }))
        }
    })
}
