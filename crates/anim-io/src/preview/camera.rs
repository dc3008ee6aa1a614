//! A look-at camera with perspective or orthographic projection. The workspace's scenes are
//! y up: [`Camera::framing`] with up `(0, 1, 0)` shows a 3-D scene standing, and
//! [`Camera::xy_plane`] a 2-D one (the xy plane, x right and y up).

use glam::DVec3;

/// How the camera projects.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Projection {
    /// Perspective with this vertical field of view, in degrees.
    Perspective {
        /// Vertical field of view in degrees (0 to 180, exclusive).
        fov_y_degrees: f64,
    },
    /// Orthographic, showing this world-space height from the bottom to the top of the image.
    Orthographic {
        /// World-space height of the view.
        height: f64,
    },
}

/// A camera at `eye` looking at `target`, `up` giving the image's upward direction.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Camera {
    /// Camera position.
    pub eye: [f64; 3],
    /// The point at the image centre.
    pub target: [f64; 3],
    /// The world direction that appears upward (need not be orthogonal to the view direction).
    pub up: [f64; 3],
    /// The projection.
    pub projection: Projection,
    /// Distance in front of the eye below which geometry is not drawn (perspective only).
    pub near: f64,
}

impl Camera {
    /// A perspective camera (40 degree vertical field of view) at `eye` looking at `target`.
    pub fn look_at(eye: [f64; 3], target: [f64; 3], up: [f64; 3]) -> Self {
        let dist = (DVec3::from(target) - DVec3::from(eye)).length();
        Camera {
            eye,
            target,
            up,
            projection: Projection::Perspective { fov_y_degrees: 40.0 },
            near: (dist * 1e-3).max(1e-9),
        }
    }

    /// The same camera with a perspective projection.
    pub fn perspective(mut self, fov_y_degrees: f64) -> Self {
        self.projection = Projection::Perspective { fov_y_degrees };
        self
    }

    /// The same camera with an orthographic projection showing `height` world units vertically.
    pub fn orthographic(mut self, height: f64) -> Self {
        self.projection = Projection::Orthographic { height };
        self
    }

    /// A perspective camera looking along `direction` at the centre of the box `[min, max]`,
    /// far enough that the box's bounding sphere fits the view (of a square or wider image).
    pub fn framing(min: [f64; 3], max: [f64; 3], direction: [f64; 3], up: [f64; 3]) -> Self {
        let (min, max) = (DVec3::from(min), DVec3::from(max));
        let centre = 0.5 * (min + max);
        let radius = (0.5 * (max - min).length()).max(1e-9);
        let fov: f64 = 40.0;
        let dist = 1.05 * radius / (0.5 * fov.to_radians()).sin();
        let dir = DVec3::from(direction).try_normalize().unwrap_or(DVec3::NEG_Z);
        let eye = centre - dir * dist;
        Camera::look_at(eye.into(), centre.into(), up).perspective(fov)
    }

    /// A perspective camera (40 degree vertical field of view) looking along `direction` at
    /// the centre of the box `[min, max]`, as near as it can be with every corner of the box in
    /// an image of width over height `aspect` (5 % in from its edges): the box fills the picture
    /// along its tighter side.
    pub fn fitting(min: [f64; 3], max: [f64; 3], direction: [f64; 3], up: [f64; 3], aspect: f64) -> Self {
        let (min, max) = (DVec3::from(min), DVec3::from(max));
        let centre = 0.5 * (min + max);
        let fov: f64 = 40.0;
        let aspect = if aspect > 0.0 && aspect.is_finite() { aspect } else { 1.0 };
        let ty = 0.95 * (0.5 * fov.to_radians()).tan();
        let tx = aspect * ty;
        let forward = DVec3::from(direction).try_normalize().unwrap_or(DVec3::NEG_Z);
        let right = forward
            .cross(DVec3::from(up))
            .try_normalize()
            .or_else(|| forward.cross(DVec3::X).try_normalize())
            .unwrap_or(DVec3::Y);
        let true_up = right.cross(forward);
        // A corner at (x, y) across the view and z along it from the centre is in the picture
        // when |x| <= tx (d + z) and |y| <= ty (d + z), d the eye's distance to the centre.
        let mut dist = 1e-9_f64;
        for i in 0..8 {
            let corner = DVec3::new(
                if i & 1 == 1 { max.x } else { min.x },
                if i & 2 == 2 { max.y } else { min.y },
                if i & 4 == 4 { max.z } else { min.z },
            );
            let v = corner - centre;
            let (x, y, z) = (v.dot(right), v.dot(true_up), v.dot(forward));
            dist = dist.max(x.abs() / tx - z).max(y.abs() / ty - z);
        }
        let eye = centre - forward * dist;
        Camera::look_at(eye.into(), centre.into(), up).perspective(fov)
    }

