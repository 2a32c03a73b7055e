//! The exposure of a photo from its EXIF: the camera's exposure time, f-number and ISO speed,
//! turned by the reflected-light meter equation into the divisor that makes the photo's
//! linear values radiance in W/(sr m^2) (docs/method.md, "The exposure from EXIF").
//!
//! A meter with calibration constant K, set to ISO speed S, gives f-number N and exposure time
//! t for a scene of luminance L when N^2 / t = L S / K. So the settings a photo was taken with
//! say which luminance the camera put at middle grey: `L_m = K N^2 / (t S)` cd/m^2. That
//! luminance is taken to be recorded at the linear value [`MIDDLE_GREY`] (0.18), and linear
//! values to be proportional to luminance, so a linear value v is the luminance
//! `v L_m / 0.18` cd/m^2, the radiance `v L_m / (0.18 * 683)` W/(sr m^2), and the exposure
//! (linear value per unit of radiance, what `--exposure` gives by hand) is
//! `0.18 * 683 * t S / (K N^2)`.

use std::io::Cursor;
use std::path::Path;

use exif::{In, Tag, Value};

use crate::settings::Setting;
use crate::{Error, Result};

/// The reflected-light meter's calibration constant K, in cd s / m^2 (ISO 2720; Canon, Nikon
/// and Sekonic use 12.5).
pub const METER_K: f64 = 12.5;
/// The linear value at which the camera records the luminance its settings meter to: 18 %
/// of the clipping level (the middle grey of ISO 12232's standard output sensitivity).
pub const MIDDLE_GREY: f64 = 0.18;
/// Lumens per watt of the photometric unit (the luminous efficacy at 555 nm): luminance in
/// cd/m^2 is this times radiance in W/(sr m^2), as `--nits-scale 683` writes it.
pub const LUMENS_PER_WATT: f64 = 683.0;

/// The settings a photo was taken with, as its EXIF tells them.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct CameraSettings {
    /// Exposure time t, seconds.
    pub exposure_time: f64,
    /// f-number N (dimensionless).
    pub f_number: f64,
    /// ISO speed S (arithmetic, e.g. 800).
    pub iso: f64,
}

impl CameraSettings {
    /// The luminance, in cd/m^2, that these settings meter to: `K N^2 / (t S)`.
    pub fn metered_luminance(&self) -> f64 {
        METER_K * self.f_number * self.f_number / (self.exposure_time * self.iso)
    }

    /// The exposure: the linear value a radiance of 1 W/(sr m^2) is recorded at.
    pub fn exposure(&self) -> f64 {
        MIDDLE_GREY * LUMENS_PER_WATT / self.metered_luminance()
    }

    /// The settings as a photographer writes them: "1/30 s, f/2.8, ISO 800".
    pub fn describe(&self) -> String {
        let t = self.exposure_time;
        let time = if t < 1.0 && (1.0 / t - (1.0 / t).round()).abs() < 1e-3 * (1.0 / t) {
            format!("1/{} s", (1.0 / t).round())
        } else {
            format!("{} s", round_to(t, 4))
        };
        format!(
            "{time}, f/{}, ISO {}",
            round_to(self.f_number, 2),
            round_to(self.iso, 1)
        )
    }
}

fn round_to(x: f64, digits: i32) -> f64 {
    let scale = 10f64.powi(digits);
    (x * scale).round() / scale
}

/// The exposure of the photo at `path` from its EXIF, and the text that says where it came
/// from ("EXIF: 1/30 s, f/2.8, ISO 800, K = 12.5, middle grey 0.18"); errors as [`read`].
pub fn exposure_of(path: &Path) -> Result<(f32, String)> {
    exposure_from_bytes(&crate::input_file::read(path)?, path)
}

/// As [`exposure_of`], from the bytes of the photo's file; `path` names it in messages.
pub fn exposure_from_bytes(bytes: &[u8], path: &Path) -> Result<(f32, String)> {
    let camera = from_bytes(bytes, path)?;
    let exposure = camera.exposure() as f32;
    if !(exposure.is_finite() && exposure > 0.0) {
        return Err(Error::photo(
            path,
            format!(
                "the exposure of its EXIF settings ({}) is {exposure}, not a usable number",
                camera.describe()
            ),
        ));
    }
    let source = format!(
        "EXIF: {}, K = {METER_K}, middle grey {MIDDLE_GREY}",
        camera.describe()
    );
    Ok((exposure, source))
}

