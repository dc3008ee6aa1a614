//! Per-cell particle count control (reseeding), run after advection when
//! [`FlipParams::reseed`](crate::FlipParams::reseed) is set.
//!
//! A particle fluid drifts away from its seeding density: particles bunch up where the flow
//! converges and leave gaps where it diverges, and a cell that loses all its particles turns
//! into air inside the liquid. After each substep's advection:
//!
//! - an **interior** cell (not solid, and every one of its `3^D - 1` neighbours solid or holding
//!   at least [`Reseed::min`] particles) with fewer than `min` particles gets new ones,
//!   including an empty interior cell (a gap). Surface cells (next to an air cell) are left
//!   alone: they are partly filled by nature, and filling them would add volume. So is spray
//!   (cells whose neighbours are sparse too): with "neighbours hold a particle" as the test
//!   instead, a 10 s sloshing run seeded spray until the fluid filled the box. New particles go into the
//!   emptiest of the cell's `2^D` sub-cells (lowest index first on ties), at a position jittered
//!   inside the sub-cell's middle half by a hash of the cell index, the substep counter, the
//!   particle's rank and the axis (no random-number state, so a resumed run repeats it). They
//!   take the grid velocity at their position (and for APIC the affine matrix `C`, as G2P
//!   would give them);
//! - a cell with more than [`Reseed::max`] particles loses the excess: repeatedly, of the
//!   closest pair of its particles, the one with the higher index (in a cell crowded beyond 64
//!   particles the highest indices go first, down to 64, to bound the cost).
//!
//! **Mass.** Every particle carries the same share of the fluid, so seeding adds mass and
//! thinning removes it. In a disordered flow, cells fall below `min` from sampling noise far
//! more often than they rise above a generous `max`, so reseeding is a net mass source: in the
//! 2D sloshing column of `cargo xtask conformance` (0.25 x 0.5 m, 10 s, volume correction 0.5)
//! bounds 2..8 per cell seeded 16 215 particles and removed 272 at 64^2 (2048 at the start),
//! and bounds 3..5 seeded 119 196 and removed 106 012; either way the fluid grew until it filled
//! the box (density-estimated volume +660% and +630%). Use it for sampling quality in short or
//! gentle runs, not to keep the volume.
//!
//! Survivors keep their relative order and new particles are appended in cell order. Planning
//! is parallel over cells with per-cell results; seeding, removal and compaction are serial
//! passes in a fixed order, so the result is bitwise identical for any number of threads.
//! Scratch buffers are kept in [`Reseeder`] and grow only with the grid or the particle count;
//! the particle arrays grow (amortised) when particles are added.

use crate::classify::Bins;
use crate::error::FlipError;
use crate::mac::{MacGrid, unflatten};
use crate::particles::Particles;
use crate::transfer::{self, Transfer};
use anim_core::bspline::Kernel;
use rayon::prelude::*;

/// Bounds on the particle count per cell.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
pub struct Reseed {
    /// Interior cells with fewer particles are topped up to this count.
    pub min: usize,
    /// Cells with more particles lose the excess.
    pub max: usize,
}

impl Reseed {
    /// Bounds for a fluid seeded with `per_cell` particles per cell: `min = per_cell / 2`
    /// (rounded up) and `max = 2 per_cell`.
    #[must_use]
    pub fn around(per_cell: usize) -> Self {
        Self { min: per_cell.div_ceil(2), max: 2 * per_cell }
    }

    /// Checks `1 <= max`, `min <= max`.
    ///
    /// # Errors
    /// [`FlipError::BadParameter`] naming `reseed.max` or `reseed.min`.
    pub fn validate(&self) -> Result<(), FlipError> {
        if self.max == 0 {
            return Err(FlipError::BadParameter {
                name: "reseed.max",
                requirement: "must be at least 1",
                value: "0".into(),
            });
        }
        if self.min > self.max {
            return Err(FlipError::BadParameter {
                name: "reseed.min",
                requirement: "must not exceed reseed.max",
                value: format!("{} (max {})", self.min, self.max),
            });
        }
        Ok(())
    }
}

