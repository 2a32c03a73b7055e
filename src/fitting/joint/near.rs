//! The stored samples near an edge (method §5, last paragraph): what a moving edge can
//! change.
//!
//! Each pixel's samples are stored in order of u, with their order in v beside them
//! ([`PlaneSamples::by_v`]), so that the few whose kernels reach a band of either axis are
//! found by bisection. An edge moving inside the band changes only their share of the
//! rectangle: the edge profiles ([`super::profile`]) and the state's updates
//! ([`super::problem`]) read them alone, and take the rest from the coefficient as it is.

use super::kernel::{kernel_coverage, kernel_outside};
use super::samples::PlaneSamples;
use crate::fitting::rect::Rect;

impl PlaneSamples {
    /// The samples `ids`' sums of weight (plain and signed by half) inside `from` and inside
    /// `to`, not yet divided by the sample count (their part of [`Self::coefficient`] for
    /// each): two rectangles that differ only along u (`along_u`) or only along v, in one
    /// pass, each sample's share across that axis being the same in both.
    fn sums_inside_both(
        &self,
        ids: Near<'_>,
        along_u: bool,
        from: &Rect,
        to: &Rect,
        band: (f32, f32),
    ) -> [(f64, f64); 2] {
        let mut sums = [(0f64, 0f64); 2];
        for q in ids {
            let (p, h) = (self.points[q], self.cells[q]);
            // A sample whose kernel lies wholly outside the band the edge sweeps has the
            // same share of both rectangles: it adds nothing to their difference, the one
            // thing the sums are read for.
            let (x, hx) = if along_u { (p.x, h.x) } else { (p.y, h.y) };
            if kernel_outside(x, hx, band.0 as f64, band.1 as f64) {
                continue;
            }
            // Each product in the order `coefficient` takes it (u, then v).
            let f = if along_u {
                let v = kernel_coverage(p.y, h.y, from.v_min, from.v_max);
                [from, to].map(|r| kernel_coverage(p.x, h.x, r.u_min, r.u_max) * v)
            } else {
                let u = kernel_coverage(p.x, h.x, from.u_min, from.u_max);
                [from, to].map(|r| u * kernel_coverage(p.y, h.y, r.v_min, r.v_max))
            };
            for (f, (sum, signed)) in f.into_iter().zip(sums.iter_mut()) {
                if f != 0.0 {
                    let w = (self.weights[q] * f) as f64;
                    *sum += w;
                    *signed += w * self.halves[q] as f64;
                }
            }
        }
        sums
    }

