//! The joint fit's region (method §5, last paragraph): which pixels of the photo are fitted,
//! and where on its plane each light's edges may go.
//!
//! The fitted region is the streaks, dilated, plus every pixel near them whose reflected rays
//! can reach a light's region of interest: a streak's faint ends fall below any
//! segmentation's threshold, and an edge seen only through them would otherwise drift.

use std::sync::OnceLock;

use glam::Vec2;
use rayon::prelude::*;

use super::descent::first_window;
use super::direct::direct_pixels;
use super::options::{PixelShare, THIN_MIN_WATER_PIXELS};
use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::fitting::{FittedLight, StreakObservation};
use crate::optics::ReflectionModel;
use crate::photo_in::Photo;
use crate::scene_in::Scene;
use crate::water_model::WaterModel;

/// The pixels of the fitted region, water only: the lights' streaks dilated by `margin`, and
/// every other pixel near them from which the reflected rays can reach a light's region of
/// interest. The second part matters as much as the first: a streak's faint ends fall below
/// any segmentation's threshold, and a pixel the fit does not look at cannot object to a
/// light that grew into it (an edge seen only through such ends then drifts by percents).
#[allow(clippy::too_many_arguments)]
pub(super) fn region(
    water_model: &dyn WaterModel,
    scene: &Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    photo: &Photo,
    water: &[bool],
    streaks: &[&StreakObservation],
    margin: u32,
    share: PixelShare,
) -> Vec<u32> {
    let (w, h) = (photo.width as i64, photo.height as i64);
    let m = margin as i64;
    let mut seeds = vec![false; (w * h) as usize];
    // Per streak, its bounding box grown by a quarter of its size: where its faint ends lie.
    let mut boxes = Vec::new();
    for s in streaks {
        let (mut x0, mut y0, mut x1, mut y1) = (w, h, -1i64, -1i64);
        for &p in &s.pixels {
            let (x, y) = (p as i64 % w, p as i64 / w);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            if let Some(seed) = seeds.get_mut(p as usize) {
                *seed = true;
            }
        }
        if x1 >= x0 {
            let (dx, dy) = (m + (x1 - x0) / 4, m + (y1 - y0) / 4);
            boxes.push((
                (x0 - dx).max(0),
                (y0 - dy).max(0),
                (x1 + dx).min(w - 1),
                (y1 + dy).min(h - 1),
            ));
        }
    }
    // The streaks' pixels dilated by `margin` on every side.
    let mark = dilated(&seeds, w as usize, margin as usize);
    let keep = |i: usize| water[i] && share.reads((i as i64 % w) as u32, (i as i64 / w) as u32);
    let mut pixels = marked(&mark, w as usize, &keep);
    let mut candidate = vec![false; (w * h) as usize];
    candidate
        .par_chunks_mut(w as usize)
        .enumerate()
        .for_each(|(y, row)| {
            for &(x0, y0, x1, y1) in &boxes {
                if (y0..=y1).contains(&(y as i64)) {
                    row[x0 as usize..=x1 as usize].fill(true);
                }
            }
        });
    for (c, &marked) in candidate.iter_mut().zip(&mark) {
        *c &= !marked;
    }
    {
        let candidates = marked(&candidate, w as usize, &keep);
        let seen: Vec<u32> = candidates
            .into_par_iter()
            .with_max_len(crate::fitting::PIXELS_PER_TASK)
            .filter(|&i| sees_region_of_interest(water_model, scene, model, planes, roi, i, photo))
            .collect();
        pixels.extend(seen);
        pixels.sort_unstable();
    }
    pixels
}

/// `marks` (an image `width` pixels wide, row-major) dilated by `margin` pixels on every side:
/// a pixel is marked when one within `margin` of it along both axes is (the square around each
/// mark, cut at the image's borders). Row by row, first along the row and then across the
/// rows, on every core: a 12-megapixel photo's streaks hold hundreds of thousands of pixels,
/// and marking each one's square took a tenth of a second a fit.
fn dilated(marks: &[bool], width: usize, margin: usize) -> Vec<bool> {
    if width == 0 {
        return Vec::new();
    }
    let height = marks.len() / width;
    let mut along = vec![false; marks.len()];
    along
        .par_chunks_mut(width)
        .zip(marks.par_chunks(width))
        .for_each(|(out, row)| {
            // The distance back to the last mark, carried along the row both ways.
            let mut since = usize::MAX;
            for x in 0..width {
                since = if row[x] { 0 } else { since.saturating_add(1) };
                out[x] = since <= margin;
            }
            since = usize::MAX;
            for x in (0..width).rev() {
                since = if row[x] { 0 } else { since.saturating_add(1) };
                out[x] |= since <= margin;
            }
        });
    let mut out = vec![false; marks.len()];
    out.par_chunks_mut(width).enumerate().for_each(|(y, row)| {
        let rows = y.saturating_sub(margin)..(y + margin + 1).min(height);
        for source in along[rows.start * width..rows.end * width].chunks(width) {
            for (o, &a) in row.iter_mut().zip(source) {
                *o |= a;
            }
        }
    });
    out
}