    /// An orthographic camera looking along `-z` at the rectangle `[min, max]` of the xy plane,
    /// x to the right and y up, with a 5 % margin: the view of a 2-D scene. `aspect` is the
    /// image's width over height.
    pub fn xy_plane(min: [f64; 2], max: [f64; 2], aspect: f64) -> Self {
        let cx = 0.5 * (min[0] + max[0]);
        let cy = 0.5 * (min[1] + max[1]);
        let w = (max[0] - min[0]).abs();
        let h = (max[1] - min[1]).abs();
        let aspect = if aspect > 0.0 && aspect.is_finite() { aspect } else { 1.0 };
        let height = (h.max(w / aspect) * 1.05).max(1e-9);
        Camera {
            eye: [cx, cy, height],
            target: [cx, cy, 0.0],
            up: [0.0, 1.0, 0.0],
            projection: Projection::Orthographic { height },
            near: 0.0,
        }
    }

    /// The projection onto an image of `width x height` pixels.
    pub(crate) fn view(&self, width: u32, height: u32) -> View {
        let eye = DVec3::from(self.eye);
        let forward = (DVec3::from(self.target) - eye).try_normalize().unwrap_or(DVec3::NEG_Z);
        let up0 = DVec3::from(self.up);
        let right = forward
            .cross(up0)
            .try_normalize()
            .or_else(|| forward.cross(DVec3::X).try_normalize())
            .or_else(|| forward.cross(DVec3::Y).try_normalize())
            .unwrap_or(DVec3::X);
        let up = right.cross(forward);
        let h = f64::from(height.max(1));
        let (perspective, focal) = match self.projection {
            Projection::Perspective { fov_y_degrees } => {
                let half = (0.5 * fov_y_degrees.clamp(1e-3, 179.0)).to_radians();
                (true, 0.5 * h / half.tan())
            }
            Projection::Orthographic { height } => (false, h / height.abs().max(1e-300)),
        };
        View {
            eye,
            right,
            up,
            forward,
            perspective,
            focal,
            cx: 0.5 * f64::from(width),
            cy: 0.5 * h,
            near: if perspective { self.near.max(1e-12) } else { f64::NEG_INFINITY },
        }
    }
}

/// A camera resolved for one image size.
#[derive(Debug, Clone, Copy)]
pub(crate) struct View {
    pub(crate) eye: DVec3,
    pub(crate) right: DVec3,
    pub(crate) up: DVec3,
    pub(crate) forward: DVec3,
    perspective: bool,
    focal: f64,
    cx: f64,
    cy: f64,
    near: f64,
}

/// A projected point: pixel coordinates (y down), view depth and its depth-buffer key.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Projected {
    pub(crate) x: f64,
    pub(crate) y: f64,
    pub(crate) depth: f64,
    pub(crate) key: f64,
}

impl View {
    /// Projects a world point; `None` when it is closer than the near plane or not finite.
    pub(crate) fn project(&self, p: DVec3) -> Option<Projected> {
        let d = p - self.eye;
        let depth = d.dot(self.forward);
        if !(depth >= self.near) || !depth.is_finite() {
            return None;
        }
        let s = if self.perspective { self.focal / depth } else { self.focal };
        let x = self.cx + s * d.dot(self.right);
        let y = self.cy - s * d.dot(self.up);
        if !(x.is_finite() && y.is_finite()) {
            return None;
        }
        Some(Projected { x, y, depth, key: self.key(depth) })
    }

    /// The depth-buffer key of a view depth: smaller is nearer, and affine in screen space across
    /// a triangle (`-1/depth` for perspective, `depth` for orthographic).
    pub(crate) fn key(&self, depth: f64) -> f64 {
        if self.perspective { -1.0 / depth } else { depth }
    }

