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
pub(super) fn images_in(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    plane: &LightPlane,
    search: Rect,
) -> Vec<DirectImage> {
    let (w, h) = (photo.width, photo.height);
    let Some((x0, y0, x1, y1)) = image_box(scene, &[plane], &[search], w, h) else {
        return Vec::new();
    };
    // Per pixel of the box, row-major: its brightness where it sees the plane inside the
    // search rectangle, else NaN. Traced row by row in parallel, the camera rays' hits from
    // the scene's cache of them (`Scene::centre_hits`).
    let origin = scene.camera.position;
    let hits = scene.centre_hits((x0, y0, x1, y1), w, h, &|i| water[i]);
    let hits = &hits;
    let (bw, bh) = ((x1 - x0 + 1) as usize, (y1 - y0 + 1) as usize);
    // Where pixel (x, y) sees the plane, if it does inside the search rectangle: plane
    // coordinates and distance from the camera.
    let on_plane = |x: u32, y: u32| -> Option<(Vec2, f32)> {
        if water[photo.index(x, y)] {
            return None;
        }
        let (triangle, t) = hits.get(x, y)?;
        if !plane.contains_triangle(scene, triangle) {
            return None;
        }
        let dir = scene.camera.direction(x as f32 + 0.5, y as f32 + 0.5, w, h);
        let q = plane.coords(origin + dir * t);
        search.contains(q).then_some((q, t))
    };
    let value: Vec<f32> = (y0..=y1)
        .into_par_iter()
        .flat_map_iter(|y| {
            (x0..=x1).map(move |x| match on_plane(x, y) {
                None => f32::NAN,
                Some(_) => {
                    let i = photo.index(x, y);
                    if photo.clipped[i] {
                        f32::INFINITY
                    } else {
                        photo.radiance[i].into_iter().fold(0.0f32, f32::max)
                    }
                }
            })
        })
        .collect();
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
        .iter()
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
            let open: Vec<bool> = g.iter().map(|&m| !surrounded(m)).collect();
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
