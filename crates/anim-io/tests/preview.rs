//! PNG and GIF output decoded by the `png` and `gif` crates' own decoders.

use anim_io::preview::{Camera, Canvas, Colors, GifWriter, MeshStyle};
use std::path::PathBuf;

fn tmp(name: &str) -> PathBuf {
    std::env::temp_dir().join(format!("anim-io-preview-{}-{name}", std::process::id()))
}

fn scene(canvas: &mut Canvas, shift: f64) -> Result<(), anim_io::IoError> {
    let cam = Camera::look_at([0.0, 0.0, 4.0], [0.0; 3], [0.0, 1.0, 0.0]);
    let quad = [
        [-1.0 + shift, -1.0, 0.0],
        [1.0 + shift, -1.0, 0.0],
        [1.0 + shift, 1.0, 0.0],
        [-1.0 + shift, 1.0, 0.0],
    ];
    canvas.clear();
    canvas.draw_mesh(&cam, &quad, &[[0, 1, 2], [0, 2, 3]], &MeshStyle::default())?;
    canvas.draw_particles(&cam, &[[shift, 0.0, 0.5]], 0.3, Colors::Uniform([250, 200, 0]))
}

#[test]
fn png_decodes_to_the_canvas_pixels() {
    let mut canvas = Canvas::new(48, 32, [255, 255, 255]);
    scene(&mut canvas, 0.0).unwrap();
    let path = tmp("a.png");
    canvas.save_png(&path).unwrap();
    let decoder = png::Decoder::new(std::io::BufReader::new(std::fs::File::open(&path).unwrap()));
    let mut reader = decoder.read_info().unwrap();
    let mut buf = vec![0; reader.output_buffer_size().unwrap()];
    let info = reader.next_frame(&mut buf).unwrap();
    assert_eq!((info.width, info.height, info.color_type), (48, 32, png::ColorType::Rgb));
    assert_eq!(&buf[..info.buffer_size()], canvas.rgb_bytes().as_slice());
    std::fs::remove_file(path).unwrap();
}

#[test]
fn gif_has_the_frames_delay_and_loop_asked_for() {
    let path = tmp("a.gif");
    let mut canvas = Canvas::new(40, 40, [255, 255, 255]);
    let mut gif = GifWriter::create(&path, 40, 40, 5, true).unwrap();
    let mut sources = Vec::new();
    for k in 0..3 {
        scene(&mut canvas, 0.3 * k as f64).unwrap();
        gif.push(&canvas).unwrap();
        sources.push(canvas.rgb_bytes());
    }
    assert!(gif.push(&Canvas::new(10, 10, [0; 3])).is_err(), "a frame of another size is refused");
    gif.finish().unwrap();

    let mut opts = gif::DecodeOptions::new();
    opts.set_color_output(gif::ColorOutput::RGBA);
    let mut dec = opts.read_info(std::fs::File::open(&path).unwrap()).unwrap();
    assert_eq!(dec.repeat(), gif::Repeat::Infinite);
    let mut frames = 0;
    while let Some(frame) = dec.read_next_frame().unwrap() {
        assert_eq!(frame.delay, 5);
        assert_eq!((frame.width, frame.height), (40, 40));
        // Quantisation to 256 colours keeps every pixel close to its source.
        let src = &sources[frames];
        let worst = frame
            .buffer
            .chunks(4)
            .zip(src.chunks(3))
            .map(|(a, b)| (0..3).map(|k| (i32::from(a[k]) - i32::from(b[k])).abs()).max().unwrap_or(0))
            .max()
            .unwrap_or(0);
        assert!(worst <= 24, "frame {frames}: a pixel is off by {worst}");
        frames += 1;
    }
    assert_eq!(frames, 3);
    std::fs::remove_file(path).unwrap();
}
