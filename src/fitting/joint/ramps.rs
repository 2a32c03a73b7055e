//! The joint fit's 1-D grid evaluation (method §5, last paragraph): a pixel's coefficient at
//! every position of one edge on a grid, in one pass over its stored samples.
//!
//! The coordinate descent and the boundary search evaluate the cost on a whole grid of edge
//! positions at once. Each sample's kernel ([`super::kernel`]) is a piecewise linear function
//! of the edge's position, so its contributions are accumulated as ramps and prefix-summed
//! ([`EdgeRamps`]); [`PlaneSamples::edge_coefficients`] adds the control variate's exact mass
//! at each grid point.

use super::kernel::{kernel_coverage, kernel_outside, POINT_CELL};
use super::near::Near;
use super::samples::PlaneSamples;
use crate::fitting::rect::Rect;
use crate::fitting::EdgeSide;

/// A rectangle seen from one of its edges as that edge moves: whether the edge is a left or
/// right one (it moves along u), whether it is the lower of its pair, where the opposite
/// edge is, and the rectangle's extent along the edge.
pub(super) struct EdgeFrame {
    pub(super) along_u: bool,
    pub(super) min_edge: bool,
    pub(super) opposite: f32,
    pub(super) across: (f32, f32),
}

impl EdgeFrame {
    pub(super) fn new(rect: &Rect, side: EdgeSide) -> Self {
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
    /// Pixel i's coefficient and half-difference, as [`Self::coefficient`] gives them, with
    /// `rect`'s edge `side` at every grid point `lo + j step` (`coef.len()` of them), in one
    /// pass over its samples (see [`EdgeRamps`]).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn edge_coefficients(
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
        self.add_to_ramps(
            Near::Run(self.range(i)),
            &EdgeFrame::new(rect, side),
            None,
            ramps,
        );
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

    /// Adds the samples `ids` to `ramps` as functions of the edge `frame` describes (each
    /// sample's kernel, its share across the edge's axis inside the rectangle counted);
    /// returns whether any counts anywhere on the ramps' grid and, with the edge at `now`,
    /// their sums of weight inside the rectangle (plain and signed by half, not yet divided
    /// by the sample count: their part of [`Self::coefficient`]; zero without `now`), from
    /// the same pass.
    pub(super) fn add_to_ramps(
        &self,
        ids: Near<'_>,
        frame: &EdgeFrame,
        now: Option<f32>,
        ramps: &mut EdgeRamps,
    ) -> (bool, (f64, f64)) {
        let mut any = false;
        let (mut sum, mut signed) = (0f64, 0f64);
        // The rectangle's extent along the edge's axis with the edge at `now`.
        let along = now.map(|t| {
            if frame.min_edge {
                (t, frame.opposite)
            } else {
                (frame.opposite, t)
            }
        });
        // With the edge at `now`, the band it sweeps: the grid and `now`. A sample whose
        // kernel lies wholly outside it counts the same at every grid point as it does now,
        // which the caller's coefficient as it is already holds, so it is passed over:
        // `ids` come from the pixel's largest reach ([`Self::near`]), and on a narrow window
        // most of them are such (about four in five on the stacked lamps from the
        // reflections alone).
        let band = now.map(|t| (ramps.lo.min(t as f64), ramps.hi.max(t as f64)));
        for q in ids {
            let (p, h) = (self.points[q], self.cells[q]);
            let (x, hx, y, hy) = if frame.along_u {
                (p.x, h.x, p.y, h.y)
            } else {
                (p.y, h.y, p.x, h.x)
            };
            if band.is_some_and(|(lo, hi)| kernel_outside(x, hx, lo, hi)) {
                continue;
            }
            let (w, half) = (self.weights[q], self.halves[q]);
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
                if let Some((a, b)) = along {
                    let f = kernel_coverage(x, hx, a, b) * across;
                    if f != 0.0 {
                        let w = (w * f) as f64;
                        sum += w;
                        signed += w * half as f64;
                    }
                }
            }
        }
        (any, (sum, signed))
    }
}

