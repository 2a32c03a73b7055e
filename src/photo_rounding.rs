//! How a photo file rounds its values, and the error that leaves in a value: what the pixels
//! of a lamp's image seen whole share, since they hold one value rounded alike, so that their
//! number does not average it away (`fitting::joint`'s uncertainties).

use crate::photo_in::linear_to_srgb;

/// How a photo file's values were rounded.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Rounding {
    /// sRGB code values `step` apart in display units: 1/255 for 8 bits, 1/65535 for 16.
    Srgb {
        /// The step between code values, display units.
        step: f32,
    },
    /// Radiance HDR's shared exponent: every channel of a pixel in steps of 1/256 to 1/128
    /// of its brightest channel (an 8-bit mantissa).
    SharedExponent,
    /// Floating-point values (OpenEXR): none counted. A half-float file's 11-bit mantissas
    /// leave under 0.03 % of a value.
    Float,
}

impl Rounding {
    /// The root mean square error the rounding leaves in a linear value `linear` (as the file
    /// holds it, before any division by the exposure) of a pixel whose brightest channel is
    /// `brightest`.
    ///
    /// sRGB: `step / sqrt(12)` through the decoding curve's slope at the value. The shared
    /// exponent: its step `2^ceil(log2(brightest)) / 256` over `sqrt(3)`, the rms of a
    /// writer that truncates (the format's reference writer does) as well as of one that
    /// rounds.
    pub fn sigma(&self, linear: f32, brightest: f32) -> f32 {
        match *self {
            Rounding::Srgb { step } => {
                let s = linear_to_srgb(linear.clamp(0.0, 1.0));
                let slope = if s <= 0.04045 {
                    1.0 / 12.92
                } else {
                    2.4 / 1.055 * ((s + 0.055) / 1.055).powf(1.4)
                };
                step / 12f32.sqrt() * slope
            }
            Rounding::SharedExponent if brightest > 0.0 => {
                brightest.log2().ceil().exp2() / 256.0 / 3f32.sqrt()
            }
            Rounding::SharedExponent | Rounding::Float => 0.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::photo_in::srgb_to_linear;

    /// Against brute force: the rms error of values spread evenly over a few steps of an
    /// 8-bit and a 16-bit encoding, rounded to it and decoded.
    #[test]
    fn srgb_sigma_is_the_rms_error_of_rounding() {
        for (linear, step) in [
            (0.002f32, 1.0 / 255.0),
            (0.05, 1.0 / 255.0),
            (0.4, 1.0 / 255.0),
            (0.7, 1.0 / 255.0),
            (0.4, 1.0 / 65535.0),
        ] {
            let s = linear_to_srgb(linear);
            let n = 100_000;
            let mut sum = 0.0f64;
            for k in 0..n {
                // Over 4 steps of the encoding around the value.
                let e = s + step * (4.0 * (k as f32 + 0.5) / n as f32 - 2.0);
                let rounded = (e / step).round() * step;
                sum += ((srgb_to_linear(rounded) - srgb_to_linear(e)) as f64).powi(2);
            }
            let rms = (sum / n as f64).sqrt() as f32;
            let got = Rounding::Srgb { step }.sigma(linear, linear);
            assert!(
                (got / rms - 1.0).abs() < 0.02,
                "{linear} {step}: {got} against {rms}"
            );
        }
    }

    /// Against brute force: values spread evenly over an octave, written with an 8-bit
    /// mantissa by truncation (as Radiance's writer does) and by rounding; the rms error over
    /// the octave below the value's power of two, where the step is fixed.
    #[test]
    fn shared_exponent_sigma_covers_truncation_and_rounding() {
        for brightest in [0.3f32, 0.7, 5.0] {
            let top = brightest.log2().ceil().exp2();
            let step = top / 256.0;
            let n = 100_000;
            let (mut cut, mut round) = (0.0f64, 0.0f64);
            for k in 0..n {
                let v = top * (0.5 + 0.5 * (k as f32 + 0.5) / n as f32);
                cut += ((v - (v / step).floor() * step) as f64).powi(2);
                round += ((v - (v / step).round() * step) as f64).powi(2);
            }
            let (cut, round) = ((cut / n as f64).sqrt(), (round / n as f64).sqrt());
            let got = Rounding::SharedExponent.sigma(brightest, brightest) as f64;
            assert!(
                (got / cut - 1.0).abs() < 0.02,
                "{brightest}: {got} against {cut}"
            );
            assert!(got >= round, "{brightest}: {got} against {round}");
        }
        assert_eq!(Rounding::Float.sigma(0.4, 0.4), 0.0);
    }
}
