//! The sparse background grid: fixed-size blocks of `4^D` nodes allocated only where particles
//! are, and the per-step binning of particles by block.
//!
//! **Layout.** Nodes sit at `x_i = i h`, `i in [0, n]^D`. The node lattice is cut into blocks of
//! [`BLOCK`]`^D` nodes; a dense table of block indices (`u32` per block, `1/4^D` of the node
//! count) maps a block coordinate to its slot in the block pool, so node storage is paid only
//! for the blocks matter touches.
//!
//! **Binning** (every step). Each particle's key is the block holding its stencil's base node.
//! A counting sort by key gives the particle order (`order`), the list of occupied particle
//! blocks in increasing key order and each block's range of sorted slots. A particle of block
//! `B` only touches nodes in `[4B, 4B + 8)` per axis (the stencil has at most 4 nodes and
//! starts inside `B`), so the grid blocks are `B + {0, 1}^D` over occupied `B`.
//!
//! **Deterministic scatter without atomics.** P2G writes each particle block's contributions
//! into its own private window of [`WINDOW`]`^D` nodes (in the particles' sorted order, by one
//! task). A grid block then sums the windows of the (at most `2^D`) particle blocks overlapping
//! it in a fixed order. Every sum is thus done in the same order whatever the thread count:
//! results are bitwise identical for 1, 2 or N threads. G2P reads velocities through the same
//! windows, gathered from the grid blocks.
//!
//! **Sorting.** G2P writes the updated particles in the sorted order, so the particle arrays are
//! re-sorted by block every step for free (a double buffer swap): particles of one block are
//! contiguous in memory and their grid window stays in cache.

use crate::kernel::Kernel;
use crate::simd::{Avx2, with_simd};
use rayon::prelude::*;
use wide::f32x4;

/// Nodes per block side.
pub(crate) const BLOCK: usize = 4;
/// Nodes per window side (a block and the next one).
pub(crate) const WINDOW: usize = 8;
/// "No block" in the dense tables.
pub(crate) const NONE: u32 = u32::MAX;

/// `base^D`.
#[inline]
pub(crate) const fn pow(base: usize, d: usize) -> usize {
    let mut r = 1;
    let mut i = 0;
    while i < d {
        r *= base;
        i += 1;
    }
    r
}

/// The sparse grid and the particle binning of the current step.
#[derive(Debug, Clone)]
pub(crate) struct SparseGrid<const D: usize> {
    /// Cells per axis (nodes `0..=n`).
    pub n: usize,
    /// Blocks per axis in the dense tables.
    pub nb: usize,
    /// Dense table: particle-block slot of a block key, or [`NONE`].
    pub pblock_of: Vec<u32>,
    /// Dense table: grid-block slot of a block key, or [`NONE`].
    pub gblock_of: Vec<u32>,
    /// Dense per-key particle counts (kept at zero between steps).
    count: Vec<u32>,
    /// Keys of the occupied particle blocks, increasing.
    pub pblocks: Vec<u32>,
    /// Block coordinates of each occupied particle block (`coords(pblocks[j])`).
    pub pcoords: Vec<[i32; D]>,
    /// `pstart[j]..pstart[j + 1]` are the sorted slots of particle block `j`.
    pub pstart: Vec<u32>,
    /// Keys of the allocated grid blocks, increasing.
    pub gblocks: Vec<u32>,
    /// Per particle: its block key.
    pub keys: Vec<u32>,
    /// Sorted slot -> particle index.
    pub order: Vec<u32>,
    /// Sorted slot -> particle block slot.
    pub slot_block: Vec<u32>,
    cursor: Vec<u32>,
    /// Particle-block windows: `pblocks.len() * WINDOW^D` nodes, each one 4-lane vector (mass,
    /// then momentum or velocity; the lanes past `D + 1` are zero in 2D).
    pub windows: Vec<f32x4>,
    /// Grid blocks: `gblocks.len() * BLOCK^D` nodes laid out as the windows' (mass, then
    /// momentum or velocity).
    pub nodes: Vec<f32x4>,
}

impl<const D: usize> SparseGrid<D> {
    /// Nodes per window.
    pub const WN: usize = pow(WINDOW, D);
    /// Nodes per block.
    pub const BN: usize = pow(BLOCK, D);

    /// An empty grid of `n` cells per axis.
    pub fn new(n: usize) -> Self {
        // Base nodes lie in [1, n - 2]; their block and the next must be in the table.
        let nb = (n >> 2) + 2;
        let cells = pow(nb, D);
        Self {
            n,
            nb,
            pblock_of: vec![NONE; cells],
            gblock_of: vec![NONE; cells],
            count: vec![0; cells],
            pblocks: Vec::new(),
            pcoords: Vec::new(),
            pstart: Vec::new(),
            gblocks: Vec::new(),
            keys: Vec::new(),
            order: Vec::new(),
            slot_block: Vec::new(),
            cursor: Vec::new(),
            windows: Vec::new(),
            nodes: Vec::new(),
        }
    }

    /// Block coordinates of a key.
    #[inline]
    pub fn coords(&self, key: u32) -> [i32; D] {
        let mut k = key as usize;
        let mut c = [0i32; D];
        for a in 0..D {
            c[a] = (k % self.nb) as i32;
            k /= self.nb;
        }
        c
    }