/// The camera settings in the EXIF of the photo at `path` (JPEG, PNG with an eXIf chunk,
/// TIFF). An error naming the photo when it has no EXIF, or the EXIF lacks the exposure
/// time, the f-number or the ISO speed, or holds a value that is not a positive number; the
/// file is read as every input is ([`crate::input_file::read`]: regular files only, bounded).
pub fn read(path: &Path) -> Result<CameraSettings> {
    from_bytes(&crate::input_file::read(path)?, path)
}

/// As [`read`], from the bytes of the photo's file; `path` names it in messages.
pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<CameraSettings> {
    let refuse = |why: String| {
        Error::photo(
            path,
            format!(
                "{why}, so its exposure cannot be read from it: give {} as a number",
                Setting::Exposure
            ),
        )
    };
    if bytes.starts_with(&[0x76, 0x2f, 0x31, 0x01]) {
        return Err(refuse("an OpenEXR file has no EXIF".into()));
    }
    if bytes.starts_with(b"#?") {
        return Err(refuse("a Radiance HDR file has no EXIF".into()));
    }
    let exif = exif::Reader::new()
        .read_from_container(&mut Cursor::new(bytes))
        .map_err(|e| match e {
            exif::Error::NotFound(_) => refuse("the photo has no EXIF".into()),
            e => refuse(format!("the photo's EXIF cannot be read ({e})")),
        })?;
    let number = |tag: Tag| -> Option<f64> {
        let field = exif.get_field(tag, In::PRIMARY)?;
        let v = match &field.value {
            Value::Rational(r) => r.first().map(|r| r.to_f64()),
            Value::SRational(r) => r.first().map(|r| r.to_f64()),
            Value::Float(f) => f.first().map(|&f| f64::from(f)),
            Value::Double(d) => d.first().copied(),
            other => other.get_uint(0).map(f64::from),
        }?;
        (v.is_finite() && v > 0.0).then_some(v)
    };
    let mut missing = Vec::new();
    let mut need = |name: &'static str, value: Option<f64>| {
        if value.is_none() {
            missing.push(name);
        }
        value.unwrap_or(f64::NAN)
    };
    let exposure_time = need(
        "the exposure time (ExposureTime)",
        number(Tag::ExposureTime),
    );
    let f_number = need("the f-number (FNumber)", number(Tag::FNumber));
    let iso = need(
        "the ISO speed (PhotographicSensitivity)",
        iso_speed(&number),
    );
    if !missing.is_empty() {
        return Err(refuse(format!(
            "the photo's EXIF has no positive value for {}",
            missing.join(", ")
        )));
    }
    Ok(CameraSettings {
        exposure_time,
        f_number,
        iso,
    })
}

/// The ISO speed: PhotographicSensitivity, unless it holds 65535, EXIF 2.3's "this or more",
/// when the exact value is in one of the sensitivity tags that EXIF 2.3 added.
fn iso_speed(number: &dyn Fn(Tag) -> Option<f64>) -> Option<f64> {
    match number(Tag::PhotographicSensitivity) {
        Some(s) if s < 65535.0 => Some(s),
        saturated => [
            Tag::ISOSpeed,
            Tag::RecommendedExposureIndex,
            Tag::StandardOutputSensitivity,
        ]
        .into_iter()
        .find_map(number)
        .or(saturated),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_equation_by_hand() {
        let s = CameraSettings {
            exposure_time: 1.0 / 30.0,
            f_number: 2.8,
            iso: 800.0,
        };
        // K N^2 / (t S) = 12.5 * 7.84 * 30 / 800 = 3.675 cd/m^2.
        assert!((s.metered_luminance() - 3.675).abs() < 1e-12);
        // 0.18 * 683 / 3.675 = 33.4531...
        assert!((s.exposure() - 122.94 / 3.675).abs() < 1e-9);
        assert_eq!(s.describe(), "1/30 s, f/2.8, ISO 800");
        let long = CameraSettings {
            exposure_time: 2.5,
            ..s
        };
        assert_eq!(long.describe(), "2.5 s, f/2.8, ISO 800");
    }

    #[test]
    fn no_exif_is_named() {
        let path = Path::new("night.exr");
        let e = from_bytes(&[0x76, 0x2f, 0x31, 0x01, 2, 0, 0, 0], path).unwrap_err();
        assert!(e.to_string().contains("night.exr") && e.to_string().contains("OpenEXR"));
        let e = from_bytes(b"not an image at all", path).unwrap_err();
        assert!(e.to_string().contains("EXIF"), "{e}");
    }
}
