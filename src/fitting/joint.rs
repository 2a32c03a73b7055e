//! Joint refinement of all lights by render and compare (METHOD §5, last paragraph; issue 5).
//!
//! The paper fits each streak alone from its edge pixels. Here every water pixel from which
//! a light can be seen counts, and all lights are fitted together: minimise
//!
//! ```text
//! S = sum_p sum_c (I_c(p) - sum_k L_k,c c_k(p; rect_k))^2
//! ```
//!
//! where a clipped pixel only counts when the model is below it (it is a lower bound,
//! METHOD §2). The fitted region is the streaks, dilated, plus every pixel near them whose
//! reflected rays can reach a light's region of interest: a streak's faint ends fall below
//! any segmentation's threshold, and an edge seen only through them would otherwise drift.
//!
//! Each pixel's coefficient is integrated over its footprint as the renderer does it
//! ([`crate::render::camera_hit`]): stratified jittered camera rays, each with a stratified
//! set of lobe samples, in two independent halves whose difference measures the estimate's
//! noise. The samples that land on each light's plane inside its region of interest are
//! traced ONCE; afterwards `c_k(p; rect)` for any rectangle is a sum over stored samples, so
//! the optimisation traces no ray. Each sample spreads its weight over a small kernel sized by
//! its lobe cell, so that a coefficient changes smoothly with the rectangle's edges (see the
//! note on the cells). The stored samples are common random numbers across all parameter
//! values, so the cost is a deterministic function of the rectangles, and the coefficients'
//! own noise is removed from it (see the note on the coefficients' noise).
//!
//! What noise is left is cut by a control variate ([`super::control_variate`]): per pixel a
//! Gaussian on the light's plane, matched to the pixel's lobe, whose mass inside a rectangle
//! is known in closed form. Each stored sample carries only its weight less the Gaussian's
//! (so an edge cutting through the samples moves the estimate by far less noise), and the
//! coefficient adds the Gaussian's exact mass back. The expectation is unchanged; on Table 3
//! the noise of a coefficient's derivative by an edge fell to about a fifth in variance, and
//! the fit's errors to what 16 times the samples gave without it (BENCHMARKS.md).
//!
//! The model is linear in the radiances: given the rectangles they are a nonnegative least
//! squares solve per channel. The edges are found by coordinate descent where each 1D step
//! evaluates the cost on a whole grid of edge positions in one pass over the samples
//! (prefix sums over binned samples), with that light's radiance re-optimised in closed form at
//! every grid point, so a far-off start (the paper's estimate can be metres off) is pulled in
//! by a global 1D search rather than a local step. The grid then shrinks around the best
//! position until it is finer than a millimetre. An edge that no pixel of the streak's edge
//! looks at (outside the photo) is held where the paper method put it.
//!
//! Overlapping streaks (two lights whose reflections merge into one region, the paper's
//! §5.3): when the residual of a fit is structured along the image rows, each light is tried
//! as two (one above the other, or side by side), and the split is kept when it removes most
//! of that structure. The second light of a split then reads a sample set of its own, drawn
//! independently on the same plane, and the boundary between the two is searched globally
//! before the final descent (`search_boundary`).

use std::time::Instant;

use glam::{Vec2, Vec3};
use rayon::prelude::*;

use super::control_variate::{self, LobeGaussian};
use super::light_plane::LightPlane;
use super::rect::Rect;
use super::{EdgeSide, EdgeStatus, FittedLight, StreakObservation};
use crate::optics::{compact_strata, ReflectionModel};
use crate::photo_in::Photo;
use crate::random::Rng;
use crate::render::{camera_hit, CameraHit, WaterPoint};
use crate::scene_in::Scene;
use crate::{Error, Result};

mod split;
use split::{search_boundary, try_split, CANDIDATE_SWEEPS};

/// Stream tag of the joint fit's random numbers: distinct from the renderer's (the bare pixel
/// index), from the plane search's and from the paper fit's footprints, so the fit never
/// reuses the photo's own noise.
const JOINT_STREAM: u64 = 3 << 48;

/// How to refine.
#[derive(Clone, Copy, Debug)]
pub struct JointOptions {
    /// Lobe samples per pixel of the fitted region. The cost sums over thousands of pixels, so
    /// far fewer than the photo's own samples suffice.
    pub samples: u32,
    /// Seed of the footprints' random numbers.
    pub seed: u64,
    /// The water's reflection model.
    pub model: ReflectionModel,
    /// Pixels by which each streak is dilated to give the fitted region: the dark water around
    /// a streak is what pins its edges down.
    pub margin: u32,
    /// Coordinate-descent sweeps, at most (each shrinks the search windows; the descent
    /// stops once they are all at their smallest).
    pub sweeps: u32,
    /// Fit every pixel (false) or a checkerboard half of them (true): neighbouring pixels
    /// carry nearly the same information, and the footprints are most of the cost.
    pub checkerboard: bool,
    /// Try explaining each light as two (overlapping streaks), keeping the split when it
    /// fits the photo far better.
    pub split: bool,
    /// The gloss whose lobe decides which pixels around the streaks are fitted (`None`: the
    /// model's). Fits under different glosses are comparable only over the same pixels, so a
    /// gloss search fixes it to the broadest lobe it will try.
    pub region_gloss: Option<f32>,
    /// Independent fits, each from its own samples, whose mean is the result (at least 1).
    /// From 2 on, their spread is added to the uncertainties (how far the samples move the
    /// fit); the mean's own error falls as one over the square root of
    /// the count.
    pub repeats: u32,
    /// Told a line as each repeat starts, when there are several (None: silent).
    pub progress: Option<fn(&str)>,
    /// Estimate the coefficients with the lobe Gaussian as a control variate (see
    /// `fitting::control_variate`): the same expectation, far less noise. Off only to
    /// measure what it brings.
    pub control_variate: bool,
}

impl JointOptions {
    /// Defaults for a model and seed.
    pub fn new(model: ReflectionModel, seed: u64) -> Self {
        JointOptions {
            samples: DEFAULT_JOINT_SAMPLES,
            seed,
            model,
            margin: 6,
            sweeps: 14,
            checkerboard: true,
            split: true,
            region_gloss: None,
            repeats: 1,
            progress: None,
            control_variate: true,
        }
    }
}

/// Default lobe samples per pixel of the joint fit.
pub const DEFAULT_JOINT_SAMPLES: u32 = 72;

/// The samples per pixel a joint fit asked for `samples` actually takes: the count is
/// rounded to two halves of `CAMERA_STRATA^2` camera rays times a square number of lobe
/// samples (8, 32, 72, 128, 200, 288, ...).
pub fn effective_samples(samples: u32) -> u32 {
    2 * CAMERA_STRATA * CAMERA_STRATA * lobe_strata(samples).pow(2)
}

/// One-sigma uncertainties of a light's parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Uncertainty {
    /// Left, right, bottom and top edges, metres along the plane's axes (indexed by
    /// [`EdgeSide`]). `None` when the photo does not constrain the edge (flat cost).
    pub edges: [Option<f32>; 4],
    /// Radiance per channel, in radiance units.
    pub radiance: [f32; 3],
}

/// The result of a joint fit.
#[derive(Clone, Debug)]
pub struct JointOutcome {
    /// The refined lights, in the order given.
    pub lights: Vec<FittedLight>,
    /// Their uncertainties, in the same order.
    pub uncertainty: Vec<Uncertainty>,
    /// Pixels in the fitted region.
    pub pixels: usize,
    /// Residual sum of squares per pixel and channel at the optimum (radiance units squared).
    pub residual_variance: f64,
    /// The fit's cost at the optimum: the residual sum of squares less the samples' own noise
    /// (module doc); comparable between fits of the same pixels. Not positive when the fit
    /// has broken down (the photo's own noise keeps a sound fit's cost positive).
    pub cost: f64,
    /// Wall-clock seconds: "footprints" and "optimise".
    pub timings: Vec<(String, f64)>,
}

/// Stored samples of one light's plane: per fitted pixel, a range of points and weights, and
/// which of the pixel's two independent halves each belongs to (what the coefficients'
/// variance is estimated from).
struct PlaneSamples {
    offsets: Vec<u32>,
    /// Per pixel, the bounding box of its samples' cells (empty pixels: an inverted box).
    bbox: Vec<Rect>,
    points: Vec<Vec2>,
    /// Per sample, the half-widths of its kernel along the plane's axes (see
    /// [`cell_half_extents`] and the note on the cells).
    cells: Vec<Vec2>,
    /// Per sample, its weight less the control variate's (see `fitting::control_variate`):
    /// negative where the Gaussian outweighs the lobe.
    weights: Vec<f32>,
    /// Per sample, which of the pixel's two independent halves it belongs to (+1 or -1).
    halves: Vec<f32>,
    /// Per pixel, the control variate ([`LobeGaussian::NONE`] without).
    gauss: Vec<LobeGaussian>,
    /// The smallest width and height a light on this plane may take ([`smallest_light`]).
    min_size: Vec2,
}

/// A rectangle seen from one of its edges as that edge moves: whether the edge is a left or
/// right one (it moves along u), whether it is the lower of its pair, where the opposite
/// edge is, and the rectangle's extent along the edge.
struct EdgeFrame {
    along_u: bool,
    min_edge: bool,
    opposite: f32,
    across: (f32, f32),
}

impl EdgeFrame {
    fn new(rect: &Rect, side: EdgeSide) -> Self {
        let (min_edge, opposite, across) = match side {
            EdgeSide::Left => (true, rect.u_max, (rect.v_min, rect.v_max)),
            EdgeSide::Right => (false, rect.u_min, (rect.v_min, rect.v_max)),
            EdgeSide::Bottom => (true, rect.v_max, (rect.u_min, rect.u_max)),
            EdgeSide::Top => (false, rect.v_min, (rect.u_min, rect.u_max)),
        };
        EdgeFrame {
            along_u: matches!(side, EdgeSide::Left | EdgeSide::Right),
            min_edge,
            opposite,
            across,
        }
    }
}

impl PlaneSamples {
    fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// `(c, d)`: the coefficient and its half-difference (see the note on the coefficients' noise).
    fn coefficient(&self, i: usize, rect: &Rect, inv_samples: f32) -> (f32, f32) {
        let r = self.range(i);
        let (mut sum, mut signed) = (0f32, 0f32);
        for (((p, h), &w), &half) in self.points[r.clone()]
            .iter()
            .zip(&self.cells[r.clone()])
            .zip(&self.weights[r.clone()])
            .zip(&self.halves[r])
        {
            let f = kernel_coverage(p.x, h.x, rect.u_min, rect.u_max)
                * kernel_coverage(p.y, h.y, rect.v_min, rect.v_max);
            if f != 0.0 {
                sum += w * f;
                signed += w * half * f;
            }
        }
        (
            sum * inv_samples + self.gauss[i].mass_inside(rect),
            signed * inv_samples,
        )
    }

    /// Pixel i's coefficient and half-difference, as [`Self::coefficient`] gives them, with
    /// `rect`'s edge `side` at every grid point `lo + j step` (`coef.len()` of them), in one
    /// pass over its samples (see [`EdgeRamps`]).
    #[allow(clippy::too_many_arguments)]
    fn edge_coefficients(
        &self,
        i: usize,
        rect: &Rect,
        side: EdgeSide,
        lo: f32,
        step: f32,
        inv_samples: f32,
        ramps: &mut EdgeRamps,
        coef: &mut [f32],
        dev: &mut [f32],
    ) {
        ramps.clear(coef.len());
        self.add_to_ramps(self.range(i), &EdgeFrame::new(rect, side), ramps);
        ramps.values(coef, dev);
        let g = &self.gauss[i];
        for (j, (c, d)) in coef.iter_mut().zip(dev.iter_mut()).enumerate() {
            let mass = if g.is_none() {
                0.0
            } else {
                g.mass_inside(&rect.with_edge(side, lo + j as f32 * step))
            };
            *c = *c * inv_samples + mass;
            *d *= inv_samples;
        }
    }

    /// Adds the samples `range` to `ramps` as functions of the edge `frame` describes (each
    /// sample's kernel, its share across the edge's axis inside the rectangle counted);
    /// returns whether any counts anywhere on the ramps' grid.
    fn add_to_ramps(
        &self,
        range: std::ops::Range<usize>,
        frame: &EdgeFrame,
        ramps: &mut EdgeRamps,
    ) -> bool {
        let mut any = false;
        for (((p, h), &w), &half) in self.points[range.clone()]
            .iter()
            .zip(&self.cells[range.clone()])
            .zip(&self.weights[range.clone()])
            .zip(&self.halves[range])
        {
            let (x, hx, y, hy) = if frame.along_u {
                (p.x, h.x, p.y, h.y)
            } else {
                (p.y, h.y, p.x, h.x)
            };
            let across = kernel_coverage(y, hy, frame.across.0, frame.across.1);
            if across != 0.0 {
                let weight = (w * across) as f64;
                any |= ramps.add_cell(
                    frame.min_edge,
                    x,
                    hx,
                    frame.opposite,
                    weight,
                    weight * half as f64,
                );
            }
        }
        any
    }
}