/// The indices, in order, of the pixels of `marks` (an image `width` pixels wide) that are
/// marked and that `keep` keeps.
fn marked(marks: &[bool], width: usize, keep: &(dyn Fn(usize) -> bool + Sync)) -> Vec<u32> {
    marks
        .par_chunks(width.max(1))
        .enumerate()
        .flat_map_iter(|(y, row)| {
            row.iter()
                .enumerate()
                .filter(move |&(x, &m)| m && keep(y * width + x))
                .map(move |(x, _)| (y * width + x) as u32)
        })
        .collect()
}

/// Lobe directions per side tried from a pixel's centre by [`sees_region_of_interest`].
const PROBE_STRATA: u32 = 6;

/// Whether any of a few reflected rays from the pixel's centre meets a light's plane inside
/// its region of interest (a geometric test only: occlusion is left to the fit's own
/// samples).
fn sees_region_of_interest(
    water_model: &dyn WaterModel,
    scene: &Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    pixel: u32,
    photo: &Photo,
) -> bool {
    let (x, y) = (pixel % photo.width, pixel / photo.width);
    let Some(water) = water_model.water_point(
        scene,
        x as f32 + 0.5,
        y as f32 + 0.5,
        photo.width,
        photo.height,
    ) else {
        return false;
    };
    let inv = 1.0 / PROBE_STRATA as f32;
    (0..PROBE_STRATA * PROBE_STRATA).any(|j| {
        let u = Vec2::new(
            ((j % PROBE_STRATA) as f32 + 0.5) * inv,
            ((j / PROBE_STRATA) as f32 + 0.5) * inv,
        );
        water_model
            .reflect_direction(&water, model, u)
            .is_some_and(|wi| {
                planes.iter().zip(roi).any(|(plane, r)| {
                    plane
                        .hit(water.start, wi)
                        .is_some_and(|(_, q)| r.contains(q))
                })
            })
    })
}

/// What a joint fit's pixels are made from, besides the scene and the photo: the probe's
/// water model and reflection model, the lights' planes and regions of interest, the streaks
/// they start from, the margin, the share of the water pixels asked for and the one a fit
/// whose every lamp pins its light reads ([`super::JointOptions::share_for`]), and whether
/// the pixels that see the walls directly are read.
pub(super) struct RegionAsk<'a> {
    pub(super) water_model: &'a dyn WaterModel,
    pub(super) model: &'a ReflectionModel,
    pub(super) planes: &'a [&'a LightPlane],
    pub(super) roi: &'a [Rect],
    pub(super) streaks: &'a [&'a StreakObservation],
    pub(super) margin: u32,
    pub(super) shares: (PixelShare, PixelShare),
    pub(super) direct_view: bool,
}

/// A [`RegionAsk`] to compare: a search's fits over one start ask alike, so the first one's
/// pixels serve the rest ([`KeptRegion`], held by [`super::proposal::ProposalCache`]):
/// probing the region and listing the pixels that see the walls took 12-20 ms a fit over
/// the harbour pair, eight to ten fits a slope search.
#[derive(Debug, PartialEq)]
pub(super) struct RegionKey {
    /// The probe's water model and reflection model as their debug text: every field, each
    /// number to its last digit.
    models: String,
    planes: Vec<LightPlane>,
    roi: Vec<Rect>,
    streaks: Vec<usize>,
    margin: u32,
    shares: (PixelShare, PixelShare),
    direct_view: bool,
}

impl RegionKey {
    fn of(ask: &RegionAsk<'_>) -> Self {
        RegionKey {
            models: format!("{:?} {:?}", ask.water_model, ask.model),
            planes: ask.planes.iter().map(|p| (*p).clone()).collect(),
            roi: ask.roi.to_vec(),
            streaks: ask.streaks.iter().map(|s| s.id).collect(),
            margin: ask.margin,
            shares: ask.shares,
            direct_view: ask.direct_view,
        }
    }
}

