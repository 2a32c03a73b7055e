//! The direct view of the lights in the joint fit (method §5, last paragraph): the pixels
//! outside the water that see a light's wall, and their samples.
//!
//! Night photos usually show the lights themselves above the water. A camera ray whose first
//! hit is a light's plane inside its rectangle sees the light's radiance, so such a pixel's
//! coefficient for a rectangle is the fraction of its footprint that lands inside it: no
//! lobe, no Fresnel, and nothing the water model decides (the rays go straight from the
//! camera to the wall). These pixels join the fitted ones as samples of the same kind as the
//! water pixels' (plane coordinates, a weight, a kernel), one per stratum of the footprint
//! (the water pixels' camera strata), without a control variate. Each is the camera ray
//! through its stratum's centre, which decides what the stratum sees (the wall, or a pole in
//! front of it), and its kernel is the stratum's image on the plane as a plain box, so that
//! the coefficient is the footprint's exact share inside a rectangle (for a footprint whose
//! sides lie along the plane's axes) and moves linearly with an edge across it.
//!
//! Not jittered samples under the lobe samples' smoothing kernel: their noise (a standard
//! deviation of 0.11 in the coefficient of a pixel an edge crosses, with 8 rays) meets the
//! clipped pixels' one-sided cost, where a pixel the noise puts below the clip is pulled up
//! and one above it is let go, and that pushed the radiances up by 0.3-0.9 % on the samples.
//! A clipped pixel (the light itself, in an 8-bit photo) is a lower bound, as everywhere in
//! the fit; the edges are pinned by the black pixels beside them and by the pixels they cross
//! that the light does not clip.
//!
//! A pixel outside a light's rectangle models 0: the walls are dark at night. A lit wall of
//! brightness w, which the model does not hold, raises the pixels around the light; an edge
//! pixel then reads as if the light covered about w / L more of it, so the edges move
//! outwards by that fraction of a pixel, while the radiance, read from the reflections and
//! from the unclipped pixels the edges cross, is barely touched. Anything bright on the wall
//! inside a region of interest that is not the light (a lit window) is not modelled either.

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::kernel::POINT_CELL;
use super::options::PixelShare;
use super::problem::Problem;
use super::samples::CAMERA_STRATA;
use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::fitting::EdgeSide;
use crate::scene_in::Scene;

/// What a probe ray through a pixel corner sees first.
#[derive(Clone, Copy, PartialEq)]
enum Corner {
    /// A light's plane inside its region of interest.
    Wall,
    /// The water: the pixel mixes reflections in, which its direct samples do not model.
    Water,
    /// Anything else, or nothing.
    Other,
}

/// The pixels outside the water (those of them `share` reads, as the water pixels are read) that see a light's plane inside its region of interest `roi[k]`
/// directly. A pixel is taken when a camera ray through one of its corners meets such a
/// plane first and none meets the water (a pixel the water's far edge crosses mixes
/// reflections in, which its direct samples would not model). Only the image box where the
/// regions of interest project is probed: a light out of frame gives no pixel.
pub(super) fn direct_pixels(
    scene: &Scene,
    planes: &[&LightPlane],
    roi: &[Rect],
    width: u32,
    height: u32,
    water: &[bool],
    share: PixelShare,
) -> Vec<u32> {
    let Some((x0, y0, x1, y1)) = image_box(scene, planes, roi, width, height) else {
        return Vec::new();
    };
    // Corner (x, y) of the image, for x in x0..=x1 + 1 and y in y0..=y1 + 1.
    let cw = (x1 + 2 - x0) as usize;
    let corners: Vec<Corner> = (0..cw * (y1 + 2 - y0) as usize)
        .into_par_iter()
        .map(|c| {
            let (x, y) = (x0 + (c % cw) as u32, y0 + (c / cw) as u32);
            probe(scene, planes, roi, x as f32, y as f32, width, height)
        })
        .collect();
    let mut out = Vec::new();
    for y in y0..=y1 {
        for x in x0..=x1 {
            let i = (y * width + x) as usize;
            if water[i] || !share.reads_direct(x, y) {
                continue;
            }
            let c = ((y - y0) as usize) * cw + (x - x0) as usize;
            let four = [
                corners[c],
                corners[c + 1],
                corners[c + cw],
                corners[c + cw + 1],
            ];
            if four.contains(&Corner::Wall) && !four.contains(&Corner::Water) {
                out.push(i as u32);
            }
        }
    }
    out
}

