//! Animated GIF output through the `gif` crate.

use super::Canvas;
use crate::IoError;
use std::fs::File;
use std::io::BufWriter;
use std::path::{Path, PathBuf};

/// NeuQuant sampling speed (1 slowest and best, 30 fastest): 20 keeps previews within a few
/// colour levels of the rendered frame at about half the cost of the default 10, so writing a
/// preview stays a small part of a run.
const QUANTIZE_SPEED: i32 = 20;

/// Writes canvases as the frames of a looping animated GIF. Each frame gets its own 256-colour
/// palette (NeuQuant quantisation from the `gif` crate), so colour-mapped fields keep their
/// gradients as they change.
pub struct GifWriter {
    path: PathBuf,
    width: u16,
    height: u16,
    delay: u16,
    encoder: gif::Encoder<BufWriter<File>>,
    frames: usize,
}

impl std::fmt::Debug for GifWriter {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("GifWriter")
            .field("path", &self.path)
            .field("size", &(self.width, self.height))
            .field("frames", &self.frames)
            .finish_non_exhaustive()
    }
}

impl GifWriter {
    /// Creates `path` for `width x height` frames shown `delay_centiseconds` each (GIF's unit;
    /// 4 = 25 frames per second). `looping` repeats the animation forever.
    pub fn create(
        path: impl AsRef<Path>,
        width: u32,
        height: u32,
        delay_centiseconds: u16,
        looping: bool,
    ) -> Result<Self, IoError> {
        let path = path.as_ref().to_path_buf();
        let (Ok(w), Ok(h)) = (u16::try_from(width), u16::try_from(height)) else {
            return Err(IoError::data(
                path.display(),
                format!("{width} x {height} exceeds GIF's 65535 x 65535"),
            ));
        };
        let file = File::create(&path).map_err(|e| IoError::io(&path, e))?;
        let mut encoder =
            gif::Encoder::new(BufWriter::new(file), w, h, &[]).map_err(|e| IoError::encode(&path, e))?;
        if looping {
            encoder.set_repeat(gif::Repeat::Infinite).map_err(|e| IoError::encode(&path, e))?;
        }
        Ok(GifWriter { path, width: w, height: h, delay: delay_centiseconds, encoder, frames: 0 })
    }

    /// Appends a frame; the canvas must have the size given to [`create`](Self::create).
    pub fn push(&mut self, canvas: &Canvas) -> Result<(), IoError> {
        if (canvas.width(), canvas.height()) != (u32::from(self.width), u32::from(self.height)) {
            return Err(IoError::data(
                self.path.display(),
                format!(
                    "frame of {} x {} in a {} x {} animation",
                    canvas.width(),
                    canvas.height(),
                    self.width,
                    self.height
                ),
            ));
        }
        let rgb = canvas.rgb_bytes();
        let mut frame = gif::Frame::from_rgb_speed(self.width, self.height, &rgb, QUANTIZE_SPEED);
        frame.delay = self.delay;
        self.encoder.write_frame(&frame).map_err(|e| IoError::encode(&self.path, e))?;
        self.frames += 1;
        Ok(())
    }

    /// Frames written so far.
    pub fn frames(&self) -> usize {
        self.frames
    }

    /// Finishes the file (writes the trailer and flushes).
    pub fn finish(self) -> Result<PathBuf, IoError> {
        let path = self.path;
        let mut w = self.encoder.into_inner().map_err(|e| IoError::encode(&path, e))?;
        std::io::Write::flush(&mut w).map_err(|e| IoError::io(&path, e))?;
        Ok(path)
    }
}
