//! Where the direct view puts a light before the joint fit starts.
//!
//! The joint fit refines its start locally: each edge moves within windows around where it
//! starts, and a light whose start is far from the truth stays far. The paper's per-streak
//! estimate can start a light badly where the reflections alone cannot tell its shape (a
//! streak over waves the scene does not hold gave one light 14 m x 1 cm for a 4 m x 2 m
//! light), and a streak broken into fragments can give a second light for the same lamp.
//! When the lamp itself is in the photo its direct image says where it is to a pixel, so:
//!
//! - a light whose start overlaps the direct image near it by less than
//!   [`REPLACE_OVERLAP`] (intersection over union) starts at that image's rectangle instead;
//! - a light so moved onto the direct image another light already starts on is merged into
//!   that light (its streaks join the other's): one lamp, one light.
//!
//! A start that already overlaps its direct image well is left alone, so that two lights
//! whose direct images touch (stacked lamps) keep the starts the reflections gave them. A
//! start with no direct image near it is cut back to the wall the photo does not show dark
//! ([`super::dark_wall`]).
//!
//! The direct image near a light: the pixels outside the water whose camera ray (through the
//! pixel's centre) meets the light's plane first, within the start rectangle grown by its own
//! larger side on every side, and that are bright (clipped in some channel, or at least half
//! the brightest such pixel's largest channel); of their 8-connected groups in the image,
//! the one whose centre on the plane is nearest the start's centre. Where that rectangle cuts
//! the group (a small start under a large lamp), it grows to hold the group, so that a
//! fragment's start finds the lamp's whole image, the one a start on the lamp finds.

use super::dark_wall::trimmed_to_unseen_wall;
use super::direct_images::{images_in, DirectImage};
use crate::fitting::rect::Rect;
use crate::fitting::FittedLight;
use crate::photo_in::Photo;
use crate::scene_in::Scene;

/// A start overlapping its direct image by less than this (intersection over union) is
/// moved onto it. Two stacked lamps' starts overlap their joint image by about a half.
pub const REPLACE_OVERLAP: f32 = 0.25;

/// The starts moved onto their direct images and merged where they meet (module doc).
pub(crate) fn direct_starts(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    start: &[FittedLight],
) -> Vec<FittedLight> {
    let mut out: Vec<FittedLight> = Vec::with_capacity(start.len());
    // For each light of `out`, the direct image it starts on, if any.
    let mut on_image: Vec<Option<usize>> = Vec::with_capacity(start.len());
    for light in start {
        let image = direct_image(scene, photo, water, light);
        let moved = image
            .as_ref()
            .filter(|im| overlap(&light.rect(), &im.rect) < REPLACE_OVERLAP);
        let Some(im) = moved else {
            let no_image = image.is_none();
            let kept = image.filter(|im| overlap(&light.rect(), &im.rect) >= REPLACE_OVERLAP);
            on_image.push(kept.as_ref().map(|im| im.first_pixel));
            out.push(match kept {
                Some(im) if im.enclosed => trimmed(light, &im.reach),
                None if no_image => trimmed_to_unseen_wall(scene, photo, water, light),
                _ => light.clone(),
            });
            continue;
        };
        let same_image = on_image.iter().position(|&o| o == Some(im.first_pixel));
        match same_image {
            Some(k) if out[k].plane.same_plane(&light.plane) => {
                out[k].streak_ids.extend(light.streak_ids.iter().copied());
            }
            _ => {
                // Onto the image, but where the image is cut (by the frame, the water or
                // something in front) the light may go on beyond it: there the start keeps
                // its own extent if it reaches further.
                let mut moved = light.clone();
                let [left, right, bottom, top] = im.cut;
                let edge = |cut: bool, own: f32, image: f32, further: fn(f32, f32) -> f32| {
                    if cut {
                        further(own, image)
                    } else {
                        image
                    }
                };
                moved.u_min = edge(left, light.u_min, im.rect.u_min, f32::min);
                moved.u_max = edge(right, light.u_max, im.rect.u_max, f32::max);
                moved.v_min = edge(bottom, light.v_min, im.rect.v_min, f32::min);
                moved.v_max = edge(top, light.v_max, im.rect.v_max, f32::max);
                on_image.push(Some(im.first_pixel));
                out.push(moved);
            }
        }
    }
    // A light that kept its start, found later to share its image with a moved one: the
    // moved one was pushed as its own light above only when it came first. Merge those too.
    let mut k = 0;
    while k < out.len() {
        let twin = (0..k).find(|&j| {
            on_image[j].is_some()
                && on_image[j] == on_image[k]
                && out[j].plane.same_plane(&out[k].plane)
        });
        if let Some(j) = twin {
            let ids = out[k].streak_ids.clone();
            out[j].streak_ids.extend(ids);
            out.remove(k);
            on_image.remove(k);
        } else {
            k += 1;
        }
    }
    for light in &mut out {
        light.streak_ids.sort_unstable();
        light.streak_ids.dedup();
    }
    out
}

