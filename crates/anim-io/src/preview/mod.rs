//! A software preview renderer: no GPU, no display. Particles as shaded spheres (discs with
//! sphere shading and per-pixel depth), triangle meshes with flat or smooth Lambert shading,
//! line segments for springs and skeletons, 2-D scalar fields through viridis; frames to PNG and
//! a run to an animated GIF.
//!
//! Everything goes through one depth buffer, so particles, meshes and lines occlude each other
//! correctly in any drawing order; particles are also drawn back to front so their anti-aliased
//! rims blend over what is behind them. Lighting is one directional light above-left-behind the
//! camera plus ambient, two-sided (cloth shows both faces; the back face gets
//! [`MeshStyle::back_color`]).
//!
//! Why hand-written: a z-buffered triangle and sphere rasteriser is about 300 lines. `tiny-skia`
//! (well kept) draws anti-aliased 2-D paths but has no depth buffer, and filling tens of thousands
//! of one-pixel cloth triangles as paths costs far more than rasterising them. PNG goes through
//! the `png` crate and GIF through the `gif` crate (both of the image-rs project; `image` itself
//! would add colour management and format plumbing a preview does not use).
//!
//! ```
//! use anim_io::preview::{Camera, Canvas, MeshStyle};
//!
//! // A unit square in the xy plane seen from the front.
//! let positions = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]];
//! let triangles = [[0, 1, 2], [0, 2, 3]];
//! let camera = Camera::look_at([0.5, 0.5, 3.0], [0.5, 0.5, 0.0], [0.0, 1.0, 0.0]);
//! let mut canvas = Canvas::new(64, 64, [255, 255, 255]);
//! canvas.draw_mesh(&camera, &positions, &triangles, &MeshStyle::default())?;
//! assert_ne!(canvas.pixel(32, 32), [255, 255, 255]); // the centre is covered
//! assert_eq!(canvas.pixel(0, 0), [255, 255, 255]); // the corner is background
//! # Ok::<(), anim_io::IoError>(())
//! ```

mod camera;
pub mod colormap;
mod gif_writer;

pub use camera::{Camera, Projection};
pub use gif_writer::GifWriter;

use crate::IoError;
use crate::data::Real;
use camera::View;
use glam::DVec3;
use std::path::Path;

/// How a triangle mesh is shaded.
#[derive(Debug, Clone, Copy, Default, PartialEq, Eq)]
pub enum Shading {
    /// One normal per triangle: facets visible.
    Flat,
    /// Area-weighted vertex normals interpolated across each triangle.
    #[default]
    Smooth,
}

/// Colours and shading of a mesh.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct MeshStyle {
    /// Colour of the front face (counter-clockwise as seen).
    pub color: [u8; 3],
    /// Colour of the back face.
    pub back_color: [u8; 3],
    /// Flat or smooth shading.
    pub shading: Shading,
}

impl Default for MeshStyle {
    fn default() -> Self {
        MeshStyle { color: [90, 140, 210], back_color: [210, 120, 80], shading: Shading::Smooth }
    }
}

/// Per-item colours: one for all, or one each.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Colors<'a> {
    /// The same colour for every item.
    Uniform([u8; 3]),
    /// One colour per item (e.g. from [`colormap::colorize`]).
    PerItem(&'a [[u8; 3]]),
}

impl Colors<'_> {
    fn check(&self, n: usize, what: &str) -> Result<(), IoError> {
        match self {
            Colors::PerItem(c) if c.len() != n => {
                Err(IoError::data("preview", format!("{} colours for {n} {what}", c.len())))
            }
            _ => Ok(()),
        }
    }

    fn get(&self, i: usize) -> [u8; 3] {
        match self {
            Colors::Uniform(c) => *c,
            Colors::PerItem(c) => c.get(i).copied().unwrap_or([0, 0, 0]),
        }
    }
}

const AMBIENT: f64 = 0.28;
const DIFFUSE: f64 = 0.72;

/// An RGB image with a depth buffer.
#[derive(Debug, Clone, PartialEq)]
pub struct Canvas {
    width: u32,
    height: u32,
    background: [u8; 3],
    color: Vec<[u8; 3]>,
    depth: Vec<f64>,
}

fn shade(c: [u8; 3], light: f64) -> [u8; 3] {
    let l = AMBIENT + DIFFUSE * light.clamp(0.0, 1.0);
    c.map(|v| (f64::from(v) * l).round().min(255.0) as u8)
}

