//! The lamps themselves in the photo: the bright groups of pixels off the water that see a
//! light's plane (its direct images), which place a light on its wall to a pixel.
//!
//! A direct image: the pixels outside the water whose camera ray (through the pixel's centre)
//! meets the plane first, within a search rectangle, and that are bright (clipped in some
//! channel, or at least half the brightest such pixel's largest channel), grouped
//! 8-connected in the image.

use std::collections::VecDeque;

use glam::Vec2;
use rayon::prelude::*;

use super::direct::image_box;
use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::photo_in::Photo;
use crate::scene_in::BoxHits;
use crate::scene_in::Scene;

/// Fewest pixels a direct image must have to count.
const MIN_PIXELS: usize = 4;

/// A bright group of direct pixels on a light's plane.
pub(super) struct DirectImage {
    /// Its pixels' smallest index: the group's identity.
    pub(super) first_pixel: usize,
    /// Its bounding rectangle on the plane, grown by half a pixel's footprint.
    pub(super) rect: Rect,
    /// Whether every pixel around the group sees the plane (dark or dim): the light ends
    /// where its image ends, on every side. False where the frame's border, the water or
    /// anything in front of the wall cuts the image, which may then hide part of the light.
    /// For the image chosen for a start: and so are all the others the start overlaps.
    pub(super) enclosed: bool,
    /// Per side of `rect` (left, right, bottom, top): whether the frame's border, the water or
    /// anything in front cuts the image there (most of the group's pixels along that side
    /// have a neighbour that does not see the plane), so that the light may reach beyond it.
    pub(super) cut: [bool; 4],
    /// For the image chosen for a start: the bounding rectangle of every image the start
    /// overlaps, what the start is trimmed to (two stacked lamps are two images under one
    /// start).
    pub(super) reach: Rect,
    /// A pixel's footprint on the plane at the image's mean distance from the camera, metres.
    pub(super) footprint: f32,
}

/// The direct images on `plane` inside `search` (module doc), each with `reach` its own
/// rectangle.
///
/// Only the pixels that can matter are looked at (their camera rays' hits read or traced, and
/// tested against the plane): those at least half as bright as the brightest the plane may
/// hold, and their neighbours (whether an image is enclosed). A night photo's box around a
/// light is mostly dark, and at 4000 x 3000, where the scene keeps no hits of the whole
/// image, looking at all of it traced millions of rays a look. The images found are those a
/// look at every pixel finds (the tests hold them equal).
pub(super) fn images_in(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    plane: &LightPlane,
    search: Rect,
) -> Vec<DirectImage> {
    images_looking_from(scene, photo, water, plane, search, None)
}

/// [`images_in`], looking first at the pixels at least `from` bright (`None`: half the
/// brightest pixel off the water in the box; `Some(0.0)`: every pixel off the water).
fn images_looking_from(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    plane: &LightPlane,
    search: Rect,
    from: Option<f32>,
) -> Vec<DirectImage> {
    let (w, h) = (photo.width, photo.height);
    let Some(area) = image_box(scene, &[plane], &[search], w, h) else {
        return Vec::new();
    };
    let (x0, y0, x1, y1) = area;
    let (bw, bh) = ((x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize);
    // Per pixel of the box, row-major, from the photo alone: its brightness off the water (a
    // clipped pixel infinite), NaN on it.
    let level: Vec<f32> = (y0..=y1)
        .into_par_iter()
        .flat_map_iter(|y| {
            (x0..=x1).map(move |x| {
                let i = photo.index(x, y);
                if water[i] {
                    f32::NAN
                } else if photo.clipped[i] {
                    f32::INFINITY
                } else {
                    photo.radiance[i].into_iter().fold(0.0f32, f32::max)
                }
            })
        })
        .collect();
    let top = level
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f32, |a, &v| a.max(v));
    let box_pixels = PixelArea {
        area,
        width: bw,
        height: bh,
    };
    // A look from `from` tests every pixel at least that bright, and its neighbours. The
    // images' threshold is half the brightest finite pixel on the plane, B (where the plane
    // holds none, only the clipped pixels count). When the look finds B >= 2 from, no pixel
    // it left out is brighter, and every pixel of B / 2 or more was tested: it is exact.
    // Else a second look from its B / 2 is (or, where it found none, from zero: every
    // pixel).
    let look_from = |from: f32| {
        Look::new(
            scene,
            photo,
            water,
            plane,
            search,
            &box_pixels,
            &level,
            from,
        )
    };
    let first = from.unwrap_or(if top > 0.0 { 0.5 * top } else { f32::INFINITY });
    let mut look = look_from(first);
    let known = look.brightest();
    let exact = if top <= 0.0 {
        // No finite bright pixel off the water in the box: only clipped ones can be bright,
        // and every one was looked at.
        true
    } else {
        known > 0.0 && first <= 0.5 * known
    };
    if !exact {
        let again = if known > 0.0 { 0.5 * known } else { 0.0 };
        look = look_from(again);
    }
    images_of(scene, photo, &look, &box_pixels)
}

