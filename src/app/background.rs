//! Work kept off the UI thread: importing OBJ files and writing PNG files.

use std::path::PathBuf;
use std::sync::mpsc::{Receiver, Sender, channel};

use crate::mesh::{MeshBuild, ObjError, load_obj};
use crate::render::{RenderError, RgbaImage, save_png};

/// One OBJ import running on a worker thread.
pub struct ObjLoad {
    pub path: PathBuf,
    rx: Receiver<Result<MeshBuild, ObjError>>,
}

impl ObjLoad {
    pub fn start(path: PathBuf) -> Self {
        let (tx, rx) = channel();
        let worker_path = path.clone();
        std::thread::spawn(move || {
            let _ = tx.send(load_obj(&worker_path));
        });
        Self { path, rx }
    }

    /// The result once the worker is done.
    pub fn poll(&self) -> Option<Result<MeshBuild, ObjError>> {
        self.rx.try_recv().ok()
    }

    /// Blocks until the worker is done (for tests and shutdown).
    pub fn wait(&self) -> Option<Result<MeshBuild, ObjError>> {
        self.rx.recv().ok()
    }
}

/// A finished PNG write.
pub struct Written {
    pub path: PathBuf,
    /// Whether the user wants a message for this file (a capture) or not (a recorded frame,
    /// summarised when recording stops).
    pub announce: bool,
    pub result: Result<(), RenderError>,
}

/// A PNG writer thread: images are encoded and written in order, results come back.
pub struct PngWriter {
    tx: Sender<(RgbaImage, PathBuf, bool)>,
    rx: Receiver<Written>,
    pending: usize,
}

impl Default for PngWriter {
    fn default() -> Self {
        let (tx, jobs) = channel::<(RgbaImage, PathBuf, bool)>();
        let (done, rx) = channel();
        std::thread::spawn(move || {
            for (image, path, announce) in jobs {
                let result = save_png(&image, &path);
                if done
                    .send(Written {
                        path,
                        announce,
                        result,
                    })
                    .is_err()
                {
                    break;
                }
            }
        });
        Self { tx, rx, pending: 0 }
    }
}

impl PngWriter {
    /// Queues `image` for `path`; `announce` is handed back with the result.
    pub fn submit(&mut self, image: RgbaImage, path: PathBuf, announce: bool) {
        if self.tx.send((image, path, announce)).is_ok() {
            self.pending += 1;
        }
    }

    /// Files written (or failed) since the last call.
    pub fn finished(&mut self) -> Vec<Written> {
        let done: Vec<_> = self.rx.try_iter().collect();
        self.pending -= done.len().min(self.pending);
        done
    }

    /// Blocks until every submitted image is written (or failed); returns those results.
    pub fn wait_all(&mut self) -> Vec<Written> {
        let mut done = Vec::with_capacity(self.pending);
        while self.pending > 0 {
            match self.rx.recv() {
                Ok(written) => {
                    done.push(written);
                    self.pending -= 1;
                }
                Err(_) => break,
            }
        }
        done
    }

    /// Images not yet written.
    pub fn pending(&self) -> usize {
        self.pending
    }
}
