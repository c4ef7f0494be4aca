//! Capture: one PNG, a PNG sequence, or an animated GIF of what the view shows. Encoding
//! and writing happen on the writer thread.

use std::path::{Path, PathBuf};
use std::time::Instant;

use super::background::Written;
use super::cloth_app::ClothApp;
use super::messages::Level;

impl ClothApp {
    /// Captures the next drawn frame to a PNG in [`Recording::capture_dir`](super::cloth_app::Recording::capture_dir).
    pub fn request_capture(&mut self) {
        self.recording.capture_requested = true;
    }

    /// Starts or stops writing every drawn frame to a new numbered folder.
    pub fn toggle_recording(&mut self) {
        if let Some((dir, n)) = self.recording.sequence.take() {
            self.message(
                Level::Info,
                format!("recorded {n} frames to {}", dir.display()),
            );
            return;
        }
        let dir = next_free(&self.recording.capture_dir, "clothsim-recording", "");
        match std::fs::create_dir_all(&dir) {
            Ok(()) => {
                self.message(Level::Info, format!("recording to {}", dir.display()));
                self.recording.sequence = Some((dir, 0));
            }
            Err(e) => self.message(
                Level::Error,
                format!("{}: cannot create folder: {e}", dir.display()),
            ),
        }
    }

    pub fn is_recording(&self) -> bool {
        self.recording.sequence.is_some()
    }

    /// Starts or stops recording what the view shows as an animated GIF
    /// (`clothsim-recording-NNNN.gif` in the capture folder).
    pub fn toggle_gif(&mut self) {
        match self.recording.gif.take() {
            Some((path, _)) => {
                self.recording.writer.gif_finish(path.clone());
                self.message(Level::Info, format!("finishing {} …", path.display()));
            }
            None => {
                let path = next_free(&self.recording.capture_dir, "clothsim-recording", ".gif");
                self.message(
                    Level::Info,
                    format!("recording a GIF to {}", path.display()),
                );
                self.recording.gif = Some((path, None));
            }
        }
    }

    pub fn is_recording_gif(&self) -> bool {
        self.recording.gif.is_some()
    }

    /// Blocks until queued files are written, then reports them (tests, shutdown).
    pub fn finish_writes(&mut self) {
        if let Some((path, _)) = self.recording.gif.take() {
            self.recording.writer.gif_finish(path);
        }
        let done = self.recording.writer.wait_all();
        self.report_writes(done);
    }

    /// Collects finished writes into messages.
    pub(super) fn poll_writes(&mut self) {
        let done = self.recording.writer.finished();
        self.report_writes(done);
    }

    fn report_writes(&mut self, done: Vec<Written>) {
        for written in done {
            match written.result {
                Ok(()) if written.announce => {
                    self.message(Level::Info, format!("saved {}", written.path.display()));
                }
                // Recorded frames are summarised when recording stops.
                Ok(()) => {}
                Err(e) => {
                    self.recording.sequence = None;
                    self.recording.gif = None;
                    self.message(Level::Error, e.to_string());
                }
            }
        }
    }

    /// Reads back the frame just drawn when a capture or a recording wants it.
    pub(super) fn capture_drawn(&mut self, rs: &egui_wgpu::RenderState) {
        let capture = std::mem::take(&mut self.recording.capture_requested);
        if !capture && self.recording.sequence.is_none() && self.recording.gif.is_none() {
            return;
        }
        let Some(viewport) = self.view.viewport.as_ref() else {
            return;
        };
        let image = match viewport.read(rs) {
            Ok(image) => image,
            Err(e) => return self.message(Level::Error, e.to_string()),
        };
        if capture {
            let path = next_free(&self.recording.capture_dir, "clothsim-capture", ".png");
            self.recording.writer.submit(image.clone(), path, true);
        }
        if let Some((dir, n)) = &mut self.recording.sequence {
            self.recording.writer.submit(
                image.clone(),
                dir.join(format!("frame_{n:05}.png")),
                false,
            );
            *n += 1;
        }
        if let Some((path, last)) = &mut self.recording.gif {
            // Each frame shows for as long as it was on screen.
            let now = Instant::now();
            let seconds = last.map_or(1.0 / 30.0, |t| now.duration_since(t).as_secs_f64());
            *last = Some(now);
            self.recording
                .writer
                .gif_frame(image, path.clone(), seconds);
        }
    }
}

/// `dir/prefix-NNNN<suffix>` with the first number not yet taken.
pub(super) fn next_free(dir: &Path, prefix: &str, suffix: &str) -> PathBuf {
    (1..)
        .map(|n| dir.join(format!("{prefix}-{n:04}{suffix}")))
        .find(|p| !p.exists())
        .unwrap_or_else(|| dir.join(format!("{prefix}{suffix}")))
}