// The noise of the coefficients, and why the fit must remove it.
//
// The coefficients are Monte Carlo estimates, and least squares with a noisy regressor is
// biased: sum c_hat^2 overestimates sum c^2 by the summed variance, which pulls the radiance
// low and pushes the edges to compensate (the weakly seen edges move by a percent). Each
// pixel's samples are two independent halves, A and B (the sign of a stored weight says
// which); the coefficient is (A + B) / 2 and `d = (A - B) / 2`, its half-difference, has
// E[d^2] = var(c_hat) whatever the stratification inside each half. More: for the modelled
// pixel m = sum_k L_k c_k, E[(sum_k L_k d_k)^2] = var(m_hat) including the covariances of
// lights that share samples (two pieces of one rectangle are strongly anti-correlated:
// subtracting their variances one by one would reward splitting a light in two). So the fit
// minimises sum (I - m_hat)^2 - (sum_k L_k d_k)^2, an unbiased estimate of the noise-free
// cost up to a constant, and its normal equations carry `c_a c_b - d_a d_b`.

// The cells, and why each sample is spread over a kernel.
//
// A coefficient is the lobe's mass inside a rectangle. Counted as points, the samples near an
// edge make it a step function of the edge's position, and the few strata an edge cuts each
// add a Bernoulli error: the cost is then rough on the scale of a stratum, and along the
// weakly seen directions the optimum follows that roughness (the fit's own-sample spread,
// BENCHMARKS.md). Each sample is instead spread over a small box around its landing point,
// sized by its stratum's image on the plane (`cell_half_extents`): an edge then moves
// through it continuously, and the strata an edge cuts err by far less. In expectation over
// the jitter, this estimates the lobe convolved with the kernel: a box would broaden the
// lobe (its variance h^2/3 is added, biasing edges and radiance by percents at a whole
// cell's width), so the kernel is the difference of two boxes, (4 B(h/2) - B(h)) / 3, whose
// second moment is zero and whose bias is of fourth order. Its width is half the cell's
// (`KERNEL_SCALE`): the stratum's image is linearised, and in the lobe's outer ring (most of
// the strata in the concentric map) the landing point bends fast enough across a cell that
// a wider kernel is biased again. Measured on Table 1 and 3 over 8 seeds of the fit's own
// samples (BENCHMARKS.md): light0's worst edge 0.61-0.87 % rms -> 0.20-0.27 %.

/// The fitting problem: observed pixels and every light's stored samples.
struct Problem {
    /// Photo width, to tell a fitted pixel's row.
    width: u32,
    /// Photo pixel index of every fitted pixel.
    pixel_ids: Vec<u32>,
    obs: Vec<[f32; 3]>,
    clipped: Vec<bool>,
    planes: Vec<PlaneSamples>,
    /// Per sample set, the start light whose plane it samples (a split light reads a set of
    /// its own, drawn independently on the same plane).
    set_origin: Vec<usize>,
    inv_samples: f32,
}

/// The pixels of the fitted region, water only: the lights' streaks dilated by `margin`, and
/// every other pixel near them from which the reflected rays can reach a light's region of
/// interest. The second part matters as much as the first: a streak's faint ends fall below
/// any segmentation's threshold, and a pixel the fit does not look at cannot object to a
/// light that grew into it (an edge seen only through such ends then drifts by percents).
#[allow(clippy::too_many_arguments)]
fn region(
    scene: &Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    photo: &Photo,
    water: &[bool],
    streaks: &[&StreakObservation],
    margin: u32,
    checkerboard: bool,
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
    let keep = |i: usize| water[i] && (!checkerboard || (i as i64 % w + i as i64 / w) % 2 == 0);
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
            .filter(|&i| sees_region_of_interest(scene, model, planes, roi, i, photo))
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
    scene: &Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    pixel: u32,
    photo: &Photo,
) -> bool {
    let (x, y) = (pixel % photo.width, pixel / photo.width);
    let CameraHit::Water(water) = camera_hit(
        scene,
        &[],
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
        water.reflect_direction(model, u).is_some_and(|wi| {
            planes.iter().zip(roi).any(|(plane, r)| {
                plane_point(plane, water.start, wi).is_some_and(|q| r.contains(q))
            })
        })
    })
}

/// Camera rays per side of a pixel's stratification grid: 2 x 2 jittered camera rays cover
/// the footprint evenly, and the lobe is sampled several times from each.
const CAMERA_STRATA: u32 = 2;

/// Lobe strata per side for `samples` samples per pixel. A pixel's samples are two
/// independent halves (for the variance estimate), each `CAMERA_STRATA^2` camera rays times
/// `lobe_strata^2` lobe samples, so the count is rounded to `32 b^2`. Stratifying the lobe
/// matters: a coefficient is the lobe's mass inside a rectangle, and stratified samples
/// estimate that with far less noise than independent ones, which is what lets the edges
/// settle at the photo's optimum rather than at the samples' noise; reusing each camera
/// ray's water hit for several lobe samples makes them cheap.
///
/// Within a half, the camera rays' lobe strata interleave: the half's lobe numbers form one
/// grid of `CAMERA_STRATA * lobe_strata` strata per side, and each camera ray takes every
/// `CAMERA_STRATA`-th stratum from its own offset (the offsets shuffled per half), so the
/// half is stratified four times finer than one camera ray's share (the water's normal
/// changes little across a pixel, so the rays' lobes nearly coincide). The numbers then go
/// through [`compact_strata`], which makes each stratum a compact cell around the lobe's axis
/// instead of a thin ring sector. Measured on Table 3 over six seeds of the fit's own
/// samples (BENCHMARKS.md): the edges' and radiance's spread fell by 10-50 %, for nothing.
fn lobe_strata(samples: u32) -> u32 {
    let per_ray = samples as f32 / (2 * CAMERA_STRATA * CAMERA_STRATA) as f32;
    (per_ray.sqrt().round() as u32).max(1)
}

/// Traces every pixel's samples once and stores, per light, those whose first hit is that
/// light's plane inside its region of interest `roi[k]` (a sample landing on a face shared by
/// several lights is stored for each). A sample whose ray meets no plane inside a region of
/// interest is never traced: it could not change any coefficient the fit will evaluate.
/// With the control variate (`gaussians`), a sample whose ray would meet a light's plane
/// inside its region of interest but hits something else first (or nothing: the wall ends)
/// is stored too, with the lobe's weight 0: the Gaussian it subtracts must be subtracted
/// wherever the Gaussian is, or the estimate would see light through the obstacle.
/// `repeat` and `draw` select independent random streams: `draw` 0 is the set every start
/// light reads, `draw` 1, 2, ... the sets of lights that splits added (one plane each).
#[allow(clippy::too_many_arguments)]
fn trace_samples(
    scene: &Scene,
    model: &ReflectionModel,
    planes: &[&LightPlane],
    roi: &[Rect],
    pixels: &[u32],
    width: u32,
    height: u32,
    samples: u32,
    seed: u64,
    repeat: u32,
    draw: u32,
    gaussians: bool,
) -> (Vec<PlaneSamples>, u32) {
    type Hits = (Vec<(u16, Vec2, Vec2, f32, f32)>, Vec<LobeGaussian>);
    let lobe = lobe_strata(samples);
    let per_pixel_samples = effective_samples(samples);
    let per_pixel: Vec<Hits> = pixels
        .par_iter()
        .map(|&pixel| {
            let stream = JOINT_STREAM | (draw as u64) << 52 | (repeat as u64) << 32 | pixel as u64;
            let mut rng = Rng::new(seed, stream);
            let (x, y) = (pixel % width, pixel / width);
            let mut hits = Vec::new();
            let mut missed_water = 0u32;
            // The control variates, matched to the pixel's first camera ray to meet the water
            // before any of its lobe samples is drawn: they depend on no lobe sample, so the
            // estimate keeps its expectation.
            let mut gauss: Option<Vec<LobeGaussian>> = None;
            let inv_c = 1.0 / CAMERA_STRATA as f32;
            let inv_grid = 1.0 / (lobe * CAMERA_STRATA) as f32;
            let mut offsets: Vec<u32> = (0..CAMERA_STRATA * CAMERA_STRATA).collect();
            for (cs, half_sign) in (0..2 * CAMERA_STRATA * CAMERA_STRATA).map(|i| {
                (
                    i % (CAMERA_STRATA * CAMERA_STRATA),
                    if i < CAMERA_STRATA * CAMERA_STRATA {
                        1.0
                    } else {
                        -1.0
                    },
                )
            }) {
                if cs == 0 {
                    shuffle(&mut offsets, &mut rng);
                }
                let (ox, oy) = (
                    offsets[cs as usize] % CAMERA_STRATA,
                    offsets[cs as usize] / CAMERA_STRATA,
                );
                let fx = ((cs % CAMERA_STRATA) as f32 + rng.next_f32()) * inv_c;
                let fy = ((cs / CAMERA_STRATA) as f32 + rng.next_f32()) * inv_c;
                let CameraHit::Water(water) =
                    camera_hit(scene, &[], x as f32 + fx, y as f32 + fy, width, height)
                else {
                    missed_water += 1;
                    // Draw the lobe numbers anyway, so that every camera ray of a pixel uses
                    // the same stream positions whatever the others hit.
                    for _ in 0..lobe * lobe {
                        rng.next_f32();
                        rng.next_f32();
                    }
                    continue;
                };
                let gauss = gauss.get_or_insert_with(|| {
                    if !gaussians {
                        return vec![LobeGaussian::NONE; planes.len()];
                    }
                    let (dirs, count) = control_variate::lobe_directions(model, &water);
                    planes
                        .iter()
                        .map(|plane| LobeGaussian::matched(plane, water.start, &dirs, count))
                        .collect()
                });
                for ls in 0..lobe * lobe {
                    let grid_u = Vec2::new(
                        (((ls % lobe) * CAMERA_STRATA + ox) as f32 + rng.next_f32()) * inv_grid,
                        (((ls / lobe) * CAMERA_STRATA + oy) as f32 + rng.next_f32()) * inv_grid,
                    );
                    let u = compact_strata(grid_u);
                    let Some(s) = water.reflect(model, u) else {
                        continue;
                    };
                    // The farthest plane it lands on inside a region of interest: nothing
                    // beyond it matters, so the trace stops there.
                    let reach = planes
                        .iter()
                        .zip(roi)
                        .filter_map(|(plane, r)| {
                            let t = plane_distance(plane, water.start, s.wi)?;
                            r.contains(plane.coords(water.start + s.wi * t))
                                .then_some(t)
                        })
                        .reduce(f32::max);
                    let Some(reach) = reach else {
                        continue;
                    };
                    let tmax = reach * 1.001 + 1e-3;
                    let hit = scene.tracer.closest_hit(water.start, s.wi, 0.0, tmax);
                    let mut lobe_cell = None;
                    for (k, plane) in planes.iter().enumerate() {
                        let g = &gauss[k];
                        let on_plane = hit.filter(|h| plane.contains_triangle(scene, h.triangle));
                        // Where the ray lands on the plane, how far, and the lobe's weight there.
                        let (q, t, lobe_weight) = match on_plane {
                            Some(h) => (plane.coords(water.start + s.wi * h.t), h.t, s.weight),
                            None if !g.is_none() => {
                                let Some(t) = plane_distance(plane, water.start, s.wi) else {
                                    continue;
                                };
                                let q = plane.coords(water.start + s.wi * t);
                                if !roi[k].contains(q) {
                                    continue;
                                }
                                (q, t, 0.0)
                            }
                            None => continue,
                        };
                        let lobe_cell = lobe_cell.get_or_insert_with(|| {
                            LobeNeighbours::new(model, &water, s.wi, grid_u, inv_grid)
                        });
                        let cell = cell_half_extents(lobe_cell, water.start, plane);
                        // Another light's sample on a shared wall, out of this light's
                        // reach: it could never fall in its rectangle.
                        if !roi[k].overlaps(&Rect {
                            u_min: q.x - cell.x,
                            u_max: q.x + cell.x,
                            v_min: q.y - cell.y,
                            v_max: q.y + cell.y,
                        }) {
                            continue;
                        }
                        let weight = if g.is_none() {
                            lobe_weight
                        } else {
                            // The Gaussian's density over the density the sample was drawn
                            // with, both per unit area of the plane.
                            let area_pdf = s.pdf * s.wi.dot(plane.normal).abs() / (t * t);
                            if area_pdf > 0.0 {
                                lobe_weight - g.density(q) / area_pdf
                            } else {
                                lobe_weight
                            }
                        };
                        if weight != 0.0 {
                            hits.push((k as u16, q, cell, weight, half_sign));
                        }
                    }
                }
            }
            // A camera ray that misses the water draws nothing, so nothing of the Gaussian
            // is subtracted for it: the closed-form part counts only the rays that drew.
            let drew = 1.0 - missed_water as f32 / (2 * CAMERA_STRATA * CAMERA_STRATA) as f32;
            let mut gauss = gauss.unwrap_or_else(|| vec![LobeGaussian::NONE; planes.len()]);
            for g in gauss.iter_mut() {
                g.mass *= drew;
            }
            (hits, gauss)
        })
        .collect();
    let stored = (0..planes.len())
        .map(|k| {
            let mut out = PlaneSamples {
                offsets: Vec::with_capacity(pixels.len() + 1),
                bbox: Vec::with_capacity(pixels.len()),
                points: Vec::new(),
                cells: Vec::new(),
                weights: Vec::new(),
                halves: Vec::new(),
                gauss: Vec::with_capacity(pixels.len()),
                min_size: Vec2::ZERO,
            };
            out.offsets.push(0);
            for (hits, gauss) in &per_pixel {
                out.gauss.push(gauss[k]);
                for &(kk, p, cell, w, half) in hits {
                    if kk as usize == k {
                        out.points.push(p);
                        out.cells.push(cell);
                        out.weights.push(w);
                        out.halves.push(half);
                    }
                }
                let first = *out.offsets.last().unwrap_or(&0) as usize;
                let mut bb = Rect {
                    u_min: f32::INFINITY,
                    u_max: f32::NEG_INFINITY,
                    v_min: f32::INFINITY,
                    v_max: f32::NEG_INFINITY,
                };
                for (p, h) in out.points[first..].iter().zip(&out.cells[first..]) {
                    bb.u_min = bb.u_min.min(p.x - h.x);
                    bb.u_max = bb.u_max.max(p.x + h.x);
                    bb.v_min = bb.v_min.min(p.y - h.y);
                    bb.v_max = bb.v_max.max(p.y + h.y);
                }
                out.bbox.push(bb);
                out.offsets.push(out.points.len() as u32);
            }
            out.min_size = smallest_light(&out.cells);
            out
        })
        .collect();
    (stored, per_pixel_samples)
}

