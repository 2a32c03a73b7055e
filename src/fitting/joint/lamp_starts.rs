//! One lamp, one light: starts for lamps the photo shows whose reflections share a streak.
//!
//! Two lamps one above the other on a wall (an orange one under a blue one, 1.5 m apart)
//! reflect into one streak when the ripples stretch each reflection over the other's, and
//! the paper's estimate starts one light per streak. The joint fit can split a light in two
//! (`split`), but with the lamps in the photo their direct pixels hold the light on one of
//! them: the dark wall between the lamps refuses a light across both, and a cut of one lamp's
//! image in half is refused as well. The fit then gave one light for the two lamps, its
//! radiance a mix of both colours.
//!
//! The photo says where each lamp is: a bright direct image on the light's wall
//! ([`super::direct_images`]), enclosed by pixels that see the wall (a whole lamp, not one cut
//! by the frame or by something in front of it). So, after [`super::direct_start`]:
//!
//! - a start over exactly two such images, each at least [`MIN_LAMP_SHARE`] of the box
//!   around both, becomes two starts, one on each image, sharing its streaks (a lit sign's
//!   letters, many small images, are left to one light);
//! - an image near a light (or near the starts of its streaks, before they were trimmed to
//!   a lamp's image) that no start overlaps starts a light of its own, sharing the light's
//!   streaks, when it is the lamp of a reflection in them: its mirror image in the
//!   water (mirrored in the horizontal plane of the water where the camera sees the streaks)
//!   projects inside the streaks' bounding box in the image.
//!
//! A light whose start lies on a lamp's image that another light starts on (a fragment of the
//! streak the paper's estimate started as its own light) is then merged into that light.
//! The joint fit shares the streaks' pixels between the lights, each pinned by its own direct
//! image.

use glam::Vec3;

use super::direct_images::{images_in, DirectImage};
use super::direct_start::{direct_starts, overlap};
use crate::fitting::light_plane::LightPlane;
use crate::fitting::observation::StreakObservation;
use crate::fitting::rect::Rect;
use crate::fitting::FittedLight;
use crate::photo_in::Photo;
use crate::progress::Reporter;
use crate::scene_in::Scene;

/// The smallest share of the box around two lamps' images that each must make for a start
/// over both to become two: two stacked lamps make a third to a half each, a sign's letters
/// far less.
const MIN_LAMP_SHARE: f32 = 0.2;

/// Most streak pixels whose camera rays find the water's height (evenly spread over the
/// streaks).
const HEIGHT_PROBES: usize = 32;

/// How far outside the streaks' bounding box a mirror image may project, as a share of the
/// photo's larger side: the ripples spread a reflection around its mirror image.
const BOX_MARGIN: f32 = 0.02;

/// A light overlapping a lamp's image by at least this (intersection over union) starts on
/// that lamp.
const ON_IMAGE: f32 = 0.5;

/// The start lights a joint fit with the direct view takes for `start`: moved onto their
/// lamps' direct images and merged where they meet (`direct_start`), then split and added to
/// one per lamp (this module's doc); `progress` hears of each change. A search
/// whose fits all start alike places them once and gives them with
/// [`JointOptions::starts_placed`](super::JointOptions::starts_placed).
pub fn place_starts(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    start: &[FittedLight],
    progress: Reporter<'_>,
) -> Vec<FittedLight> {
    let on_images = direct_starts(scene, photo, water, start);
    if on_images.len() < start.len() {
        progress.stage(&format!(
            "joint fit: {} of {} start light(s) merged into another whose lamp's direct image \
             they lay on",
            start.len() - on_images.len(),
            start.len()
        ));
    }
    let before = on_images.len();
    let placed = one_light_per_lamp(scene, photo, water, streaks, on_images, start);
    if placed.len() > before {
        progress.stage(&format!(
            "joint fit: {} lamp(s) in the photo whose reflections share another light's streak \
             start a light of their own",
            placed.len() - before
        ));
    }
    placed
}

