//! The joint fit's stored plane samples (method §5, last paragraph): each fitted pixel's
//! coefficient integrated over its footprint as the renderer does it, from samples traced
//! once ([`super::trace`]).
//!
//! Per pixel, stratified jittered camera rays, each with a stratified set of lobe samples, in
//! two independent halves whose difference measures the estimate's noise (see the note on
//! the coefficients' noise in [`super::cost`]). The samples that land on each light's plane
//! inside its region of interest are stored ([`PlaneSamples`]); afterwards `c_k(p; rect)` for
//! any rectangle is a sum over stored samples ([`PlaneSamples::coefficient`]), so the
//! optimisation traces no ray. Each sample spreads its weight over a small kernel sized by its
//! lobe cell ([`super::kernel`]) and carries its weight less the control variate's
//! ([`super::control_variate`]). The stored samples are common random numbers across all
//! parameter values, so the cost is a deterministic function of the rectangles.

use std::sync::Arc;

use glam::Vec2;

use super::control_variate::LobeGaussian;
use super::kernel::kernel_coverage;
use crate::fitting::rect::Rect;

/// Stored samples of one light's plane: per fitted pixel, a range of points and weights, and
/// which of the pixel's two independent halves each belongs to (what the coefficients'
/// variance is estimated from). Where the samples lie is shared (`Arc`) between the sets
/// that weigh them differently ([`super::reweight`]): only the weights and the control
/// variates are a set's own.
pub(super) struct PlaneSamples {
    /// Per pixel, where its samples start (and, at `i + 1`, end) in the per-sample vectors.
    pub(super) offsets: Arc<Vec<u32>>,
    /// Per pixel, the bounding box of its samples' kernels ([`Rect::EMPTY`] for a pixel with
    /// none).
    pub(super) bbox: Arc<Vec<Rect>>,
    /// Per sample, where it lands (plane coordinates).
    pub(super) points: Arc<Vec<Vec2>>,
    /// Per sample, the half-widths of its kernel along the plane's axes (see
    /// [`cell_half_extents`](super::kernel::cell_half_extents) and [`super::kernel`]); negative for a direct pixel's sample,
    /// whose kernel is the plain box of its stratum ([`super::direct`]).
    pub(super) cells: Arc<Vec<Vec2>>,
    /// Per sample, its weight less the control variate's (see [`super::control_variate`]):
    /// negative where the Gaussian outweighs the lobe. A direct pixel's samples (see
    /// [`super::direct`]) weigh the pixel's sample count over its strata.
    pub(super) weights: Vec<f32>,
    /// Per sample, which of the pixel's two independent halves it belongs to (+1 or -1); 0
    /// for a direct pixel's samples, whose coefficient is exact (no noise to measure).
    pub(super) halves: Arc<Vec<f32>>,
    /// Per sample, its pixel's samples in order of v, as offsets from the pixel's first
    /// sample (each pixel's samples are stored in order of u): with both orders, the samples
    /// near an edge of either axis are found by bisection ([`Self::near`]).
    pub(super) by_v: Arc<Vec<u16>>,
    /// Per pixel, the largest reach of its samples' kernels along u and along v (at least
    /// [`POINT_CELL`](super::kernel::POINT_CELL)).
    pub(super) reach: Arc<Vec<Vec2>>,
    /// Per pixel, the control variate ([`LobeGaussian::NONE`] without).
    pub(super) gauss: Vec<LobeGaussian>,
    /// The smallest width and height a light on this plane may take
    /// ([`super::kernel::smallest_light`]).
    pub(super) min_size: Vec2,
    /// The plane's distance from the camera ([`LightPlane::camera_distance`](crate::fitting::light_plane::LightPlane::camera_distance)): the length
    /// the fit's smallest steps on this plane are shares of.
    pub(super) distance: f32,
}

impl PlaneSamples {
    /// Pixel i's samples in the per-sample vectors.
    pub(super) fn range(&self, i: usize) -> std::ops::Range<usize> {
        self.offsets[i] as usize..self.offsets[i + 1] as usize
    }

    /// Pixel i's `(c, d)` for `rect`: the coefficient and its half-difference (see the note
    /// on the coefficients' noise in [`super::cost`]).
    pub(super) fn coefficient(&self, i: usize, rect: &Rect, inv_samples: f32) -> (f32, f32) {
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
}

/// Camera rays per side of a pixel's stratification grid: 2 x 2 jittered camera rays cover
/// the footprint evenly, and the lobe is sampled several times from each.
pub(super) const CAMERA_STRATA: u32 = 2;

/// The samples per pixel a joint fit asked for `samples` actually takes: the count is
/// rounded to two halves of `CAMERA_STRATA^2` camera rays times a square number of lobe
/// samples (8, 32, 72, 128, 200, 288, ...).
pub fn effective_samples(samples: u32) -> u32 {
    2 * CAMERA_STRATA * CAMERA_STRATA * lobe_strata(samples).pow(2)
}

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
/// through [`compact_strata`](crate::optics::compact_strata), which makes each stratum a compact cell around the lobe's axis
/// instead of a thin ring sector. Measured on Table 3 over six seeds of the fit's own
/// samples (BENCHMARKS.md): the edges' and radiance's spread fell by 10-50 %, for nothing.
pub(super) fn lobe_strata(samples: u32) -> u32 {
    let per_ray = samples as f32 / (2 * CAMERA_STRATA * CAMERA_STRATA) as f32;
    (per_ray.sqrt().round() as u32).max(1)
}

/// How far the photo could possibly move an edge: the extent of light k's stored samples.
pub(super) fn sample_extent(p: &PlaneSamples) -> Option<Rect> {
    p.bbox
        .iter()
        .filter(|b| !b.is_empty())
        .copied()
        .reduce(|a, b| a.union(&b))
}
