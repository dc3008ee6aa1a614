//! The inside test of a whole lattice, one ray per row: the triangles a row's line along x can
//! cross are bucketed by their y-z bounds, each crossing counts `+1` or `-1` by the side the
//! triangle faces, and a point's winding number is the sum over the crossings ahead of it. A row
//! that passes within rounding distance of a triangle's edge or vertex (where a crossing could
//! be counted twice or missed) is classified by the solid-angle sum instead.

use glam::DVec3;

use super::{ClosedSurface, SurfaceError};

/// The largest lattice classified at once (2^27 points: its answers alone are 128 MiB, and
/// sampling keeps a 24-byte point for each one inside).
const MAX_POINTS: usize = 1 << 27;

/// Checks a lattice's origin, spacing and size.
pub(super) fn check(origin: [f64; 3], spacing: f64, counts: [usize; 3]) -> Result<(), SurfaceError> {
    if !(spacing > 0.0 && spacing.is_finite()) {
        return Err(SurfaceError::Resolution(format!(
            "the spacing must be positive and finite, got {spacing}"
        )));
    }
    if !origin.iter().all(|x| x.is_finite()) {
        return Err(SurfaceError::Resolution(format!("the lattice origin {origin:?} is not finite")));
    }
    let total = counts.iter().try_fold(1usize, |acc, &n| acc.checked_mul(n));
    if total.is_none_or(|t| t > MAX_POINTS) {
        return Err(SurfaceError::Resolution(format!(
            "a lattice of {counts:?} points at spacing {spacing} is too large (at most {MAX_POINTS} points)"
        )));
    }
    Ok(())
}

/// The triangles each row may cross.
pub(super) struct Rows {
    y0: f64,
    z0: f64,
    h: f64,
    ny: usize,
    buckets: Vec<Vec<u32>>,
    /// Distances below this are "on" an edge or the surface.
    eps: f64,
}

impl Rows {
    /// Buckets the triangles of `s` by the rows `(y0 + j h, z0 + k h)`, `j < n[0]`, `k < n[1]`.
    pub(super) fn new(s: &ClosedSurface, y0: f64, z0: f64, h: f64, [ny, nz]: [usize; 2]) -> Self {
        let mut buckets = vec![Vec::new(); ny * nz];
        let extent = (s.hi - s.lo).max_element();
        let eps = 1e-9 * extent.max(f64::MIN_POSITIVE);
        let range = |lo: f64, hi: f64, o: f64, n: usize| {
            let a = ((lo - eps - o) / h).ceil().max(0.0);
            let b = ((hi + eps - o) / h).floor().min(n as f64 - 1.0);
            (a as usize, b as isize)
        };
        for (t, tri) in s.triangles.iter().enumerate() {
            let p = tri.map(|i| s.positions[i]);
            let (ylo, yhi) = (p[0].y.min(p[1].y).min(p[2].y), p[0].y.max(p[1].y).max(p[2].y));
            let (zlo, zhi) = (p[0].z.min(p[1].z).min(p[2].z), p[0].z.max(p[1].z).max(p[2].z));
            let (ja, jb) = range(ylo, yhi, y0, ny);
            let (ka, kb) = range(zlo, zhi, z0, nz);
            // A triangle wholly below the first row or column reaches none.
            let (Ok(jb), Ok(kb)) = (usize::try_from(jb), usize::try_from(kb)) else { continue };
            for k in ka..=kb {
                for j in ja..=jb {
                    buckets[k * ny + j].push(t as u32);
                }
            }
        }
        Rows { y0, z0, h, ny, buckets, eps }
    }