/// A box of pixels of the photo, inclusive, and its size.
struct PixelArea {
    area: (u32, u32, u32, u32),
    width: usize,
    height: usize,
}

/// The pixels of a box looked at: whether each sees `plane` inside the search rectangle.
struct Look<'a> {
    scene: &'a Scene,
    photo: &'a Photo,
    water: &'a [bool],
    plane: &'a LightPlane,
    search: Rect,
    hits: BoxHits,
    /// Per pixel of the box, row-major: its brightness (a clipped pixel infinite) where it was
    /// looked at and sees the plane inside the search rectangle, else NaN.
    value: Vec<f32>,
}

impl<'a> Look<'a> {
    /// Looks at the pixels of `pixels` whose `level` is at least `from`, and at their
    /// 8-neighbours off the water.
    #[allow(clippy::too_many_arguments)]
    fn new(
        scene: &'a Scene,
        photo: &'a Photo,
        water: &'a [bool],
        plane: &'a LightPlane,
        search: Rect,
        pixels: &PixelArea,
        level: &[f32],
        from: f32,
    ) -> Self {
        let (x0, y0, x1, y1) = pixels.area;
        let (bw, bh) = (pixels.width, pixels.height);
        let seed: Vec<bool> = level.par_iter().map(|&v| v >= from).collect();
        // The seeds and their 8-neighbours, off the water (NaN level).
        let wanted: Vec<bool> = (0..bw * bh)
            .into_par_iter()
            .map(|b| {
                if level[b].is_nan() {
                    return false;
                }
                let (x, y) = ((b % bw) as i64, (b / bw) as i64);
                (-1..=1i64).any(|dy| {
                    (-1..=1i64).any(|dx| {
                        let (nx, ny) = (x + dx, y + dy);
                        nx >= 0
                            && ny >= 0
                            && (nx as usize) < bw
                            && (ny as usize) < bh
                            && seed[ny as usize * bw + nx as usize]
                    })
                })
            })
            .collect();
        let w = photo.width as usize;
        let wanted_ref = &wanted;
        let skip = move |i: usize| {
            let (x, y) = ((i % w) as u32, (i / w) as u32);
            !wanted_ref[(y - y0) as usize * bw + (x - x0) as usize]
        };
        // The camera rays' hits, from the scene's cache of them (`Scene::centre_hits`).
        let hits = scene.centre_hits(pixels.area, photo.width, photo.height, &skip);
        let mut look = Look {
            scene,
            photo,
            water,
            plane,
            search,
            hits,
            value: Vec::new(),
        };
        let look_ref = &look;
        let value: Vec<f32> = (y0..=y1)
            .into_par_iter()
            .flat_map_iter(|y| {
                (x0..=x1).map(move |x| {
                    let b = (y - y0) as usize * bw + (x - x0) as usize;
                    if !wanted_ref[b] || look_ref.on_plane(x, y).is_none() {
                        f32::NAN
                    } else {
                        level[b]
                    }
                })
            })
            .collect();
        look.value = value;
        look
    }

    /// Where pixel (x, y) sees the plane, if it does inside the search rectangle: plane
    /// coordinates and distance from the camera.
    fn on_plane(&self, x: u32, y: u32) -> Option<(Vec2, f32)> {
        let (w, h) = (self.photo.width, self.photo.height);
        if self.water[self.photo.index(x, y)] {
            return None;
        }
        let (triangle, t) = self.hits.get(x, y)?;
        if !self.plane.contains_triangle(self.scene, triangle) {
            return None;
        }
        let dir = self
            .scene
            .camera
            .direction(x as f32 + 0.5, y as f32 + 0.5, w, h);
        let q = self.plane.coords(self.scene.camera.position + dir * t);
        self.search.contains(q).then_some((q, t))
    }

    /// The largest finite brightness of a pixel looked at that sees the plane (0 if none).
    fn brightest(&self) -> f32 {
        self.value
            .iter()
            .filter(|v| v.is_finite())
            .fold(0.0f32, |a, &v| a.max(v))
    }
}

