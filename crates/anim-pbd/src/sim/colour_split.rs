//! The parallel sweep of one colour of the coloured Gauss-Seidel solver: the colour's
//! constraints split by particle ranges (a binary tree over the particle indices, halved at the
//! middle index), each constraint at the deepest node whose range holds every particle it reads.
//! The two children of a node are swept in parallel on their halves of the positions, each
//! writing its own half directly (no buffered corrections, no second pass), then the node's own
//! constraints, those that straddle the middle, on the calling thread.
//!
//! Constraints of one colour share no movable particle and a fixed particle is never written, so
//! every projection of a colour reads what it would read in any order: the positions are the
//! same bits whatever the split, the thread count or which subtrees run in parallel. The split is
//! made once, when the sweeps are planned; a node is split only while it holds at least
//! [`LEAF`] constraints, so a parallel task always has that much work.

use crate::model::PbdModel;
use crate::project::{Access, Compiled, Ctx, project};
use anim_core::glam::DVec3;

/// A node is split only while it holds at least this many constraints of its colour (the
/// smallest parallel task is about half of it; at some 30 ns a projection, 20-40 us of work
/// against the few microseconds of a fork and join).
pub(super) const LEAF: usize = if cfg!(test) { 16 } else { 1536 };

/// A node of a colour's split: particles `lo..hi`, constraints `start..end` of the colour's
/// order, the left child's `start..left_end`, the right child's `left_end..right_end`, its own
/// `right_end..end`.
#[derive(Debug, Clone, Copy)]
pub(super) struct Node {
    lo: u32,
    mid: u32,
    hi: u32,
    start: u32,
    left_end: u32,
    right_end: u32,
    end: u32,
    /// Index of the left child; the right child follows its subtree. `u32::MAX` for a leaf.
    left: u32,
    right: u32,
}

/// The nodes of one colour, root first.
pub(super) type Split = Vec<Node>;

/// Reorders `order` (the model indices of one colour's constraints) into the split's order and
/// returns the split; `first` is the position of the colour's first constraint in the sweep.
pub(super) fn split_colour(model: &PbdModel, order: &mut [usize], first: usize) -> Split {
    let span = |j: usize| {
        let ps = model.constraint_particles(j);
        let lo = ps.iter().copied().min().unwrap_or(0);
        let hi = ps.iter().copied().max().map_or(0, |m| m + 1);
        (lo, hi)
    };
    let spans: Vec<(usize, usize)> = order.iter().map(|&j| span(j)).collect();
    let mut items: Vec<(usize, (usize, usize))> = order.iter().copied().zip(spans).collect();
    let mut nodes = Vec::new();
    build(&mut items, 0, model.num_particles(), first, &mut nodes);
    for (o, (j, _)) in order.iter_mut().zip(&items) {
        *o = *j;
    }
    nodes
}

/// Builds the subtree of `items` (constraint, particle span) over particles `lo..hi`, reordering
/// `items` into left, right, own; returns the node's index.
fn build(
    items: &mut [(usize, (usize, usize))],
    lo: usize,
    hi: usize,
    start: usize,
    nodes: &mut Split,
) -> u32 {
    let at = nodes.len();
    let mid = lo + (hi - lo) / 2;
    let end = start + items.len();
    let leaf = Node {
        lo: lo as u32,
        mid: mid as u32,
        hi: hi as u32,
        start: start as u32,
        left_end: start as u32,
        right_end: start as u32,
        end: end as u32,
        left: u32::MAX,
        right: u32::MAX,
    };
    nodes.push(leaf);
    if items.len() < LEAF || hi - lo < 2 {
        return at as u32;
    }
    // Stable partition: left half, right half, straddling.
    let side = |&(_, (a, b)): &(usize, (usize, usize))| {
        if b <= mid {
            0
        } else if a >= mid {
            1
        } else {
            2
        }
    };
    items.sort_by_key(side);
    let nl = items.iter().take_while(|it| side(it) == 0).count();
    let nr = items[nl..].iter().take_while(|it| side(it) == 1).count();
    if nl == 0 || nr == 0 {
        // Nothing to run beside it: keep the node a leaf.
        return at as u32;
    }
    let (left_items, rest) = items.split_at_mut(nl);
    let left = build(left_items, lo, mid, start, nodes);
    let right = build(&mut rest[..nr], mid, hi, start + nl, nodes);
    nodes[at] =
        Node { left_end: (start + nl) as u32, right_end: (start + nl + nr) as u32, left, right, ..leaf };
    at as u32
}