    /// Pixels per world unit at view depth `depth`.
    pub(crate) fn scale(&self, depth: f64) -> f64 {
        if self.perspective { self.focal / depth } else { self.focal }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn target_lands_at_the_image_centre_and_up_is_up() {
        let cam = Camera::look_at([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
        let v = cam.view(200, 100);
        let c = v.project(DVec3::ZERO).unwrap();
        assert!((c.x - 100.0).abs() < 1e-12 && (c.y - 50.0).abs() < 1e-12);
        assert!((c.depth - 5.0).abs() < 1e-12);
        let above = v.project(DVec3::new(0.0, 1.0, 0.0)).unwrap();
        assert!(above.y < c.y);
        let right = v.project(DVec3::new(1.0, 0.0, 0.0)).unwrap();
        assert!(right.x > c.x);
        // tan(20 deg) * 5 world units fill half the image height.
        let edge = v.project(DVec3::new(0.0, 5.0 * 20f64.to_radians().tan(), 0.0)).unwrap();
        assert!(edge.y.abs() < 1e-9, "{}", edge.y);
        assert!(v.project(DVec3::new(0.0, 0.0, 6.0)).is_none(), "behind the eye");
    }

    #[test]
    fn orthographic_scale_does_not_depend_on_depth() {
        let cam = Camera::look_at([0.0, 0.0, 5.0], [0.0; 3], [0.0, 1.0, 0.0]).orthographic(4.0);
        let v = cam.view(100, 100);
        let a = v.project(DVec3::new(1.0, 0.0, 0.0)).unwrap();
        let b = v.project(DVec3::new(1.0, 0.0, -3.0)).unwrap();
        assert!((a.x - 75.0).abs() < 1e-12 && (b.x - 75.0).abs() < 1e-12);
        assert!(a.key < b.key);
    }

    #[test]
    fn the_xy_plane_camera_fits_the_rectangle() {
        let cam = Camera::xy_plane([0.0, 0.0], [2.0, 1.0], 2.0);
        let v = cam.view(200, 100);
        // The upper right corner (x right, y up) near the image's top right, the lower left
        // near its bottom left.
        let p = v.project(DVec3::new(2.0, 1.0, 0.0)).unwrap();
        assert!(p.x <= 200.0 && p.x > 190.0 && p.y >= 0.0 && p.y < 10.0, "{p:?}");
        let q = v.project(DVec3::new(0.0, 0.0, 0.0)).unwrap();
        assert!(q.x >= 0.0 && q.x < 10.0 && q.y <= 100.0 && q.y > 90.0, "{q:?}");
    }

    /// Every corner of the box lands inside the picture, and one touches the 5 % margin of
    /// the picture's tighter side: the box is as large as it can be.
    #[test]
    fn a_fitting_camera_shows_the_whole_box_as_large_as_it_fits() {
        for (min, max, (w, h)) in [
            ([-1.0, 0.0, -1.0], [1.0, 2.0, 1.0], (400, 300)),
            ([0.0, 0.0, 0.0], [3.0, 0.5, 0.2], (400, 300)),
            ([0.0, -5.0, 0.0], [0.1, 5.0, 0.1], (300, 300)),
        ] {
            let aspect = f64::from(w) / f64::from(h);
            let v = Camera::fitting(min, max, [0.55, -0.45, -1.0], [0.0, 1.0, 0.0], aspect).view(w, h);
            let mut slack = f64::INFINITY;
            for i in 0..8 {
                let p = DVec3::new(
                    if i & 1 == 1 { max[0] } else { min[0] },
                    if i & 2 == 2 { max[1] } else { min[1] },
                    if i & 4 == 4 { max[2] } else { min[2] },
                );
                let q = v.project(p).unwrap();
                let (mx, my) = (0.025 * f64::from(w), 0.025 * f64::from(h));
                assert!(q.x >= mx - 1e-6 && q.x <= f64::from(w) - mx + 1e-6, "{min:?} {max:?}: {q:?}");
                assert!(q.y >= my - 1e-6 && q.y <= f64::from(h) - my + 1e-6, "{min:?} {max:?}: {q:?}");
                slack = slack
                    .min((q.x - mx).min(f64::from(w) - mx - q.x).min(q.y - my).min(f64::from(h) - my - q.y));
            }
            assert!(
                slack.abs() < 1e-6,
                "{min:?} {max:?}: the nearest corner is {slack} px in from the margin"
            );
        }
    }

    #[test]
    fn up_parallel_to_view_still_gives_a_basis() {
        let v = Camera::look_at([0.0, 5.0, 0.0], [0.0; 3], [0.0, 1.0, 0.0]).view(10, 10);
        assert!((v.right.length() - 1.0).abs() < 1e-12 && v.right.dot(v.forward).abs() < 1e-12);
    }
}
