//! The joint fit's sample kernels (method §5, last paragraph): the cells, and why each stored
//! sample is spread over a kernel.
//!
//! A coefficient is the lobe's mass inside a rectangle. Counted as points, the samples near an
//! edge make it a step function of the edge's position, and the few strata an edge cuts each
//! add a Bernoulli error: the cost is then rough on the scale of a stratum, and along the
//! weakly seen directions the optimum follows that roughness (the fit's own-sample spread,
//! BENCHMARKS.md). Each sample is instead spread over a small box around its landing point,
//! sized by its stratum's image on the plane ([`cell_half_extents`]): an edge then moves
//! through it continuously, and the strata an edge cuts err by far less. In expectation over
//! the jitter, this estimates the lobe convolved with the kernel: a box would broaden the
//! lobe (its variance h^2/3 is added, biasing edges and radiance by percents at a whole
//! cell's width), so the kernel is the difference of two boxes, (4 B(h/2) - B(h)) / 3, whose
//! second moment is zero and whose bias is of fourth order ([`kernel_coverage`]). Its width is
//! half the cell's ([`KERNEL_SCALE`]): the stratum's image is linearised, and in the lobe's
//! outer ring (most of the strata in the concentric map) the landing point bends fast enough
//! across a cell that a wider kernel is biased again. Measured on Table 1 and 3 over 8 seeds
//! of the fit's own samples (BENCHMARKS.md): light0's worst edge is 0.20-0.27 % rms with the
//! kernels, 0.61-0.87 % with point samples.

use glam::{Vec2, Vec3};

use crate::fitting::light_plane::LightPlane;
use crate::optics::{compact_strata, ReflectionModel};
use crate::render::WaterPoint;
use crate::water_model::WaterModel;

/// The half-width, along the plane's axes, of the kernel a sample spreads its weight over
/// (see the module doc): [`KERNEL_SCALE`] of its lobe cell. The cell is the sample's
/// stratum (side `stratum` in the lobe numbers, at `grid_u` before [`compact_strata`])
/// carried to the plane through the reflection, linearised: a parallelogram with sides
/// `J e_x s` and `J e_y s` (J the derivative of the landing point by the numbers), whose
/// extent across an edge along u is matched in variance by a box of half-width
/// `sqrt(a^2 + b^2) / 2`. Where a neighbouring direction leaves the lobe or misses the plane
/// the other side's difference is used; with neither, the sample stays a point.
pub(super) fn cell_half_extents(lobe: &LobeNeighbours, start: Vec3, plane: &LightPlane) -> Vec2 {
    let land = |wi: Option<Vec3>| wi.and_then(|wi| plane.hit(start, wi)).map(|(_, q)| q);
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
pub(super) const NEIGHBOUR_STEP: f32 = 0.25;

/// A lobe sample's direction and those of four neighbours [`NEIGHBOUR_STEP`] of its stratum
/// away along each of the lobe numbers (`None`: outside the lobe), from which
/// [`cell_half_extents`] measures its cell on any plane.
pub(super) struct LobeNeighbours {
    pub(super) here: Vec3,
    pub(super) plus_x: Option<Vec3>,
    pub(super) minus_x: Option<Vec3>,
    pub(super) plus_y: Option<Vec3>,
    pub(super) minus_y: Option<Vec3>,
}

impl LobeNeighbours {
    /// For the sample of direction `here` at `grid_u` (before [`compact_strata`]) in a
    /// stratum of side `stratum`.
    pub(super) fn new(
        water_model: &dyn WaterModel,
        model: &ReflectionModel,
        water: &WaterPoint,
        here: Vec3,
        grid_u: Vec2,
        stratum: f32,
    ) -> Self {
        let delta = NEIGHBOUR_STEP * stratum;
        let towards = |d: Vec2| {
            let u = (grid_u + d).clamp(Vec2::ZERO, Vec2::splat(1.0 - 1e-6));
            water_model.reflect_direction(water, model, compact_strata(u))
        };
        // Central differences over half a stratum: the cell's chord, not the map's slope at
        // the sample. In the lobe's outer ring, where the map bends, a slope (a forward
        // difference over 1/32 of a stratum) makes the cells smaller and the kernels with
        // them, and moves the Table 3 fit's top edge by 0.35 % (8 seeds; a quarter-stratum
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

/// The kernel's outer box as a fraction of the sample's cell (see the module doc).
pub(super) const KERNEL_SCALE: f32 = 0.5;

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
/// half-widths h/2 and h ([`coverage`]), a kernel whose second moment vanishes (see the module
/// doc). A negative `h` is the plain box `B(-h)`: a direct pixel's stratum
/// ([`super::direct`]), whose share inside the interval is exact.
#[inline]
pub(super) fn kernel_coverage(x: f32, h: f32, lo: f32, hi: f32) -> f32 {
    if h < 0.0 {
        return coverage(x, -h, lo, hi);
    }
    let (a, b) = (x - h, x + h);
    if a >= lo && b <= hi {
        1.0
    } else if b < lo || a > hi {
        0.0
    } else {
        (4.0 * coverage(x, 0.5 * h, lo, hi) - coverage(x, h, lo, hi)) / 3.0
    }
}

/// Half-extent given to a sample whose cell could not be measured, metres: a point, for
/// every purpose, but with a slope the ramps can hold.
pub(super) const POINT_CELL: f32 = 1e-6;

/// Whether the kernel of a sample at `x` with half-width `h` ([`kernel_coverage`]) lies
/// wholly below `lo` or wholly above `hi`: an edge moving between them leaves its share of
/// the rectangle as it is.
#[inline]
pub(super) fn kernel_outside(x: f32, h: f32, lo: f64, hi: f64) -> bool {
    let reach = h.abs().max(POINT_CELL);
    ((x + reach) as f64) < lo || ((x - reach) as f64) > hi
}

/// The smallest width and height of a light whose samples' kernels have the half-widths
/// `cells`: twice the median half-width along each axis, the kernels' typical full width (at
/// least [`SMALLEST_LIGHT_SHARE`] of the plane's `distance` from the camera, when the cells
/// are points). A narrower rectangle is seen only through the
/// kernels' shape (its coefficient is the kernels' density where it lies, negative lobes
/// included, from the few samples near it), so its coefficients are noise out of all
/// proportion to their size, and the fit, which subtracts the estimated noise from its cost,
/// rewards exactly that: two stacked lights 1.8 m apart came out as the lower light and a
/// 1 mm sliver at 1400 times the radiance, at a cost 90 below the truth's (docs/decisions.md, "No light
/// thinner than its samples' kernels"). A real light narrower than the bound (a strip light) comes out this
/// wide, with the radiance that keeps its reflection; more samples per pixel make the kernels,
/// and the bound, smaller.
pub(super) fn smallest_light(cells: &[Vec2], distance: f32) -> Vec2 {
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
    Vec2::new(2.0 * median(&mut xs), 2.0 * median(&mut ys))
        .max(Vec2::splat(SMALLEST_LIGHT_SHARE * distance))
}

/// The smallest light's side when the kernels are points, as a share of its distance from
/// the camera: 2 mm at 10 m.
const SMALLEST_LIGHT_SHARE: f32 = 2e-4;

#[cfg(test)]
mod tests {
    use super::*;

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
}