/// The lights of `lights` split and added to one per lamp (module doc). `starts` are the
/// lights `lights` were placed from ([`direct_starts`]): each light looks for lamps around
/// the starts of its streaks as well as around itself, since a start trimmed to one lamp's
/// image no longer reaches a lamp above or below it whose reflection shares its streak.
pub(crate) fn one_light_per_lamp(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    lights: Vec<FittedLight>,
    starts: &[FittedLight],
) -> Vec<FittedLight> {
    let near: Vec<Vec<DirectImage>> = lights
        .iter()
        .map(|light| {
            let start = starts
                .iter()
                .filter(|s| {
                    s.plane.same_plane(&light.plane)
                        && s.streak_ids.iter().any(|id| light.streak_ids.contains(id))
                })
                .fold(light.rect(), |r, s| r.union(&in_frame(s, &light.plane)));
            let search = start.grow(start.width().max(start.height()));
            images_in(scene, photo, water, &light.plane, search)
                .into_iter()
                .filter(|im| im.enclosed)
                .collect()
        })
        .collect();
    let mut out = Vec::with_capacity(lights.len());
    for (light, images) in lights.iter().zip(&near) {
        match two_lamps(&light.rect(), images) {
            Some([a, b]) => out.extend([on_image(light, a), on_image(light, b)]),
            None => out.push(light.clone()),
        }
    }
    for (light, images) in lights.iter().zip(&near) {
        let pixels: Vec<u32> = streaks
            .iter()
            .filter(|s| light.streak_ids.contains(&s.id))
            .flat_map(|s| s.pixels.iter().copied())
            .collect();
        let Some(height) = water_height(scene, photo, &pixels) else {
            continue;
        };
        for image in images {
            let taken = out.iter().any(|l| {
                l.plane.same_plane(&light.plane) && in_frame(l, &light.plane).overlaps(&image.rect)
            });
            let centre = image.rect.center();
            let lamp = light.plane.point_at(centre.x, centre.y);
            if !taken && mirror_in_box(scene, photo, &pixels, lamp, height) {
                out.push(on_image(light, image));
            }
        }
    }
    let images = lights
        .iter()
        .zip(&near)
        .flat_map(|(l, ims)| ims.iter().map(move |im| (&l.plane, im)));
    merge_fragments(out, images)
}

/// `light`'s rectangle in the frame of `plane`, a plane it lies on: lights of one wall found
/// from different streaks have the same axes but their own origins.
fn in_frame(light: &FittedLight, plane: &LightPlane) -> Rect {
    let shift = plane.coords(light.plane.point);
    let r = light.rect();
    Rect {
        u_min: r.u_min + shift.x,
        u_max: r.u_max + shift.x,
        v_min: r.v_min + shift.y,
        v_max: r.v_max + shift.y,
    }
}

/// `lights` with every light whose centre lies on a lamp's image that another light starts on
/// (overlaps by at least [`ON_IMAGE`]) merged into that light: a fragment of the streak the
/// paper's estimate started as a light of its own, on a lamp now taken. Of two lights on one
/// image, the first stays.
fn merge_fragments<'a>(
    mut lights: Vec<FittedLight>,
    images: impl Iterator<Item = (&'a LightPlane, &'a DirectImage)>,
) -> Vec<FittedLight> {
    let images: Vec<(&LightPlane, &DirectImage)> = images.collect();
    let on = |l: &FittedLight, plane: &LightPlane, im: &DirectImage| {
        l.plane.same_plane(plane) && overlap(&in_frame(l, plane), &im.rect) >= ON_IMAGE
    };
    let mut k = 0;
    while k < lights.len() {
        let host = images
            .iter()
            .filter(|(plane, im)| {
                lights[k].plane.same_plane(plane)
                    && im.rect.contains(in_frame(&lights[k], plane).center())
            })
            .find_map(|&(plane, im)| {
                let k_on = on(&lights[k], plane, im);
                (0..lights.len()).find(|&j| j != k && (!k_on || j < k) && on(&lights[j], plane, im))
            });
        match host {
            Some(j) => {
                let ids = lights[k].streak_ids.clone();
                lights[j].streak_ids.extend(ids);
                lights[j].streak_ids.sort_unstable();
                lights[j].streak_ids.dedup();
                lights.remove(k);
            }
            None => k += 1,
        }
    }
    lights
}