fn blend(under: [u8; 3], over: [u8; 3], alpha: f64) -> [u8; 3] {
    [0, 1, 2].map(|k| (f64::from(under[k]) * (1.0 - alpha) + f64::from(over[k]) * alpha).round() as u8)
}

fn index_error(what: &str, element: usize, n: usize) -> IoError {
    IoError::data("preview", format!("{what} {element} refers to a point past the last ({n} points)"))
}

impl Canvas {
    /// A `width x height` canvas filled with `background`.
    pub fn new(width: u32, height: u32, background: [u8; 3]) -> Self {
        let n = width as usize * height as usize;
        Canvas { width, height, background, color: vec![background; n], depth: vec![f64::INFINITY; n] }
    }

    /// Width in pixels.
    pub fn width(&self) -> u32 {
        self.width
    }

    /// Height in pixels.
    pub fn height(&self) -> u32 {
        self.height
    }

    /// Refills with the background colour and clears the depth buffer.
    pub fn clear(&mut self) {
        self.color.fill(self.background);
        self.depth.fill(f64::INFINITY);
    }

    /// The colour at pixel `(x, y)`, `(0, 0)` top left; the background outside the canvas.
    pub fn pixel(&self, x: u32, y: u32) -> [u8; 3] {
        if x < self.width && y < self.height {
            self.color[(y * self.width + x) as usize]
        } else {
            self.background
        }
    }

    /// The pixels, row by row from the top.
    pub fn pixels(&self) -> &[[u8; 3]] {
        &self.color
    }

    /// Depth-tests and writes one pixel; `key` smaller is nearer.
    #[inline]
    fn put(&mut self, x: usize, y: usize, key: f64, c: [u8; 3]) {
        let i = y * self.width as usize + x;
        if key < self.depth[i] {
            self.depth[i] = key;
            self.color[i] = c;
        }
    }

    /// Draws a triangle mesh. Triangles with a vertex behind the near plane are not drawn.
    /// An index past the last position is an error (nothing is drawn).
    pub fn draw_mesh<T: Real>(
        &mut self,
        camera: &Camera,
        positions: &[[T; 3]],
        triangles: &[[usize; 3]],
        style: &MeshStyle,
    ) -> Result<(), IoError> {
        self.mesh(camera, positions, triangles, style, None)
    }

    /// Draws a triangle mesh with a colour per vertex (a field through a colour map), blended
    /// across each triangle and lit as [`Canvas::draw_mesh`] lights `shading`; both faces take
    /// the vertices' colours. A colour list of another length than `positions` is an error.
    pub fn draw_mesh_colored<T: Real>(
        &mut self,
        camera: &Camera,
        positions: &[[T; 3]],
        triangles: &[[usize; 3]],
        colors: &[[u8; 3]],
        shading: Shading,
    ) -> Result<(), IoError> {
        Colors::PerItem(colors).check(positions.len(), "mesh vertices")?;
        let style = MeshStyle { shading, ..MeshStyle::default() };
        self.mesh(camera, positions, triangles, &style, Some(colors))
    }

