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
//! statistical model, unless the exact fit explains the photo all the same (at least
//! [`EXACT_MIN_EXPLAINED`] of its variance over the fitted pixels: smooth water, which the
//! exact model of a flat quad describes as it is, has no fine structure to correlate).
//!
//! A scene whose water is flat (slope variances under [`FLAT_SHARE`] of its material's) holds
//! no waves whose fine structure could match: its exact model is the statistical model with
//! the slopes fixed at the material's. The automatic choice then fits with the statistical
//! model at once, so that the slopes are estimated from the photo (a game scene's quad
//! carries a roughness that is a guess) and no exact fit is spent on the test.

use rayon::prelude::*;
use serde::Serialize;

use crate::photo_in::Photo;
use crate::pixel_index::PixelIndex;
use crate::pixel_scale::scaled_pixels;

/// Half the side of the window whose mean is subtracted, in pixels, on the samples' photos:
/// a few pixels, the scale of a glint, far below a streak's ([`high_pass_radius`] on
/// others).
pub const HIGH_PASS_RADIUS: i64 = 3;

/// The high-pass window's half side on a photo of `rows` rows through a vertical field of
/// view of `yfov` radians: [`HIGH_PASS_RADIUS`] grown with the rows per degree
/// ([`crate::pixel_scale`]), where the thresholds below were measured. A window of the
/// samples' pixels would pass a finer photo's glints' inside alone (on Table 1 rendered at
/// 4000 x 3000, its own waves correlated at 0.03).
pub fn high_pass_radius(rows: u32, yfov: f32) -> i64 {
    scaled_pixels(HIGH_PASS_RADIUS, rows, yfov)
}

/// The correlation of the high-passed photo and exact expected image below which the
/// scene's waves are taken not to be the photo's.
pub const EXACT_MIN_CORRELATION: f64 = 0.35;

/// The share of the photo's variance over the fitted pixels that the exact fit explains from
/// which the exact model is kept whatever the correlation: a photo of smooth water (rendered
/// from a flat quad) has no fine structure to correlate with, yet the exact model of the quad
/// is right for it. Measured on Table 1's setup: 0.93 for a photo rendered from a flat quad
/// (at 64 samples per pixel), 0.81 for the rippled photo against the flat quad, 0.24 and 0.41
/// for the harbour photo against other waves and a flat quad, 0.99 for the rippled photo
/// against its own mesh.
pub const EXACT_MIN_EXPLAINED: f64 = 0.9;

/// The correlation of the high-passed photo and exact expected image at the start lights
/// (the paper's estimate, before the joint fit moves an edge) under which the exact fit is
/// not made at all, when the start does not explain the photo either (under
/// [`EXACT_MIN_EXPLAINED`]). Measured on the samples at their start: 0.60-0.92 for photos of
/// the scene's own waves (13 photos, Table 1's setup and the harbour's), -0.04 to 0.06 for
/// the same photos over other waves (13 fits); at the fitted lights the latter stay within
/// 0.02 of their start values. Half the fitted threshold, so that only a start as unrelated
/// as these skips the exact fit; anything nearer it is fitted and tested as before.
pub const START_MAX_CORRELATION: f64 = 0.15;

/// Samples a pixel of the exact model's expected image at the paper's first estimate, where
/// that estimate is not kept (a light it starts on no lamp's whole direct image): rendered
/// over half the streaks' pixels alone and tested as the joint fit's start is
/// ([`FineStructure::clearly_not_exact`]) before the estimate is made again at the full
/// samples. Measured on the samples (docs/decisions.md): 0.35-0.76 for photos of the scene's
/// own waves, -0.06 to 0.04 over other waves.
pub const FIRST_ESTIMATE_TEST_SAMPLES: u32 = 8;

/// The share of the material's slope variance under which the water mesh's own slope
/// variances (both) make it flat: waves that tilt the surface by less than a third of the
/// microfacets' spread put no fine structure of their own into the reflections.
pub const FLAT_SHARE: f32 = 0.1;