    /// Classifies the points `(x, y_j, z_k)` of row `(j, k)`, `xs` ascending.
    ///
    /// Along the row the winding number changes only at crossings. A triangle the row grazes
    /// (along an edge, through a vertex: [`Crossing::Ambiguous`]) changes it by an amount the
    /// row cannot count, so the x-range of every such triangle is a *cluster* where points are
    /// classified by the solid-angle sum one by one, and the winding number just past a cluster
    /// is taken from one solid-angle sum between it and the next event. Elsewhere the count of
    /// crossings behind a point gives its winding number, so a row that grazes the surface
    /// costs a few solid-angle sums instead of one per point.
    pub(super) fn classify(&self, s: &ClosedSurface, j: usize, k: usize, xs: &[f64], out: &mut [bool]) {
        let (y, z) = (self.y0 + j as f64 * self.h, self.z0 + k as f64 * self.h);
        let mut crossings: Vec<(f64, f64)> = Vec::new();
        let mut clusters: Vec<(f64, f64)> = Vec::new();
        for &t in &self.buckets[k * self.ny + j] {
            let tri = s.triangles[t as usize];
            match self.crossing(s, tri, y, z) {
                Crossing::None => {}
                Crossing::At(x, sign) => crossings.push((x, sign)),
                Crossing::Ambiguous => {
                    let xs = tri.map(|i| s.positions[i].x);
                    let (lo, hi) = (xs[0].min(xs[1]).min(xs[2]), xs[0].max(xs[1]).max(xs[2]));
                    clusters.push((lo - self.eps, hi + self.eps));
                }
            }
        }
        crossings.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        // Overlapping clusters merge; a crossing inside one is the cluster's to account for.
        clusters.sort_unstable_by(|a, b| a.0.total_cmp(&b.0));
        let mut merged: Vec<(f64, f64)> = Vec::with_capacity(clusters.len());
        for (lo, hi) in clusters {
            match merged.last_mut() {
                Some(last) if lo <= last.1 => last.1 = last.1.max(hi),
                _ => merged.push((lo, hi)),
            }
        }
        crossings.retain(|c| !merged.iter().any(|m| c.0 >= m.0 && c.0 <= m.1));
        // Winding number (orientation applied) behind each point, 0 before every event.
        let mut winding = 0.0;
        let (mut next, mut cluster) = (0, 0);
        for (o, &x) in out.iter_mut().zip(xs) {
            loop {
                let crossing = crossings.get(next).map(|c| c.0);
                let passed = merged.get(cluster).filter(|m| m.1 < x);
                match (crossing, passed) {
                    // The nearer event first: a crossing behind the point before the cluster.
                    (Some(c), Some(m)) if c < m.0 && c < x - self.eps => {
                        winding -= s.orientation * crossings[next].1;
                        next += 1;
                    }
                    (_, Some(&(_, end))) => {
                        // Past a cluster: the winding number between it and the next event.
                        while crossings.get(next).is_some_and(|c| c.0 < end) {
                            next += 1;
                        }
                        let after = crossings.get(next).map(|c| c.0);
                        let ahead = merged.get(cluster + 1).map(|m| m.0);
                        winding = match (after, ahead) {
                            (None, None) => 0.0,
                            (a, b) => {
                                let bound = a.unwrap_or(f64::INFINITY).min(b.unwrap_or(f64::INFINITY));
                                s.winding_number([0.5 * (end + bound), y, z]).round()
                            }
                        };
                        cluster += 1;
                    }
                    (Some(c), None) if c < x - self.eps => {
                        winding -= s.orientation * crossings[next].1;
                        next += 1;
                    }
                    _ => break,
                }
            }
            let in_cluster = merged.get(cluster).is_some_and(|m| x >= m.0);
            let near_crossing = crossings.get(next).is_some_and(|c| c.0 <= x + self.eps);
            *o = if in_cluster || near_crossing { s.contains([x, y, z]) } else { winding > 0.5 };
        }
    }

    /// Where the line `(., y, z)` crosses triangle `t`, and the sign of its normal's x part.
    fn crossing(&self, s: &ClosedSurface, t: [usize; 3], y: f64, z: f64) -> Crossing {
        let [a, b, c] = t.map(|i| s.positions[i]);
        let d = (b.y - a.y) * (c.z - a.z) - (b.z - a.z) * (c.y - a.y);
        // Edge functions, each computed from the edge's lower-numbered vertex so that the two
        // triangles sharing an edge get exactly opposite values.
        let edge = |u: usize, v: usize| {
            let (p, q, sign) = if u < v {
                (s.positions[u], s.positions[v], 1.0)
            } else {
                (s.positions[v], s.positions[u], -1.0)
            };
            let e = (q.y - p.y) * (z - p.z) - (q.z - p.z) * (y - p.y);
            let length = ((q.y - p.y).powi(2) + (q.z - p.z).powi(2)).sqrt();
            (sign * e, length)
        };
        let es = [edge(t[1], t[2]), edge(t[2], t[0]), edge(t[0], t[1])];
        let near = |(e, l): (f64, f64)| e.abs() <= self.eps * l.max(self.eps);
        let inside_box = |lo: f64, hi: f64, v: f64| v >= lo - self.eps && v <= hi + self.eps;
        let in_bounds = inside_box(a.y.min(b.y).min(c.y), a.y.max(b.y).max(c.y), y)
            && inside_box(a.z.min(b.z).min(c.z), a.z.max(b.z).max(c.z), z);
        if !in_bounds {
            return Crossing::None;
        }
        let vertex_near =
            [a, b, c].iter().any(|p| (p.y - y).abs() <= self.eps && (p.z - z).abs() <= self.eps);
        if vertex_near || es.iter().any(|&e| near(e)) {
            // Along an edge or at a vertex: a count could be wrong.
            return Crossing::Ambiguous;
        }
        if d == 0.0 || !es.iter().all(|&(e, _)| e * d > 0.0) {
            // Seen edge-on (and away from its edges), or missed.
            return Crossing::None;
        }
        let w = DVec3::new(es[0].0, es[1].0, es[2].0) / d;
        Crossing::At(w.x * a.x + w.y * b.x + w.z * c.x, d.signum())
    }
}

enum Crossing {
    None,
    At(f64, f64),
    Ambiguous,
}
