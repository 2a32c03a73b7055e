//! The cost along one edge (method §5, last paragraph): the coordinate descent's 1-D step.
//!
//! [`Problem::edge_profile`] evaluates the cost on a whole grid of positions of one light's
//! edge in one pass over the samples ([`super::ramps`]), with that light's radiance
//! re-optimised at every grid point (nonnegative; in closed form, then Newton steps where
//! clipped pixels count: [`super::clipped`]) and the other lights held.
//! A far-off start is so pulled in by a global 1-D search rather than a local step.

use rayon::prelude::*;

use super::clipped::{counted, ClippedConstant, ClippedPixel, ClippedRow};
use super::control_variate;
use super::control_variate::LobeGaussian;
use super::pieces::{PieceSums, Window, CUBIC_NODES};
use super::problem::{Problem, State};
use super::ramps::{EdgeFrame, EdgeRamps};
use crate::fitting::EdgeSide;

/// Pixels per parallel piece of an edge profile.
const PROFILE_CHUNK: usize = 2048;

/// Most Newton steps of an edge profile's radiance where clipped pixels count
/// ([`Problem::edge_profile`]).
const CLIPPED_ROUNDS: usize = 8;

/// The widest window, in deviations of a pixel's Gaussian, over which its mass inside the
/// rectangle is taken as the cubic through four points: the cubic's error is below
/// `3e-4 (w / sd)^4` of the mass, 2e-9 here, far under the f32 rounding of the table the
/// distribution function is read from ([`control_variate::normal_cdf`]).
const CUBIC_WINDOW: f64 = 0.05;

/// The most ramps a pixel may have on the grid for its sums to be taken as polynomials over
/// the runs between them ([`PieceSums`]): each run costs about as much as a few grid points,
/// and the ramps are sorted first; a pixel with more is summed point by point.
const PIECE_RAMPS: usize = 8;

/// The mass of Gaussian `g` inside the rectangle as the edge moves over `window`, as a
/// cubic in the window's x ([`Window::cubic`]): its share across the edge is `across`, along
/// it the mass between the edge and the opposite edge `opp` (above the edge for a lower
/// edge, `min_edge`). `None` when the window is too wide against the Gaussian for a cubic
/// ([`CUBIC_WINDOW`]) or crosses the opposite edge.
fn narrow_gauss(
    window: &Window,
    g: &LobeGaussian,
    across: f64,
    mean: f32,
    sd: f32,
    opp: f32,
    min_edge: bool,
) -> Option<[f64; 4]> {
    if 2.0 * window.half > CUBIC_WINDOW * sd as f64 {
        return None;
    }
    let at_opp = control_variate::normal_cdf(opp, mean, sd);
    let mut values = [0f64; 4];
    for (v, x) in values.iter_mut().zip(CUBIC_NODES) {
        let t = (window.centre + window.half * x) as f32;
        let at_t = control_variate::normal_cdf(t, mean, sd);
        let inside = if min_edge {
            at_opp - at_t
        } else {
            at_t - at_opp
        };
        if inside < 0.0 {
            return None;
        }
        *v = g.mass as f64 * across * inside;
    }
    Some(Window::cubic(values))
}

/// Per grid point of an edge profile: the normal-equation sums over some pixels, and the
/// clipped pixels' coefficients (they enter the cost one-sidedly, so they are kept whole).
struct ProfileSums {
    a: Vec<f64>,
    a_raw: Vec<f64>,
    b: Vec<[f64; 3]>,
    /// The same at every grid point (pixels with no sample in the window), kept once.
    flat: FlatSums,
    clipped_rows: Vec<ClippedRow>,
    /// The clipped pixels whose coefficient is the same at every grid point.
    clipped_flat: Vec<ClippedConstant>,
}

/// Normal-equation sums that do not depend on the edge's grid position.
#[derive(Default)]
struct FlatSums {
    a: f64,
    a_raw: f64,
    b: [f64; 3],
}

