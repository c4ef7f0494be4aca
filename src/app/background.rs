//! Work kept off the UI thread: importing OBJ files and writing PNG files.

use std::path::PathBuf;
use std::sync::mpsc::{Receiver, Sender, channel};

use crate::mesh::{MeshBuild, load_obj};
use crate::render::{GifWriter, RenderError, RgbaImage, save_png};
use crate::scene::{Scene, SceneFile};

/// What a background load produced.
pub enum Loaded {
    /// A cloth (OBJ) to put into the current scene.
    Cloth(Box<MeshBuild>),
    /// A whole scene (a `.toml` scene file and the cloth it names).
    Scene(Box<Scene>),
}

/// One import running on a worker thread: an OBJ cloth, or a scene file (by extension).
pub struct Load {
    pub path: PathBuf,
    rx: Receiver<Result<Loaded, String>>,
}

impl Load {
    pub fn start(path: PathBuf) -> Self {
        let (tx, rx) = channel();
        let worker_path = path.clone();
        std::thread::spawn(move || {
            let is_scene = worker_path
                .extension()
                .is_some_and(|e| e.eq_ignore_ascii_case("toml"));
            let result = if is_scene {
                SceneFile::load(&worker_path)
                    .and_then(|loaded| Scene::from_loaded(&loaded))
                    .map(|scene| Loaded::Scene(Box::new(scene)))
                    .map_err(|e| e.to_string())
            } else {
                load_obj(&worker_path)
                    .map(|build| Loaded::Cloth(Box::new(build)))
                    .map_err(|e| e.to_string())
            };
            let _ = tx.send(result);
        });
        Self { path, rx }
    }

    /// The result once the worker is done.
    pub fn poll(&self) -> Option<Result<Loaded, String>> {
        self.rx.try_recv().ok()
    }

    /// Blocks until the worker is done (for tests and shutdown).
    pub fn wait(&self) -> Option<Result<Loaded, String>> {
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

/// Work for the writer thread.
enum Job {
    /// An image as a PNG file.
    Png(RgbaImage, PathBuf, bool),
    /// A frame for the GIF being recorded (started on its first frame), shown for the
    /// given seconds.
    GifFrame(RgbaImage, PathBuf, f64),
    /// The GIF being recorded is done.
    GifFinish(PathBuf),
}

/// A writer thread: images are encoded (PNG, or frames of a GIF) and written in order,
/// results come back.
pub struct PngWriter {
    tx: Sender<Job>,
    rx: Receiver<Written>,
    pending: usize,
}

impl Default for PngWriter {
    fn default() -> Self {
        let (tx, jobs) = channel::<Job>();
        let (done, rx) = channel();
        std::thread::spawn(move || {
            let mut gif: Option<GifWriter> = None;
            for job in jobs {
                let written = match job {
                    Job::Png(image, path, announce) => Written {
                        result: save_png(&image, &path),
                        path,
                        announce,
                    },
                    Job::GifFrame(image, path, seconds) => {
                        let result = match gif.as_mut() {
                            Some(g) => g.add(&image),
                            None => GifWriter::create(&path, seconds).and_then(|mut g| {
                                let r = g.add(&image);
                                gif = Some(g);
                                r
                            }),
                        };
                        Written {
                            path,
                            announce: false,
                            result,
                        }
                    }
                    Job::GifFinish(path) => Written {
                        result: gif.take().map_or(Ok(()), GifWriter::finish),
                        path,
                        announce: true,
                    },
                };
                if done.send(written).is_err() {
                    break;
                }
            }
        });
        Self { tx, rx, pending: 0 }
    }
}

impl PngWriter {
    fn send(&mut self, job: Job) {
        if self.tx.send(job).is_ok() {
            self.pending += 1;
        }
    }

    /// Queues `image` for `path`; `announce` is handed back with the result.
    pub fn submit(&mut self, image: RgbaImage, path: PathBuf, announce: bool) {
        self.send(Job::Png(image, path, announce));
    }

    /// Queues a frame of the GIF at `path`, shown for `seconds`.
    pub fn gif_frame(&mut self, image: RgbaImage, path: PathBuf, seconds: f64) {
        self.send(Job::GifFrame(image, path, seconds));
    }

    /// Finishes the GIF at `path`.
    pub fn gif_finish(&mut self, path: PathBuf) {
        self.send(Job::GifFinish(path));
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