/// The half-width, along the plane's axes, of the kernel a sample spreads its weight over
/// (see the note on the cells): [`KERNEL_SCALE`] of its lobe cell. The cell is the sample's
/// stratum (side `stratum` in the lobe numbers, at `grid_u` before [`compact_strata`])
/// carried to the plane through the reflection, linearised: a parallelogram with sides
/// `J e_x s` and `J e_y s` (J the derivative of the landing point by the numbers), whose
/// extent across an edge along u is matched in variance by a box of half-width
/// `sqrt(a^2 + b^2) / 2`. Where a neighbouring direction leaves the lobe or misses the plane
/// the other side's difference is used; with neither, the sample stays a point.
fn cell_half_extents(lobe: &LobeNeighbours, start: Vec3, plane: &LightPlane) -> Vec2 {
    let land = |wi: Option<Vec3>| wi.and_then(|wi| plane_point(plane, start, wi));
    let Some(here) = land(Some(lobe.here)) else {
        return Vec2::ZERO;
    };
    let side = |plus: Option<Vec3>, minus: Option<Vec3>| -> Vec2 {
        // Per unit of the stratum's side.
        let per_step = 1.0 / NEIGHBOUR_STEP;
        match (land(plus), land(minus)) {
            (Some(p), Some(m)) => (p - m) * (0.5 * per_step),
            (Some(p), None) => (p - here) * per_step,
            (None, Some(m)) => (here - m) * per_step,
            (None, None) => Vec2::ZERO,
        }
    };
    let (a, b) = (
        side(lobe.plus_x, lobe.minus_x),
        side(lobe.plus_y, lobe.minus_y),
    );
    let half = 0.5 * KERNEL_SCALE * Vec2::new(a.x.hypot(b.x), a.y.hypot(b.y));
    // A neighbour grazing the plane lands at infinity: that sample stays a point.
    if half.is_finite() {
        half
    } else {
        Vec2::ZERO
    }
}

/// How far from a sample, in strata, [`LobeNeighbours`] looks.
const NEIGHBOUR_STEP: f32 = 0.25;

/// A lobe sample's direction and those of four neighbours [`NEIGHBOUR_STEP`] of its stratum
/// away along each of the lobe numbers (`None`: outside the lobe), from which
/// [`cell_half_extents`] measures its cell on any plane.
struct LobeNeighbours {
    here: Vec3,
    plus_x: Option<Vec3>,
    minus_x: Option<Vec3>,
    plus_y: Option<Vec3>,
    minus_y: Option<Vec3>,
}

impl LobeNeighbours {
    /// For the sample of direction `here` at `grid_u` (before [`compact_strata`]) in a
    /// stratum of side `stratum`.
    fn new(
        model: &ReflectionModel,
        water: &WaterPoint,
        here: Vec3,
        grid_u: Vec2,
        stratum: f32,
    ) -> Self {
        let delta = NEIGHBOUR_STEP * stratum;
        let towards = |d: Vec2| {
            let u = (grid_u + d).clamp(Vec2::ZERO, Vec2::splat(1.0 - 1e-6));
            water.reflect_direction(model, compact_strata(u))
        };
        // Central differences over half a stratum: the cell's chord, not the map's slope at
        // the sample. In the lobe's outer ring, where the map bends, a slope (a forward
        // difference over 1/32 of a stratum) made the cells smaller and the kernels with
        // them, and the Table 3 fit's top edge moved by 0.35 % (8 seeds; a quarter-stratum
        // forward difference: 0.15 %).
        LobeNeighbours {
            here,
            plus_x: towards(Vec2::new(delta, 0.0)),
            minus_x: towards(Vec2::new(-delta, 0.0)),
            plus_y: towards(Vec2::new(0.0, delta)),
            minus_y: towards(Vec2::new(0.0, -delta)),
        }
    }
}

/// The kernel's outer box as a fraction of the sample's cell (see the note on the cells).
const KERNEL_SCALE: f32 = 0.5;

/// The fraction of the interval `[x - h, x + h]` inside `[lo, hi]` (for `h = 0`, whether `x`
/// is inside).
#[inline]
fn coverage(x: f32, h: f32, lo: f32, hi: f32) -> f32 {
    let (a, b) = (x - h, x + h);
    // Most intervals are wholly inside or outside: no division for those.
    if a >= lo && b <= hi {
        1.0
    } else if b < lo || a > hi || h <= 0.0 {
        0.0
    } else {
        ((hi.min(b) - lo.max(a)) / (2.0 * h)).clamp(0.0, 1.0)
    }
}

/// The sample kernel's mass inside `[lo, hi]`: `(4 B(h/2) - B(h)) / 3` of two boxes of
/// half-widths h/2 and h ([`coverage`]), a kernel whose second moment vanishes (see the note
/// on the cells).
#[inline]
fn kernel_coverage(x: f32, h: f32, lo: f32, hi: f32) -> f32 {
    let (a, b) = (x - h, x + h);
    if a >= lo && b <= hi {
        1.0
    } else if b < lo || a > hi {
        0.0
    } else {
        (4.0 * coverage(x, 0.5 * h, lo, hi) - coverage(x, h, lo, hi)) / 3.0
    }
}

/// Fisher-Yates shuffle from the pixel's own stream.
fn shuffle(items: &mut [u32], rng: &mut Rng) {
    for i in (1..items.len()).rev() {
        let j = ((rng.next_f32() * (i + 1) as f32) as usize).min(i);
        items.swap(i, j);
    }
}

/// Plane coordinates where the ray from `start` along `dir` meets `plane`'s front side, if it
/// does.
pub(super) fn plane_point(plane: &LightPlane, start: Vec3, dir: Vec3) -> Option<Vec2> {
    plane_distance(plane, start, dir).map(|t| plane.coords(start + dir * t))
}

/// How far along `dir` from `start` the ray meets `plane`'s front side, if it does.
fn plane_distance(plane: &LightPlane, start: Vec3, dir: Vec3) -> Option<f32> {
    let denom = dir.dot(plane.normal);
    if denom >= 0.0 {
        return None;
    }
    let t = (plane.point - start).dot(plane.normal) / denom;
    (t > 0.0).then_some(t)
}

/// Solves the nonnegative least squares `min |b - A x|^2, x >= 0` for a small dense system
/// given by its normal equations (`ata` row-major n x n, `atb`), by dropping the most negative
/// variable until none is negative (exact for the few, mostly separated lights here).
fn nnls_normal(ata: &[f64], atb: &[f64], n: usize) -> Vec<f64> {
    let mut active: Vec<bool> = vec![true; n];
    loop {
        let idx: Vec<usize> = (0..n).filter(|&i| active[i]).collect();
        let m = idx.len();
        let mut x = vec![0.0; n];
        if m == 0 {
            return x;
        }
        let mut a = vec![0.0; m * m];
        let mut b = vec![0.0; m];
        for (r, &i) in idx.iter().enumerate() {
            b[r] = atb[i];
            for (c, &j) in idx.iter().enumerate() {
                a[r * m + c] = ata[i * n + j];
            }
            // A light whose rectangle receives no sample has a zero row: keep it solvable.
            a[r * m + r] += 1e-12 * (1.0 + ata[i * n + i]);
        }
        let sol = solve(&mut a, &mut b, m);
        for (r, &i) in idx.iter().enumerate() {
            x[i] = sol[r];
        }
        let worst = idx
            .iter()
            .copied()
            .filter(|&i| x[i] < 0.0)
            .min_by(|&a, &b| x[a].total_cmp(&x[b]));
        match worst {
            Some(i) => active[i] = false,
            None => return x,
        }
    }
}

/// Gaussian elimination with partial pivoting (small dense systems).
fn solve(a: &mut [f64], b: &mut [f64], n: usize) -> Vec<f64> {
    for col in 0..n {
        let piv = (col..n)
            .max_by(|&i, &j| a[i * n + col].abs().total_cmp(&a[j * n + col].abs()))
            .unwrap_or(col);
        if piv != col {
            for c in 0..n {
                a.swap(col * n + c, piv * n + c);
            }
            b.swap(col, piv);
        }
        let d = a[col * n + col];
        if d.abs() < 1e-300 {
            continue;
        }
        for r in col + 1..n {
            let f = a[r * n + col] / d;
            if f != 0.0 {
                for c in col..n {
                    a[r * n + c] -= f * a[col * n + c];
                }
                b[r] -= f * b[col];
            }
        }
    }
    let mut x = vec![0.0; n];
    for r in (0..n).rev() {
        let mut s = b[r];
        for c in r + 1..n {
            s -= a[r * n + c] * x[c];
        }
        let d = a[r * n + r];
        x[r] = if d.abs() < 1e-300 { 0.0 } else { s / d };
    }
    x
}

/// Inverse of a small symmetric positive matrix (for the radiance covariance); `None` when
/// singular.
fn invert(m: &[f64], n: usize) -> Option<Vec<f64>> {
    let mut inv = vec![0.0; n * n];
    for j in 0..n {
        let mut a = m.to_vec();
        let mut e = vec![0.0; n];
        e[j] = 1.0;
        let col = solve(&mut a, &mut e, n);
        for i in 0..n {
            if !col[i].is_finite() {
                return None;
            }
            inv[i * n + j] = col[i];
        }
    }
    Some(inv)
}

#[derive(Clone)]
struct State {
    /// Per light, which stored sample set (plane) it reads: lights split from one start
    /// share their plane's samples.
    set_of: Vec<usize>,
    /// Per light and edge: held where it is (an edge no pixel looks at).
    pinned: Vec<[bool; 4]>,
    rects: Vec<Rect>,
    radiance: Vec<[f64; 3]>,
    /// `coef[k][i]`: light k's coefficient at fitted pixel i with the current rectangle.
    coef: Vec<Vec<f32>>,
    /// `dev[k][i]`: that estimate's half-difference (see the note on the coefficients' noise).
    dev: Vec<Vec<f32>>,
}

impl Problem {
    fn n(&self) -> usize {
        self.obs.len()
    }

    fn coefficients(&self, set: usize, rect: &Rect) -> (Vec<f32>, Vec<f32>) {
        (0..self.n())
            .into_par_iter()
            .map(|i| self.planes[set].coefficient(i, rect, self.inv_samples))
            .unzip()
    }

    /// Per pixel, the derivative of sample set `set`'s coefficient and of its half-difference
    /// by one edge, as the central difference between the rectangles `plus` and `minus` (which
    /// differ in that edge alone, by `2 h`). Only pixels with a sample in the strip between
    /// them are computed: the others' coefficients are the same for both, their derivatives 0.
    fn edge_slopes(&self, set: usize, plus: &Rect, minus: &Rect, h: f32) -> (Vec<f32>, Vec<f32>) {
        let samples = &self.planes[set];
        let strip = changed_strip(plus, minus);
        (0..self.n())
            .into_par_iter()
            .map(|i| {
                if !touches(&samples.bbox[i], strip) {
                    // The Gaussian alone can reach the strip: its exact mass, no samples.
                    let g = &samples.gauss[i];
                    if g.is_none() || !touches(&g.reach(), strip) {
                        return (0.0, 0.0);
                    }
                    return (
                        (g.mass_inside(plus) - g.mass_inside(minus)) / (2.0 * h),
                        0.0,
                    );
                }
                let (p, p_dev) = samples.coefficient(i, plus, self.inv_samples);
                let (m, m_dev) = samples.coefficient(i, minus, self.inv_samples);
                ((p - m) / (2.0 * h), (p_dev - m_dev) / (2.0 * h))
            })
            .unzip()
    }

    /// Moves light k to `rect`, recomputing only the coefficients of pixels with a sample
    /// where the old and the new rectangle differ (a one-edge move touches a thin strip).
    fn set_rect(&self, st: &mut State, k: usize, rect: Rect) {
        let old = st.rects[k];
        st.rects[k] = rect;
        let samples = &self.planes[st.set_of[k]];
        let strip = changed_strip(&old, &rect);
        let inv = self.inv_samples;
        st.coef[k]
            .par_iter_mut()
            .zip(st.dev[k].par_iter_mut())
            .enumerate()
            .for_each(|(i, (c, v))| {
                if touches(&samples.bbox[i], strip) {
                    (*c, *v) = samples.coefficient(i, &rect, inv);
                } else {
                    // Only the Gaussian can reach the strip: update its exact mass, without
                    // going through the samples (in f64; the f32 rounding this repeats is
                    // far below the samples' noise).
                    let g = &samples.gauss[i];
                    if !g.is_none() && touches(&g.reach(), strip) {
                        *c = (*c as f64 - g.mass_inside(&old) as f64 + g.mass_inside(&rect) as f64)
                            as f32;
                    }
                }
            });
    }

