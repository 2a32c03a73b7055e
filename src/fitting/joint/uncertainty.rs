//! The joint fit's uncertainties and edge statuses (method §5, last paragraph): one-sigma
//! uncertainties of every light's edges and radiances from the curvature of the cost the fit
//! minimises, and which edges the photo does not determine.

use super::colour::ColourRule;
use super::problem::{Problem, State};
use crate::fitting::linalg::invert;
use crate::fitting::rect::Rect;
use crate::fitting::{EdgeSide, EdgeStatus, FittedLight};

/// One-sigma uncertainties of a light's parameters.
#[derive(Clone, Debug, PartialEq)]
pub struct Uncertainty {
    /// Left, right, bottom and top edges, metres along the plane's axes (indexed by
    /// [`EdgeSide`]). `None` when the photo does not constrain the edge (flat cost).
    pub edges: [Option<f32>; 4],
    /// Radiance per channel, in radiance units.
    pub radiance: [f32; 3],
    /// Fitted pixels outside the water that see the light itself (a sample of their camera
    /// rays lands inside its rectangle): 0 for a light out of frame or hidden, or with the
    /// direct view off. The edges they cross pin the rectangle to a fraction of a pixel
    /// (their sigmas say how well).
    pub direct_pixels: usize,
    /// Whether a fitted pixel sees the light whole in a channel the photo did not clip, so
    /// that its radiance is read off its image (`Problem::sees_radiance`); otherwise the
    /// reflections alone give it.
    pub radiance_seen: bool,
    /// Per edge, the largest one-sigma error the light's direct image leaves it, metres
    /// (`image_bound`: a pixel's footprint over sqrt(3) where a move by a footprint either way
    /// would make the pixels that see the light disagree with the photo); `None` where the
    /// image does not pin it. The edge's sigma never exceeds it ([`Uncertainty::bound_by_image`]).
    pub image_bound: [Option<f32>; 4],
    /// Per parameter (the left, right, bottom and top edges, then the three radiances), its
    /// variance in two parts ([`VarianceParts`]); `None` for an edge the photo does not
    /// constrain, or where the covariance could not be had.
    pub parts: [Option<VarianceParts>; 7],
    /// Per edge, metres per unit `e`: how far the edge moves when the light's radiance is
    /// scaled by `1 + e` and the other parameters fitted again (the curvature's conditional
    /// response). An error of the radiance's scale that no residual shows (one realisation of
    /// the waves) carries into the edges by it (`slopes::realisation_floor`): a lamp's image
    /// clipped inside pins an edge by the pixels it crosses, whose values are radiance times
    /// coverage. 0 for an edge that is not fitted.
    pub radiance_response: [f64; 4],
}

/// A parameter's variance in two parts: what the water's pixels give, which the glitter's
/// correlation grows under the statistical model ([`Uncertainty::widen`]), and the rest,
/// which it does not: the pixels that see the light directly, the colour ratio of a channel
/// set from another (`colour`), the repeats' spread.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct VarianceParts {
    /// From the water's pixels, squared units.
    pub water: f64,
    /// The rest, squared units.
    pub other: f64,
}

impl Uncertainty {
    /// Each parameter that has [`parts`](Self::parts) gets the sigma `sqrt(area * water +
    /// other + carried(i))`, `i` indexing the parameters as `parts` does: the water's share
    /// grown by the residual's correlation area `area` (one value per `area` pixels) and
    /// `carried(i)` added, a variance carried from outside the fit. Then bound by the image
    /// ([`Self::bound_by_image`]).
    pub fn widen(&mut self, area: f64, carried: impl Fn(usize) -> f64) {
        for (i, parts) in self.parts.iter().enumerate() {
            let Some(p) = parts else { continue };
            let sd = (area * p.water + p.other + carried(i)).max(0.0).sqrt() as f32;
            if i < 4 {
                self.edges[i] = Some(sd);
            } else {
                self.radiance[i - 4] = sd;
            }
        }
        self.bound_by_image();
    }

    /// Adds `variance` (squared units; per parameter as in [`parts`](Self::parts)) to the
    /// part the glitter does not grow, and sets the sigmas from the parts.
    pub(super) fn add_other(&mut self, variance: [f64; 7]) {
        for (p, v) in self.parts.iter_mut().zip(variance) {
            if let Some(p) = p {
                p.other += v;
            }
        }
        self.widen(1.0, |_| 0.0);
    }

    /// Each edge's sigma no larger than its [`image_bound`](Self::image_bound), and one given
    /// where only the image constrains it. Whatever widens the sigmas (the repeats' spread,
    /// the glitter's correlation) says how well the reflections place the edge; the image
    /// places it within its pixels regardless.
    pub fn bound_by_image(&mut self) {
        for side in EdgeSide::ALL {
            if let Some(b) = self.image_bound[side] {
                self.edges[side] = Some(self.edges[side].map_or(b, |sd| sd.min(b)));
            }
        }
    }
}

