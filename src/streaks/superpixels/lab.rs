//! sRGB to CIELAB for SLIC.

use rayon::prelude::*;

use super::FIXED;

/// CIELAB in three planes (structure of arrays, so the distance loop vectorises).
pub(super) struct LabImage {
    pub(super) l: Vec<f32>,
    pub(super) a: Vec<f32>,
    pub(super) b: Vec<f32>,
    /// The same values times [`FIXED`], as exact integers, for the centre sums.
    pub(super) fixed: Vec<[i32; 3]>,
}

/// sRGB-encoded [0, 1] to CIELAB (D65 white), in parallel.
pub(super) fn to_lab(srgb: &[[f32; 3]]) -> LabImage {
    // 8-bit photos hold multiples of 1/255: a table saves three powf per pixel.
    let table: Vec<f32> = (0..256)
        .map(|i| crate::photo_in::srgb_to_linear(i as f32 / 255.0))
        .collect();
    let linear = |c: f32| -> f32 {
        let c = c.clamp(0.0, 1.0);
        let scaled = c * 255.0;
        let idx = (scaled + 0.5) as usize;
        if (scaled - idx as f32).abs() < 1e-3 {
            table[idx]
        } else {
            crate::photo_in::srgb_to_linear(c)
        }
    };
    let fixed: Vec<[i32; 3]> = srgb
        .par_iter()
        .with_min_len(4096)
        .map(|p| {
            let (r, g, b) = (linear(p[0]), linear(p[1]), linear(p[2]));
            // sRGB primaries to XYZ, divided by the D65 white point.
            let x = (0.412_456_4 * r + 0.357_576_1 * g + 0.180_437_5 * b) / 0.950_47;
            let y = 0.212_672_9 * r + 0.715_152_2 * g + 0.072_175 * b;
            let z = (0.019_333_9 * r + 0.119_192 * g + 0.950_304_1 * b) / 1.088_83;
            let (fx, fy, fz) = (lab_f(x), lab_f(y), lab_f(z));
            // Quantised to multiples of 1 / FIXED (rounding half away from zero), so that the
            // centre sums are exact integers.
            let q = |v: f32| {
                let s = v * FIXED;
                (s + 0.5f32.copysign(s)) as i32
            };
            [
                q(116.0 * fy - 16.0),
                q(500.0 * (fx - fy)),
                q(200.0 * (fy - fz)),
            ]
        })
        .collect();
    let plane = |c: usize| -> Vec<f32> { fixed.iter().map(|p| p[c] as f32 / FIXED).collect() };
    LabImage {
        l: plane(0),
        a: plane(1),
        b: plane(2),
        fixed,
    }
}

/// The CIELAB companding function.
fn lab_f(t: f32) -> f32 {
    const EPSILON: f32 = 216.0 / 24389.0;
    const KAPPA: f32 = 24389.0 / 27.0;
    if t > EPSILON {
        fast_cbrt(t)
    } else {
        (KAPPA * t + 16.0) / 116.0
    }
}

/// Cube root of a positive number: a bit-level first guess (Kahan's) and two Newton steps,
/// within 2e-5 relative of `cbrt` and several times faster than the library call.
fn fast_cbrt(t: f32) -> f32 {
    let mut x = f32::from_bits(t.to_bits() / 3 + 709_921_077);
    for _ in 0..2 {
        x = (2.0 * x + t / (x * x)) * (1.0 / 3.0);
    }
    x
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lab_of_known_colours() {
        // Reference values from Bruce Lindbloom's calculator (D65, sRGB).
        let lab = to_lab(&[[1.0, 1.0, 1.0], [1.0, 0.0, 0.0], [0.0, 0.0, 0.0]]);
        assert!((lab.l[0] - 100.0).abs() < 0.01 && lab.a[0].abs() < 0.01 && lab.b[0].abs() < 0.01);
        assert!((lab.l[1] - 53.24).abs() < 0.05);
        assert!((lab.a[1] - 80.09).abs() < 0.1);
        assert!((lab.b[1] - 67.20).abs() < 0.1);
        assert!(lab.l[2].abs() < 1e-4);
    }

    #[test]
    fn fast_cbrt_is_accurate() {
        for i in 0..10_000 {
            let t = 0.008 + i as f32 * 1.2e-4;
            assert!((fast_cbrt(t) - t.cbrt()).abs() <= 2e-5 * t.cbrt(), "{t}");
        }
    }
}