    fn model(&self, st: &State, i: usize) -> [f64; 3] {
        let mut m = [0.0; 3];
        for (k, l) in st.radiance.iter().enumerate() {
            let c = st.coef[k][i] as f64;
            for ch in 0..3 {
                m[ch] += l[ch] * c;
            }
        }
        m
    }

    /// Residual sum of squares (clipped pixels only where the model is below them), less the
    /// coefficients' own noise (see the note on it).
    fn cost(&self, st: &State) -> f64 {
        self.residual_squares(st, true)
    }

    /// The plain residual sum of squares, the coefficients' noise left in.
    fn raw_cost(&self, st: &State) -> f64 {
        self.residual_squares(st, false)
    }

    fn residual_squares(&self, st: &State, remove_noise: bool) -> f64 {
        (0..self.n())
            .map(|i| {
                let m = self.model(st, i);
                (0..3)
                    .map(|c| {
                        let r = self.obs[i][c] as f64 - m[c];
                        if self.clipped[i] && r < 0.0 {
                            0.0
                        } else if remove_noise {
                            let d: f64 = st
                                .radiance
                                .iter()
                                .enumerate()
                                .map(|(k, l)| l[c] * st.dev[k][i] as f64)
                                .sum();
                            r * r - d * d
                        } else {
                            r * r
                        }
                    })
                    .sum::<f64>()
            })
            .sum()
    }

    /// Whether the residual is structured along rows: for noise independent from pixel to
    /// pixel the row-summed cost is about the plain one, a light missing from the model
    /// makes it many times larger (Table 1's fit: 1.05; two stacked lights fitted as one:
    /// 15).
    fn structured(&self, st: &State) -> bool {
        self.row_cost(st) > SPLIT_STRUCTURE_RATIO * self.raw_cost(st)
    }

    /// The residual summed over each image row, squared and summed: a misfit that persists
    /// along rows (one light where there are two) grows with the row's pixel count squared,
    /// the noise only with the count, so the comparison is not at the noise's mercy.
    fn row_cost(&self, st: &State) -> f64 {
        let mut rows: std::collections::BTreeMap<u32, [f64; 3]> = Default::default();
        for i in 0..self.n() {
            if self.clipped[i] {
                continue;
            }
            let m = self.model(st, i);
            let row = rows.entry(self.pixel_ids[i] / self.width).or_default();
            for c in 0..3 {
                row[c] += self.obs[i][c] as f64 - m[c];
            }
        }
        rows.values().flatten().map(|r| r * r).sum()
    }

    /// Re-solves every radiance given the rectangles: per channel, nonnegative least squares
    /// over the pixels, a clipped pixel included only while the model stays below it.
    fn solve_radiance(&self, st: &mut State) {
        let k = st.rects.len();
        let mut include: Vec<bool> = self.clipped.iter().map(|c| !c).collect();
        for _round in 0..3 {
            for ch in 0..3 {
                let mut ata = vec![0.0; k * k];
                let mut atb = vec![0.0; k];
                let mut raw_diag = vec![0.0; k];
                for i in (0..self.n()).filter(|&i| include[i]) {
                    for a in 0..k {
                        let ca = st.coef[a][i] as f64;
                        if ca == 0.0 {
                            continue;
                        }
                        atb[a] += ca * self.obs[i][ch] as f64;
                        let da = st.dev[a][i] as f64;
                        for b in 0..k {
                            ata[a * k + b] += ca * st.coef[b][i] as f64 - da * st.dev[b][i] as f64;
                        }
                        raw_diag[a] += ca * ca;
                    }
                }
                for a in 0..k {
                    // As in the edge profile: never trust less than half the raw term.
                    ata[a * k + a] = ata[a * k + a].max(0.5 * raw_diag[a]);
                }
                let x = nnls_normal(&ata, &atb, k);
                for (l, xa) in st.radiance.iter_mut().zip(&x) {
                    l[ch] = *xa;
                }
            }
            let mut changed = false;
            for i in (0..self.n()).filter(|&i| self.clipped[i]) {
                let m = self.model(st, i);
                let below = (0..3).any(|c| m[c] < self.obs[i][c] as f64);
                if below != include[i] {
                    include[i] = below;
                    changed = true;
                }
            }
            if !changed {
                break;
            }
        }
    }

    /// At pixel i, the other lights' model and their combined half-difference, per channel.
    fn others(&self, st: &State, k: usize, i: usize) -> ([f64; 3], [f64; 3]) {
        let (mut rest, mut rest_dev) = ([0f64; 3], [0f64; 3]);
        for (kk, l) in st.radiance.iter().enumerate() {
            if kk != k {
                let (c, d) = (st.coef[kk][i] as f64, st.dev[kk][i] as f64);
                for ch in 0..3 {
                    rest[ch] += l[ch] * c;
                    rest_dev[ch] += l[ch] * d;
                }
            }
        }
        (rest, rest_dev)
    }

    /// The sums of [`Problem::edge_profile`] over the fitted pixels `chunk`.
    #[allow(clippy::too_many_arguments)]
    fn profile_sums(
        &self,
        st: &State,
        k: usize,
        side: EdgeSide,
        lo: f32,
        step: f32,
        grid: usize,
        chunk: &[usize],
    ) -> ProfileSums {
        let rect = st.rects[k];
        let plane = &self.planes[st.set_of[k]];
        let mut a = vec![0f64; grid];
        let mut a_raw = vec![0f64; grid];
        let mut b = vec![[0f64; 3]; grid];
        let mut cvals = vec![0f32; grid];
        let mut half_difference = vec![0f32; grid];
        let mut ramps = EdgeRamps::new(lo, step, grid);
        // Clipped pixels need the whole c(t) to apply their one-sided residual later.
        let mut clipped_rows: Vec<(usize, Vec<f32>)> = Vec::new();
        let mut flat = FlatSums::default();
        let hi = lo + step * (grid - 1) as f32;
        let frame = EdgeFrame::new(&rect, side);
        let (along_u, min_edge, opp) = (frame.along_u, frame.min_edge, frame.opposite);
        let (o_lo, o_hi) = frame.across;
        for &i in chunk {
            let r = plane.range(i);
            let g = plane.gauss[i];
            if r.is_empty() && g.is_none() {
                continue;
            }
            let bb = plane.bbox[i];
            let (bmin, bmax) = if along_u {
                (bb.u_min, bb.u_max)
            } else {
                (bb.v_min, bb.v_max)
            };
            // The Gaussian's mass inside the rectangle as the edge moves: its share across
            // the edge is fixed, along it a difference of distribution functions. Wherever it
            // changes at all it is counted exactly: treating small changes as none made the
            // profiles disagree with the coefficients they stand for, and the descent took
            // more sweeps to a worse end (Table 3, threshold 1e-4 of the lobe).
            let (g_across, g_mean, g_sd) = if g.is_none() {
                (0.0, 0.0, 1.0)
            } else if along_u {
                (g.share_v(o_lo, o_hi), g.mean.x, g.sd.x)
            } else {
                (g.share_u(o_lo, o_hi), g.mean.y, g.sd.y)
            };
            let gauss_varies = !g.is_none()
                && g_across * control_variate::normal_between(lo, hi, g_mean, g_sd) > 0.0;
            let samples_reach = !(bmax < lo || bmin > hi);
            // Its coefficient and half-difference, when they are the same at every grid point.
            let same_everywhere = |c: f64, d: f64, flat: &mut FlatSums| {
                if c != 0.0 {
                    let (rest, rest_dev) = self.others(st, k, i);
                    flat.a_raw += c * c;
                    flat.a += c * c - d * d;
                    for ch in 0..3 {
                        flat.b[ch] += c * (self.obs[i][ch] as f64 - rest[ch]) + d * rest_dev[ch];
                    }
                }
            };
            if !samples_reach && !gauss_varies && !self.clipped[i] {
                // Nothing of this pixel's coefficient changes over the window.
                same_everywhere(st.coef[k][i] as f64, st.dev[k][i] as f64, &mut flat);
                continue;
            }
            ramps.clear(grid);
            let mut any = false;
            if !samples_reach && !self.clipped[i] {
                // Only the Gaussian moves: the samples' part is what it is now.
                let inv = self.inv_samples as f64;
                let sampled = st.coef[k][i] as f64 - g.mass_inside(&rect) as f64;
                let dev = st.dev[k][i] as f64 / inv;
                ramps.constant(sampled / inv, dev);
                any = true;
            }
            let r = if samples_reach || self.clipped[i] {
                r
            } else {
                0..0
            };
            if plane.add_to_ramps(r, &frame, &mut ramps) {
                any = true;
            }
            if !any && !gauss_varies && !self.clipped[i] {
                same_everywhere(g.mass_inside(&rect) as f64, 0.0, &mut flat);
                continue;
            }
            if !ramps.kinked && !self.clipped[i] && !gauss_varies {
                // Every kernel it has lies wholly on one side of the window.
                let [c, d] = ramps.constant;
                let inv = self.inv_samples as f64;
                let c = c * inv + g.mass_inside(&rect) as f64;
                same_everywhere(c, d * inv, &mut flat);
                continue;
            }
            ramps.values(&mut cvals, &mut half_difference);
            if gauss_varies {
                let scale = (g.mass as f64 * g_across / self.inv_samples as f64) as f32;
                let at_opp = control_variate::normal_cdf(opp, g_mean, g_sd);
                for (j, c) in cvals.iter_mut().enumerate() {
                    let at_t = control_variate::normal_cdf(lo + step * j as f32, g_mean, g_sd);
                    let inside = if min_edge {
                        at_opp - at_t
                    } else {
                        at_t - at_opp
                    };
                    *c += scale * inside.max(0.0) as f32;
                }
            } else if !g.is_none() {
                let a = g.mass_inside(&rect) / self.inv_samples;
                for c in cvals.iter_mut() {
                    *c += a;
                }
            }
            let (rest, rest_dev) = self.others(st, k, i);
            let res = [0, 1, 2].map(|ch| self.obs[i][ch] as f64 - rest[ch]);
            if self.clipped[i] {
                clipped_rows.push((i, cvals.iter().map(|c| c * self.inv_samples).collect()));
                continue;
            }
            for j in 0..grid {
                let cf = cvals[j] * self.inv_samples;
                let c = cf as f64;
                a_raw[j] += c * c;
                let d = (half_difference[j] * self.inv_samples) as f64;
                a[j] += c * c - d * d;
                for ch in 0..3 {
                    b[j][ch] += c * res[ch] + d * rest_dev[ch];
                }
            }
        }
        ProfileSums {
            a,
            a_raw,
            b,
            flat,
            clipped_rows,
        }
    }

    /// The cost, as a function of one edge of light `k` on the grid `lo + j * step`
    /// (`j < grid`), with light k's radiance re-optimised (closed form, nonnegative) at every
    /// grid point and the other lights held. Returns per grid point (cost up to a constant,
    /// the radiance).
    fn edge_profile(
        &self,
        st: &State,
        k: usize,
        side: EdgeSide,
        lo: f32,
        step: f32,
        grid: usize,
    ) -> Vec<(f64, [f64; 3])> {
        // Fixed chunks summed in order: the same sums whatever the thread count.
        let parts: Vec<ProfileSums> = (0..self.n())
            .collect::<Vec<_>>()
            .par_chunks(PROFILE_CHUNK)
            .map(|chunk| self.profile_sums(st, k, side, lo, step, grid, chunk))
            .collect();
        let mut a = vec![0f64; grid];
        let mut a_raw = vec![0f64; grid];
        let mut b = vec![[0f64; 3]; grid];
        let mut clipped_rows: Vec<(usize, Vec<f32>)> = Vec::new();
        for part in parts {
            for j in 0..grid {
                a[j] += part.a[j] + part.flat.a;
                a_raw[j] += part.a_raw[j] + part.flat.a_raw;
                for ((total, here), flat) in b[j].iter_mut().zip(part.b[j]).zip(part.flat.b) {
                    *total += here + flat;
                }
            }
            clipped_rows.extend(part.clipped_rows);
        }
        // Pixels with no sample of light k contribute a constant, left out.
        // A rectangle that catches only a few samples has a variance as large as its mean
        // square: the corrected normal equation would divide by ~0. Keep at least half of the
        // raw term (the bias then stays bounded, and such a rectangle is far from the optimum).
        for j in 0..grid {
            a[j] = a[j].max(0.5 * a_raw[j]);
        }
        (0..grid)
            .map(|j| {
                let l = [0, 1, 2].map(|ch| {
                    if a[j] > 0.0 {
                        (b[j][ch] / a[j]).max(0.0)
                    } else {
                        0.0
                    }
                });
                // sum (r - L c)^2 - sum r^2 = L^2 A - 2 L B
                let mut cost: f64 = (0..3)
                    .map(|ch| l[ch] * l[ch] * a[j] - 2.0 * l[ch] * b[j][ch])
                    .sum();
                for (i, cs) in &clipped_rows {
                    let c = cs[j] as f64;
                    for ch in 0..3 {
                        let rest: f64 = st
                            .radiance
                            .iter()
                            .enumerate()
                            .filter(|(kk, _)| *kk != k)
                            .map(|(kk, lr)| lr[ch] * st.coef[kk][*i] as f64)
                            .sum();
                        let r = self.obs[*i][ch] as f64 - rest - l[ch] * c;
                        let r0 = self.obs[*i][ch] as f64 - rest;
                        let now = if r < 0.0 { 0.0 } else { r * r };
                        let before = if r0 < 0.0 { 0.0 } else { r0 * r0 };
                        cost += now - before;
                    }
                }
                (cost, l)
            })
            .collect()
    }
}