    /// Bins the particles at positions `x` (stride `D`, in cell units after scaling by `inv_h`):
    /// keys, counting sort, occupied blocks and grid blocks, buffer sizes. Allocates only when
    /// the particle or block count exceeds every earlier one.
    pub fn bin(&mut self, x: &[f32], inv_h: f32, kernel: Kernel, simd: Option<Avx2>) {
        let np = x.len() / D;
        for &k in &self.pblocks {
            self.pblock_of[k as usize] = NONE;
        }
        for &k in &self.gblocks {
            self.gblock_of[k as usize] = NONE;
        }
        self.pblocks.clear();
        self.pcoords.clear();
        self.pstart.clear();
        self.gblocks.clear();
        self.keys.resize(np, 0);
        self.order.resize(np, 0);
        self.slot_block.resize(np, 0);

        let nb = self.nb;
        let max_block = (nb - 2) as i32;
        let off = match kernel {
            Kernel::Quadratic => 0.5f32,
            Kernel::Cubic => 1.0,
        };
        self.keys.par_chunks_mut(4096).zip(x.par_chunks(4096 * D)).for_each(|(keys, x)| {
            with_simd(
                simd,
                #[inline(always)]
                || {
                    for (key, x) in keys.iter_mut().zip(x.chunks_exact(D)) {
                        let mut k = 0usize;
                        for a in (0..D).rev() {
                            // Positions are clamped to the domain, so `xs >= 2` and the truncating cast
                            // is the floor (the kernels compute the same base node, `floor(xs - off)`).
                            let base = (x[a] * inv_h - off).max(0.0) as i32;
                            // The clamp only guarantees an in-range index whatever the input (`max`
                            // and `min`, not `clamp`, which compiles to a data-dependent branch).
                            let b = (base >> 2).max(0).min(max_block);
                            k = k * nb + b as usize;
                        }
                        *key = k as u32;
                    }
                },
            );
        });

        // The counting sort goes by runs of equal keys: the particles come sorted by the
        // previous step, so most of a block's particles form one run.
        for run in self.keys[..np].chunk_by(|a, b| a == b) {
            let k = run[0];
            let c = &mut self.count[k as usize];
            if *c == 0 {
                self.pblocks.push(k);
            }
            *c += run.len() as u32;
        }
        self.pblocks.sort_unstable();
        self.cursor.clear();
        let mut run = 0u32;
        for (j, &k) in self.pblocks.iter().enumerate() {
            self.pcoords.push(self.coords(k));
            self.pblock_of[k as usize] = j as u32;
            self.pstart.push(run);
            self.cursor.push(run);
            run += self.count[k as usize];
            self.count[k as usize] = 0;
        }
        self.pstart.push(run);
        let mut i = 0;
        for run in self.keys[..np].chunk_by(|a, b| a == b) {
            let n = run.len();
            let j = self.pblock_of[run[0] as usize];
            let slot = &mut self.cursor[j as usize];
            let s = *slot as usize;
            for (t, o) in self.order[s..s + n].iter_mut().enumerate() {
                *o = (i + t) as u32;
            }
            self.slot_block[s..s + n].fill(j);
            *slot += n as u32;
            i += n;
        }

        // Grid blocks: every occupied block and its + {0,1}^D neighbours.
        let corners = pow(2, D);
        for j in 0..self.pblocks.len() {
            let k = self.pblocks[j] as usize;
            for o in 0..corners {
                let mut nk = k;
                let mut stride = 1;
                for a in 0..D {
                    nk += ((o >> a) & 1) * stride;
                    stride *= nb;
                }
                if self.gblock_of[nk] == NONE {
                    self.gblock_of[nk] = 0;
                    self.gblocks.push(nk as u32);
                }
            }
        }
        self.gblocks.sort_unstable();
        for (g, &k) in self.gblocks.iter().enumerate() {
            self.gblock_of[k as usize] = g as u32;
        }
        self.windows.resize(self.pblocks.len() * Self::WN, f32x4::ZERO);
        self.nodes.resize(self.gblocks.len() * Self::BN, f32x4::ZERO);
    }

    /// Number of allocated grid nodes.
    pub fn allocated_nodes(&self) -> usize {
        self.gblocks.len() * Self::BN
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn binning_sorts_by_block_and_allocates_neighbours_only() {
        let mut g = SparseGrid::<2>::new(64);
        let h = 1.0 / 64.0;
        // Two clusters far apart, given interleaved.
        let pts = [[10.2, 10.7], [50.1, 40.3], [10.9, 11.1], [50.5, 39.9], [13.6, 10.1]];
        let x: Vec<f32> = pts.iter().flat_map(|p| [p[0] * h, p[1] * h]).collect();
        g.bin(&x, 1.0 / h, Kernel::Quadratic, None);
        // Keys increase along the sorted order.
        let keys: Vec<u32> = g.order.iter().map(|&p| g.keys[p as usize]).collect();
        assert!(keys.windows(2).all(|w| w[0] <= w[1]));
        // Cluster one: bases 9..=13 in x (blocks 2, 3), 9..=10 in y (block 2): blocks (2,2), (3,2).
        assert_eq!(g.pblocks.len(), 2 + 1);
        // Each occupied block brings at most 4 grid blocks; overlaps are shared.
        assert!(g.gblocks.len() <= 4 * g.pblocks.len());
        assert_eq!(g.gblocks.len(), 6 + 4);
        assert_eq!(g.allocated_nodes(), 10 * 16);
        // Re-binning elsewhere clears the previous tables.
        g.bin(&x[..2], 1.0 / h, Kernel::Quadratic, None);
        assert_eq!(g.pblocks.len(), 1);
        assert_eq!(g.gblock_of.iter().filter(|&&b| b != NONE).count(), 4);
    }
}
