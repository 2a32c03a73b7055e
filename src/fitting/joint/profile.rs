//! The cost along one edge (method §5, last paragraph): the coordinate descent's 1-D step.
//!
//! [`Problem::edge_profile`] evaluates the cost on a whole grid of positions of one light's
//! edge in one pass over the samples ([`super::ramps`]), with that light's radiance
//! re-optimised in closed form (nonnegative) at every grid point and the other lights held.
//! A far-off start is so pulled in by a global 1-D search rather than a local step.

use rayon::prelude::*;

use super::control_variate;
use super::problem::{Problem, State};
use super::ramps::{EdgeFrame, EdgeRamps};
use crate::fitting::EdgeSide;

/// Pixels per parallel piece of an edge profile.
const PROFILE_CHUNK: usize = 2048;

/// Per grid point of an edge profile: the normal-equation sums over some pixels, and the
/// clipped pixels' coefficients (they enter the cost one-sidedly, so they are kept whole).
struct ProfileSums {
    a: Vec<f64>,
    a_raw: Vec<f64>,
    b: Vec<[f64; 3]>,
    /// The same at every grid point (pixels with no sample in the window), kept once.
    flat: FlatSums,
    clipped_rows: Vec<(usize, Vec<f32>)>,
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
        // Clipped pixels need the whole c(t) to apply their one-sided residual later.
        let mut clipped_rows: Vec<(usize, Vec<f32>)> = Vec::new();
        let mut flat = FlatSums::default();
        let hi = lo + step * (grid - 1) as f32;
        let frame = EdgeFrame::new(&rect, side);
        let (along_u, min_edge, opp) = (frame.along_u, frame.min_edge, frame.opposite);
        let (o_lo, o_hi) = frame.across;
        for &i in chunk {
            let r = plane.range(i);
            let g = plane.gauss[i];
            if r.is_empty() && g.is_none() {
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
            let samples_reach = !(bmax < lo || bmin > hi);
            // Its coefficient and half-difference, when they are the same at every grid point.
            let same_everywhere = |c: f64, d: f64, flat: &mut FlatSums| {
                if c != 0.0 {
                    let (rest, rest_dev) = self.others(st, k, i);
                    flat.a_raw += c * c;
                    flat.a += c * c - d * d;
                    for ch in 0..3 {
                        flat.b[ch] += c * (self.obs[i][ch] as f64 - rest[ch]) + d * rest_dev[ch];
                    }
                }
            };
            if !samples_reach && !gauss_varies && !self.clipped[i] {
                // Nothing of this pixel's coefficient changes over the window.
                same_everywhere(st.coef[k][i] as f64, st.dev[k][i] as f64, &mut flat);
                continue;
            }
            ramps.clear(grid);
            let mut any = false;
            if !samples_reach && !self.clipped[i] {
                // Only the Gaussian moves: the samples' part is what it is now.
                let inv = self.inv_samples as f64;
                let sampled = st.coef[k][i] as f64 - g.mass_inside(&rect) as f64;
                let dev = st.dev[k][i] as f64 / inv;
                ramps.constant(sampled / inv, dev);
                any = true;
            }
            let r = if samples_reach || self.clipped[i] {
                r
            } else {
                0..0
            };
            if plane.add_to_ramps(r, &frame, &mut ramps) {
                any = true;
            }
            if !any && !gauss_varies && !self.clipped[i] {
                same_everywhere(g.mass_inside(&rect) as f64, 0.0, &mut flat);
                continue;
            }
            if !ramps.kinked && !self.clipped[i] && !gauss_varies {
                // Every kernel it has lies wholly on one side of the window.
                let [c, d] = ramps.constant;
                let inv = self.inv_samples as f64;
                let c = c * inv + g.mass_inside(&rect) as f64;
                same_everywhere(c, d * inv, &mut flat);
                continue;
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
                let a = g.mass_inside(&rect) / self.inv_samples;
                for c in cvals.iter_mut() {
                    *c += a;
                }
            }
            let (rest, rest_dev) = self.others(st, k, i);
            let res = [0, 1, 2].map(|ch| self.obs[i][ch] as f64 - rest[ch]);
            if self.clipped[i] {
                clipped_rows.push((i, cvals.iter().map(|c| c * self.inv_samples).collect()));
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
        ProfileSums {
            a,
            a_raw,
            b,
            flat,
            clipped_rows,
        }
    }

    /// The cost, as a function of one edge of light `k` on the grid `lo + j * step`
    /// (`j < grid`), with light k's radiance re-optimised (closed form, nonnegative) at every
    /// grid point and the other lights held. Returns per grid point (cost up to a constant,
    /// the radiance).
    pub(super) fn edge_profile(
        &self,
        st: &State,
        k: usize,
        side: EdgeSide,
        lo: f32,
        step: f32,
        grid: usize,
    ) -> Vec<(f64, [f64; 3])> {
        // Fixed chunks summed in order: the same sums whatever the thread count.
        let parts: Vec<ProfileSums> = (0..self.n())
            .collect::<Vec<_>>()
            .par_chunks(PROFILE_CHUNK)
            .map(|chunk| self.profile_sums(st, k, side, lo, step, grid, chunk))
            .collect();
        let mut a = vec![0f64; grid];
        let mut a_raw = vec![0f64; grid];
        let mut b = vec![[0f64; 3]; grid];
        let mut clipped_rows: Vec<(usize, Vec<f32>)> = Vec::new();
        for part in parts {
            for j in 0..grid {
                a[j] += part.a[j] + part.flat.a;
                a_raw[j] += part.a_raw[j] + part.flat.a_raw;
                for ((total, here), flat) in b[j].iter_mut().zip(part.b[j]).zip(part.flat.b) {
                    *total += here + flat;
                }
            }
            clipped_rows.extend(part.clipped_rows);
        }
        // Pixels with no sample of light k contribute a constant, left out.
        // A rectangle that catches only a few samples has a variance as large as its mean
        // square: the corrected normal equation would divide by ~0. Keep at least half of the
        // raw term (the bias then stays bounded, and such a rectangle is far from the optimum).
        for j in 0..grid {
            a[j] = a[j].max(0.5 * a_raw[j]);
        }
        (0..grid)
            .map(|j| {
                let l = [0, 1, 2].map(|ch| {
                    if a[j] > 0.0 {
                        (b[j][ch] / a[j]).max(0.0)
                    } else {
                        0.0
                    }
                });
                // sum (r - L c)^2 - sum r^2 = L^2 A - 2 L B
                let mut cost: f64 = (0..3)
                    .map(|ch| l[ch] * l[ch] * a[j] - 2.0 * l[ch] * b[j][ch])
                    .sum();
                for (i, cs) in &clipped_rows {
                    let c = cs[j] as f64;
                    for ch in 0..3 {
                        let rest: f64 = st
                            .radiance
                            .iter()
                            .enumerate()
                            .filter(|(kk, _)| *kk != k)
                            .map(|(kk, lr)| lr[ch] * st.coef[kk][*i] as f64)
                            .sum();
                        let r = self.obs[*i][ch] as f64 - rest - l[ch] * c;
                        let r0 = self.obs[*i][ch] as f64 - rest;
                        // A clipped channel is a lower bound; the pixel's other channels
                        // are values.
                        let bound = self.clipped_channels[*i][ch];
                        let now = if bound && r < 0.0 { 0.0 } else { r * r };
                        let before = if bound && r0 < 0.0 { 0.0 } else { r0 * r0 };
                        cost += now - before;
                    }
                }
                (cost, l)
            })
            .collect()
    }
}