    /// The samples of pixel i whose kernels may reach the band `[lo, hi]` of u (`along_u`)
    /// or of v: every other sample's kernel lies wholly below `lo` or wholly above `hi`, so
    /// an edge moving inside the band leaves its share of the rectangle as it is.
    pub(super) fn near(&self, i: usize, along_u: bool, lo: f32, hi: f32) -> Near<'_> {
        let r = self.range(i);
        let points = &self.points[r.clone()];
        if along_u {
            let reach = self.reach[i].x;
            let a = points.partition_point(|p| p.x < lo - reach);
            let b = points.partition_point(|p| p.x <= hi + reach);
            Near::Run(r.start + a..r.start + b.max(a))
        } else {
            let reach = self.reach[i].y;
            let ids = &self.by_v[r.clone()];
            let a = ids.partition_point(|&j| points[j as usize].y < lo - reach);
            let b = ids.partition_point(|&j| points[j as usize].y <= hi + reach);
            Near::Listed(r.start, ids[a..b.max(a)].iter())
        }
    }

    /// How pixel i's `(c, d)` ([`Self::coefficient`]) change from rectangle `from` to `to`.
    /// When they differ in one edge, only the samples near the band it swept are read
    /// ([`Self::near`]); otherwise both are computed whole.
    pub(super) fn coefficient_change(
        &self,
        i: usize,
        from: &Rect,
        to: &Rect,
        inv_samples: f32,
    ) -> (f64, f64) {
        let du = (from.u_min != to.u_min) as u8 + (from.u_max != to.u_max) as u8;
        let dv = (from.v_min != to.v_min) as u8 + (from.v_max != to.v_max) as u8;
        let moved = match (du, dv) {
            (0, 0) => return (0.0, 0.0),
            (1, 0) if from.u_min != to.u_min => Some((true, from.u_min, to.u_min)),
            (1, 0) => Some((true, from.u_max, to.u_max)),
            (0, 1) if from.v_min != to.v_min => Some((false, from.v_min, to.v_min)),
            (0, 1) => Some((false, from.v_max, to.v_max)),
            _ => None,
        };
        let Some((along_u, a, b)) = moved else {
            let (c0, d0) = self.coefficient(i, from, inv_samples);
            let (c1, d1) = self.coefficient(i, to, inv_samples);
            return (c1 as f64 - c0 as f64, d1 as f64 - d0 as f64);
        };
        let band = (a.min(b), a.max(b));
        let near = self.near(i, along_u, band.0, band.1);
        let [(s0, d0), (s1, d1)] = self.sums_inside_both(near, along_u, from, to, band);
        let g = &self.gauss[i];
        let inv = inv_samples as f64;
        (
            (s1 - s0) * inv + (g.mass_inside(to) as f64 - g.mass_inside(from) as f64),
            (d1 - d0) * inv,
        )
    }
}

/// The samples of one pixel near a band of one axis ([`PlaneSamples::near`]), as indices
/// into the per-sample vectors.
#[derive(Clone)]
pub(super) enum Near<'a> {
    /// A run of the vectors: a band of u (each pixel's samples are stored in order of u).
    Run(std::ops::Range<usize>),
    /// Offsets from the pixel's first sample, in order of v: a band of v.
    Listed(usize, std::slice::Iter<'a, u16>),
}

impl Iterator for Near<'_> {
    type Item = usize;

    fn next(&mut self) -> Option<usize> {
        match self {
            Near::Run(r) => r.next(),
            Near::Listed(base, ids) => ids.next().map(|&j| *base + j as usize),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixture::table3_light0;
    use super::*;
    use crate::fitting::EdgeSide;

    #[test]
    fn a_change_from_the_samples_near_an_edge_is_the_whole_change() {
        // Every edge moved out and in, by a kernel's width and by half a metre, and two
        // edges at once: the change read from the samples near the moved edge must be the
        // difference of the two whole coefficients, pixel by pixel.
        let t = table3_light0();
        let (planes, n) = t.trace(72, 1, 0, true);
        let inv = 1.0 / n as f32;
        let rect = t.light.rect();
        let mut moves: Vec<Rect> = Vec::new();
        for side in EdgeSide::ALL {
            for delta in [-0.5, -0.01, 0.002, 0.3] {
                moves.push(rect.with_edge(side, rect.edge(side) + delta));
            }
        }
        moves.push(Rect {
            u_min: rect.u_min - 0.2,
            v_max: rect.v_max + 0.1,
            ..rect
        });
        let mut changed = 0;
        for to in &moves {
            for i in 0..t.pixels.len() {
                let (c0, d0) = planes[0].coefficient(i, &rect, inv);
                let (c1, d1) = planes[0].coefficient(i, to, inv);
                let (dc, dd) = planes[0].coefficient_change(i, &rect, to, inv);
                let tolerance = 1e-6 + 1e-5 * c0.abs().max(c1.abs()) as f64;
                assert!(
                    (dc - (c1 - c0) as f64).abs() <= tolerance
                        && (dd - (d1 - d0) as f64).abs() <= tolerance,
                    "{to:?} pixel {i}: ({dc}, {dd}) against ({}, {})",
                    c1 - c0,
                    d1 - d0
                );
                changed += (c1 != c0) as usize;
            }
        }
        assert!(changed > 1000, "only {changed} coefficients changed");
    }
}