/// The region where two rectangles differing in one edge differ; `None` when they differ in
/// more (then every coefficient is recomputed).
fn changed_strip(a: &Rect, b: &Rect) -> Option<Rect> {
    let du = (a.u_min != b.u_min, a.u_max != b.u_max);
    let dv = (a.v_min != b.v_min, a.v_max != b.v_max);
    let changed = [du.0, du.1, dv.0, dv.1].iter().filter(|&&d| d).count();
    match changed {
        0 => Some(Rect {
            u_min: f32::INFINITY,
            u_max: f32::NEG_INFINITY,
            v_min: f32::INFINITY,
            v_max: f32::NEG_INFINITY,
        }),
        1 => {
            let (lo_u, hi_u) = (a.u_min.min(b.u_min), a.u_max.max(b.u_max));
            let (lo_v, hi_v) = (a.v_min.min(b.v_min), a.v_max.max(b.v_max));
            Some(if du.0 {
                Rect {
                    u_min: lo_u,
                    u_max: a.u_min.max(b.u_min),
                    v_min: lo_v,
                    v_max: hi_v,
                }
            } else if du.1 {
                Rect {
                    u_min: a.u_max.min(b.u_max),
                    u_max: hi_u,
                    v_min: lo_v,
                    v_max: hi_v,
                }
            } else if dv.0 {
                Rect {
                    u_min: lo_u,
                    u_max: hi_u,
                    v_min: lo_v,
                    v_max: a.v_min.max(b.v_min),
                }
            } else {
                Rect {
                    u_min: lo_u,
                    u_max: hi_u,
                    v_min: a.v_max.min(b.v_max),
                    v_max: hi_v,
                }
            })
        }
        _ => None,
    }
}

/// Whether a pixel whose samples' kernels span `bbox` has one in `strip` (`None`: anywhere,
/// the change is not a strip).
fn touches(bbox: &Rect, strip: Option<Rect>) -> bool {
    strip.is_none_or(|s| {
        bbox.u_max >= s.u_min
            && bbox.u_min <= s.u_max
            && bbox.v_max >= s.v_min
            && bbox.v_min <= s.v_max
    })
}

/// Half-extent given to a sample whose cell could not be measured, metres: a point, for
/// every purpose, but with a slope the ramps can hold.
const POINT_CELL: f32 = 1e-6;

/// One pixel's coefficient as a function of an edge's position on the grid
/// `t_j = lo + j step`. Each sample's kernel contributes a piecewise linear function of t: a
/// constant and ramps `s max(t - kink, 0)`. A ramp is accumulated at the first grid point
/// past its kink as its slope `s` and `s kink`; after prefix sums the value at `t_j` is
/// `constant + t_j sum s - sum s kink`, exact and one pass over the samples. Kept for the
/// absolute weights (the coefficient) and the signed ones (its half-difference).
struct EdgeRamps {
    lo: f64,
    /// The last grid point.
    hi: f64,
    step: f64,
    inv_step: f64,
    constant: [f64; 2],
    /// Whether any ramp starts at or before the last grid point (otherwise the value is
    /// `constant` everywhere).
    kinked: bool,
    slope: Vec<[f64; 2]>,
    slope_kink: Vec<[f64; 2]>,
}

impl EdgeRamps {
    fn new(lo: f32, step: f32, grid: usize) -> Self {
        EdgeRamps {
            lo: lo as f64,
            hi: lo as f64 + (grid - 1) as f64 * step as f64,
            step: step as f64,
            inv_step: 1.0 / step as f64,
            constant: [0.0; 2],
            kinked: false,
            slope: vec![[0.0; 2]; grid],
            slope_kink: vec![[0.0; 2]; grid],
        }
    }

    fn clear(&mut self, grid: usize) {
        self.constant = [0.0; 2];
        self.kinked = false;
        self.slope.clear();
        self.slope.resize(grid, [0.0; 2]);
        self.slope_kink.clear();
        self.slope_kink.resize(grid, [0.0; 2]);
    }

    fn constant(&mut self, abs: f64, signed: f64) {
        self.constant[0] += abs;
        self.constant[1] += signed;
    }

    fn kink(&mut self, at: f64, abs: f64, signed: f64) {
        let f = (at - self.lo) * self.inv_step;
        // Truncation is the floor here (f >= 0), without a call to libm's floor.
        let j = if f < 0.0 { 0 } else { f as usize + 1 };
        if let (Some(s), Some(sk)) = (self.slope.get_mut(j), self.slope_kink.get_mut(j)) {
            self.kinked = true;
            s[0] += abs;
            s[1] += signed;
            sk[0] += abs * at;
            sk[1] += signed * at;
        }
    }

    /// Adds a sample's kernel of half-width h at x along the edge's axis ([`kernel_coverage`])
    /// with its weights (absolute, signed) for a min edge (`min_edge`: the kernel counts above
    /// the edge and below `opp`, the opposite edge) or a max edge (below the edge and above
    /// `opp`). Returns whether it counts anywhere.
    fn add_cell(
        &mut self,
        min_edge: bool,
        x: f32,
        h: f32,
        opp: f32,
        abs: f64,
        signed: f64,
    ) -> bool {
        let (reach_lo, reach_hi) = (x - h.max(POINT_CELL), x + h.max(POINT_CELL));
        // Nowhere on the grid (the last grid point is below the cell, or the first above it).
        if (min_edge && (reach_hi.min(opp) as f64) <= self.lo)
            || (!min_edge && (reach_lo.max(opp) as f64) >= self.hi)
        {
            return false;
        }
        // The same at every grid point (the edge never reaches the kernel): most samples,
        // once the window is narrow.
        let beyond = if min_edge {
            (reach_lo as f64 >= self.hi).then(|| kernel_coverage(x, h, f32::NEG_INFINITY, opp))
        } else {
            (reach_hi as f64 <= self.lo).then(|| kernel_coverage(x, h, opp, f32::INFINITY))
        };
        if let Some(f) = beyond {
            self.constant(abs * f as f64, signed * f as f64);
            return f != 0.0;
        }
        if h > POINT_CELL {
            let a = self.add_box(
                min_edge,
                x,
                0.5 * h,
                opp,
                abs * 4.0 / 3.0,
                signed * 4.0 / 3.0,
            );
            let b = self.add_box(min_edge, x, h, opp, -abs / 3.0, -signed / 3.0);
            return a || b;
        }
        self.add_box(min_edge, x, h, opp, abs, signed)
    }

    /// [`add_cell`](Self::add_cell) for one box of half-width h.
    fn add_box(&mut self, min_edge: bool, x: f32, h: f32, opp: f32, abs: f64, signed: f64) -> bool {
        let h = h.max(POINT_CELL) as f64;
        let (x, opp) = (x as f64, opp as f64);
        let slope = 0.5 / h;
        if min_edge {
            // [min(x + h, opp) - max(x - h, t)]+ / 2h
            let (a, b) = (x - h, (x + h).min(opp));
            if b <= a {
                return false;
            }
            self.constant(abs * (b - a) * slope, signed * (b - a) * slope);
            self.kink(a, -abs * slope, -signed * slope);
            self.kink(b, abs * slope, signed * slope);
        } else {
            // [min(x + h, t) - max(x - h, opp)]+ / 2h
            let (a, b) = ((x - h).max(opp), x + h);
            if b <= a {
                return false;
            }
            self.kink(a, abs * slope, signed * slope);
            self.kink(b, -abs * slope, -signed * slope);
        }
        true
    }

    /// The coefficient's sum of weights (absolute, signed) at every grid point.
    fn values(&self, abs: &mut [f32], signed: &mut [f32]) {
        let (mut s, mut sk) = ([0f64; 2], [0f64; 2]);
        for (j, (a, b)) in abs.iter_mut().zip(signed.iter_mut()).enumerate() {
            for c in 0..2 {
                s[c] += self.slope[j][c];
                sk[c] += self.slope_kink[j][c];
            }
            let t = self.lo + j as f64 * self.step;
            *a = (self.constant[0] + t * s[0] - sk[0]) as f32;
            *b = (self.constant[1] + t * s[1] - sk[1]) as f32;
        }
    }
}

/// Pixels per parallel piece of an edge profile.
const PROFILE_CHUNK: usize = 2048;

/// Per grid point of an edge profile: the normal-equation sums over some pixels, and the
/// clipped pixels' coefficients (they enter the cost one-sidedly, so they are kept whole).
struct ProfileSums {
    a: Vec<f64>,
    a_raw: Vec<f64>,
    b: Vec<[f64; 3]>,
    /// The same at every grid point (pixels with no sample in the window), kept once.
    flat: FlatSums,
    clipped_rows: Vec<(usize, Vec<f32>)>,
}

/// Normal-equation sums that do not depend on the edge's grid position.
#[derive(Default)]
struct FlatSums {
    a: f64,
    a_raw: f64,
    b: [f64; 3],
}

/// The smallest width and height of a light whose samples' kernels have the half-widths
/// `cells`: twice the median half-width along each axis, the kernels' typical full width (a
/// few millimetres when the cells are points). A narrower rectangle is seen only through the
/// kernels' shape (its coefficient is the kernels' density where it lies, negative lobes
/// included, from the few samples near it), so its coefficients are noise out of all
/// proportion to their size, and the fit, which subtracts the estimated noise from its cost,
/// rewards exactly that: two stacked lights 1.8 m apart came out as the lower light and a
/// 1 mm sliver at 1400 times the radiance, at a cost 90 below the truth's (BENCHMARKS.md,
/// "A sliver of light"). A real light narrower than the bound (a strip light) comes out this
/// wide, with the radiance that keeps its reflection; more samples per pixel make the kernels,
/// and the bound, smaller.
fn smallest_light(cells: &[Vec2]) -> Vec2 {
    // Every 8th sample: a median needs no more, and a plane holds millions.
    let (mut xs, mut ys): (Vec<f32>, Vec<f32>) =
        cells.iter().step_by(8).map(|c| (c.x, c.y)).unzip();
    let median = |v: &mut Vec<f32>| {
        if v.is_empty() {
            return 0.0;
        }
        let mid = v.len() / 2;
        *v.select_nth_unstable_by(mid, |a, b| a.total_cmp(b)).1
    };
    Vec2::new(2.0 * median(&mut xs), 2.0 * median(&mut ys)).max(Vec2::splat(2e-3))
}

/// How far the photo could possibly move an edge: the extent of light k's stored samples.
fn sample_extent(p: &PlaneSamples) -> Option<Rect> {
    p.bbox
        .iter()
        .filter(|b| b.u_min <= b.u_max)
        .copied()
        .reduce(|a, b| Rect {
            u_min: a.u_min.min(b.u_min),
            u_max: a.u_max.max(b.u_max),
            v_min: a.v_min.min(b.v_min),
            v_max: a.v_max.max(b.v_max),
        })
}

/// Grid points of an edge profile.
const GRID: usize = 65;
/// Smallest search half-window, metres: its grid's step (1/32 of it) is far under the 0.5 %
/// of a metre-sized light asked for. 1 mm rather than 0.2 mm: three sweeps fewer on Table
/// 3, the same errors over 8 seeds (BENCHMARKS.md, ninth session).
const MIN_WINDOW: f32 = 1e-3;
/// Factor by which an edge's search window shrinks per sweep (unless the edge is still
/// travelling). The new window keeps 8 of the old grid's steps either side of the best
/// point, and the cost is smooth on that scale (see the note on the cells): halving instead
/// took 14 sweeps rather than 8 for the same result (Table 1 and 3, 8 seeds each).
const WINDOW_SHRINK: f32 = 0.25;

/// Half-width of the first search window around a start edge: half the light's size, at
/// least 0.5 m, so that an estimate a light's size off is still inside the first grid.
fn first_window(r: &Rect) -> f32 {
    (0.5 * r.width().max(r.height())).max(0.5)
}

/// Where on its plane a light's edges may go during the fit: the start rectangle grown by
/// the first search window and a little more. Samples landing outside it are never traced.
fn region_of_interest(start: &Rect) -> Rect {
    let grow = 1.25 * first_window(start);
    Rect {
        u_min: start.u_min - grow,
        u_max: start.u_max + grow,
        v_min: start.v_min - grow,
        v_max: start.v_max + grow,
    }
}

