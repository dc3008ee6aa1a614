//! Reference scenes: particle seeding, still water, the dam break of Martin & Moyce (1952) and
//! a rotating disk.

use crate::error::FlipError;
use crate::particles::Particles;
use crate::sim::{FlipParams, FlipSimulation};

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
    let spacing = h / per_axis as f64;
    let counts: [usize; D] = std::array::from_fn(|a| ((hi[a] - lo[a]) / spacing).round().max(0.0) as usize);
    let total: usize = counts.iter().product();
    for f in 0..total {
        let idx = crate::mac::unflatten(counts, f);
        let x: [f64; D] = std::array::from_fn(|a| lo[a] + (idx[a] as f64 + 0.5) * spacing);
        particles.push(x, v(x));
    }
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
