//! Cell classification from particles: a cell is **solid** if the scene says so (walls,
//! obstacles), else **fluid** if it holds a particle, else **air** (`p = 0` at the free surface,
//! the ghost-fluid Dirichlet condition of `anim_fluid::pressure`).
//!
//! The same pass bins the particles by cell (a stable counting sort), which the gather form of
//! the particle-to-grid transfer walks in a fixed order.

use crate::mac::flatten;
use crate::par;
use anim_fluid::pressure::CellLabel;
use rayon::prelude::*;

/// Particles binned by cell: particles of cell `c` are `order[start[c]..start[c + 1]]`, in
/// increasing particle index.
#[derive(Debug, Clone, Default)]
pub struct Bins {
    pub(crate) cell_of: Vec<u32>,
    pub(crate) start: Vec<u32>,
    pub(crate) order: Vec<u32>,
    /// The position of each particle in `order` (the inverse permutation).
    pub(crate) rank: Vec<u32>,
    cursor: Vec<u32>,
}

impl Bins {
    /// Empty bins for `cells` cells.
    pub(crate) fn new(cells: usize) -> Self {
        Self {
            cell_of: Vec::new(),
            start: vec![0; cells + 1],
            order: Vec::new(),
            rank: Vec::new(),
            cursor: vec![0; cells],
        }
    }

    /// Particles of cell `c`.
    #[inline]
    pub(crate) fn cell(&self, c: usize) -> &[u32] {
        &self.order[self.start[c] as usize..self.start[c + 1] as usize]
    }

    /// Number of particles in cell `c`.
    #[inline]
    #[must_use]
    pub fn count(&self, c: usize) -> usize {
        (self.start[c + 1] - self.start[c]) as usize
    }

    /// Bins `x` (positions in m) on cells of size `h`; positions are clamped into the grid.
    /// Buffers grow only when the particle count grows.
    pub(crate) fn bin<const D: usize>(&mut self, x: &[[f64; D]], n: [usize; D], h: f64) {
        let inv_h = 1.0 / h;
        self.cell_of.resize(x.len(), 0);
        self.order.resize(x.len(), 0);
        self.rank.resize(x.len(), 0);
        self.cell_of
            .par_iter_mut()
            .zip(x.par_iter())
            .with_min_len(par::min_len(par::MIN_PARTICLES, 1))
            .for_each(|(c, p)| {
                let idx: [usize; D] =
                    std::array::from_fn(|a| ((p[a] * inv_h).floor().max(0.0) as usize).min(n[a] - 1));
                *c = flatten(n, idx) as u32;
            });
        self.cursor.fill(0);
        for &c in &self.cell_of {
            self.cursor[c as usize] += 1;
        }
        let mut acc = 0u32;
        for (c, count) in self.cursor.iter_mut().enumerate() {
            self.start[c] = acc;
            acc += *count;
            *count = self.start[c];
        }
        let cells = self.cursor.len();
        self.start[cells] = acc;
        for (p, &c) in self.cell_of.iter().enumerate() {
            let slot = &mut self.cursor[c as usize];
            self.order[*slot as usize] = p as u32;
            self.rank[p] = *slot;
            *slot += 1;
        }
    }
}

/// Labels every cell: solid where `solid`, fluid where a particle is, air elsewhere.
pub(crate) fn classify(solid: &[bool], bins: &Bins, labels: &mut [CellLabel]) {
    labels.par_iter_mut().enumerate().with_min_len(par::min_len(par::MIN_ENTRIES, 1)).for_each(|(c, l)| {
        *l = if solid[c] {
            CellLabel::Solid
        } else if bins.count(c) > 0 {
            CellLabel::Fluid
        } else {
            CellLabel::Air
        };
    });
}