/// Which water model to fit with.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum WaterChoice {
    /// The scene's water mesh is the photo's water (the paper's setting).
    Exact,
    /// The scene gives the mean surface; the waves are slope variances estimated from the
    /// photo.
    Statistical,
    /// The exact model if its fine structure matches the photo's, else the statistical one
    /// (module doc). The default.
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
    /// How: "forced" by the settings, or "detected" (from the scene's water and the photo).
    pub chosen: &'static str,
    /// Why, in words, with the measured values the choice rested on.
    pub reason: String,
    /// The correlation of the photo's fine structure with the exact model's (module doc);
    /// `None` where it was not measured.
    pub fine_structure_correlation: Option<f64>,
    /// The threshold it was compared with.
    pub threshold: f64,
    /// The share of the photo's variance over the fitted pixels that the exact fit explains;
    /// `None` where not measured.
    pub exact_explained: Option<f64>,
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
    /// uncertainty), at least what one realisation of the waves moves it by
    /// ([`crate::fitting::slopes::SLOPE_REALISATION_LN`]); `None` where not estimated or not
    /// bracketed.
    pub sigma_ln: [Option<f32>; 2],
    /// Where the estimate started.
    pub start_variance: [f32; 2],
    /// What the start came from.
    pub start_source: String,
    /// Whether the variances were estimated from the photo (false: the start was used as
    /// it is, by the paper's method, or no light was found to estimate them with).
    pub estimated: bool,
    /// Pixels per independent residual of the final fit (the glitter's correlation area):
    /// every uncertainty was grown by its square root; `None` for the paper's method.
    pub correlation_area: Option<f64>,
    /// Lobe samples per traced pixel of the paper's estimate the fit started from (reported
    /// as the settings' `samples`, not here).
    #[serde(skip)]
    pub start_samples: u32,
}

/// The fine structure of the photo and of a model over the fitted pixels `modelled` (indices
/// into a `width`-wide photo with their modelled radiance), on the sum of the channels.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FineStructure {
    /// The correlation of the two high-passes; `None` with no variation in either.
    pub correlation: Option<f64>,
    /// The share of the photo's variance the model explains, `1 - sum (I - m)^2 / sum (I -
    /// mean I)^2`; `None` for a constant photo.
    pub explained: Option<f64>,
}

impl FineStructure {
    /// Whether the exact model describes the photo (module doc): its fine structure
    /// correlates with the photo's, or it explains the photo all the same. Unmeasured counts
    /// as yes.
    pub fn exact_fits(&self) -> bool {
        self.correlation.is_none_or(|c| c >= EXACT_MIN_CORRELATION)
            || self.explained.is_none_or(|e| e >= EXACT_MIN_EXPLAINED)
    }

    /// Whether the exact model's image at the start lights is so far from the photo that its
    /// fit need not be made ([`START_MAX_CORRELATION`]): a measured correlation under it and
    /// a measured share explained under [`EXACT_MIN_EXPLAINED`]. Implies `!exact_fits()`.
    pub fn clearly_not_exact(&self) -> bool {
        self.correlation.is_some_and(|c| c < START_MAX_CORRELATION)
            && self.explained.is_some_and(|e| e < EXACT_MIN_EXPLAINED)
    }
}

/// The fine structure of `photo` (seen through a vertical field of view of `yfov` radians)
/// and of the model `modelled`, high-passed at [`high_pass_radius`].
pub fn fine_structure_of(
    photo: &Photo,
    yfov: f32,
    modelled: &[(u32, [f32; 3])],
) -> Option<FineStructure> {
    let radius = high_pass_radius(photo.height, yfov);
    fine_structure(&photo.radiance, photo.width, modelled, radius)
}