/// The box of pixels (inclusive) where the regions of interest project, grown by a pixel,
/// clipped to the image; the whole image when a corner lies behind the camera (its
/// projection is then no bound); `None` when it misses the image.
pub(super) fn image_box(
    scene: &Scene,
    planes: &[&LightPlane],
    roi: &[Rect],
    width: u32,
    height: u32,
) -> Option<(u32, u32, u32, u32)> {
    let (mut lo, mut hi) = (Vec2::splat(f32::INFINITY), Vec2::splat(f32::NEG_INFINITY));
    for (plane, r) in planes.iter().zip(roi) {
        for (u, v) in [
            (r.u_min, r.v_min),
            (r.u_max, r.v_min),
            (r.u_min, r.v_max),
            (r.u_max, r.v_max),
        ] {
            let Some((x, y)) = scene.camera.project(plane.point_at(u, v), width, height) else {
                return Some((0, 0, width - 1, height - 1));
            };
            lo = lo.min(Vec2::new(x, y));
            hi = hi.max(Vec2::new(x, y));
        }
    }
    let (w, h) = (width as f32, height as f32);
    if !(hi.x >= -1.0 && hi.y >= -1.0 && lo.x <= w + 1.0 && lo.y <= h + 1.0) {
        return None;
    }
    let clamp = |v: f32, n: u32| (v.max(0.0) as u32).min(n - 1);
    Some((
        clamp(lo.x - 1.0, width),
        clamp(lo.y - 1.0, height),
        clamp(hi.x + 1.0, width),
        clamp(hi.y + 1.0, height),
    ))
}

/// What the camera ray through image position (`x`, `y`) meets first.
fn probe(
    scene: &Scene,
    planes: &[&LightPlane],
    roi: &[Rect],
    x: f32,
    y: f32,
    width: u32,
    height: u32,
) -> Corner {
    let origin = scene.camera.position;
    let dir = scene.camera.direction(x, y, width, height);
    let Some(hit) = scene.tracer.closest_hit(origin, dir, 0.0, f32::INFINITY) else {
        return Corner::Other;
    };
    if scene.is_water[hit.triangle as usize] {
        return Corner::Water;
    }
    let p = origin + dir * hit.t;
    let on_wall = planes.iter().zip(roi).any(|(plane, r)| {
        plane.contains_triangle(scene, hit.triangle) && r.contains(plane.coords(p))
    });
    if on_wall {
        Corner::Wall
    } else {
        Corner::Other
    }
}

/// A stored sample before it is sorted by plane: the plane's index, where it lands, its
/// kernel's half-widths (negative: a plain box), its weight, its half (+1 or -1; 0 for a
/// direct sample) and, once the pixel's samples are in store order, an entry of its plane's
/// order in v (`samples::in_store_order`; 0 until then).
pub(super) type Hit = (u16, Vec2, Vec2, f32, f32, u16);

/// Camera rays per direct pixel: one through the centre of each of its `CAMERA_STRATA^2`
/// strata, as a water pixel's camera rays are stratified.
pub(super) const DIRECT_RAYS: u32 = CAMERA_STRATA * CAMERA_STRATA;

/// The samples of the direct pixel (`x`, `y`): one camera ray through the centre of each of
/// its [`DIRECT_RAYS`] strata, stored with weight `weight` (the fit divides every pixel's sum
/// by its sample count: `weight` is that count over [`DIRECT_RAYS`], so that the coefficient
/// is the fraction of the footprint inside a rectangle) and the plain box of its stratum's
/// image on the plane as its kernel (a negative half-width: see
/// [`super::kernel::kernel_coverage`]), on every plane whose face is its first hit, where the
/// box reaches that plane's region of interest. A ray whose first hit is anything else (a
/// pole in front of the wall, the water, nothing) is stored nowhere: its stratum sees no
/// light. The samples carry no half (0): the coefficient has no noise to measure.
#[allow(clippy::too_many_arguments)]
pub(super) fn direct_hits(
    scene: &Scene,
    planes: &[&LightPlane],
    roi: &[Rect],
    x: u32,
    y: u32,
    width: u32,
    height: u32,
    weight: f32,
) -> Vec<Hit> {
    let origin = scene.camera.position;
    let inv_c = 1.0 / CAMERA_STRATA as f32;
    let centre = |cs: u32| {
        (
            x as f32 + ((cs % CAMERA_STRATA) as f32 + 0.5) * inv_c,
            y as f32 + ((cs / CAMERA_STRATA) as f32 + 0.5) * inv_c,
        )
    };
    // The strata's rays traced together: they run close together.
    const N: usize = DIRECT_RAYS as usize;
    let dirs: [Vec3; N] = std::array::from_fn(|cs| {
        let (fx, fy) = centre(cs as u32);
        scene.camera.direction(fx, fy, width, height)
    });
    let mut first = [None; N];
    scene
        .tracer
        .closest_hits(origin, &dirs, 0.0, &[f32::INFINITY; N], &mut first);
    let mut hits = Vec::new();
    for ((cs, &dir), hit) in (0..DIRECT_RAYS).zip(&dirs).zip(first) {
        let (fx, fy) = centre(cs);
        let Some(hit) = hit else {
            continue;
        };
        for (k, (plane, r)) in planes.iter().zip(roi).enumerate() {
            if !plane.contains_triangle(scene, hit.triangle) {
                continue;
            }
            let q = plane.coords(origin + dir * hit.t);
            let cell = stratum_cell(scene, plane, fx, fy, inv_c, width, height);
            if r.overlaps(&Rect::around(q, cell)) {
                hits.push((k as u16, q, -cell, weight, 0.0, 0));
            }
        }
    }
    hits
}

