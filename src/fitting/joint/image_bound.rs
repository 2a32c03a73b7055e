//! How far a light's direct image lets each of its edges be off.
//!
//! A lamp in the photo pins its rectangle's edges to the pixels its image ends in. Where the
//! edge pixels measure a partial cover (not clipped, not black), the curvature of the cost
//! says how well ([`super::uncertainty`]). Where they do not (a lamp that clips in every
//! channel its light lights, next to a black wall), the curvature has nothing to read,
//! and the uncertainty falls back on the reflections alone: tens of centimetres on the
//! harbour's lamps, whose edges come out within a few millimetres. Yet the photo bounds such
//! an edge all the same: moved out by a pixel's footprint it would light black pixels, moved
//! in it would leave clipped ones below the clip. So where both moves make the direct pixels
//! disagree with the photo, the edge lies within a footprint of where it is, and its
//! one-sigma error is at most that of a position spread evenly over the two footprints
//! either side: `footprint / sqrt(3)`.

use super::cost::squared_residual;
use super::problem::{Problem, State};
use crate::fitting::EdgeSide;

/// How much more the direct pixels must disagree with the photo, in units of the fit's
/// residual variance per pixel and channel, for a move of an edge by a pixel's footprint to
/// count as refused: that of one pixel's channel at 5 sigma. A lamp's image refuses such a
/// move by orders of magnitude more (a column of pixels lit at the lamp's radiance, or left
/// below the clip); an edge whose direct pixels agree with the photo either way is not
/// pinned by them.
const MIN_RISE: f64 = 25.0;

impl Problem {
    /// Per light of `st` and edge (left, right, bottom, top), the largest one-sigma error its
    /// direct image leaves the edge (module doc), metres on its plane; `None` where the image
    /// does not pin it (no direct pixel, a held edge, or a move the photo does not refuse).
    pub(super) fn image_bounds(&self, st: &State) -> Vec<[Option<f32>; 4]> {
        if self.first_direct >= self.n() {
            return vec![[None; 4]; st.rects.len()];
        }
        let floor = MIN_RISE * self.residual_variance(st);
        (0..st.rects.len())
            .map(|k| EdgeSide::ALL.map(|side| self.image_bound(st, k, side, floor)))
            .collect()
    }

    /// [`Problem::image_bounds`] of one edge, a move refused when it raises the direct
    /// pixels' disagreement with the photo by more than `floor`.
    fn image_bound(&self, st: &State, k: usize, side: EdgeSide, floor: f64) -> Option<f32> {
        if st.pinned[k][side] {
            return None;
        }
        // A quarter of a pixel's footprint (`direct_step`).
        let footprint = 4.0 * self.direct_step(st.set_of[k], side.along_u())?;
        let r = st.rects[k];
        let refused = |to: f32| {
            let moved = r.with_edge(side, to);
            moved.width() > 0.0
                && moved.height() > 0.0
                && self.direct_disagreement(st, k, &moved) > floor
        };
        let e = r.edge(side);
        (refused(e + footprint) && refused(e - footprint)).then(|| footprint / 3f32.sqrt())
    }

    /// The direct pixels that measure edge `side` of light k: moved by it (over a quarter of
    /// a pixel's footprint either way, [`Problem::direct_step`]) in a channel that measures
    /// the model ([`Problem::measures`]) and in which the light shines. 0 without direct
    /// pixels or for a held edge.
    pub(super) fn measuring_direct_pixels(&self, st: &State, k: usize, side: EdgeSide) -> usize {
        let set = st.set_of[k];
        let Some(h) = self.direct_step(set, side.along_u()) else {
            return 0;
        };
        if st.pinned[k][side] {
            return 0;
        }
        let r = st.rects[k];
        let e = r.edge(side);
        let (plus, minus) = (r.with_edge(side, e + h), r.with_edge(side, e - h));
        let strip = minus.changed_strip(&plus);
        (self.first_direct..self.n())
            .filter(|&i| {
                self.pixel_change(set, i, &minus, &plus, strip).0 != 0.0
                    && (0..3).any(|ch| self.measures(i, ch) && st.radiance[k][ch] > 0.0)
            })
            .count()
    }

    /// How much more the direct pixels disagree with the photo (their share of the cost's
    /// squares, with its clipped bounds) with light k at `moved`, every radiance held.
    fn direct_disagreement(&self, st: &State, k: usize, moved: &crate::fitting::Rect) -> f64 {
        let from = st.rects[k];
        let strip = from.changed_strip(moved);
        let light = st.radiance[k];
        (self.first_direct..self.n())
            .map(|i| {
                let (dc, _) = self.pixel_change(st.set_of[k], i, &from, moved, strip);
                if dc == 0.0 {
                    return 0.0;
                }
                let m = self.model(st, i);
                (0..3)
                    .map(|c| {
                        let squared = |model: f64| {
                            squared_residual(self.obs[i][c], model, self.clipped_channels[i][c])
                                .unwrap_or(0.0)
                        };
                        squared(m[c] + light[c] * dc) - squared(m[c])
                    })
                    .sum::<f64>()
            })
            .sum()
    }
}