/// Scratch of the reseeding pass (sized on first use).
#[derive(Debug, Clone, Default)]
pub struct Reseeder {
    /// Particles to add per cell.
    add: Vec<u32>,
    /// Particles to remove per cell.
    excess: Vec<u32>,
    /// Whether each particle survives.
    keep: Vec<bool>,
    /// Members of the cell being thinned.
    members: Vec<u32>,
}

/// What one pass did.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct ReseedCount {
    /// Particles added.
    pub seeded: usize,
    /// Particles removed.
    pub removed: usize,
}

/// The context a pass reads.
pub(crate) struct Field<'a, const D: usize> {
    pub grid: &'a MacGrid<D>,
    pub solid: &'a [bool],
    pub kernel: Kernel,
    pub transfer: Transfer,
    /// Substep counter (hashed into the jitter).
    pub step: u64,
}

impl Reseeder {
    /// One reseeding pass over `particles` (re-binned into `bins`).
    pub(crate) fn run<const D: usize>(
        &mut self,
        bounds: Reseed,
        field: &Field<'_, D>,
        bins: &mut Bins,
        particles: &mut Particles<D>,
    ) -> ReseedCount {
        let n = field.grid.n;
        let h = field.grid.h;
        let solid = field.solid;
        bins.bin(&particles.x, n, h);
        let cells = solid.len();
        self.add.resize(cells, 0);
        self.excess.resize(cells, 0);
        let bins_ref: &Bins = bins;
        self.add
            .par_iter_mut()
            .zip(self.excess.par_iter_mut())
            .enumerate()
            .with_min_len(crate::par::min_len(crate::par::MIN_ENTRIES, 1))
            .for_each(|(c, (add, excess))| {
                *add = 0;
                *excess = 0;
                if solid[c] {
                    return;
                }
                let count = bins_ref.count(c);
                if count > bounds.max {
                    *excess = (count - bounds.max) as u32;
                } else if count < bounds.min && interior(c, n, solid, bins_ref, bounds.min) {
                    *add = (bounds.min - count) as u32;
                }
            });
        let mut out = ReseedCount::default();
        let old_len = particles.len();
        if self.excess.iter().any(|&e| e > 0) {
            self.keep.clear();
            self.keep.resize(old_len, true);
            for c in 0..cells {
                let excess = self.excess[c] as usize;
                if excess > 0 {
                    self.members.clear();
                    self.members.extend_from_slice(bins.cell(c));
                    out.removed += thin(&mut self.members, excess, &particles.x, &mut self.keep);
                }
            }
        }
        for c in 0..cells {
            let add = self.add[c] as usize;
            if add == 0 {
                continue;
            }
            let idx = unflatten(n, c);
            // Occupancy of the 2^D sub-cells (bit a of the sub-cell index: upper half on axis a).
            let mut occupied = [0u32; 8];
            for &p in bins.cell(c) {
                occupied[subcell(&particles.x[p as usize], idx, h)] += 1;
            }
            for k in 0..add {
                let sub = (0..1usize << D).min_by_key(|&s| (occupied[s], s)).unwrap_or(0);
                occupied[sub] += 1;
                let x: [f64; D] = std::array::from_fn(|a| {
                    let half = ((sub >> a) & 1) as f64;
                    let u = unit(hash(&[field.step, c as u64, k as u64, a as u64]));
                    (idx[a] as f64 + 0.5 * (half + 0.25 + 0.5 * u)) * h
                });
                let (v, cm) = transfer::sample_new(field.grid, field.kernel, field.transfer, &x);
                particles.x.push(x);
                particles.v.push(v);
                particles.c.push(cm);
                out.seeded += 1;
            }
        }
        if out.removed > 0 {
            let mut w = 0;
            for p in 0..particles.len() {
                if p >= old_len || self.keep[p] {
                    particles.x[w] = particles.x[p];
                    particles.v[w] = particles.v[p];
                    particles.c[w] = particles.c[p];
                    w += 1;
                }
            }
            particles.x.truncate(w);
            particles.v.truncate(w);
            particles.c.truncate(w);
        }
        out
    }
}

