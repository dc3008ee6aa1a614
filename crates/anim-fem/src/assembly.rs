//! Ordered parallel assembly: per-element force vectors and stiffness blocks are computed in
//! parallel into per-element buffers, then summed into the global force vector and the sparse
//! matrix by **gathering** in a fixed order (each node, each matrix entry reads its element
//! contributions in increasing element order). No two threads write the same location and no
//! float atomics are used, so the result is bitwise identical for any number of threads.
//!
//! The sparse matrix has a 3 x 3 block for every pair of nodes sharing an element. Its pattern,
//! and for every entry the list of element contributions, are computed once by
//! [`Assembly::new`]; assembling afterwards only rewrites the values (no allocation).

use anim_core::linalg::CsrMatrix;
use rayon::prelude::*;

/// Below this many entries the gather runs sequentially (the rayon overhead dominates).
const PARALLEL_MIN: usize = 4096;

/// The sparsity pattern and gather lists for elements with a fixed number of nodes.
#[derive(Debug, Clone)]
pub struct Assembly {
    nodes: usize,
    per_element: usize,
    /// Forces: for node `i`, offsets `node_src[node_ptr[i]..node_ptr[i+1]]` into the element
    /// force buffer (`e * 3n + 3a`).
    node_ptr: Vec<usize>,
    node_src: Vec<usize>,
    /// Node adjacency (sorted), one block per neighbour.
    adj_ptr: Vec<usize>,
    adj: Vec<usize>,
    /// For block slot `s` (an index into `adj`), offsets into the element matrix buffer
    /// (`e * (3n)^2 + 3a * 3n + 3b`) of the 3 x 3 blocks summed into it.
    slot_ptr: Vec<usize>,
    slot_src: Vec<usize>,
    /// For every scalar matrix entry: its block slot, row and column within the block, and row.
    entry_slot: Vec<u32>,
    entry_rc: Vec<u8>,
    entry_row: Vec<u32>,
    /// The matrix with this pattern (zero values).
    template: CsrMatrix,
}

impl Assembly {
    /// Builds the pattern of `elements` (each a list of `per_element` node indices, flattened)
    /// over `nodes` nodes. Indices must be `< nodes` (meshes are validated before this).
    #[must_use]
    pub fn new(nodes: usize, per_element: usize, elements: &[usize]) -> Self {
        assert!(per_element > 0 && elements.len().is_multiple_of(per_element), "Assembly: bad element array");
        let m = elements.len() / per_element;
        let n3 = 3 * per_element;
        // Force gather lists.
        let mut count = vec![0usize; nodes + 1];
        for &v in elements {
            count[v + 1] += 1;
        }
        for i in 0..nodes {
            count[i + 1] += count[i];
        }
        let node_ptr = count.clone();
        let mut node_src = vec![0usize; elements.len()];
        let mut next = count;
        for e in 0..m {
            for a in 0..per_element {
                let v = elements[e * per_element + a];
                node_src[next[v]] = e * n3 + 3 * a;
                next[v] += 1;
            }
        }
        // Block pairs (i, j, source), sorted: sources ascend with the element index.
        let mut pairs: Vec<(usize, usize, usize)> = Vec::with_capacity(m * per_element * per_element);
        for e in 0..m {
            let t = &elements[e * per_element..(e + 1) * per_element];
            for a in 0..per_element {
                for b in 0..per_element {
                    pairs.push((t[a], t[b], e * n3 * n3 + 3 * a * n3 + 3 * b));
                }
            }
        }
        pairs.sort_unstable();
        let mut adj_ptr = vec![0usize; nodes + 1];
        let mut adj = Vec::new();
        let mut slot_ptr = vec![0usize];
        let mut slot_src = Vec::with_capacity(pairs.len());
        let mut k = 0;
        for i in 0..nodes {
            while k < pairs.len() && pairs[k].0 == i {
                let j = pairs[k].1;
                adj.push(j);
                while k < pairs.len() && pairs[k].0 == i && pairs[k].1 == j {
                    slot_src.push(pairs[k].2);
                    k += 1;
                }
                slot_ptr.push(slot_src.len());
            }
            adj_ptr[i + 1] = adj.len();
        }
        // Scalar CSR: row 3i + r holds columns 3j + c for each neighbour j (sorted), so the
        // block (i, j) entry (r, c) sits at 9 adj_ptr[i] + 3 r deg + 3 (slot - adj_ptr[i]) + c.
        let nnz = 9 * adj.len();
        let mut row_ptr = Vec::with_capacity(3 * nodes + 1);
        let mut col_idx = vec![0usize; nnz];
        let mut entry_slot = vec![0u32; nnz];
        let mut entry_rc = vec![0u8; nnz];
        let mut entry_row = vec![0u32; nnz];
        for i in 0..nodes {
            let deg = adj_ptr[i + 1] - adj_ptr[i];
            for r in 0..3 {
                let start = 9 * adj_ptr[i] + 3 * r * deg;
                row_ptr.push(start);
                for (s, slot) in (adj_ptr[i]..adj_ptr[i + 1]).enumerate() {
                    for c in 0..3 {
                        let p = start + 3 * s + c;
                        col_idx[p] = 3 * adj[slot] + c;
                        entry_slot[p] = slot as u32;
                        entry_rc[p] = (3 * r + c) as u8;
                        entry_row[p] = (3 * i + r) as u32;
                    }
                }
            }
        }
        row_ptr.push(nnz);
        let template = CsrMatrix::try_from_parts(3 * nodes, 3 * nodes, row_ptr, col_idx, vec![0.0; nnz])
            .unwrap_or_default();
        Self {
            nodes,
            per_element,
            node_ptr,
            node_src,
            adj_ptr,
            adj,
            slot_ptr,
            slot_src,
            entry_slot,
            entry_rc,
            entry_row,
            template,
        }
    }

