//! Writing rendered images: `.png` as 8-bit sRGB (clipped at 1), `.exr` as linear float.

use std::io::Cursor;
use std::path::Path;

use crate::photo_in::linear_to_srgb;
use crate::{output_file, Error, Result};

/// The file formats an image can be written in, chosen by the path's extension.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ImageFormat {
    /// 8-bit sRGB PNG.
    Png,
    /// 16-bit sRGB PNG.
    Png16,
    /// Linear 32-bit float OpenEXR.
    Exr,
}

impl ImageFormat {
    /// The format for `path`'s extension (`.png`, `.exr`), or an error naming the path.
    pub fn from_path(path: &Path) -> Result<Self> {
        match path
            .extension()
            .and_then(|e| e.to_str())
            .map(str::to_ascii_lowercase)
            .as_deref()
        {
            Some("png") => Ok(ImageFormat::Png),
            Some("exr") => Ok(ImageFormat::Exr),
            _ => Err(Error::output(
                path,
                "unknown image type: the output must end in .png (8-bit sRGB) or .exr (linear float)",
            )),
        }
    }
}

/// Encodes linear RGB `pixels` (row-major, row 0 at the top) in `format`.
pub fn encode(width: u32, height: u32, pixels: &[[f32; 3]], format: ImageFormat) -> Vec<u8> {
    let mut bytes = Vec::new();
    let result = match format {
        ImageFormat::Png => {
            let data: Vec<u8> = pixels
                .iter()
                .flat_map(|p| p.map(|c| (linear_to_srgb(c.clamp(0.0, 1.0)) * 255.0).round() as u8))
                .collect();
            image::RgbImage::from_raw(width, height, data)
                .map(|img| img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png))
        }
        ImageFormat::Png16 => {
            let data: Vec<u16> = pixels
                .iter()
                .flat_map(|p| {
                    p.map(|c| (linear_to_srgb(c.clamp(0.0, 1.0)) * 65535.0).round() as u16)
                })
                .collect();
            image::ImageBuffer::<image::Rgb<u16>, _>::from_raw(width, height, data)
                .map(|img| img.write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::Png))
        }
        ImageFormat::Exr => {
            let data: Vec<f32> = pixels.iter().flatten().copied().collect();
            image::Rgb32FImage::from_raw(width, height, data).map(|img| {
                image::DynamicImage::ImageRgb32F(img)
                    .write_to(&mut Cursor::new(&mut bytes), image::ImageFormat::OpenExr)
            })
        }
    };
    // The buffer sizes above always match width x height, and encoding to memory cannot fail
    // for these formats; an empty result would be caught by the caller's read-back tests.
    debug_assert!(matches!(result, Some(Ok(()))));
    bytes
}

/// Writes linear RGB `pixels` to `path` atomically, in the format its extension names.
pub fn write(path: &Path, width: u32, height: u32, pixels: &[[f32; 3]]) -> Result<()> {
    let format = ImageFormat::from_path(path)?;
    let bytes = encode(width, height, pixels, format);
    if bytes.is_empty() {
        return Err(Error::output(path, "the image could not be encoded"));
    }
    output_file::write_atomically(path, &bytes)
}