/// The half-widths, along the plane's axes, of the box a direct sample through the centre
/// (`x`, `y`) of a stratum of side `stratum` pixels stands for: the stratum's image on the
/// plane, linearised (sides `J e_x s` and `J e_y s`, J the derivative of the landing point by
/// the image position), matched in variance by a box of half-width `sqrt(a^2 + b^2) / 2` per
/// axis, as [`super::kernel::cell_half_extents`] does for a lobe cell. Where the footprint's
/// sides lie along the plane's axes (a wall facing the camera, as in the samples) the box is
/// the stratum's image itself and the coefficient exact; an oblique view makes the footprint
/// a parallelogram, which the box matches in its spread. A stratum grazing the plane stays a
/// point.
fn stratum_cell(
    scene: &Scene,
    plane: &LightPlane,
    x: f32,
    y: f32,
    stratum: f32,
    width: u32,
    height: u32,
) -> Vec2 {
    let origin = scene.camera.position;
    let land = |dx: f32, dy: f32| -> Option<Vec2> {
        let dir: Vec3 = scene.camera.direction(x + dx, y + dy, width, height);
        plane.hit(origin, dir).map(|(_, q)| q)
    };
    let d = 0.25 * stratum;
    let side = |plus: Option<Vec2>, minus: Option<Vec2>| -> Option<Vec2> {
        Some((plus? - minus?) * (stratum / (2.0 * d)))
    };
    let (Some(a), Some(b)) = (
        side(land(d, 0.0), land(-d, 0.0)),
        side(land(0.0, d), land(0.0, -d)),
    ) else {
        return Vec2::splat(POINT_CELL);
    };
    let half = 0.5 * Vec2::new(a.x.hypot(b.x), a.y.hypot(b.y));
    if half.is_finite() {
        half.max(Vec2::splat(POINT_CELL))
    } else {
        Vec2::splat(POINT_CELL)
    }
}

/// Fewest pixels that see a light whole for its image's rounding to count
/// ([`Problem::shared_rounding`]).
const MIN_WHOLE_PIXELS: usize = 16;

impl Problem {
    /// Whether channel `ch` of fitted pixel i measures the model for the uncertainties: not
    /// clipped (a lower bound), and, for a direct pixel, not at the photo's black level in
    /// every channel either. A black pixel next to a light's image says that the light covers
    /// none of it, a bound on one side of an edge as a clipped one is on the other; between
    /// such bounds the edge is free, and a curvature taken across them would claim it pinned
    /// (Table 1's left edge, between a black and a clipped column of pixels, came out at
    /// 0.04 mm against a 0.8 mm error).
    pub(super) fn measures(&self, i: usize, ch: usize) -> bool {
        !self.clipped_channels[i][ch] && (i < self.first_direct || self.obs[i] != [0.0; 3])
    }

    /// The step over which the direct pixels' coefficients of set `set` are differentiated
    /// by an edge along u (`along_u`) or v: the median half-width of their samples' boxes,
    /// half a stratum, a quarter of a pixel's footprint. The coefficient of a pixel an edge crosses changes
    /// linearly across the pixel, and a wider step would average that slope with the flat
    /// cost of its neighbours. `None` without direct samples.
    pub(super) fn direct_step(&self, set: usize, along_u: bool) -> Option<f32> {
        let samples = &self.planes[set];
        let first = samples.offsets[self.first_direct] as usize;
        let mut widths: Vec<f32> = samples.cells[first..]
            .iter()
            .map(|c| if along_u { c.x.abs() } else { c.y.abs() })
            .collect();
        if widths.is_empty() {
            return None;
        }
        let mid = widths.len() / 2;
        Some(*widths.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1)
    }

