//! sRGB to CIELAB for SLIC.

use rayon::prelude::*;

use super::FIXED;

/// CIELAB in three planes (structure of arrays, so that the distance loop vectorises), each
/// value times [`FIXED`] and rounded to an integer, so that the centre sums are exact.
pub(super) struct LabImage {
    pub(super) l: Vec<f32>,
    pub(super) a: Vec<f32>,
    pub(super) b: Vec<f32>,
}

impl LabImage {
    /// The colour of pixel `i` in Lab units.
    pub(super) fn colour(&self, i: usize) -> [f32; 3] {
        [self.l[i], self.a[i], self.b[i]].map(|v| v / FIXED)
    }
}

/// Bound on the magnitude of the values in a [`LabImage`].
pub(super) const LAB_LIMIT: i32 = i16::MAX as i32;

/// Pixels per parallel task of the conversion.
const CHUNK: usize = 4096;
/// Pixels per block of the conversion: the table look-ups for a block first, then its
/// arithmetic in straight lines that the compiler vectorises.
const BLOCK: usize = 64;

/// sRGB-encoded [0, 1] to CIELAB (D65 white), in parallel.
pub(super) fn to_lab(srgb: &[[f32; 3]]) -> LabImage {
    // 8-bit photos hold multiples of 1/255: a table saves three powf per pixel. Its last entry
    // stands for "not on the table".
    let mut table = [0.0f32; 257];
    for (i, t) in table.iter_mut().take(256).enumerate() {
        *t = crate::photo_in::srgb_to_linear(i as f32 / 255.0);
    }
    let n = srgb.len();
    let mut lab = LabImage {
        l: vec![0.0; n],
        a: vec![0.0; n],
        b: vec![0.0; n],
    };
    lab.l
        .par_chunks_mut(CHUNK)
        .zip(lab.a.par_chunks_mut(CHUNK))
        .zip(lab.b.par_chunks_mut(CHUNK))
        .zip(srgb.par_chunks(CHUNK))
        .for_each(|(((l, a), b), srgb)| {
            let blocks = l
                .chunks_mut(BLOCK)
                .zip(a.chunks_mut(BLOCK))
                .zip(b.chunks_mut(BLOCK))
                .zip(srgb.chunks(BLOCK));
            for (((l, a), b), srgb) in blocks {
                let len = srgb.len();
                let mut index = [[0u32; BLOCK]; 3];
                for (j, p) in srgb.iter().enumerate() {
                    for c in 0..3 {
                        index[c][j] = table_index(p[c]);
                    }
                }
                let mut rgb = [[0.0f32; BLOCK]; 3];
                for c in 0..3 {
                    for j in 0..len {
                        let i = index[c][j].min(256) as usize;
                        rgb[c][j] = if i < 256 {
                            table[i]
                        } else {
                            crate::photo_in::srgb_to_linear(srgb[j][c].clamp(0.0, 1.0))
                        };
                    }
                }
                let mut out = [[0.0f32; BLOCK]; 3];
                for j in 0..BLOCK {
                    [out[0][j], out[1][j], out[2][j]] =
                        rgb_to_lab([rgb[0][j], rgb[1][j], rgb[2][j]]);
                }
                l.copy_from_slice(&out[0][..len]);
                a.copy_from_slice(&out[1][..len]);
                b.copy_from_slice(&out[2][..len]);
            }
        });
    lab
}

/// The entry of the 8-bit table for an sRGB value (clamped to [0, 1]), or 256 when the value
/// is not within 1e-3 / 255 of a multiple of 1/255.
#[inline(always)]
fn table_index(c: f32) -> u32 {
    let scaled = c.clamp(0.0, 1.0) * 255.0;
    let nearest = trunc_small(scaled + 0.5);
    if (scaled - nearest).abs() < 1e-3 {
        // `nearest` is an integer in 0..=255: 1.5 * 2^23 puts it in the low mantissa bits.
        (nearest + 12_582_912.0).to_bits() & 0xff
    } else {
        256
    }
}

/// `y.trunc()` for |y| < 2^23, in plain f32 arithmetic that the compiler vectorises (the
/// library call and the saturating casts to integers are not, on baseline x86-64).
#[inline(always)]
fn trunc_small(y: f32) -> f32 {
    const TWO_23: f32 = 8_388_608.0;
    let a = y.abs();
    let nearest = (a + TWO_23) - TWO_23;
    let floor = if nearest > a { nearest - 1.0 } else { nearest };
    floor.copysign(y)
}

