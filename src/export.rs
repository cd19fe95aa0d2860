//! Image export: unscaled linear-radiance EXR, and PNGs of what the viewport shows.

use std::path::Path;

use crate::base::image::ImageF32;

#[derive(Debug, thiserror::Error)]
pub enum ExportError {
    #[error("could not write {path}: {message}")]
    Write { path: String, message: String },
}

/// Writes linear RGBA floats as an EXR file, unscaled. Blocks are compressed and written
/// in order on one thread, so the same pixels give the same bytes (a capture reproduced
/// from its record compares file by file; the parallel writer orders blocks as they finish).
pub fn write_exr(path: &Path, img: &ImageF32) -> Result<(), ExportError> {
    use exr::prelude::*;
    let w = img.width as usize;
    let channels = SpecificChannels::rgba(|Vec2(x, y): Vec2<usize>| {
        let p = img.pixels[y * w + x];
        (p[0], p[1], p[2], p[3])
    });
    Image::from_channels((w, img.height as usize), channels)
        .write()
        .non_parallel()
        .to_file(path)
        .map_err(|e| ExportError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        })
}

/// Writes RGBA8 bytes (already display-encoded) as a PNG.
pub fn write_png(path: &Path, width: u32, height: u32, rgba8: &[u8]) -> Result<(), ExportError> {
    image::save_buffer(path, rgba8, width, height, image::ExtendedColorType::Rgba8).map_err(|e| {
        ExportError::Write {
            path: path.display().to_string(),
            message: e.to_string(),
        }
    })
}

/// Reads an EXR written by [`write_exr`] (tests, comparisons).
pub fn read_exr(path: &Path) -> Result<ImageF32, String> {
    use exr::prelude::*;
    let image = read_first_rgba_layer_from_file(
        path,
        |res, _| ImageF32 {
            width: res.width() as u32,
            height: res.height() as u32,
            pixels: vec![[0.0; 4]; res.width() * res.height()],
        },
        |img: &mut ImageF32, pos, (r, g, b, a): (f32, f32, f32, f32)| {
            let w = img.width as usize;
            img.pixels[pos.y() * w + pos.x()] = [r, g, b, a];
        },
    )
    .map_err(|e| e.to_string())?;
    Ok(image.layer_data.channel_data.pixels)
}