    /// Number of nodes.
    #[must_use]
    pub fn nodes(&self) -> usize {
        self.nodes
    }

    /// Nodes per element.
    #[must_use]
    pub fn per_element(&self) -> usize {
        self.per_element
    }

    /// A matrix with this pattern and zero values.
    #[must_use]
    pub fn matrix(&self) -> CsrMatrix {
        self.template.clone()
    }

    /// The row (degree of freedom) of every stored entry, in storage order.
    #[must_use]
    pub fn entry_rows(&self) -> &[u32] {
        &self.entry_row
    }

    /// Number of neighbours (including itself) of every node.
    #[must_use]
    pub fn degree(&self, node: usize) -> usize {
        self.adj_ptr[node + 1] - self.adj_ptr[node]
    }

    /// The neighbours of a node, sorted.
    #[must_use]
    pub fn neighbours(&self, node: usize) -> &[usize] {
        &self.adj[self.adj_ptr[node]..self.adj_ptr[node + 1]]
    }

    /// Sums per-element nodal vectors (`3 n` values per element, node-major) into `out`
    /// (`3 x nodes`), overwriting it.
    pub fn gather_vector(&self, element_values: &[f64], out: &mut [f64]) {
        assert_eq!(out.len(), 3 * self.nodes, "gather_vector: output length");
        let body = |(i, o): (usize, &mut [f64])| {
            let mut s = [0.0f64; 3];
            for &src in &self.node_src[self.node_ptr[i]..self.node_ptr[i + 1]] {
                s[0] += element_values[src];
                s[1] += element_values[src + 1];
                s[2] += element_values[src + 2];
            }
            o.copy_from_slice(&s);
        };
        if out.len() >= PARALLEL_MIN {
            out.par_chunks_mut(3).enumerate().for_each(body);
        } else {
            out.chunks_mut(3).enumerate().for_each(body);
        }
    }

    /// Sums per-element matrices (`(3n)^2` values per element, row-major) into the values of
    /// `out`, which must have this assembly's pattern (from [`matrix`](Self::matrix)).
    pub fn gather_matrix(&self, element_values: &[f64], out: &mut CsrMatrix) {
        let n3 = 3 * self.per_element;
        let values = out.values_mut();
        assert_eq!(values.len(), self.entry_slot.len(), "gather_matrix: pattern mismatch");
        let body = |(p, v): (usize, &mut f64)| {
            let slot = self.entry_slot[p] as usize;
            let rc = self.entry_rc[p] as usize;
            let off = (rc / 3) * n3 + rc % 3;
            let mut s = 0.0;
            for &src in &self.slot_src[self.slot_ptr[slot]..self.slot_ptr[slot + 1]] {
                s += element_values[src + off];
            }
            *v = s;
        };
        if values.len() >= PARALLEL_MIN {
            values.par_iter_mut().enumerate().for_each(body);
        } else {
            values.iter_mut().enumerate().for_each(body);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gathers_match_a_sequential_scatter() {
        // Two tetrahedra sharing a face, plus one sharing an edge.
        let elements = [0usize, 1, 2, 3, 1, 2, 3, 4, 2, 3, 5, 6];
        let asm = Assembly::new(7, 4, &elements);
        let m = elements.len() / 4;
        let vec_vals: Vec<f64> = (0..m * 12).map(|k| (k as f64 * 0.37).sin()).collect();
        let mat_vals: Vec<f64> = (0..m * 144).map(|k| (k as f64 * 0.11).cos()).collect();
        let mut f = vec![0.0; 21];
        asm.gather_vector(&vec_vals, &mut f);
        let mut dense = vec![vec![0.0; 21]; 21];
        let mut f_ref = [0.0; 21];
        for e in 0..m {
            for a in 0..4 {
                for i in 0..3 {
                    f_ref[3 * elements[4 * e + a] + i] += vec_vals[e * 12 + 3 * a + i];
                    for b in 0..4 {
                        for k in 0..3 {
                            dense[3 * elements[4 * e + a] + i][3 * elements[4 * e + b] + k] +=
                                mat_vals[e * 144 + (3 * a + i) * 12 + 3 * b + k];
                        }
                    }
                }
            }
        }
        for d in 0..21 {
            assert!((f[d] - f_ref[d]).abs() < 1e-14);
        }
        let mut k = asm.matrix();
        asm.gather_matrix(&mat_vals, &mut k);
        let kd = k.to_dense();
        for r in 0..21 {
            for c in 0..21 {
                assert!((kd[r][c] - dense[r][c]).abs() < 1e-14, "({r}, {c})");
            }
        }
        // Node 0 and node 6 share no element: no block stored.
        assert_eq!(k.get(0, 18), None);
        assert_eq!(asm.neighbours(0), &[0, 1, 2, 3]);
    }
}