/// The two images under `start` when it lies over exactly two that each make at least
/// [`MIN_LAMP_SHARE`] of the box around both (module doc).
fn two_lamps<'a>(start: &Rect, images: &'a [DirectImage]) -> Option<[&'a DirectImage; 2]> {
    let under: Vec<&DirectImage> = images
        .iter()
        .filter(|im| start.overlaps(&im.rect))
        .collect();
    let [a, b] = under[..] else {
        return None;
    };
    let around = a.rect.union(&b.rect);
    let area = |r: &Rect| r.width() * r.height();
    let big = |im: &DirectImage| area(&im.rect) >= MIN_LAMP_SHARE * area(&around);
    (big(a) && big(b) && !a.rect.overlaps(&b.rect)).then_some([a, b])
}

/// `light` started on `image`'s rectangle.
fn on_image(light: &FittedLight, image: &DirectImage) -> FittedLight {
    let mut out = light.clone();
    out.u_min = image.rect.u_min;
    out.u_max = image.rect.u_max;
    out.v_min = image.rect.v_min;
    out.v_max = image.rect.v_max;
    out
}

/// The median height (world y) where the camera rays through up to [`HEIGHT_PROBES`] of
/// `pixels` meet the water first, or `None` when none does.
fn water_height(scene: &Scene, photo: &Photo, pixels: &[u32]) -> Option<f32> {
    let step = pixels.len().div_ceil(HEIGHT_PROBES).max(1);
    let origin = scene.camera.position;
    let mut heights: Vec<f32> = pixels
        .iter()
        .step_by(step)
        .filter_map(|&p| {
            let (x, y) = (p % photo.width, p / photo.width);
            let dir =
                scene
                    .camera
                    .direction(x as f32 + 0.5, y as f32 + 0.5, photo.width, photo.height);
            let hit = scene.tracer.closest_hit(origin, dir, 0.0, f32::INFINITY)?;
            let on_water = scene.is_water.get(hit.triangle as usize) == Some(&true);
            on_water.then_some((origin + dir * hit.t).y)
        })
        .collect();
    if heights.is_empty() {
        return None;
    }
    heights.sort_by(f32::total_cmp);
    Some(heights[heights.len() / 2])
}

/// Whether `lamp`'s mirror image in the horizontal plane at `height` projects inside the
/// bounding box of `pixels`, grown by [`BOX_MARGIN`].
fn mirror_in_box(scene: &Scene, photo: &Photo, pixels: &[u32], lamp: Vec3, height: f32) -> bool {
    let mirrored = Vec3::new(lamp.x, 2.0 * height - lamp.y, lamp.z);
    let Some((x, y)) = scene.camera.project(mirrored, photo.width, photo.height) else {
        return false;
    };
    let margin = BOX_MARGIN * photo.width.max(photo.height) as f32;
    let (mut x0, mut y0, mut x1, mut y1) = (u32::MAX, u32::MAX, 0, 0);
    for &p in pixels {
        let (px, py) = (p % photo.width, p / photo.width);
        x0 = x0.min(px);
        x1 = x1.max(px);
        y0 = y0.min(py);
        y1 = y1.max(py);
    }
    !pixels.is_empty()
        && x >= x0 as f32 - margin
        && x <= x1 as f32 + 1.0 + margin
        && y >= y0 as f32 - margin
        && y <= y1 as f32 + 1.0 + margin
}

#[cfg(test)]
mod tests {
    use super::*;

    use crate::fitting::joint::fixture::rect;

    fn image(r: Rect) -> DirectImage {
        DirectImage {
            first_pixel: 0,
            rect: r,
            enclosed: true,
            cut: [false; 4],
            reach: r,
            footprint: 0.01,
        }
    }