/// `light` with every edge that reaches beyond its enclosed direct image `image` brought back
/// to the image's edge: the reflections alone can stretch a start along a lobe far larger than
/// the light (a grazing camera over glossy water gave a 3 m light a 10.96 m start, which the
/// joint fit's local steps did not undo), while the dark pixels around the image say the
/// light ends there. Two lamps sharing one image (stacked) keep their own starts inside it.
fn trimmed(light: &FittedLight, image: &Rect) -> FittedLight {
    let mut out = light.clone();
    out.u_min = light.u_min.max(image.u_min);
    out.u_max = light.u_max.min(image.u_max);
    out.v_min = light.v_min.max(image.v_min);
    out.v_max = light.v_max.min(image.v_max);
    out
}

/// Intersection over union of two rectangles (0 when either is empty).
pub(super) fn overlap(a: &Rect, b: &Rect) -> f32 {
    let w = (a.u_max.min(b.u_max) - a.u_min.max(b.u_min)).max(0.0);
    let h = (a.v_max.min(b.v_max) - a.v_min.max(b.v_min)).max(0.0);
    let inter = w * h;
    let union = a.width() * a.height() + b.width() * b.height() - inter;
    if union > 0.0 {
        inter / union
    } else {
        0.0
    }
}

/// Where `light`'s lamp ends, when its start lies on a direct image the photo shows whole
/// (every pixel around it sees the wall: not cut by the frame, the water or anything in
/// front): the rectangle of every image the start overlaps, and a pixel's footprint there.
/// The light then ends within about a footprint of that rectangle's edges.
pub(crate) fn enclosing_image(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    light: &FittedLight,
) -> Option<(Rect, f32)> {
    let im = direct_image(scene, photo, water, light)?;
    (im.enclosed && overlap(&light.rect(), &im.reach) > 0.0).then_some((im.reach, im.footprint))
}

/// The direct image near `light` (module doc), or `None` when the photo shows none.
fn direct_image(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    light: &FittedLight,
) -> Option<DirectImage> {
    let start = light.rect();
    let centre = start.center();
    // The image nearest the start, whole: where the search rectangle cuts it (a start from
    // a small fragment of a streak, under a large lamp), the rectangle grows to hold it,
    // so that the image, and its identity, do not depend on the start's size.
    let mut search = start.grow(start.width().max(start.height()));
    let mut images = images_in(scene, photo, water, &light.plane, search);
    for _ in 0..MAX_WIDENINGS {
        let Some(im) = nearest(&images, centre) else {
            break;
        };
        if !reaches(&im.rect, &search, im.footprint) {
            break;
        }
        search = search.union(&im.rect.grow(im.rect.width().max(im.rect.height())));
        images = images_in(scene, photo, water, &light.plane, search);
    }
    // What the start may be trimmed to: every image it overlaps (two stacked lamps the
    // reflections started as one light are two images), enclosed only if all of them are.
    let overlapped: Vec<&DirectImage> = images
        .iter()
        .filter(|im| overlap(&start, &im.rect) > 0.0)
        .collect();
    let reach = overlapped.iter().fold(None, |acc: Option<Rect>, im| {
        Some(acc.map_or(im.rect, |r| Rect {
            u_min: r.u_min.min(im.rect.u_min),
            u_max: r.u_max.max(im.rect.u_max),
            v_min: r.v_min.min(im.rect.v_min),
            v_max: r.v_max.max(im.rect.v_max),
        }))
    });
    let all_enclosed = overlapped.iter().all(|im| im.enclosed);
    let first = nearest(&images, centre)?.first_pixel;
    images
        .into_iter()
        .find(|im| im.first_pixel == first)
        .map(|im| DirectImage {
            enclosed: im.enclosed && all_enclosed,
            reach: reach.unwrap_or(im.rect),
            ..im
        })
}

