//! Step 2 of method §5: decode the photo into scene radiance, and mark clipped pixels.
//!
//! 8- and 16-bit images are sRGB-encoded and decoded with the exact sRGB curve; floating-point
//! images (OpenEXR, Radiance HDR) are already linear. Both are divided by the exposure.
//! A pixel at the encoding's maximum in any channel is clipped: its radiance is only a lower
//! bound.

use std::path::Path;

use image::{DynamicImage, ImageDecoder};
use rayon::prelude::*;

use crate::photo_rounding::Rounding;
use crate::settings::Setting;
use crate::{Error, Result};

/// A decoded photo. Pixels are stored row by row, row 0 at the top.
#[derive(Clone, Debug)]
pub struct Photo {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Linear scene radiance per pixel (RGB), already divided by the exposure.
    pub radiance: Vec<[f32; 3]>,
    /// True where any channel sits at the encoding's maximum (only a lower bound is known).
    pub clipped: Vec<bool>,
    /// The sRGB-encoded colour in [0, 1] per pixel, as a person sees it: what superpixels and
    /// seeds are computed on. For floating-point photos, the radiance times the exposure,
    /// clamped to [0, 1] and sRGB-encoded.
    pub display: Vec<[f32; 3]>,
    /// True when the file held floating-point (linear, unclipped) values.
    pub is_linear_float: bool,
    /// How the file rounded its values.
    pub rounding: Rounding,
    /// The exposure the file's linear values were divided by.
    pub exposure: f32,
    /// What the user should know about the file's values (negative values read as 0).
    pub warnings: Vec<String>,
}

/// The exact sRGB decoding curve (IEC 61966-2-1).
pub fn srgb_to_linear(c: f32) -> f32 {
    if c <= 0.04045 {
        c / 12.92
    } else {
        ((c + 0.055) / 1.055).powf(2.4)
    }
}

/// The exact sRGB encoding curve, the inverse of [`srgb_to_linear`].
pub fn linear_to_srgb(c: f32) -> f32 {
    if c <= 0.0031308 {
        c * 12.92
    } else {
        1.055 * c.powf(1.0 / 2.4) - 0.055
    }
}

impl Photo {
    /// Number of pixels.
    pub fn len(&self) -> usize {
        self.radiance.len()
    }

    /// True for a photo without pixels (never produced by [`load`]).
    pub fn is_empty(&self) -> bool {
        self.radiance.is_empty()
    }

    /// Which channels of pixel `i` are clipped: those at the encoding's maximum when the
    /// pixel is clipped (every channel of a pixel marked clipped by other means). The other
    /// channels of a clipped pixel hold their true values: a light of one strong colour
    /// clips its own channel only.
    pub fn clipped_channels(&self, i: usize) -> [bool; 3] {
        if !self.clipped[i] {
            return [false; 3];
        }
        let at_max = self.display[i].map(|c| c >= 1.0);
        if at_max.iter().any(|&c| c) {
            at_max
        } else {
            [true; 3]
        }
    }

    /// Index of pixel (column `x`, row `y`).
    pub fn index(&self, x: u32, y: u32) -> usize {
        y as usize * self.width as usize + x as usize
    }

    /// The photo less a `background` of the same size (radiance per pixel): each pixel's
    /// radiance less the background's, at least 0, its display colour re-encoded from it. A
    /// clipped pixel stays clipped (a lower bound on the lights' part too, less the
    /// background) and keeps its display colour.
    pub fn less(&self, background: &[[f32; 3]]) -> Photo {
        let mut out = self.clone();
        for (i, b) in background.iter().enumerate().take(out.radiance.len()) {
            let r = &mut out.radiance[i];
            for c in 0..3 {
                r[c] = (r[c] - b[c]).max(0.0);
            }
            if !out.clipped[i] {
                out.display[i] = r.map(|c| linear_to_srgb((c * self.exposure).clamp(0.0, 1.0)));
            }
        }
        out
    }

    /// Builds a photo from sRGB-encoded values in [0, 1] (as an 8-bit file would hold them,
    /// divided by 255: its [`rounding`](Self::rounding)), marking values at 1 as clipped.
    pub fn from_display(width: u32, height: u32, display: Vec<[f32; 3]>, exposure: f32) -> Self {
        // On every core: three powers a pixel, 0.2 s of a 4000 x 3000 photo on one.
        let radiance = display
            .par_iter()
            .with_min_len(4096)
            .map(|p| p.map(|c| srgb_to_linear(c) / exposure))
            .collect();
        let clipped = display
            .par_iter()
            .with_min_len(4096)
            .map(|p| p.iter().any(|&c| c >= 1.0))
            .collect();
        Photo {
            width,
            height,
            radiance,
            clipped,
            display,
            is_linear_float: false,
            rounding: Rounding::Srgb { step: 1.0 / 255.0 },
            exposure,
            warnings: Vec::new(),
        }
    }