    /// The wall z = 0 facing +z, its frame's origin at `origin` on it.
    fn wall(origin: Vec3) -> LightPlane {
        LightPlane::with_frame((0, 0, 0), origin, Vec3::Z, Vec3::X, 1.0).expect("a plane")
    }

    use crate::fitting::joint::fixture::start_light as light;

    /// Two lamps 3 x 1.5 m with 1.5 m between them, each a third of the box around both,
    /// under one start: two. A third lamp under it, or one of the two a tenth of the box (a
    /// sign's letter beside a lamp), or one image alone: not two.
    #[test]
    fn a_start_over_exactly_two_large_images_is_two_lamps() {
        let start = rect(0.0, 3.0, 0.0, 4.5);
        let (lower, upper) = (rect(0.0, 3.0, 0.0, 1.5), rect(0.0, 3.0, 3.0, 4.5));
        let images = [image(lower), image(upper)];
        let got = two_lamps(&start, &images).expect("two lamps");
        assert_eq!([got[0].rect, got[1].rect], [lower, upper]);
        let three = [image(lower), image(upper), image(rect(4.0, 5.0, 0.0, 1.0))];
        let wide = rect(0.0, 6.0, 0.0, 4.5);
        assert!(two_lamps(&wide, &three).is_none());
        let letter = [image(lower), image(rect(0.0, 0.3, 3.0, 4.5))];
        assert!(two_lamps(&start, &letter).is_none());
        assert!(two_lamps(&start, &[image(lower)]).is_none());
        // Not under the start: not counted.
        assert!(two_lamps(&rect(0.0, 3.0, 0.0, 1.0), &images).is_none());
    }

    /// A rectangle in one light's frame moves into another frame of the same wall by the
    /// offset between the frames' origins.
    #[test]
    fn a_rectangle_moves_between_frames_of_one_wall() {
        let (a, b) = (wall(Vec3::ZERO), wall(Vec3::new(2.0, -1.0, 0.0)));
        let l = light(&b, rect(0.0, 1.0, 0.0, 1.0), 0);
        assert_eq!(in_frame(&l, &a), rect(2.0, 3.0, -1.0, 0.0));
        assert_eq!(in_frame(&l, &b), l.rect());
    }

    /// A fragment's light whose centre lies on a lamp's image that another light starts on
    /// merges into that light, its streak joining, even where the two lights' frames have
    /// other origins; of two lights on one image the first stays; a light on no image, or on
    /// an image no other light is on, stays.
    #[test]
    fn fragments_on_a_taken_lamp_merge_into_its_light() {
        let (a, b) = (wall(Vec3::ZERO), wall(Vec3::new(2.0, 0.0, 0.0)));
        let lamp = image(rect(0.0, 3.0, 0.0, 1.5));
        let on_lamp = light(&a, rect(0.0, 3.0, 0.0, 1.5), 0);
        // In b's frame: u from -2 (a's 0). Centre (0.5 - 2 + 2, ...) = a's (0.5, 0.75).
        let fragment = light(&b, rect(-2.0, -1.0, 0.7, 0.8), 1);
        let elsewhere = light(&a, rect(5.0, 6.0, 0.0, 1.0), 2);
        let twin = light(&b, rect(-2.0, 1.0, 0.0, 1.5), 3);
        let out = merge_fragments(
            vec![on_lamp, fragment, elsewhere, twin],
            [(&a, &lamp)].into_iter(),
        );
        assert_eq!(out.len(), 2);
        assert_eq!(out[0].streak_ids, vec![0, 1, 3]);
        assert_eq!(out[1].streak_ids, vec![2]);
        let alone = light(&a, rect(0.5, 1.0, 0.5, 1.0), 4);
        let out = merge_fragments(vec![alone], [(&a, &lamp)].into_iter());
        assert_eq!(out.len(), 1, "no other light is on the lamp");
    }
}