/// Refines `start` (typically the paper's per-streak estimate) by fitting all lights together
/// to every water pixel of their streaks and surroundings (see the module doc).
///
/// `streaks` must hold the streaks named by the lights' `streak_ids` (their pixels, dilated,
/// are the fitted region). The lights' planes are kept; edges and radiances are refitted.
pub fn fit_joint(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    start: &[FittedLight],
    options: &JointOptions,
) -> Result<JointOutcome> {
    super::check_sizes(photo, water)?;
    let n_all = photo.width as usize * photo.height as usize;
    if options.samples == 0 {
        return Err(Error::Usage(
            "the joint fit needs at least one sample per pixel".into(),
        ));
    }
    if options.repeats == 0 {
        return Err(Error::Usage(
            "the joint fit needs at least one repeat".into(),
        ));
    }
    if start.is_empty() {
        return Ok(JointOutcome {
            lights: Vec::new(),
            uncertainty: Vec::new(),
            pixels: 0,
            residual_variance: 0.0,
            cost: 0.0,
            timings: Vec::new(),
        });
    }
    let used: Vec<&StreakObservation> = streaks
        .iter()
        .filter(|s| start.iter().any(|l| l.streak_ids.contains(&s.id)))
        .collect();
    if let Some(s) = used
        .iter()
        .find(|s| s.pixels.iter().any(|&p| p as usize >= n_all))
    {
        return Err(Error::Usage(format!(
            "streak {} holds a pixel outside the {} x {} photo",
            s.id, photo.width, photo.height
        )));
    }
    let t0 = Instant::now();
    let planes: Vec<&LightPlane> = start.iter().map(|l| &l.plane).collect();
    let roi: Vec<Rect> = start
        .iter()
        .map(|l| region_of_interest(&l.rect()))
        .collect();
    let probe_model = ReflectionModel {
        gloss: options.region_gloss.unwrap_or(options.model.gloss),
        ..options.model
    };
    let pixels = region(
        scene,
        &probe_model,
        &planes,
        &roi,
        photo,
        water,
        &used,
        options.margin,
        options.checkerboard,
    );
    let trace = |planes: &[&LightPlane], roi: &[Rect], repeat: u32, draw: u32| {
        trace_samples(
            scene,
            &options.model,
            planes,
            roi,
            &pixels,
            photo.width,
            photo.height,
            options.samples,
            options.seed,
            repeat,
            draw,
            options.control_variate,
        )
    };
    let problem_for = |repeat: u32| {
        let (stored, per_pixel_samples) = trace(&planes, &roi, repeat, 0);
        Problem {
            width: photo.width,
            pixel_ids: pixels.clone(),
            obs: pixels.iter().map(|&p| photo.radiance[p as usize]).collect(),
            clipped: pixels.iter().map(|&p| photo.clipped[p as usize]).collect(),
            planes: stored,
            set_origin: (0..planes.len()).collect(),
            inv_samples: 1.0 / per_pixel_samples as f32,
        }
    };
    // Seconds spent tracing the split lights' own sample sets (footprints, not optimisation).
    let fresh_seconds = std::cell::Cell::new(0.0);
    // The `draw`-th extra sample set of repeat `repeat`, on start light `origin`'s plane,
    // independent of every other set.
    let fresh_set = |repeat: u32, origin: usize, draw: u32| {
        let t = Instant::now();
        let (mut stored, _) = trace(&[planes[origin]], &[roi[origin]], repeat, draw);
        fresh_seconds.set(fresh_seconds.get() + t.elapsed().as_secs_f64());
        // One plane in, one set out.
        stored.swap_remove(0)
    };
    let mut problem = problem_for(0);
    let mut footprint_seconds = t0.elapsed().as_secs_f64();
    let t1 = Instant::now();
    let mut extents: Vec<Option<Rect>> = problem.planes.iter().map(sample_extent).collect();
    let (first, replay) = optimise(
        &mut problem,
        start,
        &mut extents,
        options.sweeps,
        options.split,
        &|origin, draw| fresh_set(0, origin, draw),
    );
    let mut optimise_seconds = t1.elapsed().as_secs_f64();
    let mut repeats = vec![(first.rects.clone(), first.radiance.clone())];
    for repeat in 1..options.repeats {
        if let Some(say) = options.progress {
            say(&format!(
                "joint fit: repeat {} of {} (independent samples)",
                repeat + 1,
                options.repeats
            ));
        }
        let t = Instant::now();
        let mut again = problem_for(repeat);
        footprint_seconds += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut extents: Vec<Option<Rect>> = again.planes.iter().map(sample_extent).collect();
        let extra_origins = &problem.set_origin[start.len()..];
        let st = again.replay(
            &replay,
            extra_origins,
            &mut extents,
            options.sweeps,
            &|origin, draw| fresh_set(repeat, origin, draw),
        );
        repeats.push((st.rects, st.radiance));
        optimise_seconds += t.elapsed().as_secs_f64();
    }
    footprint_seconds += fresh_seconds.get();
    optimise_seconds -= fresh_seconds.get();
    let t2 = Instant::now();
    let (st, spread) = if repeats.len() == 1 {
        // One fit: the curvature alone (see `uncertainties`). Until the control variate, the
        // samples' own noise moved the fit further than the curvature said, and the spread of
        // two refits, one from each half of the samples, was added; with it, the curvature
        // alone covers the errors (8 seeds through the pipeline: Table 3 0.5-1.3 sigma rms,
        // largest 2.1; the stacked sample 0.3-1.2, largest 1.8), and the refits, 0.7 s of
        // Table 3's fit, only widened the sigmas further (BENCHMARKS.md, ninth session).
        (first, None)
    } else {
        let (rects, radiance, spread) = mean_and_spread(&repeats);
        let st = problem.state(
            first.set_of.clone(),
            first.pinned.clone(),
            rects,
            radiance.clone(),
        );
        // The mean's radiances, not the ones the first fit's samples would give its edges.
        (State { radiance, ..st }, Some(spread))
    };
    let cost = problem.cost(&st);
    let dof = (problem.n() * 3).saturating_sub(7 * st.rects.len()).max(1) as f64;
    let variance = (cost / dof).max(f64::MIN_POSITIVE);
    let mut uncertainty = uncertainties(&problem, &st, &extents);
    // The repeats' spread, where there are several, adds to the curvature's.
    for (u, (edges, radiance)) in uncertainty.iter_mut().zip(spread.into_iter().flatten()) {
        u.edges = [0, 1, 2, 3].map(|e| u.edges[e].map(|sd| sd.hypot(edges[e])));
        u.radiance = [0, 1, 2].map(|c| u.radiance[c].hypot(radiance[c]));
    }
    optimise_seconds += t2.elapsed().as_secs_f64();
    let facing = facing_edges(&problem, &st);
    let lights = (0..st.rects.len())
        .map(|k| {
            let origin = &start[problem.set_origin[st.set_of[k]]];
            let (r, rad) = (st.rects[k], st.radiance[k]);
            let mut edges = origin.edges.clone();
            for side in EdgeSide::ALL {
                if facing[k][side as usize] {
                    edges[side as usize] = EdgeStatus::Unconstrained {
                        reason: FACING_REASON.into(),
                        unseen: false,
                    };
                }
            }
            FittedLight {
                streak_ids: origin.streak_ids.clone(),
                plane: origin.plane.clone(),
                u_min: r.u_min,
                u_max: r.u_max,
                v_min: r.v_min,
                v_max: r.v_max,
                radiance: rad.map(|c| c as f32),
                edges,
            }
        })
        .collect();
    Ok(JointOutcome {
        lights,
        uncertainty,
        pixels: pixels.len(),
        residual_variance: variance,
        cost,
        timings: vec![
            ("footprints".into(), footprint_seconds),
            ("optimise".into(), optimise_seconds),
        ],
    })
}

/// Per light, the mean rectangle and radiance of several independent fits, and the standard
/// error of each mean (edges in metres, radiance per channel): the fits' sample standard
/// deviation over the square root of their count.
#[allow(clippy::type_complexity)]
fn mean_and_spread(
    fits: &[(Vec<Rect>, Vec<[f64; 3]>)],
) -> (Vec<Rect>, Vec<[f64; 3]>, Vec<([f32; 4], [f32; 3])>) {
    let n = fits.len() as f64;
    let lights = fits[0].0.len();
    let mut rects = Vec::with_capacity(lights);
    let mut radiance = Vec::with_capacity(lights);
    let mut spread = Vec::with_capacity(lights);
    let mean_and_error = |values: &[f64]| {
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, (var / n).sqrt())
    };
    for k in 0..lights {
        let edges = EdgeSide::ALL.map(|side| {
            let values: Vec<f64> = fits.iter().map(|f| f.0[k].edge(side) as f64).collect();
            mean_and_error(&values)
        });
        let channels = [0, 1, 2].map(|c| {
            let values: Vec<f64> = fits.iter().map(|f| f.1[k][c]).collect();
            mean_and_error(&values)
        });
        rects.push(Rect {
            u_min: edges[0].0 as f32,
            u_max: edges[1].0 as f32,
            v_min: edges[2].0 as f32,
            v_max: edges[3].0 as f32,
        });
        radiance.push(channels.map(|c| c.0));
        spread.push((edges.map(|e| e.1 as f32), channels.map(|c| c.1 as f32)));
    }
    (rects, radiance, spread)
}

/// A light's rectangle clamped into the region its samples can see (an unconstrained edge
/// of the paper fit may sit far beyond it).
fn clamp_to(r: Rect, extent: Option<Rect>) -> Rect {
    match extent {
        Some(e) => {
            let u_min = r.u_min.clamp(e.u_min, e.u_max);
            let v_min = r.v_min.clamp(e.v_min, e.v_max);
            Rect {
                u_min,
                u_max: r.u_max.clamp(u_min, e.u_max),
                v_min,
                v_max: r.v_max.clamp(v_min, e.v_max),
            }
        }
        None => r,
    }
}

impl Problem {
    /// A state with these lights, their coefficients computed and radiances solved.
    fn state(
        &self,
        set_of: Vec<usize>,
        pinned: Vec<[bool; 4]>,
        rects: Vec<Rect>,
        radiance: Vec<[f64; 3]>,
    ) -> State {
        let (coef, dev) = rects
            .iter()
            .zip(&set_of)
            .map(|(r, &set)| self.coefficients(set, r))
            .unzip();
        let mut st = State {
            set_of,
            pinned,
            rects,
            radiance,
            coef,
            dev,
        };
        self.solve_radiance(&mut st);
        st
    }

    /// Coordinate descent over every free edge (see the module doc) for at most `sweeps`
    /// sweeps, stopping early once every search window has shrunk to its minimum.
    fn descend(&self, st: &mut State, extents: &[Option<Rect>], sweeps: u32) {
        // Initial half-windows: see `first_window`.
        let mut windows: Vec<[f32; 4]> = st.rects.iter().map(|r| [first_window(r); 4]).collect();
        let grid = GRID;
        for _sweep in 0..sweeps {
            for k in 0..st.rects.len() {
                let Some(ext) = extents[st.set_of[k]] else {
                    continue;
                };
                for side in EdgeSide::ALL {
                    if st.pinned[k][side as usize] {
                        windows[k][side as usize] = 0.0;
                        continue;
                    }
                    let half = windows[k][side as usize];
                    let cur = st.rects[k].edge(side);
                    let min_size = self.planes[st.set_of[k]].min_size;
                    let (lo, hi) = edge_bounds(&st.rects[k], side, &ext, min_size);
                    let a = (cur - half).max(lo);
                    let b = (cur + half).min(hi);
                    if b <= a {
                        windows[k][side as usize] = MIN_WINDOW;
                        continue;
                    }
                    let step = (b - a) / (grid - 1) as f32;
                    let prof = self.edge_profile(st, k, side, a, step, grid);
                    let cur_j = ((cur - a) / step).round().clamp(0.0, (grid - 1) as f32) as usize;
                    // Prefer the current position on ties (flat cost: an unconstrained edge).
                    let mut best = cur_j;
                    for (j, p) in prof.iter().enumerate() {
                        if p.0 < prof[best].0 - 1e-12 * prof[best].0.abs().max(1e-30) {
                            best = j;
                        }
                    }
                    let t = if best == cur_j {
                        cur
                    } else {
                        a + best as f32 * step
                    };
                    let moved_rect = st.rects[k].with_edge(side, t);
                    self.set_rect(st, k, moved_rect);
                    st.radiance[k] = prof[best].1;
                    // Shrink the window, but never below a few times the last move: an edge
                    // coupled to others (top and bottom trade against the radiance) keeps
                    // travelling for several sweeps, and a window that shrank regardless
                    // would freeze it short of the optimum.
                    let moved = (t - cur).abs();
                    windows[k][side as usize] = (half * WINDOW_SHRINK)
                        .max(4.0 * moved)
                        .min(half)
                        .max(MIN_WINDOW);
                }
            }
            self.solve_radiance(st);
            if windows.iter().flatten().all(|&w| w <= MIN_WINDOW) {
                break;
            }
        }
    }
}

/// Row-summed over plain cost above which a residual counts as structured and a split is
/// tried (see [`Problem::structured`]).
const SPLIT_STRUCTURE_RATIO: f64 = 3.0;