    /// The direct pixels (see the module doc) with a sample of set `set` inside `rect`: the
    /// pixels that see the light.
    pub(super) fn direct_pixels_inside(&self, set: usize, rect: &Rect) -> usize {
        let samples = &self.planes[set];
        (self.first_direct..self.n())
            .filter(|&i| {
                samples.points[samples.range(i)]
                    .iter()
                    .any(|p| rect.contains(*p))
            })
            .count()
    }

    /// Whether a direct pixel sees a light of set `set`, rectangle `rect` and radiance
    /// `radiance` whole (every sample inside the rectangle) in a channel the photo did not
    /// clip and the light lights: its radiance is then read off its image, where otherwise
    /// only the reflections give it (a light out of frame or hidden, or one whose image clips
    /// in every channel).
    pub(super) fn sees_radiance(&self, set: usize, rect: &Rect, radiance: [f64; 3]) -> bool {
        self.seeing_whole(set, rect)
            .any(|i| (0..3).any(|c| radiance[c] > 0.0 && !self.clipped_channels[i][c]))
    }

    /// The direct pixels that see a light of set `set` and rectangle `rect` whole: every one
    /// of their samples inside the rectangle.
    fn seeing_whole<'a>(&'a self, set: usize, rect: &'a Rect) -> impl Iterator<Item = usize> + 'a {
        let samples = &self.planes[set];
        (self.first_direct..self.n()).filter(move |&i| {
            let points = &samples.points[samples.range(i)];
            !points.is_empty() && points.iter().all(|p| rect.contains(*p))
        })
    }

    /// Per channel, the variance (radiance units squared) the photo's rounding leaves in a
    /// radiance read off the image of a light of set `set` and rectangle `rect`: the pixels
    /// that see it whole hold one value, rounded alike, so their number does not average the
    /// rounding away ([`Rounding::sigma`](crate::photo_rounding::Rounding::sigma) at their
    /// median value). 0 for a channel fewer than [`MIN_WHOLE_PIXELS`] such pixels measure
    /// ([`Problem::measures`]).
    pub(super) fn shared_rounding(&self, set: usize, rect: &Rect) -> [f64; 3] {
        let (rounding, exposure) = self.encoding;
        let whole: Vec<usize> = self.seeing_whole(set, rect).collect();
        let median = |mut values: Vec<f32>| -> Option<f32> {
            if values.len() < MIN_WHOLE_PIXELS {
                return None;
            }
            let mid = values.len() / 2;
            Some(*values.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1)
        };
        std::array::from_fn(|ch| {
            let measuring: Vec<usize> = whole
                .iter()
                .copied()
                .filter(|&i| self.measures(i, ch))
                .collect();
            let value = median(measuring.iter().map(|&i| self.obs[i][ch]).collect());
            let brightest = median(
                measuring
                    .iter()
                    .map(|&i| self.obs[i].iter().copied().fold(0.0, f32::max))
                    .collect(),
            );
            match (value, brightest) {
                (Some(v), Some(b)) => {
                    let sd = rounding.sigma(v * exposure, b * exposure) / exposure;
                    (sd as f64).powi(2)
                }
                _ => 0.0,
            }
        })
    }

    /// Per edge of `rect` (left, right, bottom, top), the direct pixels with a sample of set
    /// `set` whose kernel straddles that edge within the rectangle's span along it: the
    /// pixels that see the edge itself, and pin it to a fraction of a pixel.
    pub(super) fn direct_edge_pixels(&self, set: usize, rect: &Rect) -> [usize; 4] {
        let samples = &self.planes[set];
        let mut out = [0; 4];
        for i in self.first_direct..self.n() {
            let r = samples.range(i);
            for side in EdgeSide::ALL {
                let e = rect.edge(side);
                let straddles = samples.points[r.clone()]
                    .iter()
                    .zip(&samples.cells[r.clone()])
                    .any(|(p, h)| {
                        let (at, half, along, span) = if side.along_u() {
                            (p.x, h.x.abs(), p.y, (rect.v_min, rect.v_max))
                        } else {
                            (p.y, h.y.abs(), p.x, (rect.u_min, rect.u_max))
                        };
                        (at - half..=at + half).contains(&e) && (span.0..=span.1).contains(&along)
                    });
                out[side as usize] += straddles as usize;
            }
        }
        out
    }
}

#[cfg(test)]
pub(super) mod tests;
