//! Provisional closed-surface check and inside test, with the API of anim-core's
//! `surface::ClosedSurface` (replaced by it once it is on main).

use anim_core::glam::DVec3;
use std::collections::HashMap;

/// Why a triangle surface is not a closed one.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error("{0}")]
pub struct SurfaceError(String);

/// A closed, consistently oriented triangle surface.
#[derive(Debug, Clone)]
pub struct ClosedSurface {
    positions: Vec<[f64; 3]>,
    triangles: Vec<[usize; 3]>,
}

impl ClosedSurface {
    pub fn new(positions: Vec<[f64; 3]>, triangles: Vec<[usize; 3]>) -> Result<Self, SurfaceError> {
        if triangles.is_empty() {
            return Err(SurfaceError("no triangles".into()));
        }
        if let Some(v) = positions.iter().position(|p| !p.iter().all(|x| x.is_finite())) {
            return Err(SurfaceError(format!("vertex {v} is not finite")));
        }
        let mut edges: HashMap<(usize, usize), usize> = HashMap::new();
        for (t, tri) in triangles.iter().enumerate() {
            if let Some(&i) = tri.iter().find(|&&i| i >= positions.len()) {
                return Err(SurfaceError(format!(
                    "triangle {t} refers to vertex {i} of {}",
                    positions.len()
                )));
            }
            let [a, b, c] = tri.map(|i| DVec3::from_array(positions[i]));
            if (b - a).cross(c - a).length() == 0.0 {
                return Err(SurfaceError(format!("triangle {t} {tri:?} has zero area")));
            }
            for k in 0..3 {
                *edges.entry((tri[k], tri[(k + 1) % 3])).or_default() += 1;
            }
        }
        let mut list: Vec<_> = edges.iter().collect();
        list.sort();
        for (&(a, b), &n) in list {
            if n != 1 || edges.get(&(b, a)) != Some(&1) {
                return Err(SurfaceError(format!(
                    "edge ({a}, {b}) is not shared by exactly two triangles of opposite orientation"
                )));
            }
        }
        Ok(Self { positions, triangles })
    }

    pub fn winding_number(&self, p: [f64; 3]) -> f64 {
        let p = DVec3::from_array(p);
        let mut sum = 0.0;
        for tri in &self.triangles {
            let [a, b, c] = tri.map(|i| DVec3::from_array(self.positions[i]) - p);
            let (la, lb, lc) = (a.length(), b.length(), c.length());
            let num = a.dot(b.cross(c));
            let den = la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb;
            sum += 2.0 * num.atan2(den);
        }
        sum / (4.0 * std::f64::consts::PI)
    }

    pub fn contains(&self, p: [f64; 3]) -> bool {
        self.winding_number(p) > 0.5
    }

    pub fn bounds(&self) -> ([f64; 3], [f64; 3]) {
        let mut lo = [f64::INFINITY; 3];
        let mut hi = [f64::NEG_INFINITY; 3];
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }
}