/// Fits the lights from `start`: a descent, then a split of any light whose residual is
/// structured (see [`try_split`]), the second light of each split given a sample set of its
/// own (`fresh(origin, draw)`: the `draw`-th extra set on start light `origin`'s plane) and
/// the boundary between the two placed by [`search_boundary`], and another descent. Returns
/// the optimum and the state its last descent started from (the start, or the split lights
/// after their boundary search): a repeat on other samples starts there (see
/// [`Problem::replay`]).
fn optimise(
    problem: &mut Problem,
    start: &[FittedLight],
    extents: &mut Vec<Option<Rect>>,
    sweeps: u32,
    split: bool,
    fresh: &dyn Fn(usize, u32) -> PlaneSamples,
) -> (State, State) {
    let mut st = problem.state(
        (0..start.len()).collect(),
        start
            .iter()
            .map(|l| {
                l.edges
                    .clone()
                    .map(|e| matches!(e, EdgeStatus::Unconstrained { unseen: true, .. }))
            })
            .collect(),
        start
            .iter()
            .zip(extents.iter())
            .map(|(l, e)| clamp_to(l.rect(), *e))
            .collect(),
        start.iter().map(|l| l.radiance.map(f64::from)).collect(),
    );
    let mut replay = st.clone();
    problem.descend(&mut st, extents, sweeps);
    if split && problem.structured(&st) {
        for k in 0..start.len() {
            let Some((trial, inner)) = try_split(problem, &st, k, extents) else {
                continue;
            };
            st = trial;
            let b = st.rects.len() - 1;
            // The two lights of a split read independent samples: with one set shared, the
            // cost's noise along their common boundary has minima far from the truth
            // (BENCHMARKS.md, the stacked sample).
            let origin = problem.set_origin[st.set_of[k]];
            let draw = (problem.planes.len() - start.len()) as u32 + 1;
            let samples = fresh(origin, draw);
            extents.push(sample_extent(&samples));
            let set = problem.add_set(samples, origin);
            problem.move_to_set(&mut st, b, set);
            let starts = search_boundary(problem, &st, k, b, inner);
            let mut best: Option<(State, f64)> = None;
            for mut cand in starts {
                problem.descend(&mut cand, extents, CANDIDATE_SWEEPS);
                let c = problem.cost(&cand);
                if best.as_ref().is_none_or(|(_, b)| c < *b) {
                    best = Some((cand, c));
                }
            }
            if let Some((cand, _)) = best {
                st = cand;
            }
        }
        if problem.planes.len() > start.len() {
            replay = st.clone();
            problem.descend(&mut st, extents, sweeps);
        }
    }
    (st, replay)
}

impl Problem {
    /// The fit that `optimise` made, repeated on this problem's samples: from `from`, the
    /// state its last descent started from, whose extra sample sets (one per light a split
    /// added, on start light `extra_origins[j]`'s plane) `fresh` draws anew, as in
    /// [`optimise`].
    fn replay(
        &mut self,
        from: &State,
        extra_origins: &[usize],
        extents: &mut Vec<Option<Rect>>,
        sweeps: u32,
        fresh: &dyn Fn(usize, u32) -> PlaneSamples,
    ) -> State {
        for (draw, &origin) in extra_origins.iter().enumerate() {
            let samples = fresh(origin, draw as u32 + 1);
            extents.push(sample_extent(&samples));
            self.add_set(samples, origin);
        }
        let mut st = self.state(
            from.set_of.clone(),
            from.pinned.clone(),
            from.rects.clone(),
            from.radiance.clone(),
        );
        self.descend(&mut st, extents, sweeps);
        st
    }
}

/// Where an edge may go: inside the samples' extent (with a millimetre to spare) and no
/// nearer the opposite edge than `min_size` ([`smallest_light`]).
fn edge_bounds(r: &Rect, side: EdgeSide, ext: &Rect, min_size: Vec2) -> (f32, f32) {
    let eps = 1e-3;
    match side {
        EdgeSide::Left => (ext.u_min - eps, r.u_max - min_size.x),
        EdgeSide::Right => (r.u_min + min_size.x, ext.u_max + eps),
        EdgeSide::Bottom => (ext.v_min - eps, r.v_max - min_size.y),
        EdgeSide::Top => (r.v_min + min_size.y, ext.v_max + eps),
    }
}

/// One-sigma uncertainties of every light's free edges and radiances, from their full
/// covariance at once (Gauss-Newton, made robust to uneven noise: see below), J being the
/// model's derivatives at every unclipped fitted pixel and channel. Holding the other
/// parameters fixed, as a per-edge curvature would, understates errors that travel along
/// correlated directions (a light's height against its radiance when only one end of its
/// streak is seen); the full covariance carries them.
///
/// An edge's derivative is the change of the coefficients over a step of 2 % of the light's
/// size (at least 5 mm) each way: below a few millimetres the stored samples make the
/// coefficients a staircase. An edge that moves nothing gets no uncertainty (`None`: the photo
/// does not constrain it), and so does a pinned one.
fn uncertainties(problem: &Problem, st: &State, extents: &[Option<Rect>]) -> Vec<Uncertainty> {
    let lights = st.rects.len();
    // Parameters: per light its free edges (with the coefficients' derivative and the
    // derivative of their half-difference), then its three radiances.
    enum Param {
        Edge(usize, EdgeSide, Vec<f32>, Vec<f32>),
        Radiance(usize, usize),
    }
    let mut params: Vec<Param> = Vec::new();
    for k in 0..lights {
        let r = st.rects[k];
        let h = (0.02 * r.width().max(r.height())).max(0.005);
        for side in EdgeSide::ALL {
            if st.pinned[k][side as usize] || extents[st.set_of[k]].is_none() {
                continue;
            }
            let e = r.edge(side);
            let set = st.set_of[k];
            let (g, g_dev) =
                problem.edge_slopes(set, &r.with_edge(side, e + h), &r.with_edge(side, e - h), h);
            if g.iter().any(|&x| x != 0.0) {
                params.push(Param::Edge(k, side, g, g_dev));
            }
        }
        for ch in 0..3 {
            params.push(Param::Radiance(k, ch));
        }
    }
    let p = params.len();
    // d model[i][ch] / d param and d (half-difference)[i][ch] / d param.
    let derivative = |param: &Param, i: usize, ch: usize| -> (f64, f64) {
        match param {
            Param::Edge(k, _, g, gd) => (
                st.radiance[*k][ch] * g[i] as f64,
                st.radiance[*k][ch] * gd[i] as f64,
            ),
            Param::Radiance(k, c) if *c == ch => (st.coef[*k][i] as f64, st.dev[*k][i] as f64),
            Param::Radiance(..) => (0.0, 0.0),
        }
    };
    // Sandwich (cluster-robust) covariance: bread^-1 meat bread^-1, with the bread and the
    // scores those of the cost the fit minimises, sum of r^2 - d^2 (see the note on the
    // coefficients' noise): bread = sum of (J J^T - Jd Jd^T), score per pixel = sum over
    // channels of (r J + d Jd). The plain J^T J counts the samples' noise in the derivatives
    // as curvature (E[J_est J_est^T] = J J^T + their variance), so along a direction the photo
    // barely constrains (Table 3's light1: its height against its radiance) it claimed
    // several times the real curvature and the sigmas came out small (BENCHMARKS.md,
    // seventh session). The noise is far from uniform (a streak's bright pixels carry most
    // of it, the dark surroundings none), the three channels of a pixel share it (a white
    // light), and the stored samples add their own: a single variance sigma^2 for all would
    // understate the errors tenfold (measured on Table 1), the residuals themselves carry
    // all three.
    let mut jtj = vec![0.0; p * p];
    let mut raw_diagonal = vec![0.0; p];
    let mut meat = vec![0.0; p * p];
    let mut row = vec![0.0; p];
    let mut dev_row = vec![0.0; p];
    let mut score = vec![0.0; p];
    for i in (0..problem.n()).filter(|&i| !problem.clipped[i]) {
        let m = problem.model(st, i);
        score.iter_mut().for_each(|x| *x = 0.0);
        let mut any = false;
        for (ch, (obs, model)) in problem.obs[i].iter().zip(m).enumerate() {
            let r = *obs as f64 - model;
            let d: f64 = (0..lights)
                .map(|k| st.radiance[k][ch] * st.dev[k][i] as f64)
                .sum();
            for (a, param) in params.iter().enumerate() {
                (row[a], dev_row[a]) = derivative(param, i, ch);
                score[a] += r * row[a] + d * dev_row[a];
                any |= row[a] != 0.0;
            }
            for a in 0..p {
                if row[a] != 0.0 || dev_row[a] != 0.0 {
                    raw_diagonal[a] += row[a] * row[a];
                    for b in 0..p {
                        jtj[a * p + b] += row[a] * row[b] - dev_row[a] * dev_row[b];
                    }
                }
            }
        }
        if any {
            for a in 0..p {
                if score[a] != 0.0 {
                    for b in 0..p {
                        meat[a * p + b] += score[a] * score[b];
                    }
                }
            }
        }
    }
    // As in the fit (`solve_radiance`, the edge profiles): never trust less than half the
    // raw curvature of a parameter.
    for a in 0..p {
        jtj[a * p + a] = jtj[a * p + a].max(0.5 * raw_diagonal[a]);
    }
    // A radiance channel nothing depends on (a light with no sample) stays solvable.
    for a in 0..p {
        jtj[a * p + a] += 1e-12 * (1.0 + jtj[a * p + a]);
    }
    let covariance = invert(&jtj, p).map(|inv| {
        let product = |x: &[f64], y: &[f64]| {
            let mut out = vec![0.0; p * p];
            for a in 0..p {
                for c in 0..p {
                    let xa = x[a * p + c];
                    if xa != 0.0 {
                        for b in 0..p {
                            out[a * p + b] += xa * y[c * p + b];
                        }
                    }
                }
            }
            out
        };
        product(&product(&inv, &meat), &inv)
    });
    let mut out: Vec<Uncertainty> = (0..lights)
        .map(|_| Uncertainty {
            edges: [None; 4],
            radiance: [f32::INFINITY; 3],
        })
        .collect();
    if let Some(cov) = covariance {
        for (a, param) in params.iter().enumerate() {
            let var = cov[a * p + a];
            let sd = if var.is_finite() && var >= 0.0 {
                var.sqrt() as f32
            } else {
                f32::INFINITY
            };
            match param {
                Param::Edge(k, side, ..) => out[*k].edges[*side as usize] = Some(sd),
                Param::Radiance(k, ch) => out[*k].radiance[*ch] = sd,
            }
        }
    }
    out
}

/// Why an edge that faces another light split from the same start is reported unconstrained.
const FACING_REASON: &str = "it faces another light split from the same streak: no streak edge \
    shows it, and the fit places it only from where the two reflections overlap";

/// Per light and edge (left, right, bottom, top), whether the edge faces another light split
/// from the same start. The split lights' outer edges are the merged light's, measured from
/// its streak's edge pixels; the facing ones were made by the cut, and the streak's edges say
/// nothing about them. Two lights count as one above the other when their centres are
/// further apart vertically than horizontally, each in units of the pair's summed size.
fn facing_edges(problem: &Problem, st: &State) -> Vec<[bool; 4]> {
    let n = st.rects.len();
    let origin = |k: usize| problem.set_origin[st.set_of[k]];
    let mut out = vec![[false; 4]; n];
    for (a, facing) in out.iter_mut().enumerate() {
        for b in (0..n).filter(|&b| b != a && origin(b) == origin(a)) {
            let (ra, rb) = (st.rects[a], st.rects[b]);
            let du = (rb.u_min + rb.u_max - ra.u_min - ra.u_max) / (ra.width() + rb.width());
            let dv = (rb.v_min + rb.v_max - ra.v_min - ra.v_max) / (ra.height() + rb.height());
            let side = if dv.abs() >= du.abs() {
                if dv > 0.0 {
                    EdgeSide::Top
                } else {
                    EdgeSide::Bottom
                }
            } else if du > 0.0 {
                EdgeSide::Right
            } else {
                EdgeSide::Left
            };
            facing[side as usize] = true;
        }
    }
    out
}