/// One pixel's coefficient as a function of an edge's position on the grid
/// `t_j = lo + j step`. Each sample's kernel contributes a piecewise linear function of t: a
/// constant and ramps `s max(t - kink, 0)`. A ramp is recorded at the first grid point past
/// its kink as its slope `s` and `s kink`; summed up to `j`, the value at `t_j` is
/// `constant + t_j sum s - sum s kink`, exact and one pass over the samples. Kept for the
/// absolute weights (the coefficient) and the signed ones (its half-difference). The ramps
/// are kept as a list, not per grid point: a pixel has a few near a narrow window, and the
/// value is linear between them ([`Self::for_each_piece`]).
pub(super) struct EdgeRamps {
    lo: f64,
    /// The last grid point.
    hi: f64,
    step: f64,
    inv_step: f64,
    grid: usize,
    pub(super) constant: [f64; 2],
    /// Whether any ramp starts at or before the last grid point (otherwise the value is
    /// `constant` everywhere).
    pub(super) kinked: bool,
    /// The ramps whose kinks lie before the first grid point, summed: each is linear over
    /// the whole grid, so they add one slope and one slope times kink (absolute and signed)
    /// rather than a ramp each. Once the window is narrow, most of the samples an edge moves
    /// through are such: their kernels straddle the whole window.
    base: [[f64; 2]; 2],
    /// Per ramp with its kink on the grid: the grid point it is recorded at, its slope and
    /// its slope times its kink (absolute and signed).
    kinks: Vec<(usize, [f64; 2], [f64; 2])>,
    /// [`Self::values`]' bins: per grid point, the slopes and slopes times kinks of the ramps
    /// recorded there.
    slope: Vec<[[f64; 2]; 2]>,
}

impl EdgeRamps {
    pub(super) fn new(lo: f32, step: f32, grid: usize) -> Self {
        EdgeRamps {
            lo: lo as f64,
            hi: lo as f64 + (grid - 1) as f64 * step as f64,
            step: step as f64,
            inv_step: 1.0 / step as f64,
            grid,
            constant: [0.0; 2],
            kinked: false,
            base: [[0.0; 2]; 2],
            kinks: Vec::new(),
            slope: Vec::new(),
        }
    }

    pub(super) fn clear(&mut self, grid: usize) {
        self.constant = [0.0; 2];
        self.kinked = false;
        self.base = [[0.0; 2]; 2];
        self.kinks.clear();
        self.grid = grid;
    }

    pub(super) fn constant(&mut self, abs: f64, signed: f64) {
        self.constant[0] += abs;
        self.constant[1] += signed;
    }

    fn kink(&mut self, at: f64, abs: f64, signed: f64) {
        let f = (at - self.lo) * self.inv_step;
        if f < 0.0 {
            self.kinked = true;
            self.base[0][0] += abs;
            self.base[0][1] += signed;
            self.base[1][0] += abs * at;
            self.base[1][1] += signed * at;
            return;
        }
        // Truncation is the floor here (f >= 0), without a call to libm's floor.
        let j = f as usize + 1;
        if j < self.grid {
            self.kinked = true;
            self.kinks.push((j, [abs, signed], [abs * at, signed * at]));
        }
    }

    /// Calls `piece(j0, j1, intercept, slope)` for each run of grid points `j0..j1` over
    /// which the value (absolute, signed) is `intercept + slope t_j`, in order, the runs
    /// covering the whole grid.
    pub(super) fn for_each_piece(
        &mut self,
        mut piece: impl FnMut(usize, usize, [f64; 2], [f64; 2]),
    ) {
        // Unstable but deterministic: the same ramps give the same order on every run.
        self.kinks.sort_unstable_by_key(|k| k.0);
        let [mut s, mut sk] = self.base;
        let mut from = 0;
        let mut next = 0;
        while from < self.grid {
            while next < self.kinks.len() && self.kinks[next].0 <= from {
                let (_, slope, slope_kink) = self.kinks[next];
                for c in 0..2 {
                    s[c] += slope[c];
                    sk[c] += slope_kink[c];
                }
                next += 1;
            }
            let to = self.kinks.get(next).map_or(self.grid, |k| k.0);
            piece(
                from,
                to,
                [self.constant[0] - sk[0], self.constant[1] - sk[1]],
                s,
            );
            from = to;
        }
    }

    /// How many ramps start on the grid after its first point: [`Self::for_each_piece`]
    /// sorts them, so it is for a few; [`Self::values`] takes any number at the same cost.
    /// The ramps before the grid are one linear term ([`Self::base`]), free to either.
    pub(super) fn ramp_count(&self) -> usize {
        self.kinks.len()
    }

