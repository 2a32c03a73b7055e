//! The joint fit's region (method §5, last paragraph): which pixels of the photo are fitted,
//! and where on its plane each light's edges may go.
//!
//! The fitted region is the streaks, dilated, plus every pixel near them whose reflected rays
//! can reach a light's region of interest: a streak's faint ends fall below any
//! segmentation's threshold, and an edge seen only through them would otherwise drift.

use glam::Vec2;
use rayon::prelude::*;

use super::descent::first_window;
use super::options::PixelShare;
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
    let mut mark = vec![false; (w * h) as usize];
    // Per streak, its bounding box grown by a quarter of its size: where its faint ends lie.
    let mut boxes = Vec::new();
    for s in streaks {
        let (mut x0, mut y0, mut x1, mut y1) = (w, h, -1i64, -1i64);
        for &p in &s.pixels {
            let (x, y) = (p as i64 % w, p as i64 / w);
            (x0, y0, x1, y1) = (x0.min(x), y0.min(y), x1.max(x), y1.max(y));
            for yy in (y - m).max(0)..=(y + m).min(h - 1) {
                for xx in (x - m).max(0)..=(x + m).min(w - 1) {
                    mark[(yy * w + xx) as usize] = true;
                }
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
    let keep = |i: usize| water[i] && share.reads((i as i64 % w) as u32, (i as i64 / w) as u32);
    let mut pixels: Vec<u32> = (0..(w * h) as usize)
        .filter(|&i| mark[i] && keep(i))
        .map(|i| i as u32)
        .collect();
    let mut candidate = vec![false; (w * h) as usize];
    for &(x0, y0, x1, y1) in &boxes {
        for y in y0..=y1 {
            for x in x0..=x1 {
                candidate[(y * w + x) as usize] = true;
            }
        }
    }
    {
        let candidates: Vec<u32> = (0..(w * h) as usize)
            .filter(|&i| candidate[i] && !mark[i] && keep(i))
            .map(|i| i as u32)
            .collect();
        let seen: Vec<u32> = candidates
            .into_par_iter()
            .filter(|&i| sees_region_of_interest(water_model, scene, model, planes, roi, i, photo))
            .collect();
        pixels.extend(seen);
        pixels.sort_unstable();
    }
    pixels
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

/// Where on its plane a light's edges may go during the fit: the start rectangle grown by
/// the first search window and a little more. Samples landing outside it are never traced.
pub(super) fn region_of_interest(start: &FittedLight) -> Rect {
    let rect = start.rect();
    rect.grow(1.25 * first_window(&rect, start.plane.camera_distance()))
}
