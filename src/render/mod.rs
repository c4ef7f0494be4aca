//! Rendering with wgpu. Everything is drawn into an offscreen [`RenderTarget`]; the GUI shows
//! its texture, capture reads it back, golden tests compare it.

mod camera;
mod capture;
mod display;
mod error;
mod frame;
mod geometry;
mod gif;
mod offscreen;
mod options;
mod pipelines;
mod renderer;
mod target;

pub use camera::OrbitCamera;
pub use capture::{
    RgbaImage, padded_bytes_per_row, read_target, read_texture, save_png, strip_row_padding,
};
pub use error::RenderError;
pub use frame::{DevicePositions, Frame, MeshShape, Shape, SpringLines};
pub use gif::GifWriter;
pub use offscreen::Offscreen;
pub use options::{RenderOptions, SpringColoring};
pub use renderer::{CLEAR_COLOR, Renderer, kind_color, strain_color};
pub use target::{
    COLOR_FORMAT, DEPTH_FORMAT, RenderTarget, supported_sample_count, supported_sample_counts,
};
