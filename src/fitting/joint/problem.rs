//! The joint fitting problem (method §5, last paragraph): the fitted pixels, every light's
//! stored samples, and the state of a fit (the lights' rectangles and radiances with the
//! coefficients they give), kept up to date as one edge moves at a time.

use rayon::prelude::*;

use super::samples::PlaneSamples;
use crate::fitting::rect::Rect;
use crate::photo_rounding::Rounding;

/// The fitting problem: observed pixels and every light's stored samples.
pub(super) struct Problem {
    /// Photo width, to tell a fitted pixel's row.
    pub(super) width: u32,
    /// Photo pixel index of every fitted pixel.
    pub(super) pixel_ids: Vec<u32>,
    /// Per fitted pixel, its radiance in the photo.
    pub(super) obs: Vec<[f32; 3]>,
    /// Per fitted pixel, whether the photo clipped it (its value is a lower bound).
    pub(super) clipped: Vec<bool>,
    /// Per fitted pixel, which of its channels the photo clipped (a clipped pixel's other
    /// channels are exact values).
    pub(super) clipped_channels: Vec<[bool; 3]>,
    /// The sample sets: one per start light, then one per light a split added.
    pub(super) planes: Vec<PlaneSamples>,
    /// Per sample set, the start light whose plane it samples (a split light reads a set of
    /// its own, drawn independently on the same plane).
    pub(super) set_origin: Vec<usize>,
    /// One over the samples drawn per pixel: the divisor of every coefficient.
    pub(super) inv_samples: f32,
    /// The fitted pixels from this index on see the lights' walls directly (outside the
    /// water: [`super::direct`]); those before it are water pixels.
    pub(super) first_direct: usize,
    /// How the photo rounded its values, and its exposure: the rounding a lamp's image seen
    /// whole shares ([`Problem::shared_rounding`]).
    pub(super) encoding: (Rounding, f32),
    /// Place the edges a light's direct image pins and measures by the direct pixels alone,
    /// for a light whose radiance the photo shows ([`super::JointOptions::edges_by_image`]).
    pub(super) edges_by_image: bool,
}

/// The state of a fit: every light's rectangle and radiance, and the coefficients they give.
#[derive(Clone)]
pub(super) struct State {
    /// Per light, which stored sample set (plane) it reads: lights split from one start
    /// share their plane's samples.
    pub(super) set_of: Vec<usize>,
    /// Per light and edge: held where it is (an edge no pixel looks at).
    pub(super) pinned: Vec<[bool; 4]>,
    /// Per light, its rectangle on its plane.
    pub(super) rects: Vec<Rect>,
    /// Per light, its radiance per channel.
    pub(super) radiance: Vec<[f64; 3]>,
    /// `coef[k][i]`: light k's coefficient at fitted pixel i with the current rectangle.
    pub(super) coef: Vec<Vec<f32>>,
    /// `dev[k][i]`: that estimate's half-difference (see the note on the coefficients' noise
    /// in [`super::cost`]).
    pub(super) dev: Vec<Vec<f32>>,
}

impl Problem {
    /// Fitted pixels.
    pub(super) fn n(&self) -> usize {
        self.obs.len()
    }

    /// Per fitted pixel, sample set `set`'s coefficient and half-difference for `rect`.
    pub(super) fn coefficients(&self, set: usize, rect: &Rect) -> (Vec<f32>, Vec<f32>) {
        (0..self.n())
            .into_par_iter()
            .map(|i| self.planes[set].coefficient(i, rect, self.inv_samples))
            .unzip()
    }

    /// Per pixel, the derivative of sample set `set`'s coefficient and of its half-difference
    /// by one edge, as the central difference between the rectangles `plus` and `minus` (which
    /// differ in that edge alone, by `2 h`). Only pixels with a sample in the strip between
    /// them are computed: the others' coefficients are the same for both, their derivatives 0.
    pub(super) fn edge_slopes(
        &self,
        set: usize,
        plus: &Rect,
        minus: &Rect,
        h: f32,
    ) -> (Vec<f32>, Vec<f32>) {
        let strip = plus.changed_strip(minus);
        let h = 2.0 * h as f64;
        (0..self.n())
            .into_par_iter()
            .map(|i| {
                let (dc, dd) = self.pixel_change(set, i, minus, plus, strip);
                ((dc / h) as f32, (dd / h) as f32)
            })
            .unzip()
    }

    /// Pixel i's change of sample set `set`'s coefficient and half-difference from `from` to
    /// `to`, rectangles that differ in `strip` ([`Rect::changed_strip`]): from the samples
    /// near it, or, where only the pixel's Gaussian reaches it, from the Gaussian's exact
    /// mass (no samples, no half-difference).
    pub(super) fn pixel_change(
        &self,
        set: usize,
        i: usize,
        from: &Rect,
        to: &Rect,
        strip: Option<Rect>,
    ) -> (f64, f64) {
        let samples = &self.planes[set];
        if reaches(&samples.bbox[i], strip) {
            return samples.coefficient_change(i, from, to, self.inv_samples);
        }
        let g = &samples.gauss[i];
        if g.is_none() || !reaches(&g.reach(), strip) {
            return (0.0, 0.0);
        }
        ((g.mass_inside(to) - g.mass_inside(from)) as f64, 0.0)
    }

    /// Moves light k to `rect`, recomputing only the coefficients of pixels with a sample
    /// where the old and the new rectangle differ (a one-edge move touches a thin strip).
    pub(super) fn set_rect(&self, st: &mut State, k: usize, rect: Rect) {
        let old = st.rects[k];
        st.rects[k] = rect;
        let samples = &self.planes[st.set_of[k]];
        let strip = old.changed_strip(&rect);
        let inv = self.inv_samples;
        st.coef[k]
            .par_iter_mut()
            .zip(st.dev[k].par_iter_mut())
            .enumerate()
            .for_each(|(i, (c, v))| {
                if reaches(&samples.bbox[i], strip) {
                    // From the samples near the edges that moved (in f64; the f32 rounding
                    // each move adds is far below the samples' noise).
                    let (dc, dv) = samples.coefficient_change(i, &old, &rect, inv);
                    (*c, *v) = ((*c as f64 + dc) as f32, (*v as f64 + dv) as f32);
                } else {
                    // Only the Gaussian can reach the strip: update its exact mass, without
                    // going through the samples (in f64; the f32 rounding this repeats is
                    // far below the samples' noise).
                    let g = &samples.gauss[i];
                    if !g.is_none() && reaches(&g.reach(), strip) {
                        *c = (*c as f64 - g.mass_inside(&old) as f64 + g.mass_inside(&rect) as f64)
                            as f32;
                    }
                }
            });
    }

    /// Adds a sample set drawn on start light `origin`'s plane; returns its index.
    pub(super) fn add_set(&mut self, samples: PlaneSamples, origin: usize) -> usize {
        self.planes.push(samples);
        self.set_origin.push(origin);
        self.planes.len() - 1
    }

    /// Light k reads sample set `set` from now on.
    pub(super) fn move_to_set(&self, st: &mut State, k: usize, set: usize) {
        st.set_of[k] = set;
        (st.coef[k], st.dev[k]) = self.coefficients(set, &st.rects[k]);
    }
}

/// Whether a pixel whose samples' kernels span `bbox` has one in `strip` (`None`: anywhere,
/// the change is not a strip).
fn reaches(bbox: &Rect, strip: Option<Rect>) -> bool {
    strip.is_none_or(|s| bbox.touches(&s))
}
