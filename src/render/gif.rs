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

    /// Appends a frame (every frame must have the first one's size).
    ///
    /// # Errors
    /// [`RenderError::Write`].
    pub fn add(&mut self, image: &RgbaImage) -> Result<(), RenderError> {
        let (w, h) = image.dimensions();
        if w > u16::MAX as u32 || h > u16::MAX as u32 {
            return Err(self.write_err("frames larger than 65535 pixels do not fit a GIF"));
        }
        match self.size {
            None => {
                let file = std::fs::File::create(&self.tmp).map_err(|e| self.write_err(e))?;
                let mut encoder = gif::Encoder::new(BufWriter::new(file), w as u16, h as u16, &[])
                    .map_err(|e| self.write_err(e))?;
                encoder
                    .set_repeat(gif::Repeat::Infinite)
                    .map_err(|e| self.write_err(e))?;
                self.encoder = Some(encoder);
                self.size = Some((w, h));
            }
            Some(size) if size != (w, h) => {
                return Err(self.write_err("every frame of a GIF must have the same size"));
            }
            Some(_) => {}
        }
        let mut pixels = image.as_raw().clone();
        // Speed 10 of 1–30: good colours at a tolerable encoding time.
        let mut frame = gif::Frame::from_rgba_speed(w as u16, h as u16, &mut pixels, 10);
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

impl Drop for GifWriter {
    fn drop(&mut self) {
        if self.encoder.take().is_some() {
            let _ = std::fs::remove_file(&self.tmp);
        }
    }
}