/// Positions of particles `base..base + p.len()`, written directly.
struct Window<'a> {
    p: &'a mut [DVec3],
    base: usize,
}

impl Access for Window<'_> {
    const DIRECT: bool = true;
    #[inline(always)]
    fn get(&self, i: usize) -> DVec3 {
        self.p[i - self.base]
    }
    #[inline(always)]
    fn apply(&mut self, _slot: usize, i: usize, dx: DVec3) {
        self.p[i - self.base] += dx;
    }
}

/// Sweeps one colour along its split: `compiled` and `lambda` are the colour's (the split's
/// `start` offsets count from `first`), `p` every particle's position.
pub(super) fn sweep_colour(
    ctx: &Ctx<'_>,
    split: &Split,
    first: usize,
    compiled: &[Compiled],
    lambda: &mut [f64],
    p: &mut [DVec3],
) {
    if let Some(root) = split.first() {
        let n = root.hi as usize;
        sweep_node(ctx, split, 0, first, compiled, lambda, &mut p[..n]);
    }
}

/// Sweeps node `k`: `lambda` holds its constraints (from `compiled[node.start - first]`), `p`
/// the positions of its particles.
fn sweep_node(
    ctx: &Ctx<'_>,
    split: &Split,
    k: usize,
    first: usize,
    compiled: &[Compiled],
    lambda: &mut [f64],
    p: &mut [DVec3],
) {
    let node = split[k];
    let (lo, start) = (node.lo as usize, node.start as usize);
    let own = if node.left == u32::MAX {
        start
    } else {
        let (pl, pr) = p.split_at_mut(node.mid as usize - lo);
        let (ll, rest) = lambda.split_at_mut(node.left_end as usize - start);
        let rest = &mut rest[..(node.right_end - node.left_end) as usize];
        anim_core::par::join(
            || sweep_node(ctx, split, node.left as usize, first, compiled, ll, pl),
            || sweep_node(ctx, split, node.right as usize, first, compiled, rest, pr),
        );
        node.right_end as usize
    };
    let cs = &compiled[own - first..node.end as usize - first];
    let ls = &mut lambda[own - start..];
    let mut acc = Window { p, base: lo };
    for (c, l) in cs.iter().zip(ls.iter_mut()) {
        project(ctx, c, l, &mut acc);
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::project::colour;

    /// Every constraint lies inside its node's particle range, the children's ranges are the
    /// node's halves, and the constraints left to the roots' own sweeps (the only part no other
    /// thread can run beside) are few.
    #[test]
    fn splits_hold_their_constraints_and_leave_little_sequential() {
        let model = crate::scenes::benchmark_cloth(40).expect("cloth").model;
        let (colours, ncol) = colour(&model);
        let mut order: Vec<usize> = (0..model.num_constraints()).collect();
        order.sort_by_key(|&j| (colours[j], j));
        let mut start = 0;
        let mut straddling = 0;
        for c in 0..ncol as u32 {
            let len = colours.iter().filter(|&&k| k == c).count();
            let colour_order = &mut order[start..start + len];
            let mut sorted = colour_order.to_vec();
            let split = split_colour(&model, colour_order, start);
            // A permutation of the colour.
            let mut again = colour_order.to_vec();
            again.sort_unstable();
            sorted.sort_unstable();
            assert_eq!(again, sorted);
            assert!(split.len() > 1, "colour {c} of {len} constraints not split");
            for node in &split {
                let (s, e) = (node.start as usize - start, node.end as usize - start);
                for &j in &colour_order[s..e] {
                    for &p in model.constraint_particles(j) {
                        assert!((node.lo..node.hi).contains(&(p as u32)), "constraint {j} outside its node");
                    }
                }
                if node.left != u32::MAX {
                    let (l, r) = (split[node.left as usize], split[node.right as usize]);
                    assert_eq!((l.lo, l.hi, r.lo, r.hi), (node.lo, node.mid, node.mid, node.hi));
                    assert_eq!(
                        (l.start, l.end, r.start, r.end),
                        (node.start, node.left_end, node.left_end, node.right_end)
                    );
                }
            }
            if let Some(root) = split.first() {
                straddling += (root.end - root.right_end) as usize;
            }
            start += len;
        }
        assert!(straddling * 20 < model.num_constraints(), "{straddling} straddling constraints");
    }
}