    /// Builds a photo from linear radiance values (as a floating-point file would hold them,
    /// before division by the exposure). Nothing is clipped.
    pub fn from_linear(width: u32, height: u32, linear: Vec<[f32; 3]>, exposure: f32) -> Self {
        let display = linear
            .iter()
            .map(|p| p.map(|c| linear_to_srgb(c.clamp(0.0, 1.0))))
            .collect();
        let radiance = linear.iter().map(|p| p.map(|c| c / exposure)).collect();
        let clipped = vec![false; linear.len()];
        Photo {
            width,
            height,
            radiance,
            clipped,
            display,
            is_linear_float: true,
            rounding: Rounding::Float,
            exposure,
            warnings: Vec::new(),
        }
    }
}

/// Largest width or height accepted: larger than any camera's, small enough that a corrupt
/// header cannot make the decoder allocate without bound.
pub const MAX_SIDE: u32 = 32_768;
/// Most pixels accepted (2^27, about 134 megapixels): each costs some 25 bytes once decoded
/// into a [`Photo`], so this bounds the photo to a few GiB.
pub const MAX_PIXELS: u64 = 1 << 27;
/// Most bytes the decoder may allocate for the image (2 GiB).
pub const MAX_DECODE_BYTES: u64 = 2 << 30;

/// Reads and decodes the photo at `path`; `exposure` divides the linear values (method §2).
pub fn load(path: &Path, exposure: f32) -> Result<Photo> {
    check_exposure(exposure)?;
    let bytes = crate::input_file::read(path)?;
    decode(&bytes, exposure, path)
}

fn check_exposure(exposure: f32) -> Result<()> {
    if !(exposure.is_finite() && exposure > 0.0) {
        return Err(Error::setting(
            Setting::Exposure,
            format!("must be a positive number, not {exposure}"),
        ));
    }
    Ok(())
}

/// Decodes a photo from the bytes of its file; `path` names it in messages. A header that
/// declares more than [`MAX_SIDE`] pixels on a side, more than [`MAX_PIXELS`] pixels or more
/// than [`MAX_DECODE_BYTES`] of decoded data is refused before anything that large is
/// allocated.
pub fn decode(bytes: &[u8], exposure: f32, path: &Path) -> Result<Photo> {
    check_exposure(exposure)?;
    let mut reader = image::ImageReader::new(std::io::Cursor::new(bytes))
        .with_guessed_format()
        .map_err(|e| Error::io(path, e))?;
    let format = reader.format();
    if format.is_none() {
        return Err(Error::photo(
            path,
            "not a photo format streaklight reads (PNG, JPEG, TIFF, OpenEXR, Radiance HDR)",
        ));
    }
    let mut limits = image::Limits::default();
    limits.max_image_width = Some(MAX_SIDE);
    limits.max_image_height = Some(MAX_SIDE);
    limits.max_alloc = Some(MAX_DECODE_BYTES);
    reader.limits(limits);
    let cannot = |e: image::ImageError| {
        let message = match e {
            image::ImageError::Limits(e) => format!(
                "the photo is too large ({e}); streaklight reads photos of at most {MAX_SIDE} pixels on a side and {} GiB of pixel data",
                MAX_DECODE_BYTES >> 30
            ),
            e => format!("cannot decode the photo: {}", in_words(&e)),
        };
        Error::photo(path, message)
    };
    let decoder = reader.into_decoder().map_err(cannot)?;
    let (width, height) = decoder.dimensions();
    let pixels = u64::from(width) * u64::from(height);
    if width > MAX_SIDE || height > MAX_SIDE || pixels > MAX_PIXELS {
        return Err(Error::photo(
            path,
            format!(
                "the photo is too large ({width} x {height} pixels); streaklight reads photos of at most {MAX_SIDE} pixels on a side and {MAX_PIXELS} pixels in all"
            ),
        ));
    }
    crate::limits::check_memory(
        pixels.saturating_mul(crate::limits::FIT_BYTES_PER_PIXEL),
        &format!("the fit of this {width} x {height} photo"),
    )
    .map_err(|m| Error::photo(path, m))?;
    if decoder.total_bytes() > MAX_DECODE_BYTES {
        return Err(Error::photo(
            path,
            format!(
                "the photo is too large ({width} x {height} pixels, {} bytes decoded); streaklight reads at most {} GiB of pixel data",
                decoder.total_bytes(),
                MAX_DECODE_BYTES >> 30
            ),
        ));
    }
    let image = DynamicImage::from_decoder(decoder).map_err(cannot)?;
    let mut photo = from_image(image, exposure).map_err(|message| Error::photo(path, message))?;
    if format == Some(image::ImageFormat::Hdr) {
        photo.rounding = Rounding::SharedExponent;
    }
    for w in &mut photo.warnings {
        *w = format!("{}: {w}", path.display());
    }
    Ok(photo)
}

