//! Overlapping streaks, method §5 and the paper's §5.3: where two lights split from one
//! meet. A global search over the boundary between them and their outer edges, since the
//! split's coarse descent from the half cut cannot find it (see [`search_boundary`]).

use rayon::prelude::*;

use super::problem::{Problem, State};
use super::ramps::EdgeRamps;
use crate::fitting::rect::Rect;
use crate::fitting::EdgeSide;

/// Grid points per inner edge in [`search_boundary`].
const BOUNDARY_GRID: usize = 33;

/// Positions of each outer edge in [`search_boundary`], around where the split's coarse fit
/// put it, and their spacing as a fraction of the two lights' span.
const OUTER_GRID: usize = 5;
const OUTER_STEP: f32 = 0.015;

/// Places the boundary between lights `a` and `b`, split from one light (`inner`: a's edge
/// and b's edge that face each other), by a global search: every pair of positions of the
/// two inner edges on a grid across their span (a's inner edge never past b's), each with
/// the two outer edges across that axis at a few positions around where they are, both
/// radiances re-solved for each combination. The lowest [`BOUNDARY_STARTS`] local minima of
/// that cost are each refined by the same search on a finer grid around them; returns the
/// refined states, lowest coarse minimum first. The split's coarse descent from the half cut
/// cannot do this: the boundary hardly moves from where the cut put it (moving one inner
/// edge alone opens a gap or an overlap), the outer edges have settled to match it, and the
/// half cut lies in another basin than the truth's (BENCHMARKS.md, the stacked sample). The
/// other lights stay where they are; clipped pixels are left out of the search (the descent
/// after it counts them as lower bounds).
pub(super) fn search_boundary(
    problem: &Problem,
    st: &State,
    a: usize,
    b: usize,
    inner: [EdgeSide; 2],
) -> Vec<State> {
    let here = [st.rects[a], st.rects[b]];
    let coarse = boundary_minima(
        problem,
        st,
        a,
        b,
        inner,
        here,
        None,
        BOUNDARY_GRID,
        OUTER_STEP,
    );
    coarse
        .iter()
        .take(BOUNDARY_STARTS)
        .filter_map(|&(rects, _, window)| {
            let fine = boundary_minima(
                problem,
                st,
                a,
                b,
                inner,
                rects,
                Some(window),
                FINE_GRID,
                OUTER_STEP / 2.0,
            );
            let &(rects, _, _) = fine.first()?;
            let mut cand = st.clone();
            problem.set_rect(&mut cand, a, rects[0]);
            problem.set_rect(&mut cand, b, rects[1]);
            problem.solve_radiance(&mut cand);
            Some(cand)
        })
        .collect()
}

/// Grid points per inner edge of the refining search around each coarse minimum.
const FINE_GRID: usize = 13;