/// Linear sRGB to CIELAB times [`FIXED`], rounded half away from zero.
#[inline(always)]
fn rgb_to_lab([r, g, b]: [f32; 3]) -> [f32; 3] {
    // sRGB primaries to XYZ, divided by the D65 white point.
    let x = (0.412_456_4 * r + 0.357_576_1 * g + 0.180_437_5 * b) / 0.950_47;
    let y = 0.212_672_9 * r + 0.715_152_2 * g + 0.072_175 * b;
    let z = (0.019_333_9 * r + 0.119_192 * g + 0.950_304_1 * b) / 1.088_83;
    let (fx, fy, fz) = (lab_f(x), lab_f(y), lab_f(z));
    let q = |v: f32| {
        let s = v * FIXED;
        // Adding zero turns -0 into 0, as a cast to an integer and back does.
        let rounded = trunc_small(s + 0.5f32.copysign(s)) + 0.0;
        // Colours in [0, 1] stay within +-110 Lab units; the clamp only guards the centre
        // sums. A NaN (from a NaN in the photo) becomes 0.
        if rounded.is_nan() {
            0.0
        } else {
            rounded.clamp(-LAB_LIMIT as f32, LAB_LIMIT as f32)
        }
    };
    [
        q(116.0 * fy - 16.0),
        q(500.0 * (fx - fy)),
        q(200.0 * (fy - fz)),
    ]
}

/// The CIELAB companding function.
#[inline(always)]
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
#[inline(always)]
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
        let [l, a, b] = lab.colour(0);
        assert!((l - 100.0).abs() < 0.01 && a.abs() < 0.01 && b.abs() < 0.01);
        let [l, a, b] = lab.colour(1);
        assert!((l - 53.24).abs() < 0.05);
        assert!((a - 80.09).abs() < 0.1);
        assert!((b - 67.20).abs() < 0.1);
        assert!(lab.colour(2)[0].abs() < 1e-4);
    }

    #[test]
    fn fast_cbrt_is_accurate() {
        for i in 0..10_000 {
            let t = 0.008 + i as f32 * 1.2e-4;
            assert!((fast_cbrt(t) - t.cbrt()).abs() <= 2e-5 * t.cbrt(), "{t}");
        }
    }

    /// The conversion as first written, one pixel at a time with integer casts: the blocked,
    /// vectorised one must give the same values.
    fn scalar_reference(p: [f32; 3]) -> [f32; 3] {
        let linear = |c: f32| -> f32 {
            let c = c.clamp(0.0, 1.0);
            let scaled = c * 255.0;
            let idx = (scaled + 0.5) as usize;
            if (scaled - idx as f32).abs() < 1e-3 {
                crate::photo_in::srgb_to_linear(idx as f32 / 255.0)
            } else {
                crate::photo_in::srgb_to_linear(c)
            }
        };
        let (r, g, b) = (linear(p[0]), linear(p[1]), linear(p[2]));
        let x = (0.412_456_4 * r + 0.357_576_1 * g + 0.180_437_5 * b) / 0.950_47;
        let y = 0.212_672_9 * r + 0.715_152_2 * g + 0.072_175 * b;
        let z = (0.019_333_9 * r + 0.119_192 * g + 0.950_304_1 * b) / 1.088_83;
        let (fx, fy, fz) = (lab_f(x), lab_f(y), lab_f(z));
        let q = |v: f32| {
            let s = v * FIXED;
            ((s + 0.5f32.copysign(s)) as i32).clamp(-LAB_LIMIT, LAB_LIMIT) as f32
        };
        [
            q(116.0 * fy - 16.0),
            q(500.0 * (fx - fy)),
            q(200.0 * (fy - fz)),
        ]
    }

    #[test]
    fn blocks_give_the_scalar_values() {
        let mut pixels = Vec::new();
        // 8-bit colours (every level of each channel against a coarse grid of the others).
        for i in 0..256 {
            for j in (0..256).step_by(15) {
                for k in (0..256).step_by(51) {
                    let [u, v, w] = [i, j, k].map(|c| c as f32 / 255.0);
                    pixels.extend([[u, v, w], [v, w, u], [w, u, v]]);
                }
            }
        }
        // Values off the 8-bit levels, outside [0, 1] and not numbers; an odd count, so that
        // the last block is short.
        let mut state = 0x9e37_79b9_7f4a_7c15u64;
        for _ in 0..10_001 {
            state = state
                .wrapping_mul(6_364_136_223_846_793_005)
                .wrapping_add(1);
            let c = |s: u64| (s >> 40) as f32 / (1u64 << 24) as f32 * 1.2 - 0.1;
            pixels.push([c(state), c(state >> 8), c(state >> 16)]);
        }
        pixels.push([f32::NAN, 0.5, 0.5]);
        pixels.push([f32::INFINITY, -0.0, f32::NEG_INFINITY]);
        let lab = to_lab(&pixels);
        for (i, &p) in pixels.iter().enumerate() {
            let ours = [lab.l[i], lab.a[i], lab.b[i]];
            assert_eq!(
                ours.map(f32::to_bits),
                scalar_reference(p).map(f32::to_bits),
                "{p:?}"
            );
        }
    }
}