/// Whether every neighbour of cell `c` (the `3^D - 1` cells around it) is solid or holds at
/// least `min` particles. Cells on the grid's edge count as not interior.
fn interior<const D: usize>(c: usize, n: [usize; D], solid: &[bool], bins: &Bins, min: usize) -> bool {
    let idx = unflatten(n, c);
    if (0..D).any(|a| idx[a] == 0 || idx[a] + 1 >= n[a]) {
        return false;
    }
    let mut stride = [1usize; D];
    for a in 1..D {
        stride[a] = stride[a - 1] * n[a - 1];
    }
    let centre = (3usize.pow(D as u32) - 1) / 2;
    (0..3usize.pow(D as u32)).filter(|&code| code != centre).all(|code| {
        let mut nb = c;
        let mut k = code;
        for s in stride {
            match k % 3 {
                0 => nb -= s,
                2 => nb += s,
                _ => {}
            }
            k /= 3;
        }
        solid[nb] || bins.count(nb) >= min
    })
}

/// Sub-cell of `x` in cell `idx` (bit `a` set in the upper half along axis `a`).
fn subcell<const D: usize>(x: &[f64; D], idx: [usize; D], h: f64) -> usize {
    (0..D).map(|a| usize::from(x[a] / h - idx[a] as f64 >= 0.5) << a).sum()
}

/// Largest cell population thinned by the closest-pair rule.
const THIN_PAIRWISE: usize = 64;

/// Marks `excess` of `members` (particle indices) as removed in `keep`: repeatedly, of the
/// closest remaining pair, the one with the higher index. Returns how many were removed.
fn thin<const D: usize>(members: &mut Vec<u32>, excess: usize, x: &[[f64; D]], keep: &mut [bool]) -> usize {
    let dist2 = |p: u32, q: u32| -> f64 {
        let (a, b) = (&x[p as usize], &x[q as usize]);
        (0..D).map(|k| (a[k] - b[k]).powi(2)).sum()
    };
    let mut removed = 0;
    // The pair search costs O(m^2) per removal: in a pathologically crowded cell the highest
    // indices go first, down to THIN_PAIRWISE members.
    while removed < excess && members.len() > THIN_PAIRWISE {
        if let Some(victim) = members.pop() {
            keep[victim as usize] = false;
            removed += 1;
        }
    }
    while removed < excess && members.len() > 1 {
        let mut best = (f64::INFINITY, 0usize);
        for i in 0..members.len() {
            for j in i + 1..members.len() {
                let d = dist2(members[i], members[j]);
                // Members are in increasing index order, so `j` holds the higher index.
                if d < best.0 {
                    best = (d, j);
                }
            }
        }
        let victim = members.remove(best.1);
        keep[victim as usize] = false;
        removed += 1;
    }
    removed
}

/// SplitMix64 finaliser folded over `words`.
fn hash(words: &[u64]) -> u64 {
    let mut z: u64 = 0x9e37_79b9_7f4a_7c15;
    for &w in words {
        z = z.wrapping_add(w).wrapping_add(0x9e37_79b9_7f4a_7c15);
        z = (z ^ (z >> 30)).wrapping_mul(0xbf58_476d_1ce4_e5b9);
        z = (z ^ (z >> 27)).wrapping_mul(0x94d0_49bb_1331_11eb);
        z ^= z >> 31;
    }
    z
}