/// The local minima of the boundary search's cost (see [`search_boundary`]), lowest first:
/// the two rectangles, the cost, and the half-window a finer search around the minimum
/// should cover (one and a half grid steps of the inner edges). The inner edges range over
/// their whole span (`window` None) or over +-`window` about their current positions, on
/// `grid` points each; the outer edges over [`OUTER_GRID`] positions `outer_step` of the
/// span apart. The search is centred on `around` (a's and b's rectangles; the other lights
/// are read from `st`).
#[allow(clippy::too_many_arguments)]
fn boundary_minima(
    problem: &Problem,
    st: &State,
    a: usize,
    b: usize,
    inner: [EdgeSide; 2],
    around: [Rect; 2],
    window: Option<f32>,
    grid: usize,
    outer_step: f32,
) -> Vec<([Rect; 2], f64, f32)> {
    let [ra, rb] = around;
    let outer = [inner[1], inner[0]];
    let (set_a, set_b) = (st.set_of[a], st.set_of[b]);
    let vertical = inner[0] == EdgeSide::Top;
    let min_size = |set: usize| {
        let m = problem.planes[set].min_size;
        if vertical {
            m.y
        } else {
            m.x
        }
    };
    let (start_a, end_b) = (ra.edge(outer[0]), rb.edge(outer[1]));
    let span = end_b - start_a;
    let (lo, hi) = (start_a + min_size(set_a), end_b - min_size(set_b));
    if hi <= lo {
        return Vec::new();
    }
    // Positions of a's inner edge (`at_a`) and b's (`at_b`): a common grid over the span, or
    // each about its current place.
    let (step, base_a, base_b) = match window {
        None => ((hi - lo) / (grid - 1) as f32, lo, lo),
        Some(w) => (
            2.0 * w / (grid - 1) as f32,
            ra.edge(inner[0]) - w,
            rb.edge(inner[1]) - w,
        ),
    };
    let at_a = |j: usize| base_a + j as f32 * step;
    let at_b = |j: usize| base_b + j as f32 * step;
    let offset = |o: usize| (o as f32 - (OUTER_GRID / 2) as f32) * outer_step * span;
    let n = problem.n();
    let used: Vec<usize> = (0..n).filter(|&i| !problem.clipped[i]).collect();
    // The photo less the other lights, and the other lights' half-difference, per pixel.
    let (target, rest_dev): (Vec<[f64; 3]>, Vec<[f64; 3]>) = used
        .iter()
        .map(|&i| {
            let (mut rest, mut dev) = ([0f64; 3], [0f64; 3]);
            for (k, l) in st.radiance.iter().enumerate() {
                if k != a && k != b {
                    for ch in 0..3 {
                        rest[ch] += l[ch] * st.coef[k][i] as f64;
                        dev[ch] += l[ch] * st.dev[k][i] as f64;
                    }
                }
            }
            (
                [0, 1, 2].map(|ch| problem.obs[i][ch] as f64 - rest[ch]),
                dev,
            )
        })
        .unzip();
    // Per (outer offset, inner position) of one light: its coefficients and half-differences
    // on the used pixels, its terms of the normal equations, and its raw diagonal (0 where
    // the rectangle would be too small).
    struct Column {
        coef: Vec<f32>,
        dev: Vec<f32>,
        rhs: [f64; 3],
        diag: f64,
        raw: f64,
    }
    let empty = || Column {
        coef: Vec::new(),
        dev: Vec::new(),
        rhs: [0.0; 3],
        diag: 0.0,
        raw: 0.0,
    };
    // Per outer offset, one pass over each pixel's samples gives its coefficient at every
    // inner position (edge ramps); then the columns' sums.
    let columns = |set: usize, r: Rect, outer: EdgeSide, inner: EdgeSide, base: f32| {
        let samples = &problem.planes[set];
        let mut out = Vec::with_capacity(OUTER_GRID * grid);
        for o in 0..OUTER_GRID {
            let r_o = r.with_edge(outer, r.edge(outer) + offset(o));
            let rows: Vec<(Vec<f32>, Vec<f32>)> = used
                .par_iter()
                .map_init(
                    || EdgeRamps::new(base, step, grid),
                    |ramps, &i| {
                        let (mut c, mut d) = (vec![0f32; grid], vec![0f32; grid]);
                        samples.edge_coefficients(
                            i,
                            &r_o,
                            inner,
                            base,
                            step,
                            problem.inv_samples,
                            ramps,
                            &mut c,
                            &mut d,
                        );
                        (c, d)
                    },
                )
                .collect();
            for j in 0..grid {
                let t = base + j as f32 * step;
                let rect = r_o.with_edge(inner, t);
                let size = if vertical {
                    rect.v_max - rect.v_min
                } else {
                    rect.u_max - rect.u_min
                };
                if !(lo..=hi).contains(&t) || size < min_size(set) {
                    out.push(empty());
                    continue;
                }
                let coef: Vec<f32> = rows.iter().map(|row| row.0[j]).collect();
                let dev: Vec<f32> = rows.iter().map(|row| row.1[j]).collect();
                let mut rhs = [0f64; 3];
                let (mut diag, mut raw) = (0f64, 0f64);
                for (u, (&c, &d)) in coef.iter().zip(&dev).enumerate() {
                    let (c, d) = (c as f64, d as f64);
                    for ch in 0..3 {
                        rhs[ch] += target[u][ch] * c + rest_dev[u][ch] * d;
                    }
                    diag += c * c - d * d;
                    raw += c * c;
                }
                out.push(Column {
                    coef,
                    dev,
                    rhs,
                    diag: diag.max(0.5 * raw),
                    raw,
                });
            }
        }
        out
    };
    let col_a = columns(set_a, ra, outer[0], inner[0], base_a);
    let col_b = columns(set_b, rb, outer[1], inner[1], base_b);
    // The cost, less its constant part, with both radiances at their nonnegative optimum:
    // per channel min over L >= 0 of L^T A L - 2 L . g.
    let pair_cost = |xa: usize, xb: usize| -> f64 {
        let (ca, cb) = (&col_a[xa], &col_b[xb]);
        if ca.raw == 0.0 || cb.raw == 0.0 {
            return f64::INFINITY;
        }
        let cross: f64 = ca
            .coef
            .iter()
            .zip(&cb.coef)
            .zip(ca.dev.iter().zip(&cb.dev))
            .map(|((&x, &y), (&dx, &dy))| x as f64 * y as f64 - dx as f64 * dy as f64)
            .sum();
        let (aa, bb) = (ca.diag, cb.diag);
        (0..3)
            .map(|ch| {
                let (ga, gb) = (ca.rhs[ch], cb.rhs[ch]);
                let det = aa * bb - cross * cross;
                let mut best = 0f64;
                if det > 0.0 {
                    let la = (bb * ga - cross * gb) / det;
                    let lb = (aa * gb - cross * ga) / det;
                    if la >= 0.0 && lb >= 0.0 {
                        best = best.min(-(la * ga + lb * gb));
                    }
                }
                if ga > 0.0 {
                    best = best.min(-ga * ga / aa);
                }
                if gb > 0.0 {
                    best = best.min(-gb * gb / bb);
                }
                best
            })
            .sum()
    };
    // Grid coordinates: a's outer offset, a's inner position, b's inner position, b's outer
    // offset.
    type Point = [usize; 4];
    let points: Vec<Point> = (0..OUTER_GRID)
        .flat_map(|oa| {
            (0..grid).flat_map(move |ja| {
                (0..grid).flat_map(move |jb| (0..OUTER_GRID).map(move |ob| [oa, ja, jb, ob]))
            })
        })
        .filter(|p| at_a(p[1]) <= at_b(p[2]))
        .collect();
    let costs: Vec<f64> = points
        .par_iter()
        .map(|p| pair_cost(p[0] * grid + p[1], p[3] * grid + p[2]))
        .collect();
    let index: std::collections::HashMap<Point, f64> =
        points.iter().copied().zip(costs.iter().copied()).collect();
    // The local minima: no lower neighbour in the 4-D grid.
    let mut minima: Vec<(Point, f64)> = index
        .par_iter()
        .filter(|(p, &c)| {
            c.is_finite()
                && (0..81).all(|d| {
                    let q = [0, 1, 2, 3]
                        .map(|axis| p[axis] as i64 + (d / 3i64.pow(axis as u32)) % 3 - 1);
                    q.iter().any(|&x| x < 0)
                        || index.get(&q.map(|x| x as usize)).is_none_or(|&qc| qc >= c)
                })
        })
        .map(|(p, &c)| (*p, c))
        .collect();
    minima.sort_by(|x, y| x.1.total_cmp(&y.1));
    minima
        .iter()
        .map(|&(p, c)| {
            let new_a = ra
                .with_edge(outer[0], ra.edge(outer[0]) + offset(p[0]))
                .with_edge(inner[0], at_a(p[1]));
            let new_b = rb
                .with_edge(outer[1], rb.edge(outer[1]) + offset(p[3]))
                .with_edge(inner[1], at_b(p[2]));
            ([new_a, new_b], c, 1.5 * step)
        })
        .collect()
}

/// How many of the boundary search's lowest local minima are refined and descended from
/// (the search's cost leaves out clipped pixels and holds the other edges, so its ranking
/// is not final; on the stacked sample the lowest of them is often not the best basin).
const BOUNDARY_STARTS: usize = 3;

/// Sweeps of the descent from each of the boundary search's starts, before the lowest is
/// kept and descended fully. 4 give the same fits as the full 14 on the stacked sample (8
/// seeds), in half the time.
pub(super) const CANDIDATE_SWEEPS: u32 = 4;
