//! The joint fit's coordinate descent (method §5, last paragraph): every free edge in turn,
//! each step a global search on a grid of positions that shrinks around the best.
//!
//! Each 1-D step evaluates the cost on a whole grid of edge positions in one pass over the
//! samples ([`Problem::edge_profile`]), with that light's radiance re-optimised at every grid
//! point, so a far-off start (the paper's estimate can be metres off) is pulled
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

/// Fewest direct pixels that must measure an edge (moved by it in a channel that is neither
/// clipped nor black and in which the light shines) for them alone to place it
/// ([`super::JointOptions::edges_by_image`]); as many as the uncertainties ask of them to
/// count.
const MIN_MEASURING: usize = super::uncertainty::MIN_DIRECT_PIXELS;

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

    /// [`Self::descend`], with a pattern move after each sweep from the second on
    /// ([`Self::pattern_move`]): the descent after a split, whose lights creep along a valley
    /// that single-edge steps cross only in a zig-zag.
    pub(super) fn descend_with_pattern_moves(
        &self,
        st: &mut State,
        extents: &[Option<Rect>],
        sweeps: u32,
    ) {
        self.descend_from(st, extents, sweeps, &[], true);
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
        self.descend_from(st, extents, sweeps, near, false);
    }

    /// The descent: [`Self::descend_near`], with [`Self::pattern_move`]s when `pattern`.
    fn descend_from(
        &self,
        st: &mut State,
        extents: &[Option<Rect>],
        sweeps: u32,
        near: &[bool],
        pattern: bool,
    ) {
        let mut windows = self.descent_windows(st, near);
        self.descend_windows(st, extents, sweeps, &mut windows, pattern);
    }

    /// The search windows a descent of `st` starts with (see [`Self::descend_near`] for
    /// `near`): [`Self::descend_windows`] carries on from them.
    pub(super) fn descent_windows(&self, st: &State, near: &[bool]) -> Windows {
        // Initial half-windows: see `first_window`; a few pixel footprints for a light its
        // direct image pins on every side (`image_bounds`), which lies within about one of
        // its optimum already.
        let bounds = self.image_bounds(st);
        let windows: Vec<[f32; 4]> = st
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
        let least: Vec<f32> = st.rects.iter().map(min_window).collect();
        let by_image: Vec<[bool; 4]> = (0..st.rects.len())
            .map(|k| {
                let seen = self.edges_by_image
                    && self.sees_radiance(st.set_of[k], &st.rects[k], st.radiance[k]);
                EdgeSide::ALL.map(|side| {
                    seen && bounds[k][side].is_some()
                        && self.measuring_direct_pixels(st, k, side) >= MIN_MEASURING
                })
            })
            .collect();
        Windows {
            half: windows,
            least,
            by_image,
            sweeps: 0,
        }
    }

    /// Up to `sweeps` more sweeps of the descent whose search windows are `w` (the state
    /// `st` they were made for, moved only by descents through them): a descent cut in two
    /// this way ends where one of the summed sweeps does. Returns whether it converged
    /// (every window at its least).
    pub(super) fn descend_windows(
        &self,
        st: &mut State,
        extents: &[Option<Rect>],
        sweeps: u32,
        w: &mut Windows,
        pattern: bool,
    ) -> bool {
        let Windows {
            half: windows,
            least: min_windows,
            by_image,
            sweeps: done,
        } = w;
        let grid = GRID;
        for _ in 0..sweeps {
            // Checked after each sweep, as the first sweep runs whatever the windows.
            if *done > 0 && all_least(windows, min_windows) {
                return true;
            }
            let sweep = *done;
            *done += 1;
            let sweep_start = st.rects.clone();
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
                    let pixels = if by_image[k][side] {
                        self.first_direct..self.n()
                    } else {
                        0..self.n()
                    };
                    let prof = self.edge_profile(st, k, side, a, step, grid, pixels);
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
            if pattern && sweep >= 1 {
                self.pattern_move(st, extents, &sweep_start, min_windows);
            }
        }
        all_least(windows, min_windows)
    }
}

/// Whether every search half-window in `half` is down to its light's least.
fn all_least(half: &[[f32; 4]], least: &[f32]) -> bool {
    half.iter()
        .zip(least)
        .all(|(w, &least)| w.iter().all(|&w| w <= least))
}