/// One-sigma uncertainties of every light's free edges and radiances, from their full
/// covariance at once (Gauss-Newton, made robust to uneven noise: see below), J being the
/// model's derivatives at every fitted pixel that measures it and every channel. Holding the
/// other parameters fixed, as a per-edge curvature would, understates errors that travel
/// along correlated directions (a light's height against its radiance when only one end of
/// its streak is seen); the full covariance carries them.
///
/// An edge's derivative is the change of the coefficients over a step of 2 % of the light's
/// size (at least 5e-4 of its distance from the camera, 5 mm at 10 m) each way: below a few
/// millimetres at that distance the stored samples make the coefficients a staircase. A
/// direct pixel's (`direct`) is taken over a quarter of its footprint, and only the channels
/// that measure the model count ([`Problem::measures`]: not clipped, and not black where the
/// light is seen directly): a lamp's image clipped in its strong channels still measures its
/// weak one. An edge that moves nothing gets no uncertainty (`None`: the photo does not
/// constrain it), and so does a pinned one. An edge the light's direct image pins within its
/// pixels (`image_bound`: clipped on one side, black on the other) gets no more than that
/// bound.
///
/// The variance comes in two parts ([`VarianceParts`]), the water pixels' scores and the
/// direct pixels' summed apart; a radiance its image gives also carries the rounding its
/// pixels share ([`Problem::shared_rounding`]). A channel the colour rule set from another
/// (`colours`) gets that channel's variance times the squared ratio, plus the ratio's own.
pub(super) fn uncertainties(
    problem: &Problem,
    st: &State,
    extents: &[Option<Rect>],
    colours: &[Option<ColourRule>],
) -> Vec<Uncertainty> {
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
        let h =
            (0.02 * r.width().max(r.height())).max(5e-4 * problem.planes[st.set_of[k]].distance);
        for side in EdgeSide::ALL {
            if st.pinned[k][side] || extents[st.set_of[k]].is_none() {
                continue;
            }
            let e = r.edge(side);
            let set = st.set_of[k];
            let (mut g, mut g_dev) =
                problem.edge_slopes(set, &r.with_edge(side, e + h), &r.with_edge(side, e - h), h);
            // The direct pixels' coefficients are smooth on a far finer scale.
            if let Some(hd) = problem.direct_step(set, side.along_u()) {
                let (gd, gd_dev) = problem.edge_slopes(
                    set,
                    &r.with_edge(side, e + hd),
                    &r.with_edge(side, e - hd),
                    hd,
                );
                let direct = problem.first_direct..problem.n();
                // A handful of pixels (the corners of a light whose sides lie between a black
                // and a clipped column) cannot tell their own noise: their scatter would make
                // the sigma, and it came out at a fifth of the error on the stacked1000
                // sample. Such an edge is left to the other pixels.
                let measuring = direct
                    .clone()
                    .filter(|&i| gd[i] != 0.0 && (0..3).any(|ch| problem.measures(i, ch)))
                    .count();
                let keep = measuring >= MIN_DIRECT_PIXELS;
                for i in direct {
                    (g[i], g_dev[i]) = if keep { (gd[i], gd_dev[i]) } else { (0.0, 0.0) };
                }
            }
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
    // coefficients' noise in `cost`): bread = sum of (J J^T - Jd Jd^T), score per pixel = sum
    // over channels of (r J + d Jd). The plain J^T J counts the samples' noise in the
    // derivatives as curvature (E[J_est J_est^T] = J J^T + their variance), so along a
    // direction the photo barely constrains (Table 3's light1: its height against its
    // radiance) it claims several times the real curvature and the sigmas come out small
    // (docs/decisions.md, "Uncertainties: the curvature of the noise-corrected
    // cost"). The
    // noise is far from uniform (a streak's bright pixels carry most of it, the dark
    // surroundings none), the three channels of a pixel share it (a white light), and the
    // stored samples add their own: a single variance sigma^2 for all would
    // understate the errors tenfold (measured on Table 1), the residuals themselves carry
    // all three.
    let mut jtj = vec![0.0; p * p];
    let mut raw_diagonal = vec![0.0; p];
    // The scores' products, the water pixels' and the direct pixels' apart.
    let mut meats = [vec![0.0; p * p], vec![0.0; p * p]];
    let mut row = vec![0.0; p];
    let mut dev_row = vec![0.0; p];
    let mut score = vec![0.0; p];
    for i in 0..problem.n() {
        let m = problem.model(st, i);
        score.iter_mut().for_each(|x| *x = 0.0);
        let mut any = false;
        for (ch, (obs, model)) in problem.obs[i].iter().zip(m).enumerate() {
            if !problem.measures(i, ch) {
                continue;
            }
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
            let meat = &mut meats[usize::from(i >= problem.first_direct)];
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
    // The diagonal of the sandwich inv M inv, for each part's M.
    let parts = invert(&jtj, p).map(|inv| {
        meats.map(|meat| {
            (0..p)
                .map(|a| {
                    let mut sum = 0.0;
                    for b in 0..p {
                        let ab = inv[a * p + b];
                        if ab != 0.0 {
                            for c in 0..p {
                                sum += ab * meat[b * p + c] * inv[c * p + a];
                            }
                        }
                    }
                    sum
                })
                .collect::<Vec<f64>>()
        })
    });
    let mut out: Vec<Uncertainty> = (0..lights)
        .map(|_| Uncertainty {
            edges: [None; 4],
            radiance: [f32::INFINITY; 3],
            direct_pixels: 0,
            radiance_seen: false,
            image_bound: [None; 4],
            parts: [None; 7],
            radiance_response: [0.0; 4],
        })
        .collect();
    // Each light's edges' response to a scale of its radiance: the edges' block of the
    // curvature solved against its coupling to the radiance so scaled.
    let edge_params: Vec<usize> = (0..p)
        .filter(|&a| matches!(params[a], Param::Edge(..)))
        .collect();
    let ne = edge_params.len();
    let block: Vec<f64> = edge_params
        .iter()
        .flat_map(|&a| edge_params.iter().map(move |&b| (a, b)))
        .map(|(a, b)| jtj[a * p + b])
        .collect();
    if let Some(block_inv) = invert(&block, ne).filter(|_| ne > 0) {
        for (k, u) in out.iter_mut().enumerate() {
            let coupling: Vec<f64> = edge_params
                .iter()
                .map(|&a| {
                    (0..p)
                        .filter_map(|b| match params[b] {
                            Param::Radiance(kk, ch) if kk == k => {
                                Some(jtj[a * p + b] * st.radiance[k][ch])
                            }
                            _ => None,
                        })
                        .sum()
                })
                .collect();
            for (x, &a) in edge_params.iter().enumerate() {
                if let Param::Edge(kk, side, ..) = params[a] {
                    if kk == k {
                        let moved: f64 = (0..ne).map(|y| block_inv[x * ne + y] * coupling[y]).sum();
                        u.radiance_response[side as usize] = -moved;
                    }
                }
            }
        }
    }
    if let Some([water, direct]) = parts {
        for (a, param) in params.iter().enumerate() {
            let (k, i) = match param {
                Param::Edge(k, side, ..) => (*k, *side as usize),
                Param::Radiance(k, ch) => (*k, 4 + ch),
            };
            let finite = |v: f64| {
                if v.is_finite() && v >= 0.0 {
                    v
                } else {
                    f64::INFINITY
                }
            };
            out[k].parts[i] = Some(VarianceParts {
                water: finite(water[a]),
                other: finite(direct[a]),
            });
        }
    }
    for (k, u) in out.iter_mut().enumerate() {
        let rounding = problem.shared_rounding(st.set_of[k], &st.rects[k]);
        for (p, r) in u.parts[4..].iter_mut().zip(rounding) {
            if let Some(p) = p {
                p.other += r;
            }
        }
        let Some(rule) = colours.get(k).copied().flatten() else {
            continue;
        };
        let Some(best) = u.parts[4 + rule.best] else {
            continue;
        };
        let from = st.radiance[k][rule.best];
        for ch in (0..3).filter(|&ch| rule.set[ch]) {
            let value = st.radiance[k][ch];
            let f2 = if from > 0.0 {
                (value / from).powi(2)
            } else {
                0.0
            };
            u.parts[4 + ch] = Some(VarianceParts {
                water: f2 * best.water,
                other: f2 * best.other + value * value * rule.ratio_variance[ch],
            });
        }
    }
    for (u, bound) in out.iter_mut().zip(problem.image_bounds(st)) {
        u.image_bound = bound;
        u.widen(1.0, |_| 0.0);
    }
    out
}

/// Fewest direct pixels that must measure an edge (not clipped, not black, moved by it) for
/// them to count in its uncertainty (see [`uncertainties`]).
pub(super) const MIN_DIRECT_PIXELS: usize = 16;

/// Why an edge that faces another light split from the same start is reported unconstrained.
pub(super) const FACING_REASON: &str =
    "it faces another light split from the same streak: no streak edge \
    shows it, and the fit places it only from where the two reflections overlap";

/// Per light and edge (left, right, bottom, top), whether the edge faces another light split
/// from the same start. The split lights' outer edges are the merged light's, measured from
/// its streak's edge pixels; the facing ones were made by the cut, and the streak's edges say
/// nothing about them. Two lights count as one above the other when their centres are
/// further apart vertically than horizontally, each in units of the pair's summed size.
pub(super) fn facing_edges(problem: &Problem, st: &State) -> Vec<[bool; 4]> {
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
            facing[side] = true;
        }
    }
    out
}

/// Marks edges the joint fit found unconstrained (flat cost) as such, keeping the paper's
/// reason where it had one.
pub fn edge_statuses(light: &FittedLight, u: &Uncertainty) -> [EdgeStatus; 4] {
    let mut out = light.edges.clone();
    for side in EdgeSide::ALL {
        if let (None, EdgeStatus::Constrained { pixels }) = (u.edges[side], &out[side]) {
            out[side] = EdgeStatus::Unconstrained {
                reason: "moving this edge does not change the modelled photo".into(),
                pixels: *pixels,
                unseen: false,
            };
        }
    }
    out
}
