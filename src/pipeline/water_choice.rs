//! Which water model the fit inverts (method §10), and how the choice is made.
//!
//! The exact model (the scene's water mesh is the photo's water) is right when its fine
//! structure matches the photo's: where the mesh's ripples put a glint, the photo shows one.
//! After the exact joint fit, both images are high-passed over the fitted pixels (each value
//! less the mean of the fitted pixels within [`HIGH_PASS_RADIUS`] of it) and correlated. On
//! a photo of the scene's own waves the correlation is high (the glints coincide; the fit's
//! Monte Carlo noise keeps it below 1); on a photo of other waves, or of water the scene
//! holds as a flat quad, the exact model's fine structure is unrelated to the photo's, and
//! the correlation is near 0. Below [`EXACT_MIN_CORRELATION`] the fit is made again with the
//! statistical model.

use serde::Serialize;

/// Half the side of the window whose mean is subtracted, in pixels: a few pixels, the scale
/// of a glint, far below a streak's.
pub const HIGH_PASS_RADIUS: i64 = 3;

/// The correlation of the high-passed photo and exact expected image below which the
/// scene's waves are taken not to be the photo's.
pub const EXACT_MIN_CORRELATION: f64 = 0.35;

/// Which water model to fit with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WaterChoice {
    /// The scene's water mesh is the photo's water (the paper's setting).
    Exact,
    /// The scene gives the mean surface; the waves are slope variances estimated from the
    /// photo.
    Statistical,
    /// The exact model if its fine structure matches the photo's, else the statistical one
    /// (module doc).
    #[default]
    Auto,
}

impl WaterChoice {
    /// "exact", "statistical" or "auto".
    pub fn name(self) -> &'static str {
        match self {
            WaterChoice::Exact => "exact",
            WaterChoice::Statistical => "statistical",
            WaterChoice::Auto => "auto",
        }
    }
}

/// What the fit used, and why.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct WaterModelUsed {
    /// "exact" or "statistical".
    pub model: &'static str,
    /// Why: "forced" by the settings, or "detected" (from `fine_structure_correlation`).
    pub chosen: &'static str,
    /// The correlation of the photo's fine structure with the exact model's (module doc);
    /// `None` where it was not measured.
    pub fine_structure_correlation: Option<f64>,
    /// The threshold it was compared with.
    pub threshold: f64,
    /// The statistical model's slopes, when it was used.
    pub slopes: Option<SlopesUsed>,
}

/// The statistical model's slope variances.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct SlopesUsed {
    /// Total slope variance (microfacets and waves) along the camera's view on the water and
    /// across it (dimensionless).
    pub variance: [f32; 2],
    /// One-sigma uncertainty of the natural logarithm of each (about the relative
    /// uncertainty); `None` where not estimated or not bracketed.
    pub sigma_ln: [Option<f32>; 2],
    /// Where the estimate started.
    pub start_variance: [f32; 2],
    /// What the start came from.
    pub start_source: String,
    /// Whether the variances were estimated from the photo (false: the start was used as
    /// it is, by the paper's method).
    pub estimated: bool,
    /// Pixels per independent residual of the final fit (the glitter's correlation area):
    /// every uncertainty was grown by its square root; `None` for the paper's method.
    pub correlation_area: Option<f64>,
}

/// The correlation of the high-passed photo and model over the fitted pixels `modelled`
/// (indices into a `width`-wide photo with their modelled radiance), on the sum of the
/// channels; `None` with fewer than 16 pixels or no variation in either.
pub fn fine_structure_correlation(
    photo: &[[f32; 3]],
    width: u32,
    modelled: &[(u32, [f32; 3])],
) -> Option<f64> {
    if modelled.len() < 16 || width == 0 {
        return None;
    }
    let w = width as i64;
    let index: std::collections::HashMap<u32, usize> = modelled
        .iter()
        .enumerate()
        .map(|(i, &(p, _))| (p, i))
        .collect();
    let sum = |c: [f32; 3]| (c[0] + c[1] + c[2]) as f64;
    let photo_value: Vec<f64> = modelled
        .iter()
        .map(|&(p, _)| photo.get(p as usize).map_or(0.0, |&c| sum(c)))
        .collect();
    let model_value: Vec<f64> = modelled.iter().map(|&(_, m)| sum(m)).collect();
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    let r = HIGH_PASS_RADIUS;
    for (i, &(p, _)) in modelled.iter().enumerate() {
        let (x, y) = (p as i64 % w, p as i64 / w);
        let (mut mp, mut mm, mut n) = (0.0, 0.0, 0.0);
        for dy in -r..=r {
            for dx in -r..=r {
                let (nx, ny) = (x + dx, y + dy);
                if nx < 0 || nx >= w || ny < 0 {
                    continue;
                }
                if let Some(&j) = index.get(&((ny * w + nx) as u32)) {
                    mp += photo_value[j];
                    mm += model_value[j];
                    n += 1.0;
                }
            }
        }
        let hp = photo_value[i] - mp / n;
        let hm = model_value[i] - mm / n;
        sxx += hp * hp;
        syy += hm * hm;
        sxy += hp * hm;
    }
    (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A smooth streak with glints: the correlation of the photo with itself is 1, with the
    /// smooth streak alone (no fine structure to match) near 0, and with glints elsewhere
    /// near 0; a smooth difference (a wider streak) does not count.
    #[test]
    fn correlation_sees_the_fine_structure_only() {
        let (w, h) = (64u32, 64u32);
        let smooth = |x: f64, y: f64, width: f64| {
            (-(x - 32.0).powi(2) / (2.0 * width * width)).exp() * (y / 64.0)
        };
        // Pseudo-random glints from a hash of the pixel index.
        let glint = |p: u32, salt: u32| {
            let v = (p.wrapping_mul(2_654_435_761) ^ salt).wrapping_mul(40_503) >> 16;
            if v.is_multiple_of(7) {
                2.0
            } else {
                0.0
            }
        };
        let image = |width: f64, salt: Option<u32>| -> Vec<[f32; 3]> {
            (0..w * h)
                .map(|p| {
                    let (x, y) = ((p % w) as f64, (p / w) as f64);
                    let v = smooth(x, y, width) * (1.0 + salt.map_or(0.0, |s| glint(p, s)));
                    [v as f32; 3]
                })
                .collect()
        };
        let photo = image(6.0, Some(1));
        let region: Vec<u32> = (0..w * h)
            .filter(|p| (p % w) >= 8 && (p % w) < 56)
            .collect();
        let as_model = |img: &[[f32; 3]]| -> Vec<(u32, [f32; 3])> {
            region.iter().map(|&p| (p, img[p as usize])).collect()
        };
        let same = fine_structure_correlation(&photo, w, &as_model(&photo)).unwrap();
        assert!((same - 1.0).abs() < 1e-9, "{same}");
        let flat = fine_structure_correlation(&photo, w, &as_model(&image(9.0, None))).unwrap();
        assert!(flat.abs() < 0.15, "{flat}");
        let other = fine_structure_correlation(&photo, w, &as_model(&image(6.0, Some(99))));
        assert!(other.unwrap().abs() < 0.15, "{other:?}");
        // The same glints under a wider smooth streak still match.
        let wider = fine_structure_correlation(&photo, w, &as_model(&image(9.0, Some(1))));
        assert!(wider.unwrap() > 0.8, "{wider:?}");
        assert_eq!(fine_structure_correlation(&photo, w, &[]), None);
    }
}