/// The fine structure of `photo` and of the model `modelled` (see [`FineStructure`]), each
/// value less the mean of the fitted pixels within `radius` of it; `None` with fewer than 16
/// pixels.
pub fn fine_structure(
    photo: &[[f32; 3]],
    width: u32,
    modelled: &[(u32, [f32; 3])],
    radius: i64,
) -> Option<FineStructure> {
    if modelled.len() < 16 || width == 0 {
        return None;
    }
    let w = width as i64;
    let index = PixelIndex::new(modelled.iter().map(|m| m.0), width);
    let sum = |c: [f32; 3]| (c[0] + c[1] + c[2]) as f64;
    let photo_value: Vec<f64> = modelled
        .iter()
        .map(|&(p, _)| photo.get(p as usize).map_or(0.0, |&c| sum(c)))
        .collect();
    let model_value: Vec<f64> = modelled.iter().map(|&(_, m)| sum(m)).collect();
    let photo_mean = photo_value.iter().sum::<f64>() / photo_value.len() as f64;
    let photo_var: f64 = photo_value.iter().map(|v| (v - photo_mean).powi(2)).sum();
    let residual: f64 = photo_value
        .iter()
        .zip(&model_value)
        .map(|(p, m)| (p - m).powi(2))
        .sum();
    let r = radius.max(1);
    // Each pixel's high-passed pair, in parallel (the window of a fine photo reads hundreds
    // of neighbours), summed in order below.
    let passed: Vec<(f64, f64)> = (0..modelled.len())
        .into_par_iter()
        .map(|i| {
            let (x, y) = (modelled[i].0 as i64 % w, modelled[i].0 as i64 / w);
            let (mut mp, mut mm, mut n) = (0.0, 0.0, 0.0);
            for dy in -r..=r {
                for dx in -r..=r {
                    if let Some(j) = index.at(x + dx, y + dy) {
                        mp += photo_value[j];
                        mm += model_value[j];
                        n += 1.0;
                    }
                }
            }
            (photo_value[i] - mp / n, model_value[i] - mm / n)
        })
        .collect();
    let (mut sxx, mut syy, mut sxy) = (0.0, 0.0, 0.0);
    for (hp, hm) in passed {
        sxx += hp * hp;
        syy += hm * hm;
        sxy += hp * hm;
    }
    Some(FineStructure {
        correlation: (sxx > 0.0 && syy > 0.0).then(|| sxy / (sxx * syy).sqrt()),
        explained: (photo_var > 0.0).then(|| 1.0 - residual / photo_var),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The window is the samples' 3 pixels grown with the rows per degree: 5 at 1080 rows
    /// over 60 degrees.
    #[test]
    fn the_high_pass_window_follows_the_rows_per_degree() {
        let sixty = 60f32.to_radians();
        assert_eq!(high_pass_radius(600, sixty), HIGH_PASS_RADIUS);
        assert_eq!(high_pass_radius(1080, sixty), 5);
    }

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
        let correlation = |img: &[[f32; 3]]| {
            fine_structure(&photo, w, &as_model(img), HIGH_PASS_RADIUS)
                .unwrap()
                .correlation
        };
        let same = correlation(&photo).unwrap();
        assert!((same - 1.0).abs() < 1e-9, "{same}");
        let flat = correlation(&image(9.0, None)).unwrap();
        assert!(flat.abs() < 0.15, "{flat}");
        let other = correlation(&image(6.0, Some(99)));
        assert!(other.unwrap().abs() < 0.15, "{other:?}");
        // The same glints under a wider smooth streak still match.
        let wider = correlation(&image(9.0, Some(1)));
        assert!(wider.unwrap() > 0.8, "{wider:?}");
        assert_eq!(fine_structure(&photo, w, &[], HIGH_PASS_RADIUS), None);
        // A smooth photo explained by a smooth model: nothing to correlate, and the exact
        // model fits all the same; a glittering photo against a smooth model does not.
        let smooth = image(6.0, None);
        let faint_glints: Vec<[f32; 3]> = smooth
            .iter()
            .zip(image(6.0, Some(99)))
            .map(|(s, g)| [s[0] + 0.03 * (g[0] - s[0]); 3])
            .collect();
        let f = fine_structure(&smooth, w, &as_model(&faint_glints), HIGH_PASS_RADIUS).unwrap();
        assert!(f.explained.unwrap() > 0.95 && f.exact_fits(), "{f:?}");
        // The rule: either test keeps the exact model.
        let rule = |c, e| {
            FineStructure {
                correlation: Some(c),
                explained: Some(e),
            }
            .exact_fits()
        };
        assert!(rule(0.0, 0.95) && rule(0.5, 0.1) && !rule(0.3, 0.85));
        // The start's rule: only a start both unrelated and unexplained skips the exact fit,
        // and whatever it skips the fitted rule would have rejected.
        let skip = |c: Option<f64>, e: Option<f64>| {
            FineStructure {
                correlation: c,
                explained: e,
            }
            .clearly_not_exact()
        };
        assert!(skip(Some(0.05), Some(0.3)) && skip(Some(-0.2), Some(0.85)));
        assert!(!skip(Some(0.2), Some(0.3)) && !skip(Some(0.05), Some(0.95)));
        assert!(!skip(None, Some(0.3)) && !skip(Some(0.05), None));
        for c in [-0.5, 0.0, 0.1, 0.14, 0.15, 0.3, 0.6] {
            for e in [-1.0, 0.0, 0.5, 0.89, 0.9, 0.99] {
                assert!(!skip(Some(c), Some(e)) || !rule(c, e), "{c} {e}");
            }
        }
        let f = fine_structure(&photo, w, &as_model(&image(9.0, None)), HIGH_PASS_RADIUS).unwrap();
        assert!(f.explained.unwrap() < 0.9 && !f.exact_fits(), "{f:?}");
    }
}