/// A fit's pixels as [`fit_pixels`] made them, with what they were made from.
pub(super) struct KeptRegion {
    key: RegionKey,
    pixels: Vec<u32>,
    first_direct: usize,
    share: PixelShare,
}

/// The pixels a joint fit reads: the water pixels of its region ([`region`]), then, when
/// the direct view is read, those that see a light's wall directly ([`direct_pixels`]),
/// with the index of the first of those and the share of the water they read. Where every
/// lamp pins its light and the water is plenty, one water pixel of each 2 x 2 block
/// (`JointOptions::thin_seen_whole`): its region is the checkerboard's region's pixels it
/// reads, so it is probed alone first. A search's later fit takes them from `kept`, where its
/// first fit left them, when it asks alike.
pub(super) fn fit_pixels(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    ask: &RegionAsk<'_>,
    kept: Option<&OnceLock<KeptRegion>>,
) -> (Vec<u32>, usize, PixelShare) {
    let key = RegionKey::of(ask);
    if let Some(k) = kept.and_then(OnceLock::get).filter(|k| k.key == key) {
        return (k.pixels.clone(), k.first_direct, k.share);
    }
    let read = |share| {
        region(
            ask.water_model,
            scene,
            ask.model,
            ask.planes,
            ask.roi,
            photo,
            water,
            ask.streaks,
            ask.margin,
            share,
        )
    };
    let (asked, thinned) = ask.shares;
    let (mut pixels, share) = match (thinned != asked).then(|| read(thinned)) {
        Some(kept) if kept.len() >= THIN_MIN_WATER_PIXELS => (kept, thinned),
        _ => (read(asked), asked),
    };
    let first_direct = pixels.len();
    if ask.direct_view {
        pixels.extend(direct_pixels(
            scene,
            ask.planes,
            ask.roi,
            photo.width,
            photo.height,
            water,
            share,
        ));
    }
    if let Some(kept) = kept {
        let _ = kept.set(KeptRegion {
            key,
            pixels: pixels.clone(),
            first_direct,
            share,
        });
    }
    (pixels, first_direct, share)
}

/// Where on its plane a light's edges may go during the fit: samples landing outside it are
/// never traced.
///
/// By default the region is the start rectangle grown by the first search window and a
/// little more: a start from the reflections alone may be off by half its size. A light
/// whose start lies on a direct image the photo shows whole (`image`: that image's rectangle
/// and a pixel's footprint there, [`super::direct_start::enclosing_image`]) ends within about
/// a footprint of the image's edges, so its region is the start and the image grown by a
/// margin of [`IMAGE_MARGIN_SHARE`] of the image's larger side, at least
/// [`IMAGE_MARGIN_FOOTPRINTS`] footprints.
pub(super) fn region_of_interest(start: &FittedLight, image: Option<(Rect, f32)>) -> Rect {
    let rect = start.rect();
    let default = rect.grow(1.25 * first_window(&rect, start.plane.camera_distance()));
    let Some((image, footprint)) = image else {
        return default;
    };
    let margin = (IMAGE_MARGIN_SHARE * image.width().max(image.height()))
        .max(IMAGE_MARGIN_FOOTPRINTS * footprint);
    let close = rect.union(&image).grow(margin);
    // Never wider than the default.
    if close.width() * close.height() < default.width() * default.height() {
        close
    } else {
        default
    }
}

/// The margin of a region of interest around a light's whole direct image, as a share of the
/// image's larger side (15 cm on Table 1's 3 m light): a few footprints beyond where the
/// image lets the light end (at 10 m a footprint is 1.2 cm; at the harbour's 40 m, 7.4 cm,
/// where the floor of [`IMAGE_MARGIN_FOOTPRINTS`] sets the margin).
const IMAGE_MARGIN_SHARE: f32 = 0.05;

