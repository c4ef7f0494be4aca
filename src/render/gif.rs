//! Animated GIFs of rendered frames, written atomically when finished.

use std::io::{BufWriter, Write};
use std::path::{Path, PathBuf};

use super::capture::RgbaImage;
use super::error::RenderError;

/// A GIF being written: frames go into a temporary file beside the target, renamed into
/// place by [`GifWriter::finish`]; dropped unfinished, it leaves nothing behind.
pub struct GifWriter {
    encoder: Option<gif::Encoder<BufWriter<std::fs::File>>>,
    tmp: PathBuf,
    path: PathBuf,
    /// Hundredths of a second per frame.
    delay: u16,
    size: Option<(u32, u32)>,
}

impl GifWriter {
    /// Starts `path`, showing each frame for `frame_seconds`, looping forever.
    ///
    /// # Errors
    /// [`RenderError::MissingDirectory`] or [`RenderError::Write`].
    pub fn create(path: &Path, frame_seconds: f64) -> Result<Self, RenderError> {
        let dir = match path.parent() {
            Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
            _ => PathBuf::from("."),
        };
        if !dir.is_dir() {
            return Err(RenderError::MissingDirectory {
                path: path.to_path_buf(),
                dir,
            });
        }
        if path.file_name().is_none() {
            return Err(RenderError::Write {
                path: path.to_path_buf(),
                detail: "the path names no file".into(),
            });
        }
        let name = path.file_name().map(|n| n.to_string_lossy().into_owned());
        let tmp = dir.join(format!(
            ".{}.{}.tmp",
            name.unwrap_or_default(),
            std::process::id()
        ));
        Ok(Self {
            encoder: None,
            tmp,
            path: path.to_path_buf(),
            delay: (frame_seconds * 100.0).round().clamp(2.0, 6000.0) as u16,
            size: None,
        })
    }

    fn write_err(&self, detail: impl ToString) -> RenderError {
        RenderError::Write {
            path: self.path.clone(),
            detail: detail.to_string(),
        }
    }

    /// Appends a frame (scaled to the first frame's size if it differs).
    ///
    /// # Errors
    /// [`RenderError::Write`].
    pub fn add(&mut self, image: &RgbaImage) -> Result<(), RenderError> {
        let (w, h) = image.dimensions();
        if w > u16::MAX as u32 || h > u16::MAX as u32 {
            return Err(self.write_err("frames larger than 65535 pixels do not fit a GIF"));
        }
        if self.size.is_none() {
            let file = std::fs::File::create(&self.tmp).map_err(|e| self.write_err(e))?;
            let mut encoder = gif::Encoder::new(BufWriter::new(file), w as u16, h as u16, &[])
                .map_err(|e| self.write_err(e))?;
            encoder
                .set_repeat(gif::Repeat::Infinite)
                .map_err(|e| self.write_err(e))?;
            self.encoder = Some(encoder);
            self.size = Some((w, h));
        }
        let (fw, fh) = self.size.unwrap_or((w, h));
        // A GIF has one size: a frame of another size (the window was resized while
        // recording) is scaled to fit the first, keeping its aspect, on its own background.
        let mut pixels = if (w, h) == (fw, fh) {
            image.as_raw().clone()
        } else {
            fit(image, fw, fh).into_raw()
        };
        // Speed 10 of 1–30: good colours at a tolerable encoding time.
        let mut frame = gif::Frame::from_rgba_speed(fw as u16, fh as u16, &mut pixels, 10);
        frame.delay = self.delay;
        let result = match self.encoder.as_mut() {
            Some(encoder) => encoder.write_frame(&frame).map_err(|e| e.to_string()),
            None => Err("the GIF is not open".to_string()),
        };
        result.map_err(|e| self.write_err(e))
    }

    /// Finishes the file and moves it into place.
    ///
    /// # Errors
    /// [`RenderError::Write`] (also for a GIF without frames).
    pub fn finish(mut self) -> Result<(), RenderError> {
        let encoder = self
            .encoder
            .take()
            .ok_or_else(|| self.write_err("no frames were rendered"))?;
        let result = encoder
            .into_inner()
            .map_err(|e| e.to_string())
            .and_then(|mut out| out.flush().map_err(|e| e.to_string()))
            .and_then(|()| std::fs::rename(&self.tmp, &self.path).map_err(|e| e.to_string()));
        if result.is_err() {
            let _ = std::fs::remove_file(&self.tmp);
        }
        result.map_err(|e| self.write_err(e))
    }
}

/// `image` scaled to fit `w × h` with its aspect kept, centred on its corner colour.
fn fit(image: &RgbaImage, w: u32, h: u32) -> RgbaImage {
    let (iw, ih) = image.dimensions();
    let scale = (w as f32 / iw.max(1) as f32).min(h as f32 / ih.max(1) as f32);
    let (sw, sh) = (
        ((iw as f32 * scale).round() as u32).clamp(1, w),
        ((ih as f32 * scale).round() as u32).clamp(1, h),
    );
    let scaled = image::imageops::resize(image, sw, sh, image::imageops::FilterType::Triangle);
    let background = image
        .get_pixel_checked(0, 0)
        .copied()
        .unwrap_or(image::Rgba([0, 0, 0, 255]));
    let mut out = RgbaImage::from_pixel(w, h, background);
    image::imageops::overlay(
        &mut out,
        &scaled,
        ((w - sw) / 2) as i64,
        ((h - sh) / 2) as i64,
    );
    out
}

impl Drop for GifWriter {
    fn drop(&mut self) {
        if self.encoder.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_frame_of_another_size_is_fitted_into_the_first_size() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("a.gif");
        let mut gif = GifWriter::create(&path, 0.1).unwrap();
        let grey = image::Rgba([90, 90, 90, 255]);
        gif.add(&RgbaImage::from_pixel(40, 20, grey)).unwrap();
        // Twice as tall: scaled to 20 × 20 and centred, grey bars either side.
        let mut tall = RgbaImage::from_pixel(40, 40, grey);
        for y in 0..40 {
            for x in 10..30 {
                tall.put_pixel(x, y, image::Rgba([255, 0, 0, 255]));
            }
        }
        gif.add(&tall).unwrap();
        assert!(!path.exists(), "nothing at the path until finished");
        gif.finish().unwrap();
        let mut options = gif::DecodeOptions::new();
        options.set_color_output(gif::ColorOutput::RGBA);
        let mut decoder = options
            .read_info(std::fs::File::open(&path).unwrap())
            .unwrap();
        let mut sizes = Vec::new();
        let mut last = Vec::new();
        while let Some(frame) = decoder.read_next_frame().unwrap() {
            sizes.push((frame.width, frame.height));
            last = frame.buffer.to_vec();
        }
        assert_eq!(sizes, [(40, 20), (40, 20)]);
        let red_at =
            |x: usize, y: usize| last[4 * (y * 40 + x)] > 200 && last[4 * (y * 40 + x) + 1] < 60;
        assert!(red_at(20, 10), "the red middle of the tall frame, scaled");
        assert!(!red_at(2, 10) && !red_at(37, 10), "grey bars at the sides");
    }
}