    fn mesh<T: Real>(
        &mut self,
        camera: &Camera,
        positions: &[[T; 3]],
        triangles: &[[usize; 3]],
        style: &MeshStyle,
        vertex_colors: Option<&[[u8; 3]]>,
    ) -> Result<(), IoError> {
        let n = positions.len();
        if let Some(e) = triangles.iter().position(|t| t.iter().any(|&i| i >= n)) {
            return Err(index_error("triangle", e, n));
        }
        let view = camera.view(self.width, self.height);
        let world: Vec<DVec3> = positions.iter().map(|p| DVec3::from(p.map(T::to_f64))).collect();
        let projected: Vec<_> = world.iter().map(|&p| view.project(p)).collect();
        let light = light_dir(&view);
        let normals = match style.shading {
            Shading::Smooth => {
                let mut nrm = vec![DVec3::ZERO; n];
                for t in triangles {
                    let w = (world[t[1]] - world[t[0]]).cross(world[t[2]] - world[t[0]]);
                    if w.is_finite() {
                        for &i in t {
                            nrm[i] += w;
                        }
                    }
                }
                nrm.iter_mut().for_each(|v| *v = v.normalize_or_zero());
                nrm
            }
            Shading::Flat => Vec::new(),
        };
        let (w, h) = (self.width as f64, self.height as f64);
        for t in triangles {
            let (Some(a), Some(b), Some(c)) = (projected[t[0]], projected[t[1]], projected[t[2]]) else {
                continue;
            };
            let area = (b.x - a.x) * (c.y - a.y) - (b.y - a.y) * (c.x - a.x);
            if area.abs() < 1e-12 || !area.is_finite() {
                continue;
            }
            // y points down, so a counter-clockwise triangle as seen has negative area here.
            let front = area < 0.0;
            let base = if front { style.color } else { style.back_color };
            let face_n = (world[t[1]] - world[t[0]]).cross(world[t[2]] - world[t[0]]).normalize_or_zero();
            let toward = |nv: DVec3| if nv.dot(view.eye - world[t[0]]) >= 0.0 { nv } else { -nv };
            let flat = shade(base, toward(face_n).dot(light));
            let x0 = a.x.min(b.x).min(c.x).floor().max(0.0);
            let x1 = a.x.max(b.x).max(c.x).ceil().min(w - 1.0);
            let y0 = a.y.min(b.y).min(c.y).floor().max(0.0);
            let y1 = a.y.max(b.y).max(c.y).ceil().min(h - 1.0);
            if x0 > x1 || y0 > y1 {
                continue;
            }
            let inv = 1.0 / area;
            for py in y0 as usize..=y1 as usize {
                let sy = py as f64 + 0.5;
                for px in x0 as usize..=x1 as usize {
                    let sx = px as f64 + 0.5;
                    let w0 = ((b.x - sx) * (c.y - sy) - (b.y - sy) * (c.x - sx)) * inv;
                    let w1 = ((c.x - sx) * (a.y - sy) - (c.y - sy) * (a.x - sx)) * inv;
                    let w2 = 1.0 - w0 - w1;
                    if w0 < 0.0 || w1 < 0.0 || w2 < 0.0 {
                        continue;
                    }
                    let key = w0 * a.key + w1 * b.key + w2 * c.key;
                    let i = py * self.width as usize + px;
                    if key >= self.depth[i] {
                        continue;
                    }
                    let base = match vertex_colors {
                        Some(vc) => [0, 1, 2].map(|k| {
                            let mix = w0 * f64::from(vc[t[0]][k])
                                + w1 * f64::from(vc[t[1]][k])
                                + w2 * f64::from(vc[t[2]][k]);
                            mix.round().clamp(0.0, 255.0) as u8
                        }),
                        None => base,
                    };
                    let col = match style.shading {
                        Shading::Flat if vertex_colors.is_none() => flat,
                        Shading::Flat => shade(base, toward(face_n).dot(light)),
                        Shading::Smooth => {
                            let nv = (w0 * normals[t[0]] + w1 * normals[t[1]] + w2 * normals[t[2]])
                                .try_normalize()
                                .unwrap_or(face_n);
                            shade(base, toward(nv).dot(light))
                        }
                    };
                    self.depth[i] = key;
                    self.color[i] = col;
                }
            }
        }
        Ok(())
    }

    /// Draws particles as spheres of world radius `radius` (at least one pixel across), shaded
    /// and depth-tested per pixel, back to front with anti-aliased rims.
    pub fn draw_particles<T: Real>(
        &mut self,
        camera: &Camera,
        positions: &[[T; 3]],
        radius: f64,
        colors: Colors<'_>,
    ) -> Result<(), IoError> {
        colors.check(positions.len(), "particles")?;
        let view = camera.view(self.width, self.height);
        let light = light_dir(&view);
        // Light in camera coordinates (x right, y up, z toward the viewer).
        let lc = DVec3::new(light.dot(view.right), light.dot(view.up), -light.dot(view.forward));
        let mut order: Vec<(f64, usize, camera::Projected)> = positions
            .iter()
            .enumerate()
            .filter_map(|(i, p)| view.project(DVec3::from(p.map(T::to_f64))).map(|q| (q.depth, i, q)))
            .collect();
        order.sort_by(|a, b| b.0.total_cmp(&a.0).then(a.1.cmp(&b.1)));
        let (w, h) = (self.width as f64, self.height as f64);
        for (_, i, q) in order {
            let rp = (radius * view.scale(q.depth)).max(0.5);
            let x0 = (q.x - rp - 1.0).floor().max(0.0);
            let x1 = (q.x + rp + 1.0).ceil().min(w - 1.0);
            let y0 = (q.y - rp - 1.0).floor().max(0.0);
            let y1 = (q.y + rp + 1.0).ceil().min(h - 1.0);
            if x0 > x1 || y0 > y1 {
                continue;
            }
            let base = colors.get(i);
            for py in y0 as usize..=y1 as usize {
                let dy = (py as f64 + 0.5 - q.y) / rp;
                for px in x0 as usize..=x1 as usize {
                    let dx = (px as f64 + 0.5 - q.x) / rp;
                    let r2 = dx * dx + dy * dy;
                    let coverage = (rp * (1.0 - r2.sqrt()) + 0.5).clamp(0.0, 1.0);
                    if coverage <= 0.0 {
                        continue;
                    }
                    let nz = (1.0 - r2.min(1.0)).sqrt();
                    let key = view.key(q.depth - nz * radius);
                    let k = py * self.width as usize + px;
                    if key >= self.depth[k] {
                        continue;
                    }
                    let nrm = DVec3::new(dx, -dy, nz).normalize_or_zero();
                    let c = shade(base, nrm.dot(lc));
                    if coverage >= 1.0 {
                        self.depth[k] = key;
                        self.color[k] = c;
                    } else {
                        self.color[k] = blend(self.color[k], c, coverage);
                    }
                }
            }
        }
        Ok(())
    }