/// A decoder's error in words: the decoders' own texts can be dumps of their internal state
/// (`CrcMismatch { .. }`, `Unknown(32)`).
fn in_words(e: &image::ImageError) -> String {
    use image::error::{ImageFormatHint, UnsupportedErrorKind};
    use image::ImageError;
    let format = |hint: &ImageFormatHint| match hint {
        ImageFormatHint::Exact(f) => format!("{f:?}").to_uppercase(),
        ImageFormatHint::Name(n) => n.to_uppercase(),
        _ => "image".into(),
    };
    match e {
        ImageError::Decoding(d) => format!(
            "its {} data is damaged or cut short (a checksum, a length or a code in it is not \
             what the format allows)",
            format(&d.format_hint())
        ),
        ImageError::Unsupported(u) => match u.kind() {
            UnsupportedErrorKind::Color(_) => format!(
                "its {} pixel type is not one streaklight reads (8- or 16-bit integer grey or \
                 RGB(A), or 32-bit float in OpenEXR and Radiance HDR): save it as one of those",
                format(&u.format_hint())
            ),
            UnsupportedErrorKind::Format(hint) => format!(
                "{} files are not read (PNG, JPEG, TIFF, OpenEXR, Radiance HDR are)",
                format(&hint)
            ),
            _ => format!(
                "it uses a feature of the {} format that streaklight does not read (for TIFF: \
                 floating-point, planar or unusual sample formats; save it as 16-bit TIFF, PNG \
                 or OpenEXR)",
                format(&u.format_hint())
            ),
        },
        ImageError::IoError(io) => format!("it cannot be read ({io})"),
        _ => "its data is not a valid image".into(),
    }
}

/// Converts a decoded image to a [`Photo`], choosing the decoding by the sample type.
pub fn from_image(image: DynamicImage, exposure: f32) -> std::result::Result<Photo, String> {
    let (width, height) = (image.width(), image.height());
    if width == 0 || height == 0 {
        return Err("the photo has no pixels".into());
    }
    match image {
        DynamicImage::ImageRgb32F(_) | DynamicImage::ImageRgba32F(_) => {
            let rgb = image.into_rgb32f();
            let linear: Vec<[f32; 3]> = rgb.pixels().map(|p| p.0).collect();
            if linear.iter().flatten().any(|c| !c.is_finite()) {
                return Err("the photo holds NaN or infinite values".into());
            }
            // Light is never negative: such values (a denoiser's or a subtraction's undershoot)
            // are read as 0, and the user is told how many and how far below.
            let negative = linear.iter().flatten().filter(|&&c| c < 0.0).count();
            let lowest = linear.iter().flatten().copied().fold(0.0_f32, f32::min);
            let mut photo = Photo::from_linear(
                width,
                height,
                linear.into_iter().map(|p| p.map(|c| c.max(0.0))).collect(),
                exposure,
            );
            if negative > 0 {
                photo.warnings.push(format!(
                    "{negative} negative value(s) (the lowest {lowest}) were read as 0: light is \
                     never negative"
                ));
            }
            Ok(photo)
        }
        DynamicImage::ImageLuma16(_)
        | DynamicImage::ImageLumaA16(_)
        | DynamicImage::ImageRgb16(_)
        | DynamicImage::ImageRgba16(_) => {
            let rgb = image.into_rgb16();
            let display = rgb
                .pixels()
                .map(|p| p.0.map(|c| c as f32 / 65535.0))
                .collect();
            Ok(Photo {
                rounding: Rounding::Srgb {
                    step: 1.0 / 65535.0,
                },
                ..Photo::from_display(width, height, display, exposure)
            })
        }
        _ => {
            let rgb = image.into_rgb8();
            let display = rgb
                .pixels()
                .map(|p| p.0.map(|c| c as f32 / 255.0))
                .collect();
            Ok(Photo::from_display(width, height, display, exposure))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_curve_round_trips_and_matches_known_points() {
        // 0.5 encoded is 0.21404 linear (IEC 61966-2-1 tables).
        assert!((srgb_to_linear(0.5) - 0.214_041).abs() < 1e-5);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-6);
        for i in 0..=255 {
            let c = i as f32 / 255.0;
            assert!((linear_to_srgb(srgb_to_linear(c)) - c).abs() < 1e-5);
        }
    }

    #[test]
    fn clipped_pixels_are_marked_and_exposure_divides() {
        let p = Photo::from_display(2, 1, vec![[1.0, 0.2, 0.2], [0.5, 0.5, 0.5]], 2.0);
        assert_eq!(p.clipped, vec![true, false]);
        assert!((p.radiance[1][0] - 0.214_041 / 2.0).abs() < 1e-5);
    }
}