/// The direct images a look holds: its bright pixels grouped (module doc).
fn images_of(scene: &Scene, photo: &Photo, look: &Look, pixels: &PixelArea) -> Vec<DirectImage> {
    let (w, h) = (photo.width, photo.height);
    let (x0, y0, _, _) = pixels.area;
    let (bw, bh) = (pixels.width, pixels.height);
    let value = &look.value;
    let on_plane = |x: u32, y: u32| look.on_plane(x, y);
    let brightest = value
        .iter()
        .filter(|v| v.is_finite())
        .fold(0.0f32, |a, &v| a.max(v));
    let any_clipped = value.iter().any(|v| v.is_infinite());
    if brightest <= 0.0 && !any_clipped {
        return Vec::new();
    }
    let threshold = if any_clipped && brightest <= 0.0 {
        f32::INFINITY
    } else {
        0.5 * brightest
    };
    // The bright pixels, in the box's order: box index, image index, plane coordinates,
    // distance.
    let bright: Vec<(usize, usize, Vec2, f32)> = value
        .par_iter()
        .enumerate()
        .filter(|(_, v)| **v >= threshold)
        .filter_map(|(b, _)| {
            let (x, y) = (x0 + (b % bw) as u32, y0 + (b / bw) as u32);
            on_plane(x, y).map(|(q, t)| (b, photo.index(x, y), q, t))
        })
        .collect();
    let groups = groups_8(&bright.iter().map(|s| s.0).collect::<Vec<_>>(), bw, bh);
    // Whether every 8-neighbour of group pixel m is in the frame and sees the plane.
    let surrounded = |m: usize| {
        let b = bright[m].0;
        let (x, y) = ((b % bw) as i64, (b / bw) as i64);
        let (gx, gy) = (x + x0 as i64, y + y0 as i64);
        (-1..=1i64).all(|dy| {
            (-1..=1i64).all(|dx| {
                let (nx, ny) = (x + dx, y + dy);
                gx + dx >= 0
                    && gy + dy >= 0
                    && gx + dx < w as i64
                    && gy + dy < h as i64
                    && nx >= 0
                    && ny >= 0
                    && (nx as usize) < bw
                    && (ny as usize) < bh
                    && !value[ny as usize * bw + nx as usize].is_nan()
            })
        })
    };
    // One pixel's footprint on the plane at distance t, across: t times the pixel's angle.
    let pixel_angle = 2.0 * (scene.camera.yfov * 0.5).tan() / h as f32;
    groups
        .into_iter()
        .filter(|g| g.len() >= MIN_PIXELS)
        .map(|g| {
            let mut rect = Rect {
                u_min: f32::INFINITY,
                u_max: f32::NEG_INFINITY,
                v_min: f32::INFINITY,
                v_max: f32::NEG_INFINITY,
            };
            let mut t_sum = 0.0;
            for &m in &g {
                let (_, _, q, t) = bright[m];
                rect.u_min = rect.u_min.min(q.x);
                rect.u_max = rect.u_max.max(q.x);
                rect.v_min = rect.v_min.min(q.y);
                rect.v_max = rect.v_max.max(q.y);
                t_sum += t;
            }
            let half_pixel = 0.5 * pixel_angle * t_sum / g.len() as f32;
            // Per side, its pixels within half a footprint of it (its own row or column of
            // the image) and how many of those are not surrounded: a side most of whose
            // pixels are not is cut (a corner pixel of a side the frame cuts lies on the
            // neighbouring side too).
            let open: Vec<bool> = g.par_iter().map(|&m| !surrounded(m)).collect();
            let mut along = [(0usize, 0usize); 4];
            for (&m, &open) in g.iter().zip(&open) {
                let q = bright[m].2;
                let gaps = [
                    q.x - rect.u_min,
                    rect.u_max - q.x,
                    q.y - rect.v_min,
                    rect.v_max - q.y,
                ];
                for (count, gap) in along.iter_mut().zip(gaps) {
                    if gap <= half_pixel {
                        count.0 += 1;
                        count.1 += open as usize;
                    }
                }
            }
            let cut = along.map(|(all, open)| 2 * open > all);
            DirectImage {
                first_pixel: g.iter().map(|&m| bright[m].1).min().unwrap_or(0),
                rect: rect.grow(half_pixel),
                enclosed: !open.contains(&true),
                cut,
                reach: rect.grow(half_pixel),
                footprint: 2.0 * half_pixel,
            }
        })
        .collect()
}