    /// Draws line segments `width` pixels wide (springs, rods, bones), depth-tested. Segments with
    /// an end behind the near plane are not drawn.
    pub fn draw_lines<T: Real>(
        &mut self,
        camera: &Camera,
        positions: &[[T; 3]],
        segments: &[[usize; 2]],
        width: f64,
        colors: Colors<'_>,
    ) -> Result<(), IoError> {
        let n = positions.len();
        if let Some(e) = segments.iter().position(|s| s.iter().any(|&i| i >= n)) {
            return Err(index_error("segment", e, n));
        }
        colors.check(segments.len(), "segments")?;
        let view = camera.view(self.width, self.height);
        let half = (0.5 * width).max(0.5);
        let (w, h) = (self.width as i64, self.height as i64);
        for (s, seg) in segments.iter().enumerate() {
            let p = |i: usize| view.project(DVec3::from(positions[i].map(T::to_f64)));
            let (Some(a), Some(b)) = (p(seg[0]), p(seg[1])) else { continue };
            let c = colors.get(s);
            let steps = (b.x - a.x).abs().max((b.y - a.y).abs()).ceil().clamp(1.0, 1e5) as usize;
            for k in 0..=steps {
                let f = k as f64 / steps as f64;
                let x = a.x + f * (b.x - a.x);
                let y = a.y + f * (b.y - a.y);
                // Pulled slightly toward the viewer so lines on a surface stay visible.
                let key = (a.key + f * (b.key - a.key)) - 1e-6 * (a.key.abs() + b.key.abs());
                let (xa, xb) = ((x - half).round() as i64, (x + half).round() as i64 - 1);
                let (ya, yb) = ((y - half).round() as i64, (y + half).round() as i64 - 1);
                for py in ya.max(0)..=yb.max(ya).min(h - 1) {
                    for px in xa.max(0)..=xb.max(xa).min(w - 1) {
                        self.put(px as usize, py as usize, key, c);
                    }
                }
            }
        }
        Ok(())
    }

    /// Fills the canvas with a 2-D scalar field of `nx x ny` cells through viridis: cell `(i, j)`
    /// is `values[j * nx + i]` (x fastest, the `.vti` layout), `j = 0` at the bottom. `range`
    /// fixes the colour scale (keep it fixed across frames of a run); `None` uses the field's
    /// own finite range. Non-finite values are drawn magenta. Resets the depth buffer.
    pub fn draw_scalar_field(
        &mut self,
        values: &[f64],
        nx: usize,
        ny: usize,
        range: Option<(f64, f64)>,
    ) -> Result<(), IoError> {
        if nx.checked_mul(ny) != Some(values.len()) || values.is_empty() {
            return Err(IoError::data("preview", format!("{} values for a {nx} x {ny} field", values.len())));
        }
        let colors = colormap::colorize(values, range, [255, 0, 255]);
        let (w, h) = (self.width as usize, self.height as usize);
        let cols: Vec<usize> = (0..w).map(|px| (px * nx / w.max(1)).min(nx - 1)).collect();
        for py in 0..h {
            let j = ((h - 1 - py) * ny / h.max(1)).min(ny - 1);
            let row = &colors[j * nx..(j + 1) * nx];
            let out = &mut self.color[py * w..(py + 1) * w];
            for (o, &i) in out.iter_mut().zip(&cols) {
                *o = row[i];
            }
        }
        self.depth.fill(f64::INFINITY);
        Ok(())
    }

