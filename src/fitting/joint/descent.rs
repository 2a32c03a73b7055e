//! The joint fit's coordinate descent (method §5, last paragraph): every free edge in turn,
//! each step a global search on a grid of positions that shrinks around the best.
//!
//! Each 1-D step evaluates the cost on a whole grid of edge positions in one pass over the
//! samples ([`Problem::edge_profile`]), with that light's radiance re-optimised in closed form
//! at every grid point, so a far-off start (the paper's estimate can be metres off) is pulled
//! in by a global 1-D search rather than a local step. The grid then shrinks around the best
//! position until it is finer than a ten-thousandth of the light's size. An edge that no pixel of the streak's edge
//! looks at (outside the photo) is held where the paper method put it.

use glam::Vec2;

use super::problem::{Problem, State};
use crate::fitting::rect::Rect;
use crate::fitting::EdgeSide;

/// Grid points of an edge profile.
const GRID: usize = 65;
/// Smallest search half-window, as a share of the light's larger side at the descent's start
/// (1 mm for the 3 m light of Table 1): its grid's step (1/32 of it) is far under the 0.5 %
/// of the light's size asked for. 1 mm rather than 0.2 mm: three sweeps fewer on Table 3,
/// the same errors over 8 seeds (BENCHMARKS.md).
const MIN_WINDOW_SHARE: f32 = 1.0 / 3000.0;
/// Factor by which an edge's search window shrinks per sweep (unless the edge is still
/// travelling). The new window keeps 8 of the old grid's steps either side of the best
/// point, and the cost is smooth on that scale (see [`super::kernel`]): halving instead
/// takes 14 sweeps rather than 8 for the same result (Table 1 and 3, 8 seeds each).
const WINDOW_SHRINK: f32 = 0.25;

/// Half-width of the first search window around a start edge: half the light's size, at
/// least [`FIRST_WINDOW_SHARE`] of its `distance` from the camera, so that an estimate a
/// light's size off is still inside the first grid.
pub(super) fn first_window(r: &Rect, distance: f32) -> f32 {
    (0.5 * r.width().max(r.height())).max(FIRST_WINDOW_SHARE * distance)
}

/// The first half-window of an edge a light's direct image pins, in units of the one-sigma
/// bound the image sets on it (`footprint / sqrt(3)`, [`Problem::image_bounds`]): two pixel
/// footprints.
const IMAGE_FIRST_WINDOW: f32 = 2.0 * 1.732_050_8;

/// The first half-window of such an edge of a light near its optimum already
/// ([`Problem::descend_near`]), in the same units: half a bound, about 0.3 of a footprint.
const NEAR_FIRST_WINDOW: f32 = 0.5;

/// The least first window, as a share of the light's distance from the camera: 0.5 m at the
/// harbour's 40 m (at the paper's 10 m, 12.5 cm: no light of its samples is that small).
const FIRST_WINDOW_SHARE: f32 = 0.0125;

/// The smallest search half-window of a light whose rectangle is `r`: see
/// [`MIN_WINDOW_SHARE`].
fn min_window(r: &Rect) -> f32 {
    MIN_WINDOW_SHARE * r.width().max(r.height())
}

impl Problem {
    /// Coordinate descent over every free edge (see the module doc) for at most `sweeps`
    /// sweeps, stopping early once every search window has shrunk to its minimum.
    pub(super) fn descend(&self, st: &mut State, extents: &[Option<Rect>], sweeps: u32) {
        self.descend_near(st, extents, sweeps, &[]);
    }

    /// [`Self::descend`], with the lights `near` marks (by light; missing: not near) taken
    /// to lie within a fraction of a pixel's footprint of their optimum already: where their
    /// direct image pins every edge, their first windows are [`NEAR_FIRST_WINDOW`] bounds
    /// wide rather than [`IMAGE_FIRST_WINDOW`].
    pub(super) fn descend_near(
        &self,
        st: &mut State,
        extents: &[Option<Rect>],
        sweeps: u32,
        near: &[bool],
    ) {
        // Initial half-windows: see `first_window`; a few pixel footprints for a light its
        // direct image pins on every side (`image_bounds`), which lies within about one of
        // its optimum already.
        let bounds = self.image_bounds(st);
        let mut windows: Vec<[f32; 4]> = st
            .rects
            .iter()
            .zip(&st.set_of)
            .zip(&bounds)
            .enumerate()
            .map(|(k, ((r, &set), bound))| {
                let wide = first_window(r, self.planes[set].distance);
                let first = if near.get(k).copied().unwrap_or(false) {
                    NEAR_FIRST_WINDOW
                } else {
                    IMAGE_FIRST_WINDOW
                };
                match bound {
                    [Some(l), Some(rt), Some(b), Some(t)] => {
                        [*l, *rt, *b, *t].map(|s| (first * s).min(wide))
                    }
                    _ => [wide; 4],
                }
            })
            .collect();
        let min_windows: Vec<f32> = st.rects.iter().map(min_window).collect();
        let grid = GRID;
        for _sweep in 0..sweeps {
            for k in 0..st.rects.len() {
                let Some(ext) = extents[st.set_of[k]] else {
                    continue;
                };
                for side in EdgeSide::ALL {
                    if st.pinned[k][side] {
                        windows[k][side] = 0.0;
                        continue;
                    }
                    let half = windows[k][side];
                    let cur = st.rects[k].edge(side);
                    let min_size = self.planes[st.set_of[k]].min_size;
                    let (lo, hi) = edge_bounds(&st.rects[k], side, &ext, min_size, min_windows[k]);
                    let a = (cur - half).max(lo);
                    let b = (cur + half).min(hi);
                    if b <= a {
                        windows[k][side] = min_windows[k];
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
                    windows[k][side] = (half * WINDOW_SHRINK)
                        .max(4.0 * moved)
                        .min(half)
                        .max(min_windows[k]);
                }
            }
            self.solve_radiance(st);
            if windows
                .iter()
                .zip(&min_windows)
                .all(|(w, &least)| w.iter().all(|&w| w <= least))
            {
                break;
            }
        }
    }
}

/// Where an edge may go: inside the samples' extent (with `eps`, the smallest window, to
/// spare) and no nearer the opposite edge than `min_size`
/// ([`super::kernel::smallest_light`]).
fn edge_bounds(r: &Rect, side: EdgeSide, ext: &Rect, min_size: Vec2, eps: f32) -> (f32, f32) {
    match side {
        EdgeSide::Left => (ext.u_min - eps, r.u_max - min_size.x),
        EdgeSide::Right => (r.u_min + min_size.x, ext.u_max + eps),
        EdgeSide::Bottom => (ext.v_min - eps, r.v_max - min_size.y),
        EdgeSide::Top => (r.v_min + min_size.y, ext.v_max + eps),
    }
}
