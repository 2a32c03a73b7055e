//! Photos in every format we read decode to the radiance they hold: sRGB-encoded 8- and
//! 16-bit files through the exact sRGB curve, floating-point files as linear values, all
//! divided by the exposure; clipped pixels marked; bad files refused clearly.

mod common;

use std::io::Cursor;

use image::{DynamicImage, ImageBuffer, ImageFormat, Rgb};
use streaklight::photo_in::{load, srgb_to_linear};
use streaklight::photo_rounding::Rounding;

/// Linear radiance values to store, including some above 1 (only float formats keep those).
fn linear_values() -> Vec<[f32; 3]> {
    (0..64)
        .map(|i| {
            let t = i as f32 / 63.0;
            [t * 0.9, (t * 3.0).min(5.0), 4.0 * t * t]
        })
        .collect()
}

fn save(img: DynamicImage, path: &std::path::Path, format: ImageFormat) {
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), format).unwrap();
    std::fs::write(path, bytes).unwrap();
}

#[test]
fn float_formats_are_linear_and_never_clipped() {
    let dir = common::temp_dir("photo-float");
    let values = linear_values();
    let data: Vec<f32> = values.iter().flatten().copied().collect();
    let img = DynamicImage::ImageRgb32F(ImageBuffer::<Rgb<f32>, _>::from_raw(8, 8, data).unwrap());
    for (name, format, rel_tol) in [
        ("p.exr", ImageFormat::OpenExr, 1e-6f32),
        // Radiance HDR stores an 8-bit mantissa with a shared exponent: ~1 % precision.
        ("p.hdr", ImageFormat::Hdr, 1.0 / 128.0),
    ] {
        let path = dir.join(name);
        save(img.clone(), &path, format);
        let photo = load(&path, 2.0).unwrap();
        assert!(photo.is_linear_float);
        // Radiance HDR rounds to 8-bit mantissas under a shared exponent.
        let rounding = if name == "p.hdr" {
            Rounding::SharedExponent
        } else {
            Rounding::Float
        };
        assert_eq!(photo.rounding, rounding, "{name}");
        assert!(
            photo.clipped.iter().all(|&c| !c),
            "{name}: nothing is clipped in a float photo"
        );
        for (got, want) in photo.radiance.iter().zip(&values) {
            for c in 0..3 {
                let w = want[c] / 2.0;
                assert!(
                    (got[c] - w).abs()
                        <= rel_tol * want[c].max(want[0].max(want[1]).max(want[2])) / 2.0 + 1e-6,
                    "{name}: {} vs {w}",
                    got[c]
                );
            }
        }
    }
}

#[test]
fn integer_formats_are_srgb_with_clipping_at_the_maximum() {
    let dir = common::temp_dir("photo-int");
    // 8-bit PNG and JPEG-free formats: every code value decodes by the sRGB curve.
    let codes: Vec<u8> = (0..=255u8).flat_map(|v| [v, 255 - v, v / 2]).collect();
    let img8 = DynamicImage::ImageRgb8(ImageBuffer::from_raw(16, 16, codes.clone()).unwrap());
    save(img8, &dir.join("p8.png"), ImageFormat::Png);
    let photo = load(&dir.join("p8.png"), 0.5).unwrap();
    assert!(!photo.is_linear_float);
    // Its code values are 1/255 apart: the rounding a lamp's image shares.
    assert_eq!(photo.rounding, Rounding::Srgb { step: 1.0 / 255.0 });
    for (k, px) in photo.radiance.iter().enumerate() {
        let code = [codes[3 * k], codes[3 * k + 1], codes[3 * k + 2]];
        for c in 0..3 {
            let want = srgb_to_linear(code[c] as f32 / 255.0) / 0.5;
            assert!((px[c] - want).abs() < 1e-6);
        }
        assert_eq!(photo.clipped[k], code.contains(&255), "pixel {k}");
    }
    // 16-bit PNG and TIFF: 65535 is the maximum, 255 * 257 = 65535 too.
    let codes16: Vec<u16> = (0..256u32)
        .flat_map(|v| [(v * 257) as u16, 1000, 65535 - v as u16])
        .collect();
    let img16 = DynamicImage::ImageRgb16(ImageBuffer::from_raw(16, 16, codes16.clone()).unwrap());
    for (name, format) in [
        ("p16.png", ImageFormat::Png),
        ("p16.tiff", ImageFormat::Tiff),
    ] {
        save(img16.clone(), &dir.join(name), format);
        let photo = load(&dir.join(name), 1.0).unwrap();
        assert_eq!(
            photo.rounding,
            Rounding::Srgb {
                step: 1.0 / 65535.0
            },
            "{name}"
        );
        for (k, px) in photo.radiance.iter().enumerate() {
            let code = [codes16[3 * k], codes16[3 * k + 1], codes16[3 * k + 2]];
            for c in 0..3 {
                let want = srgb_to_linear(code[c] as f32 / 65535.0);
                assert!((px[c] - want).abs() < 1e-6, "{name}");
            }
            assert_eq!(photo.clipped[k], code.contains(&65535), "{name} pixel {k}");
        }
    }
}

#[test]
fn bad_photos_are_refused_with_the_file_named() {
    let dir = common::temp_dir("photo-bad");
    let missing = dir.join("missing.png");
    let e = load(&missing, 1.0).unwrap_err().to_string();
    assert!(e.contains("missing.png"), "{e}");
    std::fs::write(dir.join("text.png"), b"this is not an image").unwrap();
    let e = load(&dir.join("text.png"), 1.0).unwrap_err().to_string();
    assert!(e.contains("text.png"), "{e}");
    // A PNG cut in half.
    let img = DynamicImage::ImageRgb8(ImageBuffer::from_pixel(64, 64, Rgb([10u8, 20, 30])));
    let mut bytes = Vec::new();
    img.write_to(&mut Cursor::new(&mut bytes), ImageFormat::Png)
        .unwrap();
    std::fs::write(dir.join("cut.png"), &bytes[..bytes.len() / 2]).unwrap();
    let e = load(&dir.join("cut.png"), 1.0).unwrap_err().to_string();
    assert!(e.contains("cut.png") && e.contains("decode"), "{e}");
    std::fs::write(dir.join("ok.png"), &bytes).unwrap();
    assert!(
        load(&dir.join("ok.png"), 0.0).is_err(),
        "a zero exposure is refused"
    );
    assert!(load(&dir.join("ok.png"), f32::NAN).is_err());
}