/// A hash as a number in `[0, 1)` (its top 53 bits).
fn unit(z: u64) -> f64 {
    (z >> 11) as f64 * (1.0 / (1u64 << 53) as f64)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{FlipParams, FlipSimulation, scenes};

    /// Particles of cell `idx` (cells of size `h`).
    fn in_cell(p: &Particles<2>, idx: [usize; 2], h: f64) -> Vec<usize> {
        (0..p.len()).filter(|&q| (0..2).all(|a| (p.x[q][a] / h).floor() as usize == idx[a])).collect()
    }

    /// Water at rest in a box with no gravity: 16 x 16 cells, the lower half filled with 2 x 2
    /// particles per cell.
    fn still(reseed: Reseed, transfer: Transfer) -> (FlipSimulation<2>, Particles<2>, f64) {
        let params =
            FlipParams::<2> { gravity: [0.0; 2], reseed: Some(reseed), transfer, ..FlipParams::default() };
        let (sim, p) = scenes::still_water::<2>(16, params).unwrap();
        (sim, p, 1.0 / 16.0)
    }

    /// An interior cell emptied of its particles (a gap) is refilled to `min`, one new particle
    /// per sub-cell, each inside the middle half of its sub-cell; nothing else changes.
    #[test]
    fn an_interior_gap_is_refilled() {
        let (mut sim, mut p, h) = still(Reseed { min: 4, max: 8 }, Transfer::Apic);
        let gap = [5, 4];
        let members = in_cell(&p, gap, h);
        assert_eq!(members.len(), 4);
        for &q in members.iter().rev() {
            p.x.remove(q);
            p.v.remove(q);
            p.c.remove(q);
        }
        let kept = p.clone();
        let info = sim.advance(&mut p, 0.01).unwrap();
        assert_eq!((info.seeded, info.removed), (4, 0));
        // The fluid is at rest, so the old particles have not moved and the new ones came last.
        assert_eq!(p.x[..kept.len()], kept.x[..]);
        let new = &p.x[kept.len()..];
        let mut quadrants = [0; 4];
        for x in new {
            let local = [x[0] / h - gap[0] as f64, x[1] / h - gap[1] as f64];
            let sub = usize::from(local[0] >= 0.5) + 2 * usize::from(local[1] >= 0.5);
            quadrants[sub] += 1;
            for (a, &l) in local.iter().enumerate() {
                let within = (l * 2.0).fract();
                assert!((0.25..=0.75).contains(&within), "axis {a}: {local:?}");
            }
        }
        assert_eq!(quadrants, [1; 4]);
        assert!(p.v.iter().flatten().chain(p.c.iter().flatten().flatten()).all(|v| v.abs() < 1e-12));
    }

    /// Surface cells are not topped up: a half-filled cell at the free surface keeps its count.
    #[test]
    fn surface_cells_are_left_alone() {
        let (mut sim, mut p, h) = still(Reseed { min: 4, max: 8 }, Transfer::Apic);
        let top = p.x.iter().map(|x| (x[1] / h).floor() as usize).max().unwrap();
        let members = in_cell(&p, [5, top], h);
        // Remove the upper two particles of a top-row cell.
        for &q in members.iter().rev().take(2) {
            p.x.remove(q);
            p.v.remove(q);
            p.c.remove(q);
        }
        let before = p.clone();
        let info = sim.advance(&mut p, 0.01).unwrap();
        assert_eq!((info.seeded, info.removed), (0, 0));
        assert_eq!(p, before);
    }

    /// A crowded cell loses its excess: two extra particles placed next to two of the cell's
    /// four go, the original four stay.
    #[test]
    fn a_crowded_cell_loses_the_closest_extras() {
        let (mut sim, mut p, h) = still(Reseed { min: 1, max: 4 }, Transfer::Flip(0.97));
        let cell = [6, 3];
        let members = in_cell(&p, cell, h);
        let originals: Vec<[f64; 2]> = members.iter().map(|&q| p.x[q]).collect();
        for &q in &members[..2] {
            let x = p.x[q];
            p.push([x[0] + 1e-3 * h, x[1] + 2e-3 * h], [0.0; 2]);
        }
        let info = sim.advance(&mut p, 0.01).unwrap();
        assert_eq!((info.seeded, info.removed), (0, 2));
        let now: Vec<[f64; 2]> = in_cell(&p, cell, h).iter().map(|&q| p.x[q]).collect();
        assert_eq!(now, originals);
    }

    /// A new particle takes the grid's velocity and, for APIC, its gradient: in a rigidly
    /// rotating disk (an affine, divergence-free field that APIC's transfers and the projection
    /// keep exactly) the particles seeded into an emptied interior cell get
    /// `v = omega (-(y - c), x - c)` and `C = [[0, -omega], [omega, 0]]`.
    #[test]
    fn new_particles_take_the_rotation() {
        let omega = 2.0;
        let params = FlipParams::<2> { reseed: Some(Reseed { min: 4, max: 8 }), ..FlipParams::default() };
        let (mut sim, mut p) = scenes::rotating_disk(32, 0.3, omega, params).unwrap();
        let h = 1.0 / 32.0;
        let hole = [20, 16];
        let members = in_cell(&p, hole, h);
        assert_eq!(members.len(), 4);
        for &q in members.iter().rev() {
            p.x.remove(q);
            p.v.remove(q);
            p.c.remove(q);
        }
        let info = sim.advance(&mut p, 1e-3).unwrap();
        assert_eq!(info.substeps, 1);
        let new = in_cell(&p, hole, h);
        assert_eq!(new.len(), 4, "{info:?}");
        for q in new {
            let x = p.x[q];
            let exact = [-omega * (x[1] - 0.5), omega * (x[0] - 0.5)];
            let err = (0..2).map(|a| (p.v[q][a] - exact[a]).abs()).fold(0.0, f64::max);
            assert!(err < 1e-9, "v {:?} vs {exact:?}", p.v[q]);
            let c_exact = [[0.0, -omega], [omega, 0.0]];
            let err =
                (0..4).map(|k| (p.c[q][k / 2][k % 2] - c_exact[k / 2][k % 2]).abs()).fold(0.0, f64::max);
            assert!(err < 1e-9, "C {:?}", p.c[q]);
        }
    }

    /// Reseeding (seeding and thinning both active) gives the same bits on 1 and 2 threads.
    #[test]
    fn bitwise_identical_on_1_and_2_threads() {
        let run = |threads: usize, transfer: Transfer| {
            let pool = rayon::ThreadPoolBuilder::new().num_threads(threads).build().unwrap();
            pool.install(|| {
                let params = FlipParams::<2> {
                    transfer,
                    reseed: Some(Reseed { min: 3, max: 5 }),
                    volume_correction: 0.5,
                    ..FlipParams::default()
                };
                let (mut sim, mut p, _) = scenes::dam_break(24, 0.3, params).unwrap();
                let (mut seeded, mut removed) = (0, 0);
                for _ in 0..10 {
                    let info = sim.advance(&mut p, 0.02).unwrap();
                    seeded += info.seeded;
                    removed += info.removed;
                }
                let bits: Vec<u64> =
                    p.x.iter()
                        .chain(&p.v)
                        .flatten()
                        .chain(p.c.iter().flatten().flatten())
                        .map(|x| x.to_bits())
                        .collect();
                (bits, seeded, removed)
            })
        };
        for transfer in [Transfer::Apic, Transfer::Flip(0.97)] {
            let one = run(1, transfer);
            assert!(one.1 > 0 && one.2 > 0, "both paths run: seeded {}, removed {}", one.1, one.2);
            assert_eq!(one, run(2, transfer));
        }
    }

    /// Parameter files written before `reseed` existed still parse (reseeding off), and bad
    /// bounds are rejected by name.
    #[test]
    fn parameters_parse_and_validate() {
        let mut json = serde_json::to_value(FlipParams::<2>::default()).unwrap();
        json.as_object_mut().unwrap().remove("reseed");
        let params: FlipParams<2> = serde_json::from_value(json).unwrap();
        assert_eq!(params.reseed, None);
        let bad = |r: Reseed| match FlipSimulation::<2>::new(
            [8, 8],
            0.1,
            FlipParams { reseed: Some(r), ..FlipParams::default() },
        ) {
            Err(FlipError::BadParameter { name, .. }) => name,
            other => panic!("{other:?}"),
        };
        assert_eq!(bad(Reseed { min: 5, max: 4 }), "reseed.min");
        assert_eq!(bad(Reseed { min: 0, max: 0 }), "reseed.max");
        assert_eq!(Reseed::around(4), Reseed { min: 2, max: 8 });
    }
}