/// The least margin of a region of interest around a light's whole direct image, in pixel
/// footprints.
const IMAGE_MARGIN_FOOTPRINTS: f32 = 4.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fitting::joint::fixture::{rect, start_light};
    use crate::fitting::light_plane::LightPlane;
    use glam::Vec3;

    fn assert_close(got: Rect, want: Rect) {
        let d = [
            got.u_min - want.u_min,
            got.u_max - want.u_max,
            got.v_min - want.v_min,
            got.v_max - want.v_max,
        ];
        assert!(d.iter().all(|d| d.abs() < 1e-5), "{got:?} against {want:?}");
    }

    /// A 3 x 2 m start 10 m from the camera. With no whole image its edges may move by 1.25
    /// times half its larger side (1.875 m); on a whole image of 3.1 x 2.1 m seen with 1 cm
    /// footprints, by 5 % of the image's 3.1 m (0.155 m) around the start and the image
    /// together; with 10 cm footprints, by 4 of them (0.4 m). A footprint so coarse that the
    /// region would pass the default gives the default.
    #[test]
    fn a_light_on_its_whole_image_searches_close_around_it() {
        let plane =
            LightPlane::with_frame((0, 0, 0), Vec3::new(0.0, 0.0, -10.0), Vec3::Z, Vec3::X, 1.0)
                .expect("a plane");
        let start = rect(0.0, 3.0, 0.0, 2.0);
        let light = start_light(&plane, start, 0);
        assert_close(region_of_interest(&light, None), start.grow(1.875));
        let image = rect(-0.05, 3.05, 0.1, 2.2);
        let union = rect(-0.05, 3.05, 0.0, 2.2);
        assert_close(
            region_of_interest(&light, Some((image, 0.01))),
            union.grow(0.155),
        );
        assert_close(
            region_of_interest(&light, Some((image, 0.1))),
            union.grow(0.4),
        );
        assert_close(
            region_of_interest(&light, Some((image, 0.5))),
            start.grow(1.875),
        );
    }

    /// A search's later fit reads its first fit's pixels only where everything they were made
    /// from is the same: the probe's water model to its last digit (a statistical surface of
    /// other slope variances, or the exact model), its gloss, the planes, the regions of
    /// interest, the margin and the shares.
    #[test]
    fn a_kept_region_serves_only_a_fit_made_alike() {
        use crate::fitting::slopes::water_with_total;
        use crate::water_model::{ExactSurface, MeanSurface};
        let plane =
            LightPlane::with_frame((0, 0, 0), Vec3::new(0.0, 0.0, -10.0), Vec3::Z, Vec3::X, 1.0)
                .expect("a plane");
        let surface = MeanSurface::new(Vec3::new(0.0, -1.0, 0.0), Vec3::Y, Vec3::Z, Vec3::Y);
        let broad = water_with_total(surface, [4e-3, 3e-3]);
        let model = ReflectionModel::new(500.0, 1.33);
        let roi = [rect(0.0, 3.0, 0.0, 2.0)];
        let shares = (PixelShare::Checkerboard, PixelShare::Quarter);
        let key = |water_model: &dyn WaterModel, model: &ReflectionModel, roi: &[Rect], margin| {
            RegionKey::of(&RegionAsk {
                water_model,
                model,
                planes: &[&plane],
                roi,
                streaks: &[],
                margin,
                shares,
                direct_view: true,
            })
        };
        let first = key(&broad, &model, &roi, 6);
        assert_eq!(first, key(&broad, &model, &roi, 6));
        let narrower = water_with_total(surface, [4e-3, 2.9999e-3]);
        assert_ne!(first, key(&narrower, &model, &roi, 6));
        assert_ne!(first, key(&ExactSurface, &model, &roi, 6));
        let glossier = ReflectionModel {
            gloss: 501.0,
            ..model
        };
        assert_ne!(first, key(&broad, &glossier, &roi, 6));
        assert_ne!(first, key(&broad, &model, &[rect(0.0, 3.0, 0.0, 2.001)], 6));
        assert_ne!(first, key(&broad, &model, &roi, 7));
    }

    /// The separable dilation marks what marking each mark's square did: random marks on an
    /// odd-sized image, near its borders too, at margins 0 to 7.
    #[test]
    fn dilating_row_by_row_marks_each_marks_square() {
        let (w, h) = (37usize, 23usize);
        let mut rng = crate::random::Rng::new(3, 5);
        let marks: Vec<bool> = (0..w * h).map(|_| rng.next_f32() < 0.02).collect();
        assert!(marks.iter().filter(|&&m| m).count() > 5);
        for margin in 0..8usize {
            let mut brute = vec![false; w * h];
            for (i, _) in marks.iter().enumerate().filter(|(_, &m)| m) {
                let (x, y) = (i % w, i / w);
                for yy in y.saturating_sub(margin)..=(y + margin).min(h - 1) {
                    for xx in x.saturating_sub(margin)..=(x + margin).min(w - 1) {
                        brute[yy * w + xx] = true;
                    }
                }
            }
            assert_eq!(dilated(&marks, w, margin), brute, "margin {margin}");
        }
        let keep = |i: usize| !i.is_multiple_of(3);
        let want: Vec<u32> = (0..w * h)
            .filter(|&i| marks[i] && keep(i))
            .map(|i| i as u32)
            .collect();
        assert_eq!(marked(&marks, w, &keep), want);
    }
}
