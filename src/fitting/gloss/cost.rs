//! The cost of a candidate gloss: the joint fit at that gloss from the search's start, over
//! the pixels and the trace every candidate shares (the module doc of [`super`], "Comparable
//! costs"), as a point of the search's curve.

use super::search::{Curve, Point};
use super::GlossSearch;
use crate::fitting::joint::{
    fit_joint, JointOptions, Lobe, ModelledPixel, ProposalCache, Reweight, StartGate,
};
use crate::fitting::{FittedLight, Rect, StreakObservation};
use crate::optics::ReflectionModel;
use crate::photo_in::Photo;
use crate::progress::Reporter;
use crate::scene_in::Scene;
use crate::Result;

/// What the search's fits share: the start's model (the gloss varies), the seed, and whom
/// to tell as each starts.
#[derive(Clone, Copy)]
pub(super) struct SearchFit<'a> {
    pub(super) model: ReflectionModel,
    pub(super) seed: u64,
    pub(super) progress: Reporter<'a>,
    /// Whether the candidates' fits read the direct view, as the final fit does.
    pub(super) direct_view: bool,
    /// Whether a light on its lamp's whole image searches close around the image, as the
    /// final fit does ([`JointOptions::close_regions`]).
    pub(super) close_regions: bool,
}

/// The gloss whose lobe picks the fitted pixels for every candidate: a quarter of the start
/// (no lower than the search's floor), broad enough to hold the streaks of the candidates the
/// search visits from there. Costs are comparable only over the same pixels; with the region
/// following each candidate's own lobe, a broader lobe could add faint pixels and with them
/// cost (on the samples the streaks' boxes bound the region, so it did not change).
pub(super) fn region_gloss(options: &GlossSearch, start: f32) -> f32 {
    (start / 4.0).max(options.min_gloss)
}

/// How much broader than the gloss it is drawn for a search's proposal is, in slope
/// variance: from `e` it serves the glosses from about `e / 1.6` to `2.5 e`
/// ([`crate::fitting::joint::TARGET_OVER_PROPOSAL`]): the search's first three points, and a
/// step of up to a factor 2 towards narrower lobes ([`GlossSearch::max_step_ln`]); a step
/// to a broader one beyond `e / 1.6` traces again.
const PROPOSAL_BROADER: f32 = 1.6;

/// The lobe a search's trace is drawn from when it is to serve `x = ln e` and the glosses
/// around it ([`PROPOSAL_BROADER`]).
pub(super) fn proposal(x: f64) -> Lobe {
    // Gloss e has the slope variance 1 / (e + 2); no lobe is broader than e = 0's.
    let gloss = ((x.exp() as f32 + 2.0) / PROPOSAL_BROADER - 2.0).max(0.0);
    Lobe::Exact { gloss }
}

/// The cost of a candidate gloss, with a record of every evaluation.
pub(super) struct Cost<'a> {
    pub(super) scene: &'a Scene,
    pub(super) photo: &'a Photo,
    pub(super) water: &'a [bool],
    pub(super) streaks: &'a [StreakObservation],
    pub(super) start: &'a [FittedLight],
    /// Where each start light's lamp ends, when the start's estimate found it
    /// ([`JointOptions::start_images`]).
    pub(super) start_images: &'a [Option<(Rect, f32)>],
    pub(super) options: &'a GlossSearch,
    pub(super) fit: SearchFit<'a>,
    /// The trace every fit weighs (module doc).
    pub(super) proposal: ProposalCache,
    /// (ln e, cost), in the order evaluated.
    pub(super) evaluations: Vec<(f64, f64)>,
    /// Evaluations whose fit broke down (module doc), for a warning.
    pub(super) failed: Vec<f32>,
    /// The first fit's start gate (the final fit's [`JointOptions::start_gate`]).
    pub(super) gate: Option<StartGate<'a>>,
    /// The first fit's start image, where its gate ended it.
    pub(super) stopped: Option<Vec<ModelledPixel>>,
    /// The lights the first fit on the current trace saw whole in the photo, by start light
    /// ([`super::joint::JointOutcome::seen_whole`]): every later fit on it holds them there,
    /// their images pinning them whatever the gloss (module doc).
    pub(super) held: Option<Vec<Option<Rect>>>,
}