/// Marks edges the joint fit found unconstrained (flat cost) as such, keeping the paper's
/// reason where it had one.
pub fn edge_statuses(light: &FittedLight, u: &Uncertainty) -> [EdgeStatus; 4] {
    let mut out = light.edges.clone();
    for side in EdgeSide::ALL {
        if u.edges[side as usize].is_none()
            && matches!(out[side as usize], EdgeStatus::Constrained { .. })
        {
            out[side as usize] = EdgeStatus::Unconstrained {
                reason: "moving this edge does not change the modelled photo".into(),
                unseen: false,
            };
        }
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The control variate must leave the coefficients' expectation alone and cut their
    /// noise. Reference: the plain estimate with 1152 samples per pixel (9 times the
    /// default's 128). On Table 3's fitted region (every 8th pixel), over 6 seeds of 72
    /// samples: the mean over seeds and pixels of the coefficients, with and without it, must
    /// agree with the reference to within 0.2 % (the fit moves an edge by about as much as a
    /// coefficient bias; measured well under that), the squared error must fall, and the
    /// derivative by the top edge, which is what moves the fit, far more (measured: to 0.45
    /// and 0.05-0.1 of the plain estimate's, BENCHMARKS.md).
    /// Table 3's photo and scene, light0 as the paper fits it, and every 8th pixel of its
    /// fitted region: what the tests below trace samples for.
    struct Table3Light0 {
        scene: crate::scene_in::Scene,
        model: ReflectionModel,
        light: FittedLight,
        roi: Rect,
        pixels: Vec<u32>,
        width: u32,
        height: u32,
    }

    fn table3_light0() -> Table3Light0 {
        let root = std::path::Path::new(env!("CARGO_MANIFEST_DIR"));
        let dir = std::env::temp_dir().join(format!(
            "streaklight-joint-{}-{:?}",
            std::process::id(),
            std::thread::current().id()
        ));
        crate::samples::write_scenes(&dir).expect("sample scenes");
        let scene =
            crate::scene_in::load(&dir.join("scene.gltf"), &Default::default()).expect("scene");
        let _ = std::fs::remove_dir_all(&dir);
        let photo = crate::photo_in::load(
            &root.join("samples/table3.png"),
            crate::samples::PHOTO_EXPOSURE,
        )
        .expect("photo");
        let water = crate::water_mask::water_mask(&scene, photo.width, photo.height);
        let segmented =
            crate::streaks::extract_streaks(&photo, &water, &Default::default()).expect("streaks");
        let observations: Vec<StreakObservation> = segmented
            .streaks
            .iter()
            .map(|s| crate::convert::observation(s, photo.width))
            .collect();
        let model = ReflectionModel::new(scene.water.gloss, scene.water.ior);
        let options = super::super::FitOptions {
            samples: 256,
            seed: 1,
            model,
        };
        let paper = super::super::fit_paper(&scene, &photo, &water, &observations, &options)
            .expect("paper fit");
        let light = paper.lights[0].clone();
        let roi = region_of_interest(&light.rect());
        let used: Vec<&StreakObservation> = observations.iter().collect();
        let pixels: Vec<u32> = region(
            &scene,
            &model,
            &[&light.plane],
            &[roi],
            &photo,
            &water,
            &used,
            6,
            true,
        )
        .into_iter()
        .step_by(8)
        .collect();
        Table3Light0 {
            scene,
            model,
            light,
            roi,
            pixels,
            width: photo.width,
            height: photo.height,
        }
    }

    impl Table3Light0 {
        fn trace(&self, samples: u32, seed: u64, draw: u32, cv: bool) -> (Vec<PlaneSamples>, u32) {
            trace_samples(
                &self.scene,
                &self.model,
                &[&self.light.plane],
                &[self.roi],
                &self.pixels,
                self.width,
                self.height,
                samples,
                seed,
                0,
                draw,
                cv,
            )
        }
    }

    #[test]
    fn edge_coefficients_match_the_coefficient_at_every_grid_point() {
        let t = table3_light0();
        let (planes, n) = t.trace(72, 1, 0, true);
        let inv = 1.0 / n as f32;
        let rect = t.light.rect();
        let grid = 17;
        let (mut coef, mut dev) = (vec![0f32; grid], vec![0f32; grid]);
        let mut compared = 0;
        for side in EdgeSide::ALL {
            // Across the edge, from 0.4 m inside to 0.4 m outside the rectangle.
            let (lo, step) = (rect.edge(side) - 0.4, 0.05);
            let mut ramps = EdgeRamps::new(lo, step, grid);
            for i in 0..t.pixels.len() {
                planes[0].edge_coefficients(
                    i, &rect, side, lo, step, inv, &mut ramps, &mut coef, &mut dev,
                );
                for j in 0..grid {
                    let moved = rect.with_edge(side, lo + j as f32 * step);
                    let (c, d) = planes[0].coefficient(i, &moved, inv);
                    let tolerance = 1e-6 + 1e-4 * c.abs().max(d.abs());
                    assert!(
                        (coef[j] - c).abs() <= tolerance && (dev[j] - d).abs() <= tolerance,
                        "{side:?} pixel {i} point {j}: ({}, {}) against ({c}, {d})",
                        coef[j],
                        dev[j]
                    );
                    compared += (c != 0.0) as usize;
                }
            }
        }
        assert!(
            compared > 1000,
            "only {compared} nonzero coefficients compared"
        );
    }

    #[test]
    fn extra_sample_sets_are_independent_draws_of_the_same_coefficients() {
        // A split light's own set (draw 1) against the set every light reads (draw 0): other
        // samples, the same expectation.
        let t = table3_light0();
        let rect = t.light.rect();
        let sums = |draw: u32| -> (Vec<Vec2>, Vec<f64>) {
            let (planes, n) = t.trace(72, 1, draw, true);
            let inv = 1.0 / n as f32;
            let c = (0..t.pixels.len())
                .map(|i| planes[0].coefficient(i, &rect, inv).0 as f64)
                .collect();
            (planes[0].points.clone(), c)
        };
        let (points0, c0) = sums(0);
        let (points1, c1) = sums(1);
        let shared = points0.iter().zip(&points1).filter(|(a, b)| a == b).count();
        assert!(
            shared * 100 < points0.len(),
            "{shared} of {} points alike",
            points0.len()
        );
        let total: f64 = c0.iter().sum();
        let diff: f64 = c0.iter().zip(&c1).map(|(a, b)| a - b).sum();
        // The two sums differ by their samples' noise alone: per pixel the half-differences
        // measure it; summed over the pixels the relative difference is far under 1 %.
        assert!(total > 0.0);
        assert!(
            (diff / total).abs() < 0.005,
            "sums {total} and {}",
            total - diff
        );
        // Not the same numbers: the pixels' values differ.
        let differing = c0.iter().zip(&c1).filter(|(a, b)| a != b).count();
        assert!(differing * 2 > c0.iter().filter(|c| **c != 0.0).count());
    }

    #[test]
    fn the_control_variate_keeps_the_expectation_and_cuts_the_noise() {
        let t = table3_light0();
        let light = &t.light;
        let pixels = &t.pixels;
        let trace = |samples: u32, seed: u64, cv: bool| t.trace(samples, seed, 0, cv);
        let rect = light.rect();
        let moved = rect.with_edge(EdgeSide::Top, rect.v_max + 0.02);
        // Per pixel: the coefficient and its change as the top edge moves up 2 cm.
        let values = |(planes, n): &(Vec<PlaneSamples>, u32)| -> Vec<(f64, f64)> {
            let inv = 1.0 / *n as f32;
            (0..pixels.len())
                .map(|i| {
                    let (c, _) = planes[0].coefficient(i, &rect, inv);
                    let (m, _) = planes[0].coefficient(i, &moved, inv);
                    (c as f64, (m - c) as f64)
                })
                .collect()
        };
        let reference = values(&trace(1152, 1000, false));
        let total: f64 = reference.iter().map(|r| r.0).sum();
        assert!(total > 0.0, "the region sees the light");
        let mut bias = [0f64; 2];
        let mut value_error = [0f64; 2];
        let mut slope_error = [0f64; 2];
        for seed in 1..=6 {
            for (m, cv) in [false, true].into_iter().enumerate() {
                for (got, want) in values(&trace(72, seed, cv)).iter().zip(&reference) {
                    bias[m] += got.0 - want.0;
                    value_error[m] += (got.0 - want.0).powi(2);
                    slope_error[m] += (got.1 - want.1).powi(2);
                }
            }
        }
        let relative_bias = bias.map(|b| b / (6.0 * total));
        eprintln!(
            "bias plain {:.5} cv {:.5}; squared error cv/plain: value {:.3}, slope {:.3}",
            relative_bias[0],
            relative_bias[1],
            value_error[1] / value_error[0],
            slope_error[1] / slope_error[0]
        );
        assert!(
            relative_bias[0].abs() < 0.002,
            "plain bias {}",
            relative_bias[0]
        );
        assert!(
            relative_bias[1].abs() < 0.002,
            "control variate bias {}",
            relative_bias[1]
        );
        assert!(
            value_error[1] < 0.7 * value_error[0],
            "values: {} against {}",
            value_error[1],
            value_error[0]
        );
        assert!(
            slope_error[1] < 0.3 * slope_error[0],
            "slopes: {} against {}",
            slope_error[1],
            slope_error[0]
        );
    }

    #[test]
    fn the_kernel_smooths_without_broadening_the_lobe() {
        // Samples of a Gaussian lobe (sigma 1) jittered over a fine grid, each spread over a
        // kernel of half-width h: the expected mass inside [lo, hi] is the lobe convolved with
        // the kernel. A plain box of the same width adds its variance h^2/3 to the lobe's and
        // errs at second order; the two-box kernel must err far less, and both keep the
        // whole mass.
        let gauss = |x: f64| (-0.5 * x * x).exp() / (2.0 * std::f64::consts::PI).sqrt();
        let (lo, hi) = (0.5f32, 3.0f32);
        let lobe_mass = {
            // Reference: the lobe's own mass inside [lo, hi], by fine quadrature.
            let n = 200_000;
            let dx = (hi - lo) as f64 / n as f64;
            (0..n)
                .map(|i| gauss(lo as f64 + (i as f64 + 0.5) * dx) * dx)
                .sum::<f64>()
        };
        for h in [0.2f32, 0.4] {
            let (mut kernel, mut boxed, mut total) = (0f64, 0f64, 0f64);
            let n = 400_000;
            let (a, b) = (-8.0f64, 8.0f64);
            let dx = (b - a) / n as f64;
            for i in 0..n {
                let x = a + (i as f64 + 0.5) * dx;
                let w = gauss(x) * dx;
                kernel += w * kernel_coverage(x as f32, h, lo, hi) as f64;
                boxed += w * coverage(x as f32, h, lo, hi) as f64;
                total += w * kernel_coverage(x as f32, h, -100.0, 100.0) as f64;
            }
            let (kernel_err, box_err) = ((kernel - lobe_mass).abs(), (boxed - lobe_mass).abs());
            assert!((total - 1.0).abs() < 1e-4, "mass {total}");
            assert!(
                kernel_err < 0.1 * box_err,
                "h {h}: kernel error {kernel_err:.2e}, box {box_err:.2e}"
            );
        }
    }

    #[test]
    fn repeats_give_their_mean_and_its_standard_error() {
        let rect = |v: f32| Rect {
            u_min: v,
            u_max: v + 1.0,
            v_min: 2.0 * v,
            v_max: 3.0,
        };
        // Two fits: the standard error of their mean is half their difference.
        let (rects, radiance, spread) = mean_and_spread(&[
            (vec![rect(0.0)], vec![[1.0, 2.0, 3.0]]),
            (vec![rect(0.5)], vec![[3.0, 2.0, 0.0]]),
        ]);
        assert_eq!(rects[0], rect(0.25));
        assert_eq!(radiance[0], [2.0, 2.0, 1.5]);
        assert_eq!(spread[0].0, [0.25, 0.25, 0.5, 0.0]);
        assert_eq!(spread[0].1, [1.0, 0.0, 1.5]);
        // Four: sample standard deviation over 2. Values 1, 2, 3, 6: mean 3, sd sqrt(14/3).
        let fits: Vec<(Vec<Rect>, Vec<[f64; 3]>)> = [1.0, 2.0, 3.0, 6.0]
            .iter()
            .map(|&x| (vec![rect(0.0)], vec![[x, 0.0, 0.0]]))
            .collect();
        let (_, radiance, spread) = mean_and_spread(&fits);
        assert_eq!(radiance[0][0], 3.0);
        let expected = ((14.0f64 / 3.0).sqrt() / 2.0) as f32;
        assert!(
            (spread[0].1[0] - expected).abs() < 1e-6,
            "{:?}",
            spread[0].1
        );
    }

    #[test]
    fn edge_ramps_match_the_kernels_mass_at_every_grid_point() {
        // Random cells (some points, some wider than the grid, some cut by the opposite
        // edge) against the direct coverage sum, for both kinds of edge.
        let mut rng = Rng::new(7, 0);
        let (lo, step, grid) = (-0.3f32, 0.01f32, 65);
        for min_edge in [true, false] {
            let opp = if min_edge { 0.2 } else { -0.1 };
            let mut ramps = EdgeRamps::new(lo, step, grid);
            ramps.clear(grid);
            let mut cells = Vec::new();
            for n in 0..200 {
                let x = -0.6 + 1.2 * rng.next_f32();
                let h = match n % 4 {
                    0 => 0.0,
                    1 => 0.5 * rng.next_f32(),
                    _ => 0.05 * rng.next_f32(),
                };
                let w = if n % 3 == 0 { -1.0 } else { 1.0 } * (0.5 + rng.next_f32());
                ramps.add_cell(min_edge, x, h, opp, w.abs() as f64, w as f64);
                cells.push((x, h, w));
            }
            let (mut abs, mut signed) = (vec![0f32; grid], vec![0f32; grid]);
            ramps.values(&mut abs, &mut signed);
            for j in 0..grid {
                let t = lo + j as f32 * step;
                let (mut want_abs, mut want_signed) = (0f32, 0f32);
                for &(x, h, w) in &cells {
                    // In f64: a point's 2e-6 wide cell is a few f32 ulps of its position.
                    let (t, opp) = (t as f64, opp as f64);
                    let (a, b) = if min_edge { (t, opp) } else { (opp, t) };
                    let boxed = |h: f64| {
                        let (x, h) = (x as f64, h.max(POINT_CELL as f64));
                        ((b.min(x + h) - a.max(x - h)) / (2.0 * h)).clamp(0.0, 1.0)
                    };
                    let h = h as f64;
                    let f = if h > POINT_CELL as f64 {
                        (4.0 * boxed(0.5 * h) - boxed(h)) / 3.0
                    } else {
                        boxed(h)
                    } as f32;
                    want_abs += w.abs() * f;
                    want_signed += w * f;
                }
                assert!(
                    (abs[j] - want_abs).abs() < 1e-3,
                    "{min_edge} {j}: {} vs {want_abs}",
                    abs[j]
                );
                assert!(
                    (signed[j] - want_signed).abs() < 1e-3,
                    "{min_edge} {j}: {} vs {want_signed}",
                    signed[j]
                );
            }
        }
    }
}
