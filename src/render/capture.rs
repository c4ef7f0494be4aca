//! Reading the render target back and writing PNG files atomically.

use std::path::Path;

use crate::device::map_read;
use crate::output::write_atomically;

use super::error::RenderError;
use super::target::RenderTarget;

/// An RGBA8 image, rows top to bottom, no padding.
pub type RgbaImage = image::RgbaImage;

/// Removes the row padding wgpu requires in buffer copies (rows aligned to 256 bytes):
/// returns `height` rows of `width · 4` bytes.
pub fn strip_row_padding(data: &[u8], width: u32, height: u32, padded_row: u32) -> Vec<u8> {
    let row = width as usize * 4;
    let mut out = Vec::with_capacity(row * height as usize);
    for r in 0..height as usize {
        let start = r * padded_row as usize;
        out.extend_from_slice(&data[start..start + row]);
    }
    out
}

/// Bytes per row of a buffer copy of `width` RGBA8 pixels.
pub fn padded_bytes_per_row(width: u32) -> u32 {
    let align = wgpu::COPY_BYTES_PER_ROW_ALIGNMENT;
    (width * 4).div_ceil(align) * align
}

/// Copies the target's resolved colour texture to memory (blocks until the GPU is done).
///
/// # Errors
/// [`RenderError::Readback`] when mapping the buffer fails.
pub fn read_target(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    target: &RenderTarget,
) -> Result<RgbaImage, RenderError> {
    read_texture(device, queue, target.texture())
}

/// Reads a 2D texture of four bytes a texel (made with `COPY_SRC`) back to the CPU.
///
/// # Errors
/// [`RenderError::Readback`] if mapping fails.
pub fn read_texture(
    device: &wgpu::Device,
    queue: &wgpu::Queue,
    texture: &wgpu::Texture,
) -> Result<RgbaImage, RenderError> {
    let (width, height) = (texture.width(), texture.height());
    let padded = padded_bytes_per_row(width);
    let buffer = device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("clothsim readback"),
        size: padded as u64 * height as u64,
        usage: wgpu::BufferUsages::COPY_DST | wgpu::BufferUsages::MAP_READ,
        mapped_at_creation: false,
    });
    let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
        label: Some("clothsim readback"),
    });
    encoder.copy_texture_to_buffer(
        texture.as_image_copy(),
        wgpu::TexelCopyBufferInfo {
            buffer: &buffer,
            layout: wgpu::TexelCopyBufferLayout {
                offset: 0,
                bytes_per_row: Some(padded),
                rows_per_image: Some(height),
            },
        },
        wgpu::Extent3d {
            width,
            height,
            depth_or_array_layers: 1,
        },
    );
    queue.submit([encoder.finish()]);
    let slice = buffer.slice(..);
    map_read(device, &slice)?;
    let pixels = {
        let view = slice
            .get_mapped_range()
            .map_err(|e| RenderError::Readback(e.to_string()))?;
        strip_row_padding(&view, width, height, padded)
    };
    buffer.unmap();
    RgbaImage::from_raw(width, height, pixels)
        .ok_or_else(|| RenderError::Readback("image size mismatch".into()))
}

/// Encodes `image` as PNG and writes it to `path` atomically: into a temporary file in the
/// same directory, then renamed. On any failure no file is left at `path` or beside it.
///
/// # Errors
/// [`RenderError::MissingDirectory`] or [`RenderError::Write`].
pub fn save_png(image: &RgbaImage, path: &Path) -> Result<(), RenderError> {
    write_atomically(path, |out| {
        // `write_to` needs `Seek`: encode into memory first.
        let mut png = std::io::Cursor::new(Vec::new());
        image
            .write_to(&mut png, image::ImageFormat::Png)
            .map_err(|e| e.to_string())?;
        out.write_all(png.get_ref()).map_err(|e| e.to_string())
    })
    .map_err(RenderError::from)
}
