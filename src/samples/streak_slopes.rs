//! The slopes of a wave mesh under the streaks its lights make: the yardstick the
//! statistical water model's slope variances are held to (docs/method.md §10). A photo's
//! streaks tell the slopes of the few metres of water they reflect, not the slopes of the
//! whole field, so the mesh a photo was rendered from is measured where its streaks lie: over
//! the pixels where each light's reflection in the harbour waves' expected image passes 2 %
//! of its peak, with the mesh's shading normals against the mean plane's axes.

use crate::optics::GaussianSlopes;
use crate::render::{camera_hit, render_with_lights, CameraHit, RenderOptions};
use crate::scene_in::Scene;
use crate::water_model::{water_statistics, StatisticalSurface};
use crate::{Error, Result};

use super::harbour_waves::harbour_spectrum;

/// The share of a light's peak in its expected image that counts a pixel as under its streak.
pub const FOOTPRINT_SHARE: f32 = 0.02;

/// Per pixel of a `w` x `h` image, whether the camera ray through its centre meets the
/// water first.
pub fn water_pixels(scene: &Scene, w: u32, h: u32) -> Vec<bool> {
    (0..w * h)
        .map(|i| {
            let (x, y) = ((i % w) as f32 + 0.5, (i / w) as f32 + 0.5);
            matches!(camera_hit(scene, &[], x, y, w, h), CameraHit::Water(_))
        })
        .collect()
}

/// The statistical water over `scene`'s mean plane with the harbour waves' own slope
/// variances (the spectrum the harbour samples' meshes are drawn from), for a `w` x `h`
/// image; `None` when the camera sees no water.
pub fn harbour_expectation(scene: &Scene, w: u32, h: u32) -> Option<StatisticalSurface> {
    let spectrum = harbour_spectrum();
    Some(StatisticalSurface {
        surface: water_statistics(scene, w, h)?.surface,
        waves: [
            spectrum.rms_slope_along.powi(2) as f32,
            spectrum.rms_slope_across.powi(2) as f32,
        ],
    })
}

/// The pixels of a `w`-wide image `image` among `keep` where `value` passes `share` of its
/// largest value there: a streak's footprint in its expected image.
pub fn footprint(
    image: &[[f32; 3]],
    keep: impl Fn(usize) -> bool,
    value: impl Fn([f32; 3]) -> f32,
    share: f32,
) -> Vec<usize> {
    let peak = (0..image.len())
        .filter(|&i| keep(i))
        .map(|i| value(image[i]))
        .fold(0f32, f32::max);
    (0..image.len())
        .filter(|&i| keep(i) && value(image[i]) >= share * peak)
        .collect()
}

/// The union of the footprints of `scene`'s lights in the expected image under `water` (16
/// rays a pixel, each light alone): the water pixels where a light's image passes
/// [`FOOTPRINT_SHARE`] of its peak in its strongest channel.
pub fn streak_footprints(
    scene: &Scene,
    water: &StatisticalSurface,
    w: u32,
    h: u32,
) -> Result<Vec<usize>> {
    let sees_water = water_pixels(scene, w, h);
    let mut union = vec![false; (w * h) as usize];
    for light in &scene.area_lights {
        let options = RenderOptions {
            width: w,
            height: h,
            samples_per_pixel: 16,
            water: Some(water),
            ..Default::default()
        };
        let image = render_with_lights(scene, std::slice::from_ref(light), &options)?;
        let strongest = |p: [f32; 3]| p[0].max(p[1]).max(p[2]);
        for i in footprint(&image.pixels, |i| sees_water[i], strongest, FOOTPRINT_SHARE) {
            union[i] = true;
        }
    }
    Ok((0..union.len()).filter(|&i| union[i]).collect())
}

/// The slope variances of `scene`'s water mesh (its shading normals against `water`'s mean
/// plane), along and across its axes, over `pixels` of a `w` x `h` image: four camera rays
/// a pixel, each slope the normal's rise over run. Fails when no ray meets the water.
pub fn mesh_slope_variances(
    scene: &Scene,
    water: &StatisticalSurface,
    pixels: &[usize],
    w: u32,
    h: u32,
) -> Result<[f64; 2]> {
    let (n0, along, across) = (
        water.surface.normal,
        water.surface.along,
        water.surface.across(),
    );
    let (mut n, mut s, mut s2) = (0f64, [0f64; 2], [0f64; 2]);
    for &i in pixels {
        for k in 0..4u32 {
            let x = (i as u32 % w) as f32 + 0.25 + 0.5 * (k % 2) as f32;
            let y = (i as u32 / w) as f32 + 0.25 + 0.5 * (k / 2) as f32;
            if let CameraHit::Water(p) = camera_hit(scene, &[], x, y, w, h) {
                for (a, axis) in [along, across].into_iter().enumerate() {
                    let slope = -(p.normal.dot(axis) / p.normal.dot(n0)) as f64;
                    s[a] += slope;
                    s2[a] += slope * slope;
                }
                n += 1.0;
            }
        }
    }
    if n == 0.0 {
        return Err(Error::NothingFound(
            "no camera ray of the pixels given meets the water".into(),
        ));
    }
    Ok([0, 1].map(|a| s2[a] / n - (s[a] / n).powi(2)))
}

/// The total slope variances (the lobe's whole, along and across the view) of the harbour
/// waves' mesh in `scene` under its lights' streaks in a `w` x `h` photo, as the statistical
/// model's estimate stands for them: the mesh's slopes ([`streak_footprints`],
/// [`mesh_slope_variances`]) plus the photo's microfacets of Blinn-Phong gloss
/// `photo_gloss` (1 / (e + 2) an axis) less the model's own of gloss `model_gloss`.
pub fn lobe_under_streaks(
    scene: &Scene,
    w: u32,
    h: u32,
    photo_gloss: f64,
    model_gloss: f64,
) -> Result<[f64; 2]> {
    let water = harbour_expectation(scene, w, h)
        .ok_or_else(|| Error::NothingFound("the camera sees no water".into()))?;
    let pixels = streak_footprints(scene, &water, w, h)?;
    let mesh = mesh_slope_variances(scene, &water, &pixels, w, h)?;
    let micro = |gloss: f64| GaussianSlopes::from_gloss(gloss as f32).variance[0] as f64;
    Ok(mesh.map(|v| v + micro(photo_gloss) - micro(model_gloss)))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A footprint is the kept pixels at or above the share of the kept pixels' peak: a
    /// brighter pixel left out sets no peak.
    #[test]
    fn a_footprint_is_the_kept_pixels_above_a_share_of_their_peak() {
        let image: Vec<[f32; 3]> = [0.0, 1.0, 0.5, 0.019, 0.02, 9.0]
            .iter()
            .map(|&v| [v, 0.0, 0.0])
            .collect();
        let kept = footprint(&image, |i| i < 5, |p| p[0], 0.02);
        assert_eq!(kept, [1, 2, 4]);
        assert!(footprint(&image, |_| false, |p| p[0], 0.02).is_empty());
    }
}
