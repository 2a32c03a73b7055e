//! Overlapping streaks, method §5 and the paper's §5.3: where two lights split from one
//! meet. A global search over the boundary between them and their outer edges, since the
//! split's coarse descent from the half cut cannot find it (see [`search_boundary`]).

use rayon::prelude::*;

use super::problem::{Problem, State};
use super::ramps::EdgeRamps;
use super::samples::PlaneSamples;
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
    let [parts_a, parts_b] = [(set_a, ra, 0), (set_b, rb, 1)].map(|(set, r, m)| {
        LightParts::new(
            &problem.planes[set],
            problem.inv_samples,
            &used,
            r,
            [inner[m], outer[m]],
            (if m == 0 { base_a } else { base_b }, step, grid),
            (r.edge(outer[m]) + offset(0), outer_step * span),
        )
    });
    // Per (outer offset, inner position) of one light: its terms of the normal equations
    // and its raw diagonal; None where the rectangle would be too small.
    let summaries =
        |parts: &LightParts, set: usize, r: Rect, at: &dyn Fn(usize) -> f32, outer_side| {
            let own = parts.cross(parts);
            let rhs = |c: &[f32], d: &[f32]| {
                let mut g = [0f64; 3];
                for (u, (&c, &d)) in c.iter().zip(d).enumerate() {
                    for ch in 0..3 {
                        g[ch] += target[u][ch] * c as f64 + rest_dev[u][ch] * d as f64;
                    }
                }
                g
            };
            let rhs_inner: Vec<[f64; 3]> = (0..grid)
                .into_par_iter()
                .map(|j| rhs(&parts.inner[j].0, &parts.inner[j].1))
                .collect();
            let rhs_outer: Vec<[f64; 3]> = (0..OUTER_GRID)
                .into_par_iter()
                .map(|o| rhs(&parts.outer[o].0, &parts.outer[o].1))
                .collect();
            let mut out = Vec::with_capacity(OUTER_GRID * grid);
            for (o, g_outer) in rhs_outer.iter().enumerate() {
                let x_o = r.edge(outer_side) + offset(o);
                for (j, g_inner) in rhs_inner.iter().enumerate() {
                    let t = at(j);
                    let size = if outer_side.is_min() {
                        t - x_o
                    } else {
                        x_o - t
                    };
                    if !(lo..=hi).contains(&t) || size < min_size(set) {
                        out.push(None);
                        continue;
                    }
                    let [plain, signed] = own.pair(j, o, j, o);
                    out.push(Some(Column {
                        rhs: [0, 1, 2].map(|ch| g_inner[ch] + g_outer[ch]),
                        diag: (plain - signed).max(0.5 * plain),
                        raw: plain,
                    }));
                }
            }
            out
        };
    let col_a = summaries(&parts_a, set_a, ra, &at_a, outer[0]);
    let col_b = summaries(&parts_b, set_b, rb, &at_b, outer[1]);
    let cross_ab = parts_a.cross(&parts_b);
    // The cost, less its constant part, with both radiances at their nonnegative optimum:
    // per channel min over L >= 0 of L^T A L - 2 L . g.
    let pair_cost = |(oa, ja): (usize, usize), (ob, jb): (usize, usize)| -> f64 {
        let (Some(ca), Some(cb)) = (&col_a[oa * grid + ja], &col_b[ob * grid + jb]) else {
            return f64::INFINITY;
        };
        if ca.raw == 0.0 || cb.raw == 0.0 {
            return f64::INFINITY;
        }
        let [plain, signed] = cross_ab.pair(ja, oa, jb, ob);
        let cross = plain - signed;
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
        .map(|p| pair_cost((p[0], p[1]), (p[3], p[2])))
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

/// One column's terms of the boundary search's normal equations: `g = sum (target c +
/// rest_dev d)` per channel, its diagonal (noise-debiased, floored at half the raw one) and
/// its raw diagonal `sum c^2`.
struct Column {
    rhs: [f64; 3],
    diag: f64,
    raw: f64,
}

/// An edge beyond every sample, as the far side of a rectangle whose near side alone moves.
const FAR: f32 = 1.0e6;

/// One light's coefficients and half-differences on the used pixels with its inner edge at
/// every grid point `j` and its outer edge at every offset `o`, in two parts: along the edges'
/// axis every sample's kernel, and the control variate's Gaussian, put a mass `F(hi) - F(lo)`
/// inside the rectangle (one cumulative function read at both edges), so
/// `c(o, j) = inner[j] + outer[o]` with `inner[j]` the coefficient with the outer edge at its
/// offset farthest from the inner one (every valid rectangle holds it) and
/// `outer[o] = F(x_far) - F(x_o)` (with its sign for the side). Two passes over the samples
/// give every combination, and the dot products the search needs split the same way
/// ([`LightParts::cross`]).
struct LightParts {
    /// Per inner grid point: (coefficients, half-differences) over the used pixels.
    inner: Vec<(Vec<f32>, Vec<f32>)>,
    /// Per outer offset: the same, as the change from the farthest offset.
    outer: Vec<(Vec<f32>, Vec<f32>)>,
}

/// The dot products `sum c c'` and `sum d d'` between two lights' parts (see
/// [`LightParts::cross`]).
struct Cross {
    inner_inner: Vec<[f64; 2]>,
    inner_outer: Vec<[f64; 2]>,
    outer_inner: Vec<[f64; 2]>,
    outer_outer: Vec<[f64; 2]>,
    grid: usize,
}

impl Cross {
    /// `[sum c c', sum d d']` between the first light at inner point `j` and outer offset `o`
    /// and the second at `j2`, `o2`.
    fn pair(&self, j: usize, o: usize, j2: usize, o2: usize) -> [f64; 2] {
        let g = self.grid;
        let terms = [
            self.inner_inner[j * g + j2],
            self.inner_outer[j * OUTER_GRID + o2],
            self.outer_inner[o * g + j2],
            self.outer_outer[o * OUTER_GRID + o2],
        ];
        [0, 1].map(|m| terms.iter().map(|t| t[m]).sum())
    }
}

impl LightParts {
    /// The parts of light `r` reading `samples` (each sample's weight times `inv`) on the
    /// pixels `used`, whose `[inner, outer]` edges move: the inner one over `grid` points
    /// `base + j step`, the outer one over [`OUTER_GRID`] offsets `outer_base + o outer_step`.
    #[allow(clippy::too_many_arguments)]
    fn new(
        samples: &PlaneSamples,
        inv: f32,
        used: &[usize],
        r: Rect,
        [inner, outer]: [EdgeSide; 2],
        (base, step, grid): (f32, f32, usize),
        (outer_base, outer_step): (f32, f32),
    ) -> Self {
        // The outer offset farthest from the inner edge: the lowest for a bottom or left edge.
        let far = if outer.is_min() { 0 } else { OUTER_GRID - 1 };
        let with_far_outer = r.with_edge(outer, outer_base + far as f32 * outer_step);
        let with_far_inner = r.with_edge(inner, if inner.is_min() { -FAR } else { FAR });
        type Row = (Vec<f32>, Vec<f32>, [f32; OUTER_GRID], [f32; OUTER_GRID]);
        let rows: Vec<Row> = used
            .par_iter()
            .map_init(
                || {
                    (
                        EdgeRamps::new(base, step, grid),
                        EdgeRamps::new(outer_base, outer_step, OUTER_GRID),
                    )
                },
                |(ramps, outer_ramps), &i| {
                    let (mut c, mut d) = (vec![0f32; grid], vec![0f32; grid]);
                    samples.edge_coefficients(
                        i,
                        &with_far_outer,
                        inner,
                        base,
                        step,
                        inv,
                        ramps,
                        &mut c,
                        &mut d,
                    );
                    let (mut oc, mut od) = ([0f32; OUTER_GRID], [0f32; OUTER_GRID]);
                    samples.edge_coefficients(
                        i,
                        &with_far_inner,
                        outer,
                        outer_base,
                        outer_step,
                        inv,
                        outer_ramps,
                        &mut oc,
                        &mut od,
                    );
                    let (fc, fd) = (oc[far], od[far]);
                    (c, d, oc.map(|x| x - fc), od.map(|x| x - fd))
                },
            )
            .collect();
        LightParts {
            inner: (0..grid)
                .map(|j| rows.iter().map(|r| (r.0[j], r.1[j])).unzip())
                .collect(),
            outer: (0..OUTER_GRID)
                .map(|o| rows.iter().map(|r| (r.2[o], r.3[o])).unzip())
                .collect(),
        }
    }

    /// The dot products between every part of this light and every part of `other`.
    fn cross(&self, other: &LightParts) -> Cross {
        let dots = |xs: &[(Vec<f32>, Vec<f32>)], ys: &[(Vec<f32>, Vec<f32>)]| -> Vec<[f64; 2]> {
            (0..xs.len() * ys.len())
                .into_par_iter()
                .map(|n| {
                    let (x, y) = (&xs[n / ys.len()], &ys[n % ys.len()]);
                    [dot(&x.0, &y.0), dot(&x.1, &y.1)]
                })
                .collect()
        };
        Cross {
            inner_inner: dots(&self.inner, &other.inner),
            inner_outer: dots(&self.inner, &other.outer),
            outer_inner: dots(&self.outer, &other.inner),
            outer_outer: dots(&self.outer, &other.outer),
            grid: other.inner.len(),
        }
    }
}

fn dot(x: &[f32], y: &[f32]) -> f64 {
    x.iter().zip(y).map(|(&a, &b)| a as f64 * b as f64).sum()
}

/// How many of the boundary search's lowest local minima are refined and descended from
/// (the search's cost leaves out clipped pixels and holds the other edges, so its ranking
/// is not final; on the stacked sample the lowest of them is often not the best basin).
const BOUNDARY_STARTS: usize = 3;

/// Sweeps of the descent from each of the boundary search's starts, before the lowest is
/// kept and descended fully. 4 give the same fits as the full 14 on the stacked sample (8
/// seeds), in half the time.
pub(super) const CANDIDATE_SWEEPS: u32 = 4;

#[cfg(test)]
mod tests {
    use super::super::fixture::table3_light0;
    use super::*;

    /// The two parts add up to the coefficient and half-difference of every rectangle of the
    /// search, and their dot products to those of the sums, for a light whose inner edge is
    /// its top and one whose inner edge is its bottom.
    #[test]
    fn the_parts_add_up_to_every_rectangles_coefficients() {
        let t = table3_light0();
        let (planes, n) = t.trace(72, 1, 0, true);
        let (samples, inv) = (&planes[0], 1.0 / n as f32);
        let used: Vec<usize> = (0..t.pixels.len()).collect();
        let r = t.light.rect();
        let (grid, outer_step) = (9, 0.05 * r.height());
        let step = 0.08 * r.height();
        let mut parts = Vec::new();
        for [inner, outer] in [
            [EdgeSide::Top, EdgeSide::Bottom],
            [EdgeSide::Bottom, EdgeSide::Top],
        ] {
            let base = r.edge(inner) - 0.3 * r.height();
            let outer_base = r.edge(outer) - 2.0 * outer_step;
            let p = LightParts::new(
                samples,
                inv,
                &used,
                r,
                [inner, outer],
                (base, step, grid),
                (outer_base, outer_step),
            );
            let mut compared = 0;
            for o in 0..OUTER_GRID {
                for j in 0..grid {
                    let rect = r
                        .with_edge(outer, outer_base + o as f32 * outer_step)
                        .with_edge(inner, base + j as f32 * step);
                    if rect.v_max - rect.v_min <= 0.0 {
                        continue;
                    }
                    for &i in &used {
                        let (c, d) = samples.coefficient(i, &rect, inv);
                        let (pc, pd) = (
                            p.inner[j].0[i] + p.outer[o].0[i],
                            p.inner[j].1[i] + p.outer[o].1[i],
                        );
                        let tolerance = 1e-6 + 1e-4 * c.abs().max(d.abs());
                        assert!(
                            (pc - c).abs() <= tolerance && (pd - d).abs() <= tolerance,
                            "{inner:?} o {o} j {j} pixel {i}: ({pc}, {pd}) against ({c}, {d})"
                        );
                        compared += (c != 0.0) as usize;
                    }
                }
            }
            assert!(compared > 1000, "only {compared} nonzero coefficients");
            parts.push(p);
        }
        let (a, b) = (&parts[0], &parts[1]);
        let cross = a.cross(b);
        for (j, o, j2, o2) in [(0, 0, 8, 4), (4, 2, 3, 1), (8, 4, 0, 0)] {
            let sum = |p: &LightParts, j: usize, o: usize, m: usize| -> Vec<f64> {
                let (inner, outer) = if m == 0 {
                    (&p.inner[j].0, &p.outer[o].0)
                } else {
                    (&p.inner[j].1, &p.outer[o].1)
                };
                inner
                    .iter()
                    .zip(outer)
                    .map(|(&x, &y)| x as f64 + y as f64)
                    .collect()
            };
            let got = cross.pair(j, o, j2, o2);
            for (m, got) in got.into_iter().enumerate() {
                let (x, y) = (sum(a, j, o, m), sum(b, j2, o2, m));
                let want: f64 = x.iter().zip(&y).map(|(p, q)| p * q).sum();
                assert!(
                    (got - want).abs() <= 1e-9 * want.abs().max(1e-12),
                    "{m}: {got} against {want}"
                );
            }
        }
    }
}