    /// The pixels as packed RGB bytes.
    pub fn rgb_bytes(&self) -> Vec<u8> {
        self.color.as_flattened().to_vec()
    }

    /// Writes the canvas as an 8-bit RGB PNG.
    pub fn save_png(&self, path: impl AsRef<Path>) -> Result<(), IoError> {
        let path = path.as_ref();
        let file = std::fs::File::create(path).map_err(|e| IoError::io(path, e))?;
        let mut enc = png::Encoder::new(std::io::BufWriter::new(file), self.width, self.height);
        enc.set_color(png::ColorType::Rgb);
        enc.set_depth(png::BitDepth::Eight);
        enc.set_compression(png::Compression::Fast);
        let mut w = enc.write_header().map_err(|e| IoError::encode(path, e))?;
        w.write_image_data(self.color.as_flattened()).map_err(|e| IoError::encode(path, e))?;
        w.finish().map_err(|e| IoError::encode(path, e))
    }
}

/// Direction toward the light: above, left of and behind the camera.
fn light_dir(view: &View) -> DVec3 {
    (-0.35 * view.right + 0.6 * view.up - 0.72 * view.forward).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;

    fn front_camera() -> Camera {
        Camera::look_at([0.0, 0.0, 5.0], [0.0, 0.0, 0.0], [0.0, 1.0, 0.0]).orthographic(4.0)
    }

    #[test]
    fn nearer_geometry_wins_whatever_the_order() {
        let far = [[-1.0, -1.0, -1.0], [1.0, -1.0, -1.0], [0.0, 1.0, -1.0]];
        let near = [[-1.0, -1.0, 1.0], [1.0, -1.0, 1.0], [0.0, 1.0, 1.0]];
        let red = MeshStyle { color: [255, 0, 0], back_color: [255, 0, 0], shading: Shading::Flat };
        let green = MeshStyle { color: [0, 255, 0], back_color: [0, 255, 0], shading: Shading::Flat };
        let mut a = Canvas::new(32, 32, [0; 3]);
        a.draw_mesh(&front_camera(), &far, &[[0, 1, 2]], &red).unwrap();
        a.draw_mesh(&front_camera(), &near, &[[0, 1, 2]], &green).unwrap();
        let mut b = Canvas::new(32, 32, [0; 3]);
        b.draw_mesh(&front_camera(), &near, &[[0, 1, 2]], &green).unwrap();
        b.draw_mesh(&front_camera(), &far, &[[0, 1, 2]], &red).unwrap();
        assert_eq!(a, b);
        let c = a.pixel(16, 16);
        assert!(c[1] > 0 && c[0] == 0, "{c:?}");
    }

    #[test]
    fn front_and_back_faces_get_their_colours_and_lambert_falls_off() {
        let ccw = [[-1.0, -1.0, 0.0], [1.0, -1.0, 0.0], [0.0, 1.0, 0.0]];
        let style = MeshStyle { color: [200, 0, 0], back_color: [0, 0, 200], shading: Shading::Flat };
        let mut c = Canvas::new(32, 32, [0; 3]);
        c.draw_mesh(&front_camera(), &ccw, &[[0, 1, 2]], &style).unwrap();
        let front = c.pixel(16, 16);
        assert!(front[0] > 0 && front[2] == 0, "{front:?}");
        c.clear();
        c.draw_mesh(&front_camera(), &ccw, &[[0, 2, 1]], &style).unwrap();
        let back = c.pixel(16, 16);
        assert!(back[2] > 0 && back[0] == 0, "{back:?}");
        // A face seen edge-on to the light is darker than one facing it.
        let light = light_dir(&front_camera().view(32, 32));
        let lit = shade([200, 200, 200], 1.0);
        assert_eq!(lit, [200, 200, 200]);
        assert_eq!(shade([200, 200, 200], 0.0), [56, 56, 56]);
        assert!(light.z > 0.0, "the light is on the camera's side");
    }

    #[test]
    fn particle_is_a_shaded_disc_of_the_right_size() {
        let mut c = Canvas::new(40, 40, [0; 3]);
        // Orthographic height 4 over 40 px: 10 px per unit, radius 1 -> 10 px.
        c.draw_particles(&front_camera(), &[[0.0f32, 0.0, 0.0]], 1.0, Colors::Uniform([255, 255, 255]))
            .unwrap();
        assert_ne!(c.pixel(20, 20), [0; 3]);
        assert_ne!(c.pixel(20, 11), [0; 3]);
        assert_eq!(c.pixel(20, 8), [0; 3]);
        assert_eq!(c.pixel(31, 20), [0; 3]);
        // Lit from the upper left: the upper-left part is brighter than the lower right.
        assert!(c.pixel(16, 16)[0] > c.pixel(24, 24)[0]);
        let e = c.draw_particles(&front_camera(), &[[0.0f32; 3]], 1.0, Colors::PerItem(&[])).unwrap_err();
        assert!(e.to_string().contains("0 colours for 1 particles"), "{e}");
    }

    #[test]
    fn particle_behind_a_mesh_is_hidden() {
        let wall = [[-2.0, -2.0, 1.0], [2.0, -2.0, 1.0], [2.0, 2.0, 1.0], [-2.0, 2.0, 1.0]];
        let mut c = Canvas::new(20, 20, [0; 3]);
        let style = MeshStyle { color: [0, 100, 0], back_color: [0, 100, 0], shading: Shading::Flat };
        c.draw_mesh(&front_camera(), &wall, &[[0, 1, 2], [0, 2, 3]], &style).unwrap();
        let before = c.clone();
        c.draw_particles(&front_camera(), &[[0.0, 0.0, 0.0]], 0.5, Colors::Uniform([255, 0, 0])).unwrap();
        assert_eq!(c, before);
    }

    #[test]
    fn lines_and_fields() {
        let mut c = Canvas::new(20, 20, [0; 3]);
        let p = [[-1.5, 0.0, 0.0], [1.5, 0.0, 0.0]];
        c.draw_lines(&front_camera(), &p, &[[0, 1]], 1.0, Colors::Uniform([9, 9, 9])).unwrap();
        assert_eq!(c.pixel(10, 10), [9, 9, 9]);
        assert_eq!(c.pixel(10, 5), [0; 3]);
        assert!(c.draw_lines(&front_camera(), &p, &[[0, 2]], 1.0, Colors::Uniform([9; 3])).is_err());
        // A 2 x 2 field: bottom-left is the minimum, top-right the maximum.
        c.draw_scalar_field(&[0.0, 1.0, 2.0, 3.0], 2, 2, None).unwrap();
        assert_eq!(c.pixel(0, 19), colormap::VIRIDIS[0]);
        assert_eq!(c.pixel(19, 0), colormap::VIRIDIS[255]);
        assert!(c.draw_scalar_field(&[0.0; 3], 2, 2, None).is_err());
    }

    /// A square red on its left vertices and blue on its right, lit head on: the left edge is
    /// red, the right blue, the middle a blend of both; a colour list of the wrong length is an
    /// error naming the counts.
    #[test]
    fn vertex_colours_blend_across_the_triangles() {
        let square = [[-1.5, -1.5, 0.0], [1.5, -1.5, 0.0], [1.5, 1.5, 0.0], [-1.5, 1.5, 0.0]];
        let colors = [[250, 0, 0], [0, 0, 250], [0, 0, 250], [250, 0, 0]];
        let mut c = Canvas::new(40, 40, [0; 3]);
        c.draw_mesh_colored(&front_camera(), &square, &[[0, 1, 2], [0, 2, 3]], &colors, Shading::Flat)
            .unwrap();
        let (left, mid, right) = (c.pixel(6, 20), c.pixel(20, 20), c.pixel(33, 20));
        assert!(left[0] > 150 && left[2] < 40, "{left:?}");
        assert!(right[2] > 150 && right[0] < 40, "{right:?}");
        assert!(mid[0] > 60 && mid[2] > 60 && mid[0].abs_diff(mid[2]) < 30, "{mid:?}");
        let e = c
            .draw_mesh_colored(&front_camera(), &square, &[[0, 1, 2]], &colors[..3], Shading::Smooth)
            .unwrap_err();
        assert!(e.to_string().contains("3 colours for 4 mesh vertices"), "{e}");
    }

    #[test]
    fn out_of_range_triangles_are_an_error_not_a_panic() {
        let mut c = Canvas::new(8, 8, [0; 3]);
        let e = c.draw_mesh(&front_camera(), &[[0.0; 3]], &[[0, 0, 1]], &MeshStyle::default()).unwrap_err();
        assert!(e.to_string().contains("triangle 0"), "{e}");
        // Non-finite positions are skipped, not drawn across the image.
        let p = [[f64::NAN, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]];
        c.draw_mesh(&front_camera(), &p, &[[0, 1, 2]], &MeshStyle::default()).unwrap();
        assert!(c.pixels().iter().all(|&p| p == [0; 3]));
    }
}