    /// The coefficient's sum of weights (absolute, signed) at every grid point: the ramps
    /// binned by grid point, then prefix sums.
    pub(super) fn values(&mut self, abs: &mut [f32], signed: &mut [f32]) {
        self.slope.clear();
        self.slope.resize(self.grid, [[0.0; 2]; 2]);
        for &(j, slope, slope_kink) in &self.kinks {
            let bin = &mut self.slope[j];
            for c in 0..2 {
                bin[0][c] += slope[c];
                bin[1][c] += slope_kink[c];
            }
        }
        let [mut s, mut sk] = self.base;
        for (j, (a, b)) in abs.iter_mut().zip(signed.iter_mut()).enumerate() {
            for c in 0..2 {
                s[c] += self.slope[j][0][c];
                sk[c] += self.slope[j][1][c];
            }
            let t = self.lo + j as f64 * self.step;
            *a = (self.constant[0] + t * s[0] - sk[0]) as f32;
            *b = (self.constant[1] + t * s[1] - sk[1]) as f32;
        }
    }

    /// Adds a sample's kernel of half-width h at x along the edge's axis ([`kernel_coverage`];
    /// a negative h is a plain box) with its weights (absolute, signed) for a min edge (`min_edge`: the kernel counts above
    /// the edge and below `opp`, the opposite edge) or a max edge (below the edge and above
    /// `opp`). Returns whether it counts anywhere.
    pub(super) fn add_cell(
        &mut self,
        min_edge: bool,
        x: f32,
        h: f32,
        opp: f32,
        abs: f64,
        signed: f64,
    ) -> bool {
        let reach = h.abs().max(POINT_CELL);
        let (reach_lo, reach_hi) = (x - reach, x + reach);
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
        if h < 0.0 {
            // A plain box: a direct pixel's stratum (see `kernel_coverage`).
            return self.add_box(min_edge, x, -h, opp, abs, signed);
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
}

#[cfg(test)]
mod tests {
    use super::super::fixture::table3_light0;
    use super::*;
    use crate::random::Rng;

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
    fn edge_ramps_match_the_kernels_mass_at_every_grid_point() {
        // Random cells (some points, some wider than the grid, some cut by the opposite
        // edge, some plain boxes) against the direct coverage sum, for both kinds of edge.
        let mut rng = Rng::new(7, 0);
        let (lo, step, grid) = (-0.3f32, 0.01f32, 65);
        for min_edge in [true, false] {
            let opp = if min_edge { 0.2 } else { -0.1 };
            let mut ramps = EdgeRamps::new(lo, step, grid);
            ramps.clear(grid);
            let mut cells = Vec::new();
            for n in 0..200 {
                let x = -0.6 + 1.2 * rng.next_f32();
                // A negative half-width is a plain box (a direct pixel's stratum).
                let h = match n % 5 {
                    0 => 0.0,
                    1 => 0.5 * rng.next_f32(),
                    4 => -0.05 * rng.next_f32() - 1e-3,
                    _ => 0.05 * rng.next_f32(),
                };
                let w = if n % 3 == 0 { -1.0 } else { 1.0 } * (0.5 + rng.next_f32());
                ramps.add_cell(min_edge, x, h, opp, w.abs() as f64, w as f64);
                cells.push((x, h, w));
            }
            let (mut abs, mut signed) = (vec![0f32; grid], vec![0f32; grid]);
            ramps.values(&mut abs, &mut signed);
            // The cells reaching below the grid (their ramps summed as one linear term; a max
            // edge's opposite edge lies on the grid, so only a min edge has them) and those
            // kinked on it, read as pieces: the same values.
            assert_eq!(ramps.base != [[0.0; 2]; 2], min_edge);
            assert!(ramps.ramp_count() > 0);
            let mut covered = 0;
            ramps.for_each_piece(|j0, j1, intercept, slope| {
                assert_eq!(j0, covered);
                covered = j1;
                for j in j0..j1 {
                    let t = lo as f64 + j as f64 * step as f64;
                    let (a, b) = (intercept[0] + slope[0] * t, intercept[1] + slope[1] * t);
                    assert!((a - abs[j] as f64).abs() < 1e-4, "{min_edge} {j}: {a}");
                    assert!((b - signed[j] as f64).abs() < 1e-4, "{min_edge} {j}: {b}");
                }
            });
            assert_eq!(covered, grid);
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
                    let f = if h < 0.0 {
                        boxed(-h)
                    } else if h > POINT_CELL as f64 {
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