/// The 8-connected groups of the pixels `pixels` (indices into a row-major box of `width` x
/// `height` pixels), each a list of positions in `pixels`.
fn groups_8(pixels: &[usize], width: usize, height: usize) -> Vec<Vec<usize>> {
    const ABSENT: u32 = u32::MAX;
    let mut position = vec![ABSENT; width * height];
    for (k, &p) in pixels.iter().enumerate() {
        position[p] = k as u32;
    }
    let mut group_of = vec![usize::MAX; pixels.len()];
    let mut groups = Vec::new();
    for k in 0..pixels.len() {
        if group_of[k] != usize::MAX {
            continue;
        }
        let id = groups.len();
        let mut members = Vec::new();
        let mut queue = VecDeque::from([k]);
        group_of[k] = id;
        while let Some(m) = queue.pop_front() {
            members.push(m);
            let (x, y) = ((pixels[m] % width) as i64, (pixels[m] / width) as i64);
            for dy in -1..=1i64 {
                for dx in -1..=1i64 {
                    let (nx, ny) = (x + dx, y + dy);
                    if (dx, dy) == (0, 0)
                        || nx < 0
                        || ny < 0
                        || nx >= width as i64
                        || ny >= height as i64
                    {
                        continue;
                    }
                    let n = position[ny as usize * width + nx as usize];
                    if n != ABSENT && group_of[n as usize] == usize::MAX {
                        group_of[n as usize] = id;
                        queue.push_back(n as usize);
                    }
                }
            }
        }
        groups.push(members);
    }
    groups
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fitting::joint::direct_start::tests::table1;

    /// What an image is, field by field, for comparing two looks.
    fn key(im: &DirectImage) -> (usize, Rect, bool, [bool; 4], Rect, f32) {
        (
            im.first_pixel,
            im.rect,
            im.enclosed,
            im.cut,
            im.reach,
            im.footprint,
        )
    }

    fn keys(images: &[DirectImage]) -> Vec<(usize, Rect, bool, [bool; 4], Rect, f32)> {
        images.iter().map(key).collect()
    }

    /// The look at the bright pixels alone finds the images a look at every pixel of the box
    /// finds, to the bit: around Table 1's lamp with searches of several sizes (the box
    /// reaching the frame's top and the water), and where the brightest pixel of the box lies
    /// outside the search (a first look that is not enough, and a second).
    #[test]
    fn a_look_at_the_bright_pixels_finds_what_a_look_at_all_finds() {
        let (scene, photo, water, plane, truth) = table1();
        for grow in [0.05f32, 1.0, 3.0] {
            let search = truth.grow(grow);
            let lazy = images_in(scene, photo, water, &plane, search);
            let full = images_looking_from(scene, photo, water, &plane, search, Some(0.0));
            assert_eq!(lazy.len(), 1, "one lamp, searched {grow} m around it");
            assert_eq!(keys(&lazy), keys(&full), "searched {grow} m around it");
        }
        // A pixel off the water, inside the search's box but outside the search (its box
        // reaches a pixel past the rectangle's projection), made brighter than anything the
        // lamp shows unclipped: the first look, from half of it, is not exact.
        let search = truth.grow(0.3);
        let (x0, y0, _, _) = image_box(scene, &[&plane], &[search], photo.width, photo.height)
            .expect("the lamp's box");
        let corner = photo.index(x0, y0);
        assert!(!water[corner]);
        let dir =
            scene
                .camera
                .direction(x0 as f32 + 0.5, y0 as f32 + 0.5, photo.width, photo.height);
        let q = plane.hit(scene.camera.position, dir).expect("the wall").1;
        assert!(
            !search.contains(q),
            "the box's corner lies outside the search"
        );
        let lamp_brightest = (0..photo.radiance.len())
            .filter(|&i| !water[i] && !photo.clipped[i])
            .map(|i| photo.radiance[i].into_iter().fold(0.0f32, f32::max))
            .fold(0.0f32, f32::max);
        assert!(lamp_brightest > 0.0);
        let mut bright = photo.clone();
        bright.radiance[corner] = [4.0 * lamp_brightest; 3];
        let lazy = images_in(scene, &bright, water, &plane, search);
        let full = images_looking_from(scene, &bright, water, &plane, search, Some(0.0));
        assert_eq!(lazy.len(), 1);
        assert_eq!(keys(&lazy), keys(&full));
        assert_eq!(
            keys(&lazy),
            keys(&images_in(scene, photo, water, &plane, search))
        );
    }

    #[test]
    fn groups_are_8_connected() {
        // Width 5: (0,0),(1,1) touch diagonally; (4,0) is alone; (3,3),(4,3) touch.
        let px = [0, 6, 4, 18, 19];
        let mut g = groups_8(&px, 5, 4);
        g.iter_mut().for_each(|m| m.sort_unstable());
        g.sort();
        assert_eq!(g, vec![vec![0, 1], vec![2], vec![3, 4]]);
    }
}