/// A descent's search windows, to carry it on ([`Problem::descent_windows`]).
pub(super) struct Windows {
    /// Per light, each edge's search half-window.
    half: Vec<[f32; 4]>,
    /// Per light, the least half-window ([`min_window`]).
    least: Vec<f32>,
    /// Per light and edge, whether the edge is placed by the direct pixels alone
    /// ([`super::JointOptions::edges_by_image`]): the photo shows the light's radiance
    /// ([`Problem::sees_radiance`]), its direct image pins the edge
    /// ([`Problem::image_bounds`]) and at least [`MIN_MEASURING`] of its pixels measure it.
    by_image: Vec<[bool; 4]>,
    /// Sweeps made.
    sweeps: u32,
}

/// How far a pattern move tries to carry a sweep's displacement, in multiples of it: each
/// tried only while the one before lowered the cost.
const PATTERN_STEPS: [f32; 3] = [1.0, 2.0, 4.0];

impl Problem {
    /// A pattern move (Hooke and Jeeves): the displacement of every free edge over the last
    /// sweep (from `start`) carried on by [`PATTERN_STEPS`] times itself, all radiances
    /// re-solved, kept at the lowest cost if that is below the cost now. After a split, a
    /// light's height trades against its radiance (the streak's flux fixes about their
    /// product) while the streak pins its centre; each single-edge step moves the centre
    /// too, so the descent creeps along that valley by a shrinking step a sweep and stops at
    /// its sweep limit short of the minimum: on the orange and blue lamps out of frame the
    /// blue light's height still shrank by half a millimetre and its radiance rose by 0.3 %
    /// in the 14th sweep (docs/decisions.md). A sweep's displacement points along the
    /// valley, and a move along it costs a few cost evaluations, not a sweep.
    fn pattern_move(
        &self,
        st: &mut State,
        extents: &[Option<Rect>],
        start: &[Rect],
        min_windows: &[f32],
    ) {
        let travelled = |k: usize, side: EdgeSide| st.rects[k].edge(side) - start[k].edge(side);
        let moved = (0..st.rects.len()).any(|k| {
            EdgeSide::ALL
                .iter()
                .any(|&side| !st.pinned[k][side] && travelled(k, side).abs() > min_windows[k])
        });
        if !moved {
            return;
        }
        let mut best: Option<(State, f64)> = None;
        let now = self.cost(st);
        for m in PATTERN_STEPS {
            let mut trial = st.clone();
            for k in 0..st.rects.len() {
                let Some(ext) = extents[st.set_of[k]] else {
                    continue;
                };
                let min_size = self.planes[st.set_of[k]].min_size;
                for side in EdgeSide::ALL {
                    let d = travelled(k, side);
                    if st.pinned[k][side] || d == 0.0 {
                        continue;
                    }
                    // One edge at a time, each within where the descent lets it go.
                    let r = trial.rects[k];
                    let (lo, hi) = edge_bounds(&r, side, &ext, min_size, min_windows[k]);
                    if hi <= lo {
                        continue;
                    }
                    let t = (st.rects[k].edge(side) + m * d).clamp(lo, hi);
                    self.set_rect(&mut trial, k, r.with_edge(side, t));
                }
            }
            self.solve_radiance(&mut trial);
            let c = self.cost(&trial);
            if c >= best.as_ref().map_or(now, |(_, b)| *b) {
                break;
            }
            best = Some((trial, c));
        }
        if let Some((trial, _)) = best {
            *st = trial;
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

#[cfg(test)]
mod tests {
    use super::super::fixture::table3_light0;
    use super::super::samples::sample_extent;
    use super::*;

    /// Table 3's light0 as the photo (its paper estimate, radiance (1, 0.6, 0.3), no noise but
    /// the samples'), and a start a fifth of its height too tall about its centre, every
    /// radiance solved: (the problem, its extents, the start, the light's height).
    fn too_tall_start() -> (Problem, Vec<Option<Rect>>, State, f32) {
        let t = table3_light0();
        let (planes, n) = t.trace(72, 1, 0, true);
        let truth = t.light.rect();
        let problem = t.problem(planes, 1.0 / n as f32, &truth);
        let extents = vec![sample_extent(&problem.planes[0])];
        let h = truth.height();
        let start = truth
            .with_edge(EdgeSide::Bottom, truth.v_min - 0.1 * h)
            .with_edge(EdgeSide::Top, truth.v_max + 0.1 * h);
        let st = problem.state(vec![0], vec![[false; 4]], vec![start], vec![[1.0; 3]]);
        (problem, extents, st, h)
    }

    /// From [`too_tall_start`], which lies in the valley along which the light's height trades
    /// against its radiance: with pattern moves the descent ends at no higher a cost than the
    /// plain one in every number of sweeps, and after 5 sweeps it is within a quarter of the
    /// plain descent's distance from the cost both reach at 14 (measured: 0.06 of it; the
    /// plain descent needs 8 sweeps for what the pattern moves reach in 5).
    #[test]
    fn pattern_moves_carry_a_light_along_its_valley() {
        let (problem, extents, st, h) = too_tall_start();
        let costs = |sweeps: u32| {
            let mut plain = st.clone();
            problem.descend(&mut plain, &extents, sweeps);
            let mut pattern = st.clone();
            problem.descend_with_pattern_moves(&mut pattern, &extents, sweeps);
            println!(
                "{sweeps} sweeps: plain cost {:.8e}, height {:+.3} %; pattern {:.8e}, {:+.3} %",
                problem.cost(&plain),
                100.0 * (plain.rects[0].height() / h - 1.0),
                problem.cost(&pattern),
                100.0 * (pattern.rects[0].height() / h - 1.0),
            );
            (problem.cost(&plain), problem.cost(&pattern))
        };
        let (converged, _) = costs(14);
        for sweeps in [3, 5, 8] {
            let (plain, pattern) = costs(sweeps);
            assert!(
                pattern <= plain + 1e-9 * plain.abs(),
                "{sweeps} sweeps: {pattern} above {plain}"
            );
            if sweeps == 5 {
                assert!(
                    pattern - converged < 0.25 * (plain - converged),
                    "5 sweeps: {pattern} against {plain}, converged {converged}"
                );
            }
        }
    }

    /// A descent carried on through its windows ([`Problem::descend_windows`], as the split's
    /// trial does when its split does not pay yet) ends where the whole descent does, to the
    /// last bit, with and without pattern moves; and one that converged says so and stays.
    #[test]
    fn a_descent_cut_in_two_ends_where_the_whole_one_does() {
        let (problem, extents, st, _) = too_tall_start();
        for pattern in [false, true] {
            let mut whole = st.clone();
            let mut w = problem.descent_windows(&whole, &[]);
            let whole_converged = problem.descend_windows(&mut whole, &extents, 8, &mut w, pattern);
            let mut cut = st.clone();
            let mut w = problem.descent_windows(&cut, &[]);
            let first = problem.descend_windows(&mut cut, &extents, 3, &mut w, pattern);
            assert!(!first, "3 sweeps from a fifth too tall do not converge");
            let second = problem.descend_windows(&mut cut, &extents, 5, &mut w, pattern);
            assert_eq!(second, whole_converged);
            assert_eq!(cut.rects, whole.rects, "pattern moves: {pattern}");
            assert_eq!(cut.radiance, whole.radiance, "pattern moves: {pattern}");
            assert_ne!(cut.rects[0], st.rects[0], "the descent moved");
            if pattern {
                let mut plain = st.clone();
                problem.descend_with_pattern_moves(&mut plain, &extents, 8);
                assert_eq!(plain.rects, whole.rects);
            } else {
                let mut plain = st.clone();
                problem.descend(&mut plain, &extents, 8);
                assert_eq!(plain.rects, whole.rects);
            }
        }
        // Carried on to convergence, a descent reports it and moves no more.
        let mut done = st.clone();
        let mut w = problem.descent_windows(&done, &[]);
        assert!(problem.descend_windows(&mut done, &extents, 40, &mut w, false));
        let before = done.rects.clone();
        assert!(problem.descend_windows(&mut done, &extents, 5, &mut w, false));
        assert_eq!(done.rects, before);
    }
}