impl Problem {
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
        // Pixels whose coefficient is smooth over the window are summed as polynomials
        // (`pieces`); a one-point grid has no window to speak of.
        let window = (grid >= 2).then(|| Window::new(lo, step, grid));
        let mut pieces = PieceSums::new(grid);
        // Clipped pixels need the whole c(t) to apply their one-sided residual later.
        let mut clipped_rows: Vec<ClippedRow> = Vec::new();
        let mut clipped_flat: Vec<ClippedConstant> = Vec::new();
        let mut flat = FlatSums::default();
        let hi = lo + step * (grid - 1) as f32;
        let frame = EdgeFrame::new(&rect, side);
        let (along_u, min_edge, opp) = (frame.along_u, frame.min_edge, frame.opposite);
        let (o_lo, o_hi) = frame.across;
        for &i in chunk {
            let g = plane.gauss[i];
            if plane.range(i).is_empty() && g.is_none() {
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
            // changes at all it is counted exactly: treating small changes as none (below
            // 1e-4 of the lobe) makes the profiles disagree with the coefficients they stand
            // for, and the descent takes more sweeps to a worse end (Table 3).
            let (g_across, g_mean, g_sd) = if g.is_none() {
                (0.0, 0.0, 1.0)
            } else if along_u {
                (g.share_v(o_lo, o_hi), g.mean.x, g.sd.x)
            } else {
                (g.share_u(o_lo, o_hi), g.mean.y, g.sd.y)
            };
            let gauss_varies = !g.is_none()
                && g_across * control_variate::normal_between(lo, hi, g_mean, g_sd) > 0.0;
            // Whether any of its samples' kernels can be inside the rectangle as the edge
            // moves over the window: reaching into the window, and across it into the
            // rectangle's extent along the edge (a kernel outside that counts nowhere).
            let (cmin, cmax) = if along_u {
                (bb.v_min, bb.v_max)
            } else {
                (bb.u_min, bb.u_max)
            };
            let samples_reach = !(bmax < lo || bmin > hi || cmax < o_lo || cmin > o_hi);
            // Its coefficient and half-difference, when they are the same at every grid point
            // (a clipped pixel's cost is one-sided, not a normal-equation sum: `clipped`).
            let mut same_everywhere = |c: f64, d: f64, flat: &mut FlatSums| {
                if self.clipped[i] {
                    if c != 0.0 || d != 0.0 {
                        let pixel = self.clipped_pixel(st, k, i);
                        clipped_flat.push(ClippedConstant { pixel, c, d });
                    }
                } else if c != 0.0 {
                    let (rest, rest_dev) = self.others(st, k, i);
                    flat.a_raw += c * c;
                    flat.a += c * c - d * d;
                    for ch in 0..3 {
                        flat.b[ch] += c * (self.obs[i][ch] as f64 - rest[ch]) + d * rest_dev[ch];
                    }
                }
            };
            if !samples_reach && !gauss_varies {
                // Nothing of this pixel's coefficient changes over the window.
                same_everywhere(st.coef[k][i] as f64, st.dev[k][i] as f64, &mut flat);
                continue;
            }
            // The Gaussian's mass inside the rectangle as it is now.
            let g_now = g.mass_inside(&rect);
            ramps.clear(grid);
            let mut any = false;
            if !samples_reach {
                // Only the Gaussian moves: the samples' part is what it is now.
                let inv = self.inv_samples as f64;
                let sampled = st.coef[k][i] as f64 - g_now as f64;
                let dev = st.dev[k][i] as f64 / inv;
                ramps.constant(sampled / inv, dev);
                any = true;
            }
            if samples_reach {
                // Only the samples near the window (and the edge's place now) move with the
                // edge: the others count as they do now, which the current coefficient less
                // the near samples' share gives without reading them (in late sweeps, a
                // tenth of the samples are near).
                let cur = rect.edge(side);
                let near = plane.near(i, along_u, lo.min(cur), hi.max(cur));
                let (touched, (near_now, near_now_signed)) =
                    plane.add_to_ramps(near, &frame, Some(cur), &mut ramps);
                let inv = self.inv_samples as f64;
                let far = (st.coef[k][i] as f64 - g_now as f64) / inv - near_now;
                let far_signed = st.dev[k][i] as f64 / inv - near_now_signed;
                if far != 0.0 || far_signed != 0.0 {
                    ramps.constant(far, far_signed);
                    any = true;
                }
                any |= touched;
            }
            if !any && !gauss_varies {
                same_everywhere(g_now as f64, 0.0, &mut flat);
                continue;
            }
            if !ramps.kinked && !gauss_varies {
                // Every kernel it has lies wholly on one side of the window.
                let [c, d] = ramps.constant;
                let inv = self.inv_samples as f64;
                let c = c * inv + g_now as f64;
                same_everywhere(c, d * inv, &mut flat);
                continue;
            }
            let (rest, rest_dev) = self.others(st, k, i);
            let res = [0, 1, 2].map(|ch| self.obs[i][ch] as f64 - rest[ch]);
            let few_ramps = ramps.ramp_count() <= PIECE_RAMPS;
            if let (false, true, Some(window)) = (self.clipped[i], few_ramps, window) {
                // The control variate's part as a cubic in the window's x, when it is one.
                let gauss = if gauss_varies {
                    narrow_gauss(&window, &g, g_across, g_mean, g_sd, opp, min_edge)
                } else {
                    Some([g_now as f64, 0.0, 0.0, 0.0])
                };
                if let Some(gauss) = gauss {
                    let inv = self.inv_samples as f64;
                    ramps.for_each_piece(|j0, j1, intercept, slope| {
                        let c = [
                            (intercept[0] + slope[0] * window.centre) * inv + gauss[0],
                            slope[0] * window.half * inv + gauss[1],
                            gauss[2],
                            gauss[3],
                        ];
                        let d = [
                            (intercept[1] + slope[1] * window.centre) * inv,
                            slope[1] * window.half * inv,
                        ];
                        pieces.add(j0, j1, c, d, res, rest_dev);
                    });
                    continue;
                }
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
                let a = g_now / self.inv_samples;
                for c in cvals.iter_mut() {
                    *c += a;
                }
            }
            if self.clipped[i] {
                let inv = self.inv_samples;
                clipped_rows.push(ClippedRow {
                    pixel: ClippedPixel {
                        res,
                        rest_dev,
                        bound: self.clipped_channels[i],
                    },
                    c: cvals.iter().map(|c| c * inv).collect(),
                    d: half_difference.iter().map(|d| d * inv).collect(),
                });
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
        if let Some(window) = window {
            pieces.add_to(&window, &mut a, &mut a_raw, &mut b);
        }
        ProfileSums {
            a,
            a_raw,
            b,
            flat,
            clipped_rows,
            clipped_flat,
        }
    }

    /// Clipped pixel i's residual and the other lights' half-difference with light k dark.
    fn clipped_pixel(&self, st: &State, k: usize, i: usize) -> ClippedPixel {
        let (rest, rest_dev) = self.others(st, k, i);
        ClippedPixel {
            res: [0, 1, 2].map(|ch| self.obs[i][ch] as f64 - rest[ch]),
            rest_dev,
            bound: self.clipped_channels[i],
        }
    }

    /// The cost over the fitted pixels `pixels` (every one, or those that see the lights
    /// directly alone: [`super::JointOptions::edges_by_image`]), as a function of one edge
    /// of light `k` on the grid `lo + j * step` (`j < grid`), with light k's radiance
    /// re-optimised over the same pixels (nonnegative, the clipped ones counted as the cost
    /// counts them) at every grid point and the other lights held. Returns per grid point (cost up to a constant, the radiance).
    #[allow(clippy::too_many_arguments)]
    pub(super) fn edge_profile(
        &self,
        st: &State,
        k: usize,
        side: EdgeSide,
        lo: f32,
        step: f32,
        grid: usize,
        pixels: std::ops::Range<usize>,
    ) -> Vec<(f64, [f64; 3])> {
        // Fixed chunks summed in order: the same sums whatever the thread count.
        let parts: Vec<ProfileSums> = pixels
            .collect::<Vec<_>>()
            .par_chunks(PROFILE_CHUNK)
            .map(|chunk| self.profile_sums(st, k, side, lo, step, grid, chunk))
            .collect();
        let mut a = vec![0f64; grid];
        let mut a_raw = vec![0f64; grid];
        let mut b = vec![[0f64; 3]; grid];
        let mut clipped_rows: Vec<ClippedRow> = Vec::new();
        let mut clipped_flat: Vec<ClippedConstant> = Vec::new();
        for part in parts {
            for j in 0..grid {
                a[j] += part.a[j] + part.flat.a;
                a_raw[j] += part.a_raw[j] + part.flat.a_raw;
                for ((total, here), flat) in b[j].iter_mut().zip(part.b[j]).zip(part.flat.b) {
                    *total += here + flat;
                }
            }
            clipped_rows.extend(part.clipped_rows);
            clipped_flat.extend(part.clipped_flat);
        }
        // Pixels with no sample of light k contribute a constant, left out.
        // A rectangle that catches only a few samples has a variance as large as its mean
        // square: the corrected normal equation would divide by ~0. Keep at least half of the
        // raw term (the bias then stays bounded, and such a rectangle is far from the optimum).
        for j in 0..grid {
            a[j] = a[j].max(0.5 * a_raw[j]);
        }
        let base = |j: usize, l: [f64; 3]| -> f64 {
            // sum (r - L c)^2 - sum r^2 = L^2 A - 2 L B
            (0..3)
                .map(|ch| l[ch] * l[ch] * a[j] - 2.0 * l[ch] * b[j][ch])
                .sum()
        };
        // The radiance over the pixels not clipped, in closed form; then, where the clipped
        // pixels count at it (a clipped channel whose model is below the photo, every value
        // channel of a clipped pixel), the radiance that minimises the whole cost, by Newton
        // steps on it: each the least-squares radiance of the channels that count at the
        // last. From below the clip (where a clipped image holds a light's radiance up) the
        // steps rise to the minimum without passing it, as fewer channels count further up.
        let mut radiance: Vec<[f64; 3]> = (0..grid)
            .map(|j| {
                [0, 1, 2].map(|ch| {
                    if a[j] > 0.0 {
                        (b[j][ch] / a[j]).max(0.0)
                    } else {
                        0.0
                    }
                })
            })
            .collect();
        let mut best = vec![(f64::INFINITY, [0.0; 3]); grid];
        for round in 0..=CLIPPED_ROUNDS {
            let counted = counted(&clipped_flat, &clipped_rows, &radiance);
            for (j, (best, &l)) in best.iter_mut().zip(&radiance).enumerate() {
                let cost = base(j, l) + counted.cost(j, l);
                if cost < best.0 {
                    *best = (cost, l);
                }
            }
            if round == CLIPPED_ROUNDS || (clipped_flat.is_empty() && clipped_rows.is_empty()) {
                break;
            }
            let next: Vec<[f64; 3]> = (0..grid)
                .map(|j| {
                    [0, 1, 2].map(|ch| {
                        let s = counted.sums[j][ch];
                        let curvature = (a[j] + s[2]).max(0.5 * a[j]);
                        if curvature > 0.0 {
                            ((b[j][ch] + s[1]) / curvature).max(0.0)
                        } else {
                            0.0
                        }
                    })
                })
                .collect();
            if next == radiance {
                break;
            }
            radiance = next;
        }
        best
    }
}

#[cfg(test)]
mod tests {
    use super::super::fixture::table3_light0;
    use super::super::problem::Problem;
    use crate::fitting::rect::Rect;
    use crate::fitting::EdgeSide;

    #[test]
    fn an_edge_profile_is_the_cost_and_radiance_at_every_grid_point() {
        // Table 3's light0 samples, a photo its true rectangle gives, and a start 0.3 m off
        // on every side. At every grid point of every edge, over a wide window and two narrow
        // ones, the profile (which reads only the samples near the window) must give the
        // radiance that minimises the whole cost there, and the cost differences the whole
        // cost gives. Three photos: none clipped; the brightest pixels clipped in their first
        // channel (counted only while the model is below them, their other channels always);
        // and those pixels clipped at their own value with every other pixel 5 % darker, so
        // that the clip holds the radiance up (a lamp exactly at the clip over one
        // realisation's darker water), where a radiance solved without the clipped pixels
        // comes out 5 % low and the clipped pixels' cost then decides the profile.
        let t = table3_light0();
        let (planes, n) = t.trace(72, 1, 0, true);
        let truth = t.light.rect();
        let mut problem = t.problem(planes, 1.0 / n as f32, &truth);
        the_profile_is_the_cost(&problem, &truth, "none clipped");
        let photo = problem.obs.clone();
        let top = photo.iter().fold(0f32, |m, o| m.max(o[0]));
        let bright: Vec<bool> = photo.iter().map(|o| o[0] > 0.5 * top).collect();
        let clipped = bright.iter().filter(|&&b| b).count();
        assert!(clipped > 20, "{clipped} pixels clipped");
        for i in (0..problem.n()).filter(|&i| bright[i]) {
            problem.obs[i][0] = 0.5 * top;
            problem.clipped[i] = true;
            problem.clipped_channels[i] = [true, false, false];
        }
        the_profile_is_the_cost(&problem, &truth, "clipped");
        for (i, o) in problem.obs.iter_mut().enumerate() {
            *o = if bright[i] {
                photo[i]
            } else {
                photo[i].map(|o| 0.95 * o)
            };
        }
        the_profile_is_the_cost(&problem, &truth, "clipped at the model");
    }

    fn the_profile_is_the_cost(problem: &Problem, truth: &Rect, photo: &str) {
        let start = Rect {
            u_min: truth.u_min + 0.3,
            u_max: truth.u_max - 0.3,
            v_min: truth.v_min - 0.3,
            v_max: truth.v_max + 0.3,
        };
        let st = problem.state(vec![0], vec![[false; 4]], vec![start], vec![[1.0; 3]]);
        let grid = 17;
        for side in EdgeSide::ALL {
            let cur = start.edge(side);
            // A wide window, a narrow one, and a narrow one wholly beside the edge's place
            // now (the band the profile reads then spans both).
            for (lo, step) in [
                (cur - 0.5, 1.0 / 16.0),
                (cur - 0.004, 0.0005),
                (cur + 0.05, 0.0005),
            ] {
                let profile = problem.edge_profile(&st, 0, side, lo, step, grid, 0..problem.n());
                let mut costs = Vec::new();
                for (j, (_, l)) in profile.iter().enumerate() {
                    let rect = start.with_edge(side, lo + j as f32 * step);
                    let mut at = problem.state(vec![0], vec![[false; 4]], vec![rect], vec![*l]);
                    // Each channel's radiance at the whole cost's minimum: no radiance within
                    // 3 % of it costs less, up to the noise terms of the clipped channels (the
                    // cost steps by one, `(L d)^2`, where such a channel stops counting).
                    for (ch, &x) in l.iter().enumerate() {
                        let cost_at = |x: f64| {
                            let mut s = at.clone();
                            s.radiance[0][ch] = x;
                            problem.cost(&s)
                        };
                        let here = cost_at(x);
                        let around: Vec<f64> = (-20..=20)
                            .map(|k| cost_at((x.max(1e-3) * (1.0 + 1.5e-3 * k as f64)).max(0.0)))
                            .collect();
                        let least = around.iter().fold(f64::INFINITY, |m, &c| m.min(c));
                        let steps: f64 = (0..problem.n())
                            .filter(|&i| problem.clipped_channels[i][ch])
                            .map(|i| (1.03 * x * at.dev[0][i] as f64).powi(2))
                            .sum();
                        assert!(
                            here <= least + steps,
                            "{photo}: {side:?} window {lo} point {j} channel {ch}: radiance {x} \
                            costs {here}, a radiance within 3 % {least} (steps {steps})"
                        );
                    }
                    at.radiance = vec![*l];
                    costs.push(problem.cost(&at));
                }
                let scale = costs.iter().fold(0f64, |m, c| m.max(c.abs()));
                for (j, p) in profile.iter().enumerate() {
                    let (got, want) = (p.0 - profile[0].0, costs[j] - costs[0]);
                    assert!(
                        (got - want).abs() <= 1e-4 * scale,
                        "{side:?} window {lo} point {j}: cost change {got} against {want}"
                    );
                }
            }
        }
    }
}