impl Curve for &mut Cost<'_> {
    /// The cost at `x = ln e` as a point of the curve.
    fn point(&mut self, x: f64) -> Result<Point> {
        let gloss = x.exp() as f32;
        self.fit.progress.stage(&format!(
            "gloss search: joint fit {} at e = {gloss:.0} (at most {} glosses, besides those \
             fitted again on a new trace)",
            self.evaluations.len() + 1,
            self.options.max_evaluations
        ));
        let fit = fit_joint(
            self.scene,
            self.photo,
            self.water,
            self.streaks,
            self.start,
            &JointOptions {
                samples: self.options.search_samples,
                sweeps: self.options.search_sweeps,
                pixels: self.options.search_pixels,
                // A wrong gloss leaves a structured residual too: splitting lights there
                // would fit the lobe's error, not a second light.
                split: false,
                region_gloss: Some(region_gloss(self.options, self.fit.model.gloss)),
                close_regions: self.fit.close_regions,
                direct_view: self.fit.direct_view,
                reweight: Some(Reweight {
                    cache: &self.proposal,
                    target: Lobe::Exact { gloss },
                }),
                start_gate: self.gate.filter(|_| self.evaluations.is_empty()),
                starts_placed: true,
                start_images: self.start_images,
                held: self.held.as_deref().unwrap_or(&[]),
                progress: self.fit.progress,
                ..JointOptions::new(
                    ReflectionModel {
                        gloss,
                        ..self.fit.model
                    },
                    self.fit.seed,
                )
            },
        )?;
        if fit.stopped_at_start {
            self.stopped = Some(fit.modelled);
            return Ok(Point {
                x,
                s: f64::INFINITY,
                variance: 0.0,
            });
        }
        if self.held.is_none() {
            self.held = Some(fit.to_hold("gloss search", self.fit.progress));
        }
        let mut s = fit.cost;
        // The residuals hold the photo's own noise, so a cost that is not positive is the fit
        // exploiting its coefficients' noise (module doc): no evidence for this gloss.
        if !(s.is_finite() && s > 0.0) {
            self.failed.push(gloss);
            s = f64::INFINITY;
        }
        self.evaluations.push((x, s));
        Ok(Point {
            x,
            s,
            variance: fit.residual_variance,
        })
    }

    fn abandoned(&self) -> bool {
        self.stopped.is_some()
    }

    /// Whether the kept trace serves gloss `exp(x)`.
    fn serves(&self, x: f64) -> bool {
        self.proposal.covers(&Lobe::Exact {
            gloss: x.exp() as f32,
        })
    }

    /// A new trace, drawn from a lobe broader than the lower of `next` and `best` by
    /// [`PROPOSAL_BROADER`].
    fn rebase(&mut self, next: f64, best: f64) {
        self.proposal = ProposalCache::new(proposal(next.min(best)));
        // The first fit on the new trace, nearer the estimate, places the held lights again.
        self.held = None;
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A search's proposal serves the gloss it is drawn for, the first points either side
    /// of it, a step of a factor 2 towards narrower lobes and down to about `e / 1.6`, not
    /// below; its gloss stays a gloss however low the gloss asked for.
    #[test]
    fn a_proposal_serves_the_steps_around_its_gloss() {
        let first = GlossSearch::default().first_step_ln as f64;
        for e in [50.0f64, 500.0, 5000.0] {
            let cache = ProposalCache::new(proposal(e.ln()));
            for x in [
                e.ln(),
                e.ln() - first,
                e.ln() + first,
                (2.0 * e).ln(),
                (e / 1.55).ln(),
            ] {
                let gloss = x.exp() as f32;
                assert!(cache.covers(&Lobe::Exact { gloss }), "{e}: {gloss}");
            }
            for gloss in [e / 1.7, 2.6 * e] {
                let gloss = gloss as f32;
                assert!(!cache.covers(&Lobe::Exact { gloss }), "{e}: {gloss}");
            }
        }
        assert_eq!(proposal(0.5f64.ln()), Lobe::Exact { gloss: 0.0 });
    }
}
