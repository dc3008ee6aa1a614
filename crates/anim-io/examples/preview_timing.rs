//! Times the preview renderer on the sizes a run previews: a 128 x 128 vertex cloth and 10 000
//! particles into a 256 x 256 frame, plus PNG and GIF encoding, and leaves the pictures in the
//! temporary folder (or the folder given as the first argument).
//!
//! `cargo run --release -p anim-io --example preview_timing [OUT_DIR]`

use anim_io::preview::{Camera, Canvas, Colors, GifWriter, MeshStyle, Shading, colormap};
use std::time::Instant;

/// A cloth draped over a sphere-ish bump, with a fold: `n x n` vertices.
fn cloth(n: usize, phase: f64) -> (Vec<[f64; 3]>, Vec<[usize; 3]>) {
    let mut p = Vec::with_capacity(n * n);
    for j in 0..n {
        for i in 0..n {
            let u = i as f64 / (n - 1) as f64 * 2.0 - 1.0;
            let v = j as f64 / (n - 1) as f64 * 2.0 - 1.0;
            let r2 = u * u + v * v;
            let y = 0.6 * (-2.5 * r2).exp() - 0.25 * r2 + 0.05 * (6.0 * u + phase).sin() * (1.0 - v * v);
            p.push([u, y, v]);
        }
    }
    let mut t = Vec::with_capacity(2 * (n - 1) * (n - 1));
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let a = j * n + i;
            t.push([a, a + n, a + 1]);
            t.push([a + 1, a + n, a + n + 1]);
        }
    }
    (p, t)
}

/// 10 000 particles in a splash-shaped cloud, deterministic.
fn particles(count: usize, phase: f64) -> Vec<[f32; 3]> {
    let golden = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    (0..count)
        .map(|k| {
            let f = (k as f64 + 0.5) / count as f64;
            let r = f.sqrt() * 0.9;
            let a = k as f64 * golden;
            let h = 0.5 * (1.0 - r * r) * (1.0 + 0.3 * (3.0 * a + phase).sin()) * (k % 7) as f64 / 6.0;
            [(r * a.cos()) as f32, h as f32, (r * a.sin()) as f32]
        })
        .collect()
}

fn best_of<R>(runs: usize, mut f: impl FnMut() -> R) -> (f64, R) {
    let mut best = f64::INFINITY;
    let mut out = None;
    for _ in 0..runs {
        let t = Instant::now();
        let r = f();
        best = best.min(t.elapsed().as_secs_f64());
        out = Some(r);
    }
    (best * 1e3, out.unwrap_or_else(|| unreachable!()))
}

fn main() -> Result<(), anim_io::IoError> {
    let dir = std::env::args().nth(1).map(std::path::PathBuf::from).unwrap_or_else(std::env::temp_dir);
    let camera = Camera::framing([-1.0, -0.5, -1.0], [1.0, 0.6, 1.0], [-0.6, -0.55, -1.0], [0.0, 1.0, 0.0]);
    let (pos, tris) = cloth(128, 0.0);
    let mut canvas = Canvas::new(256, 256, [245, 245, 240]);
    for shading in [Shading::Smooth, Shading::Flat] {
        let style = MeshStyle { shading, ..MeshStyle::default() };
        let (ms, r) = best_of(10, || {
            canvas.clear();
            canvas.draw_mesh(&camera, &pos, &tris, &style)
        });
        r?;
        println!("cloth 128x128 vertices ({} triangles), {shading:?}: {ms:.2} ms", tris.len());
        let name = format!("anim-io-cloth-{shading:?}.png").to_lowercase();
        canvas.save_png(dir.join(&name))?;
    }
    // A coarse cloth shows the facets of flat shading; 400 large particles show the sphere shading.
    let (coarse, coarse_tris) = cloth(12, 0.0);
    canvas.clear();
    let flat = MeshStyle { shading: Shading::Flat, ..MeshStyle::default() };
    canvas.draw_mesh(&camera, &coarse, &coarse_tris, &flat)?;
    canvas.save_png(dir.join("anim-io-cloth-coarse-flat.png"))?;
    let big = particles(400, 1.0);
    canvas.clear();
    canvas.draw_particles(&camera, &big, 0.05, Colors::Uniform([220, 90, 60]))?;
    canvas.save_png(dir.join("anim-io-particles-large.png"))?;

    let (ms, r) = best_of(10, || canvas.save_png(dir.join("anim-io-cloth-smooth.png")));
    r?;
    println!("PNG encode 256x256: {ms:.2} ms");

    let pts = particles(10_000, 0.0);
    let speed: Vec<f64> = pts.iter().map(|p| f64::from(p[1])).collect();
    let colors = colormap::colorize(&speed, None, [255, 0, 255]);
    let (ms, r) = best_of(10, || {
        canvas.clear();
        canvas.draw_particles(&camera, &pts, 0.012, Colors::PerItem(&colors))
    });
    r?;
    println!("10k particles: {ms:.2} ms");
    canvas.save_png(dir.join("anim-io-particles.png"))?;

    let springs: Vec<[usize; 2]> = (0..127).map(|i| [64 * 128 + i, 64 * 128 + i + 1]).collect();
    let field: Vec<f64> =
        (0..128 * 128).map(|k| ((k % 128) as f64 * 0.1).sin() * ((k / 128) as f64 * 0.07).cos()).collect();
    let (ms, r) = best_of(10, || canvas.draw_scalar_field(&field, 128, 128, Some((-1.0, 1.0))));
    r?;
    println!("128x128 scalar field: {ms:.2} ms");
    canvas.save_png(dir.join("anim-io-field.png"))?;

    let gif_path = dir.join("anim-io-cloth.gif");
    let mut gif = GifWriter::create(&gif_path, 256, 256, 4, true)?;
    let frames = 24;
    let mut render = 0.0;
    let mut encode = 0.0;
    for f in 0..frames {
        let phase = f as f64 / frames as f64 * std::f64::consts::TAU;
        let (p, _) = cloth(128, phase);
        let t = Instant::now();
        canvas.clear();
        canvas.draw_mesh(&camera, &p, &tris, &MeshStyle::default())?;
        canvas.draw_lines(&camera, &p, &springs, 1.5, Colors::Uniform([30, 30, 30]))?;
        render += t.elapsed().as_secs_f64();
        let t = Instant::now();
        gif.push(&canvas)?;
        encode += t.elapsed().as_secs_f64();
    }
    gif.finish()?;
    println!(
        "GIF of {frames} frames: render {:.2} ms/frame, quantise+encode {:.2} ms/frame",
        render * 1e3 / frames as f64,
        encode * 1e3 / frames as f64
    );
    println!("pictures in {}", dir.display());
    Ok(())
}