/// The image of `images` whose centre lies nearest `centre`.
fn nearest(images: &[DirectImage], centre: glam::Vec2) -> Option<&DirectImage> {
    images.iter().min_by(|a, b| {
        let da = (a.rect.center() - centre).length();
        let db = (b.rect.center() - centre).length();
        da.total_cmp(&db)
    })
}

/// Most times [`direct_image`]'s search rectangle grows to hold the image it cuts: each
/// growth at least doubles its reach beyond the image found, and a lamp that a start's
/// rectangle grown three times over cannot hold is no fragment's.
const MAX_WIDENINGS: usize = 3;

/// Whether `image` (a direct image's rectangle, grown by half a pixel's `footprint`) reaches
/// the edge of the rectangle `search` it was looked for in: the search may have cut it.
fn reaches(image: &Rect, search: &Rect, footprint: f32) -> bool {
    image.u_min <= search.u_min + footprint
        || image.u_max >= search.u_max - footprint
        || image.v_min <= search.v_min + footprint
        || image.v_max >= search.v_max - footprint
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;
    use crate::fitting::light_plane::LightPlane;

    /// Table 1's scene and photo (one 3 m x 3 m light on the wall, in frame), the wall as a
    /// light plane, and the light's true rectangle on it (from the sample's definition).
    pub(in crate::fitting::joint) fn table1() -> (
        &'static Scene,
        &'static Photo,
        &'static [bool],
        LightPlane,
        Rect,
    ) {
        let (scene, photo, water, plane) = crate::fitting::joint::direct::tests::table1_wall();
        let rect = table1_rect(scene, &plane);
        (scene, photo, water, plane, rect)
    }

    /// Table 1's true light as a rectangle on `plane` (the wall's) of its sample scene.
    pub(in crate::fitting::joint) fn table1_rect(scene: &Scene, plane: &LightPlane) -> Rect {
        let truth = crate::samples::table1_light();
        let at = |x: f64, y: f64| {
            plane.coords((glam::DVec3::new(x, y, truth.corner.z) - scene.origin).as_vec3())
        };
        let (a, b) = (
            at(truth.corner.x, truth.corner.y),
            at(truth.corner.x + truth.width, truth.corner.y + truth.height),
        );
        Rect {
            u_min: a.x.min(b.x),
            u_max: a.x.max(b.x),
            v_min: a.y.min(b.y),
            v_max: a.y.max(b.y),
        }
    }

    /// Every edge of `got` within `footprint` (a pixel's, on the wall) of `truth`'s.
    fn assert_within(got: &Rect, truth: &Rect, footprint: f32) {
        for (name, g, t) in [
            ("left", got.u_min, truth.u_min),
            ("right", got.u_max, truth.u_max),
            ("bottom", got.v_min, truth.v_min),
            ("top", got.v_max, truth.v_max),
        ] {
            assert!(
                (g - t).abs() < footprint,
                "{name} edge {g} against {t} (a pixel is {footprint} m)"
            );
        }
    }

    use crate::fitting::joint::fixture::start_light as light;

    /// The first and last rows of the lamp's image: those of the clipped pixels off the water.
    fn image_rows(photo: &Photo, water: &[bool]) -> (usize, usize) {
        let rows: Vec<usize> = (0..photo.radiance.len())
            .filter(|&i| photo.clipped[i] && !water[i])
            .map(|i| i / photo.width as usize)
            .collect();
        let top = *rows.iter().min().expect("the image's rows");
        let bottom = *rows.iter().max().expect("the image's rows");
        (top, bottom)
    }

    /// A start 14 m wide and 1 cm tall across the light (as the reflections alone gave one)
    /// moves onto the light's direct image: every edge within a pixel's footprint on the
    /// wall (10 m away, 60 degrees over 600 pixels: 1.8 cm) of the truth. A second start
    /// far off on the same image (a fragment of the streak) is merged into it, its streak
    /// joining the first's; a start that already overlaps the image well stays as it was.
    #[test]
    fn far_starts_move_onto_the_direct_image_and_fragments_merge() {
        let (scene, photo, water, plane, truth) = table1();
        let c = truth.center();
        let thin = Rect {
            u_min: c.x - 7.0,
            u_max: c.x + 7.0,
            v_min: c.y - 0.4,
            v_max: c.y - 0.39,
        };
        let fragment = Rect {
            u_min: c.x + 0.5,
            u_max: c.x + 3.5,
            v_min: c.y + 1.0,
            v_max: c.y + 6.0,
        };
        let out = direct_starts(
            scene,
            photo,
            water,
            &[light(&plane, thin, 0), light(&plane, fragment, 1)],
        );
        assert_eq!(out.len(), 1, "the fragment merges");
        assert_eq!(out[0].streak_ids, vec![0, 1]);
        let got = out[0].rect();
        let footprint = 10.0 * 2.0 * (30f32.to_radians()).tan() / photo.height as f32;
        assert_within(&got, &truth, footprint);

        let inside = truth.grow(-0.3);
        let kept = direct_starts(scene, photo, water, &[light(&plane, inside, 0)]);
        assert_eq!(kept.len(), 1);
        assert_eq!(kept[0].rect(), inside);
    }

    /// A start from a small fragment of a streak, under the lamp and barely reaching its
    /// image (as one wave field's reflections started one for Table 1's lamp): the rectangle
    /// it searches cuts the lamp's image, and grows to hold it, so it finds the whole image
    /// (enclosed, within a pixel's footprint of the truth), the one a start on the lamp
    /// finds, and the two merge whichever comes first: one lamp, one light. Taking the cut
    /// piece for an image of its own gave the lamp two lights.
    #[test]
    fn a_small_start_under_a_large_image_finds_it_whole() {
        let (scene, photo, water, plane, truth) = table1();
        let footprint = 10.0 * 2.0 * (30f32.to_radians()).tan() / photo.height as f32;
        let c = truth.center();
        let small = Rect {
            u_min: c.x - 0.4,
            u_max: c.x + 0.4,
            v_min: truth.v_min - 1.3,
            v_max: truth.v_min + 0.15,
        };
        // Its own search rectangle alone stops short of the image's top.
        let search = small.grow(small.width().max(small.height()));
        assert!(search.v_max < truth.v_max - 1.0, "{search:?}");
        let image = direct_image(scene, photo, water, &light(&plane, small, 1)).unwrap();
        assert!(image.enclosed);
        assert_within(&image.rect, &truth, footprint);
        let on_lamp = light(&plane, truth.grow(-0.3), 0);
        for starts in [
            [light(&plane, small, 1), on_lamp.clone()],
            [on_lamp.clone(), light(&plane, small, 1)],
        ] {
            let out = direct_starts(scene, photo, water, &starts);
            assert_eq!(
                out.len(),
                1,
                "{:?}",
                out.iter().map(|l| l.rect()).collect::<Vec<_>>()
            );
            assert_eq!(out[0].streak_ids, vec![0, 1]);
        }
    }

    /// A start on the light's whole image learns where the light ends: the image's
    /// rectangle within a pixel's footprint of the truth on every edge, and that footprint
    /// as a pixel's angle (60 degrees over 600 pixels) times a distance between the light's
    /// nearest and farthest corners from the camera. The same start with a row
    /// of pixels above the image marked as water (the image may be cut there) learns nothing,
    /// nor does a start off the image.
    #[test]
    fn a_start_on_a_whole_image_learns_where_the_light_ends() {
        let (scene, photo, water, plane, truth) = table1();
        let footprint = 10.0 * 2.0 * (30f32.to_radians()).tan() / photo.height as f32;
        let start = light(&plane, truth.grow(-0.3), 0);
        let (image, measured) =
            enclosing_image(scene, photo, water, &start).expect("a whole image");
        assert_within(&image, &truth, footprint);
        // A pixel's angle times the camera's distance, between the light's nearest corner
        // and its farthest.
        let distances: Vec<f32> = [
            (truth.u_min, truth.v_min),
            (truth.u_min, truth.v_max),
            (truth.u_max, truth.v_min),
            (truth.u_max, truth.v_max),
        ]
        .iter()
        .map(|&(u, v)| (plane.point_at(u, v) - scene.camera.position).length())
        .collect();
        let angle = footprint / 10.0;
        let (near, far) = distances
            .iter()
            .fold((f32::INFINITY, 0.0f32), |(a, b), &d| (a.min(d), b.max(d)));
        assert!(
            (angle * near..=angle * far).contains(&measured),
            "footprint {measured}, not between {} and {}",
            angle * near,
            angle * far
        );
        let (top, _) = image_rows(photo, water);
        let mut cut = water.to_vec();
        let w = photo.width as usize;
        cut[(top - 1) * w..top * w]
            .iter_mut()
            .for_each(|m| *m = true);
        assert!(enclosing_image(scene, photo, &cut, &start).is_none());
        let off = Rect {
            u_min: truth.u_max + 3.0,
            u_max: truth.u_max + 4.0,
            ..truth
        };
        assert!(enclosing_image(scene, photo, water, &light(&plane, off, 0)).is_none());
    }

    /// A start that overlaps the light's image well but reaches beyond it (as a grazing
    /// camera's long lobes start one: 2 m below and 6 m above a 3 m light) is brought back to
    /// the image's edges where the image is enclosed by pixels that see the wall, and every
    /// edge then lies within a pixel's footprint of the truth; a start reaching 0.2 m beyond
    /// on every side likewise. Where something else is seen right above the image (a row of
    /// pixels marked as water), the image may be cut there and the start is kept.
    #[test]
    fn starts_beyond_an_enclosed_image_are_trimmed_to_it() {
        let (scene, photo, water, plane, truth) = table1();
        let footprint = 10.0 * 2.0 * (30f32.to_radians()).tan() / photo.height as f32;
        let tall = Rect {
            v_min: truth.v_min - 2.0,
            v_max: truth.v_max + 6.0,
            ..truth
        };
        for start in [tall, truth.grow(0.2)] {
            let out = direct_starts(scene, photo, water, &[light(&plane, start, 0)]);
            assert_eq!(out.len(), 1);
            let got = out[0].rect();
            assert_within(&got, &truth, footprint);
        }
        let (top, bottom) = image_rows(photo, water);
        // Two stacked lamps: the image cut in two by three dark rows across its middle. A
        // start over both, reaching 0.2 m beyond them (overlapping each by more than a
        // quarter), is trimmed to both, not to the one nearer its centre.
        let mut stacked = photo.clone();
        let middle = (top + bottom) / 2;
        for i in (middle - 1) * photo.width as usize..(middle + 2) * photo.width as usize {
            stacked.radiance[i] = [0.0; 3];
            stacked.clipped[i] = false;
        }
        let out = direct_starts(scene, &stacked, water, &[light(&plane, truth.grow(0.2), 0)]);
        let got = out[0].rect();
        assert!(
            (got.v_min - truth.v_min).abs() < footprint
                && (got.v_max - truth.v_max).abs() < footprint,
            "{got:?} against {truth:?}"
        );
        let mut cut = water.to_vec();
        let row = (top - 1) * photo.width as usize;
        cut[row..row + photo.width as usize].fill(true);
        let out = direct_starts(scene, photo, &cut, &[light(&plane, tall, 0)]);
        assert_eq!(out[0].rect(), tall);
    }

    #[test]
    fn overlap_is_intersection_over_union() {
        let a = Rect {
            u_min: 0.0,
            u_max: 2.0,
            v_min: 0.0,
            v_max: 1.0,
        };
        let b = Rect {
            u_min: 1.0,
            u_max: 3.0,
            v_min: 0.0,
            v_max: 1.0,
        };
        assert!((overlap(&a, &b) - 1.0 / 3.0).abs() < 1e-6);
        assert_eq!(overlap(&a, &a), 1.0);
        let far = b.grow(-0.5);
        assert_eq!(
            overlap(
                &a,
                &Rect {
                    u_min: 5.0,
                    u_max: 6.0,
                    ..far
                }
            ),
            0.0
        );
    }
}
