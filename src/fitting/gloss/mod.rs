//! Estimating the water's gloss exponent `e` from the photo together with the lights
//! ([`crate::pipeline::GlossFit::Estimate`]).
//!
//! The paper takes `e` as known. A wrong `e` does not stop a fit: the lights come out with
//! the wrong size and radiance (a lobe that is too wide is answered by a light that is too
//! small and too bright, method §6), so `e` has to be measured too. What tells it apart is the
//! streak's profile: the width of the lobe sets how fast each edge of the streak fades, and a
//! rectangle cannot mimic that at every edge at once. So `e` is the gloss whose best lights
//! explain the photo best:
//!
//! ```text
//! e_hat = argmin_e  min_{lights} S(e, lights)
//! ```
//!
//! with `S` the joint fit's noise-debiased residual sum of squares over the water near the
//! streaks ([`super::joint`]). The inner minimum is [`fit_joint`] with the model
//! `ReflectionModel { gloss: e, .. }`; the outer one is a one-dimensional search over `ln e`
//! (gloss acts multiplicatively: the lobe's width goes as `1/sqrt(e)`; on the samples the
//! cost is close to a parabola in `ln e` over a factor of about 1.3 either side of its
//! minimum, and rises steadily, though not always symmetrically, beyond).
//!
//! # Comparable costs
//!
//! * Every candidate starts from the same lights, the paper fit at the starting gloss, so the
//!   fitted region (the streaks, dilated, and the pixels that can see the start lights'
//!   surroundings) is the same up to its fringe, and the costs are sums over nearly the same
//!   pixels. The cost compared is the sum `S`, not `S` per degree of freedom: the region test
//!   depends on the lobe, so the region still gains or loses a few hundred of its ~50,000
//!   pixels at its dark fringe across `e` (on `gloss1000.png`), which add ~0 to the sum but
//!   would change a mean.
//! * The candidates' fits weigh the samples of one trace (`joint::ProposalCache`), drawn from
//!   a lobe broader than theirs and weighted for each gloss by importance sampling, so the
//!   cost is a smooth function of `e` rather than one with fresh noise at every evaluation,
//!   and a fit costs its descent, not a trace. A trace serves the glosses whose slope
//!   variance is a quarter to the whole of its own: from `e` about `e / 1.6` to `2.5 e`
//!   (`cost::PROPOSAL_BROADER`). When the search steps beyond, it traces again from around the
//!   step and makes again, on the new trace, the points that trace serves: costs of
//!   different traces differ in level by more than the curve changes near its minimum.
//! * The fits read the joint fit's default samples per pixel ([`SEARCH_SAMPLES`]). Too few
//!   and the cost is not to be trusted: the edge search picks, among thousands of
//!   rectangles, ones whose coefficients' estimated noise (which the cost subtracts) happens
//!   to be large, and with a wide lobe and 32 samples that wins outright (on `gloss200.png`
//!   at e = 100-125: a rectangle a sixth of the true height, seven times too bright, with a
//!   cost below zero). With the lobe's Gaussian as control variate, the starts placed on the
//!   lamps' images and the lights seen whole held, 72 samples give the estimates that 128
//!   give, within the seeds' scatter, from every start tried and without the direct view too
//!   (docs/decisions.md), in two thirds of the time. A fit whose cost still comes out
//!   non-positive counts as no evidence
//!   (infinite cost). The fits of the search run fewer coordinate-descent sweeps than a
//!   final fit ([`GlossSearch::search_sweeps`]): the cost at the optimum moves by 0.3 % and
//!   uniformly across `e`.
//! * The fits read a quarter of the region's pixels, one of each 2 x 2 block
//!   ([`GlossSearch::search_pixels`]), half of what a final fit reads: where the minimum lies
//!   is set by how the streaks' profiles change with `e`, which every part of a streak shows
//!   alike, not by how closely each candidate's lights are pinned. Against the checkerboard
//!   the estimates moved by under 2 % (Table 3 from e = 100: 502.3 instead of 511.9; the
//!   others within 0.6 %) and an evaluation took 1.6 s instead of 3.6 s.
//! * A light the first fit on a trace finds whole in the photo, every edge pinned by its
//!   direct image within a pixel's footprint or beyond what the photo tells
//!   ([`super::joint::JointOutcome::seen_whole`]), is
//!   held there by the later fits on that trace ([`JointOptions::held`]): its image places it
//!   whatever the gloss, and a held fit costs the weighting and a radiance solve, not a
//!   descent. The searches took 2.8 s instead of 4.0 s on `table1.png`, 3.4 s instead of
//!   7.1 s on `gloss1000.png` (the estimate 983 instead of 1004), 9.4 and 16.9 s instead of
//!   14.1 and 19.3 s on `table3.png` from e = 100 and 2000 (501 and 512 instead of 503 and
//!   504). A fit far from the photo's gloss can pull a light off its image (`gloss200.png` at
//!   e = 430: an edge 14 cm out), and then nothing is held: that search is as before.
//! * A light on its lamp's whole image searches close around the image in every fit of the
//!   search, as in a fit of a given gloss ([`JointOptions::close_regions`]): the image pins it
//!   whatever the gloss, so the trace need not reach the wide region a start from the
//!   reflections alone needs. The fit then reads the wall's pixels seen directly inside the
//!   close region and the water pixels that can see it (on `table1.png`, a quarter of each:
//!   7 482 and 19 654 pixels instead of 26 622 and 24 768), and a trace draws fewer samples
//!   that land. The estimates from every start tried came out within 0.1 % of
//!   the wide region's, and `gloss1000.png` from e = 100 at 997 instead of 901
//!   (docs/decisions.md); the searches took a third to a half less time and memory.
//!
//! # Search
//!
//! Three points around the start, `ln e` apart by [`GlossSearch::first_step_ln`]. While the
//! lowest point is an outermost one, step beyond it to the vertex of the parabola through it
//! and its two neighbours (at least one first step, at most [`GlossSearch::max_step_ln`]),
//! or, when that vertex lies between it and its neighbour (a long step overshot), try the
//! vertex.
//! Once the minimum is bracketed, step to the vertex of the parabola through the lowest point
//! and its neighbours, or, when that vertex is already within [`GlossSearch::tolerance_ln`]
//! of the lowest point but the bracket is wider than [`GlossSearch::max_bracket_ln`] (too
//! wide to trust a parabola over: the cost is skewed), narrow the bracket's wider side. Stop
//! when the vertex is within the tolerance of the lowest point in a narrow bracket; the
//! estimate is that vertex. On the samples that takes 3 evaluations from the right gloss, 7
//! from a start 2 times off (`gloss1000.png` from 500) and 8 from one 2.5 times off
//! (`gloss200.png` from 500, with 2 more made again on a second trace). On 2 cores (the AMD
//! EPYC machine of BENCHMARKS.md) a fit from the kept trace takes about 0.5 s, most of it
//! the descent (a held one 0.15 s), and a trace about 0.7 s; then the final joint fit at the
//! estimate. Where the fits on the last
//! trace held every light and that trace serves the estimate, the final fit weighs it too,
//! over the search's pixels and region, each light resumed where it was held (its edges
//! searched a fraction of a footprint around it: [`JointOptions::resume`]); otherwise it is
//! a fit of a given gloss from the start.
//!
//! # Uncertainty
//!
//! Near the minimum `S(x) ~ S0 + k (x - x0)^2` with `x = ln e`; a one-sigma change of `x` raises
//! the cost by the residual variance per degree of freedom `s2`, so `sigma(ln e) = sqrt(s2 / k)`.
//! That is the photo's statistical limit (pixel noise independent): it leaves out the model's
//! own errors and the Monte Carlo noise of the fits, and is a lower bound. On the samples it
//! is about 0.06 %, while the estimates (`tests/gloss.rs`) are 201.4 for e = 200, 503.3 for
//! 500 and 989.4 for 1000, and the seed of the fits moved them by about 1 % (seeds 1-3,
//! measured when the search was written). Read the estimate as good to a few percent.
//!
//! # Limits
//!
//! The gloss is whatever lets the fitted lights explain the photo best, so it absorbs any
//! error in the lights' kind: where one rectangle stands for two lights (`stacked.png`, two
//! lights one above the other whose reflections merge into one streak, fitted as one light),
//! the estimate comes out at 813 for a water of 500, the narrower lobe making up for the dark
//! gap between the lights. `table3.png` (two lights side by side, one reaching out of the
//! photo) gives 502.

mod cost;
pub(super) mod search;

use std::time::Instant;

use super::joint::{
    fit_joint, start_estimate, JointOptions, Lobe, ModelledPixel, PixelShare, ProposalCache,
    Reweight, Split, StartEstimate, Uncertainty, DEFAULT_JOINT_SAMPLES,
};
use super::{FitOptions, FitOutcome, FittedLight, PaperEstimates, Skipped, StreakObservation};
use crate::optics::ReflectionModel;
use crate::photo_in::Photo;
use crate::progress::Reporter;
use crate::scene_in::Scene;
use crate::water_model::ExactSurface;
use crate::{Error, Result};
use cost::{proposal, Cost, SearchFit};
pub(super) use search::placed_search_start;
use search::{search, Stop};

/// How to search for the gloss. What the fits themselves read (samples, pixels, repeats,
/// seed) is the joint fit's options, given beside it to [`estimate_gloss`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct GlossSearch {
    /// Smallest gloss considered.
    pub min_gloss: f32,
    /// Largest gloss considered.
    pub max_gloss: f32,
    /// Spacing of the first three points, in `ln e`, and the smallest step beyond a bracket.
    pub first_step_ln: f32,
    /// Largest step beyond the points so far, in `ln e` (ln 2: at most a factor 2 at once).
    pub max_step_ln: f32,
    /// Stop when the parabola's vertex is this close to the lowest point, in `ln e`.
    pub tolerance_ln: f32,
    /// Trust a parabola's vertex only over a bracket at most this wide, in `ln e`.
    pub max_bracket_ln: f32,
    /// At most this many cost evaluations (each a joint fit).
    pub max_evaluations: usize,
    /// Joint-fit samples per pixel during the search (module doc: fewer are not to be
    /// trusted).
    pub search_samples: u32,
    /// Coordinate-descent sweeps of the search's joint fits.
    pub search_sweeps: u32,
    /// The pixels the search's joint fits read.
    pub search_pixels: PixelShare,
}

/// Joint-fit samples per pixel of the search: the joint fit's default, which the final fit
/// reads too (module doc: fewer make the cost untrustworthy).
pub const SEARCH_SAMPLES: u32 = DEFAULT_JOINT_SAMPLES;

impl Default for GlossSearch {
    /// Search `e` in [50, 5000] from the start.
    fn default() -> Self {
        GlossSearch {
            min_gloss: 50.0,
            max_gloss: 5000.0,
            first_step_ln: 0.15,
            max_step_ln: std::f32::consts::LN_2,
            tolerance_ln: 0.03,
            max_bracket_ln: 0.35,
            max_evaluations: 12,
            search_samples: SEARCH_SAMPLES,
            search_sweeps: 6,
            search_pixels: PixelShare::Quarter,
        }
    }
}

impl GlossSearch {
    fn validate(&self, paper: &FitOptions, final_fit: &JointOptions) -> Result<()> {
        let bad = |what: &str| Err(Error::Usage(format!("gloss search: {what}")));
        if !(self.min_gloss.is_finite() && self.min_gloss > 0.0) {
            return bad(&format!(
                "the smallest gloss must be positive, not {}",
                self.min_gloss
            ));
        }
        if !(self.max_gloss.is_finite() && self.max_gloss > self.min_gloss) {
            return bad(&format!(
                "the largest gloss ({}) must be finite and above the smallest ({})",
                self.max_gloss, self.min_gloss
            ));
        }
        if !(paper.model.gloss.is_finite() && paper.model.gloss > 0.0) {
            return bad(&format!(
                "the starting gloss must be positive, not {}",
                paper.model.gloss
            ));
        }
        for (name, v) in [
            ("first step", self.first_step_ln),
            ("largest step", self.max_step_ln),
            ("tolerance", self.tolerance_ln),
            ("largest bracket", self.max_bracket_ln),
        ] {
            if !(v.is_finite() && v > 0.0) {
                return bad(&format!("the {name} must be positive, not {v}"));
            }
        }
        if self.max_evaluations < 3 {
            return bad("at least 3 evaluations are needed to bracket a minimum");
        }
        if self.search_samples == 0 || final_fit.samples == 0 || paper.samples == 0 {
            return bad("the fits need at least one sample per pixel");
        }
        if final_fit.repeats == 0 {
            return bad("the final fit needs at least one repeat");
        }
        Ok(())
    }
}

/// The estimated gloss, and the lights fitted with it.
#[derive(Clone, Debug)]
pub struct GlossEstimate {
    /// The estimated gloss exponent `e`.
    pub gloss: f32,
    /// One-sigma statistical uncertainty of `ln e` (so roughly the relative uncertainty of
    /// `e`), from the curvature of the cost. A lower bound: the fits' Monte Carlo noise and
    /// the parabola's shape each add about 1 % (module doc). `None` when the minimum was not
    /// bracketed (it lies at a limit of the search, or the evaluations ran out).
    pub sigma_ln: Option<f32>,
    /// Every cost evaluation in the order made: (gloss, residual sum of squares of the joint
    /// fit at it, radiance units squared; infinite where the fit broke down).
    pub evaluations: Vec<(f32, f64)>,
    /// The lights jointly fitted at the estimated gloss (with the final fit's options), edges
    /// the photo does not constrain marked as such.
    pub lights: Vec<FittedLight>,
    /// Their uncertainties at that gloss (the gloss's own uncertainty not included).
    pub uncertainty: Vec<Uncertainty>,
    /// The final fit's residual variance per pixel and channel.
    pub residual_variance: f64,
    /// The paper fit's lights at the starting gloss: every candidate's start, and the final
    /// fit's.
    pub start: Vec<FittedLight>,
    /// Streaks the paper fit could not turn into a light (left out of the search).
    pub skipped: Vec<Skipped>,
    /// Things the user should know (the paper fit's warnings, a minimum at a search limit).
    pub warnings: Vec<String>,
    /// Wall-clock seconds per stage: "paper fit", "search (N evaluations)", "final joint
    /// fit".
    pub timings: Vec<(String, f64)>,
    /// The final joint fit's expected image: its fitted water pixels with their modelled
    /// radiance ([`super::joint::JointOutcome::modelled`]).
    pub modelled: Vec<ModelledPixel>,
    /// How many pixels the final fit read, its water pixels and those that see a light's wall
    /// directly ([`JointOutcome::pixels`](super::joint::JointOutcome::pixels)); 0 where the
    /// search ended at its first fit.
    pub pixels: usize,
    /// Which pixels the final fit read ([`JointOutcome::share`](super::joint::JointOutcome::share)).
    pub share: PixelShare,
    /// The start lights the final fit explained as two
    /// ([`super::joint::JointOutcome::splits`]).
    pub splits: Vec<Split>,
    /// Whether the search ended at its first fit, whose start gate
    /// ([`JointOptions::start_gate`] of the final fit's options) said so: then there is no
    /// estimate and no light, and `modelled` is that fit's start image.
    pub stopped_at_start: bool,
    /// Lobe samples per traced pixel of the paper's estimate every fit started from.
    pub start_samples: u32,
}

/// Estimates the water's gloss from the photo and fits the lights with it (see the module
/// doc for the method).
///
/// The inputs are those of [`fit_paper`](super::fit_paper): the photo, its water mask and the streaks found in
/// it. `paper` is the paper fit that gives every candidate its start (its `model.gloss` is
/// the first guess, the scene's typically; its seed is also the search's fits'), first made
/// with `quick_samples` when given ([`start_estimate`]); `final_fit`
/// is the joint fit run at the estimate (its model's gloss is replaced by the estimate; its
/// progress reporter hears each evaluation). Fails on inconsistent inputs, bad search
/// options, when there is no streak, and when no streak gives a light (the message says why
/// for each).
#[allow(clippy::too_many_arguments)]
pub fn estimate_gloss(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    paper: &FitOptions,
    quick_samples: Option<u32>,
    final_fit: &JointOptions,
    options: &GlossSearch,
) -> Result<GlossEstimate> {
    options.validate(paper, final_fit)?;
    super::check_sizes(photo, water)?;
    if streaks.is_empty() {
        return Err(Error::NothingFound(
            "no streak to estimate the gloss from: the photo shows no reflection of a light".into(),
        ));
    }
    let (lo, hi) = (
        (options.min_gloss as f64).ln(),
        (options.max_gloss as f64).ln(),
    );
    let x0 = (paper.model.gloss as f64).ln().clamp(lo, hi);
    let mut timings = Vec::new();

    // The common start: the paper fit at the first guess.
    let t = Instant::now();
    let start_options = FitOptions {
        model: ReflectionModel {
            gloss: paper
                .model
                .gloss
                .clamp(options.min_gloss, options.max_gloss),
            ..paper.model
        },
        ..*paper
    };
    let search_fit = SearchFit {
        model: paper.model,
        seed: paper.seed,
        progress: final_fit.progress,
        direct_view: final_fit.direct_view,
        close_regions: final_fit.close_regions,
    };
    let place = |fit: &FitOutcome, progress: Reporter<'_>| {
        let placing = final_fit.direct_view.then_some(progress);
        placed_search_start(scene, photo, water, streaks, fit, "gloss", placing)
    };
    let estimates = PaperEstimates::new(&ExactSurface, scene, photo, water, streaks);
    let StartEstimate {
        fit: paper,
        placed,
        samples: start_samples,
        ..
    } = start_estimate(
        scene,
        photo,
        water,
        quick_samples.filter(|_| final_fit.direct_view),
        start_options.samples,
        &|samples| {
            estimates.fit(&FitOptions {
                samples,
                ..start_options
            })
        },
        &place,
        None,
        final_fit.progress,
    )?;
    timings.push(("paper fit".to_string(), t.elapsed().as_secs_f64()));
    let (start, start_images) = match placed {
        Some(p) => (p.lights, p.images),
        None => (place(&paper, final_fit.progress)?, Vec::new()),
    };
    let mut warnings = paper.warnings.clone();

    let t = Instant::now();
    let mut cost = Cost {
        scene,
        photo,
        water,
        streaks,
        start: &start,
        start_images: &start_images,
        options,
        fit: search_fit,
        proposal: ProposalCache::new(proposal(x0)),
        evaluations: Vec::new(),
        failed: Vec::new(),
        gate: final_fit.start_gate,
        stopped: None,
        held: None,
    };
    let found = search(
        options,
        x0,
        (lo, hi),
        ("gloss", &|e| format!("{e:.0}")),
        &mut cost,
    )?;
    // Where the fits on the kept trace held every light (each seen whole: its image pins
    // it) and that trace serves the estimate, the final fit weighs it and resumes the lights
    // where they were held (module doc); otherwise the trace is freed before the final fit
    // traces its own: the peak memory is the larger of the two, not their sum.
    let (evaluations, failed, stopped, kept) = {
        let done = cost;
        let all_held = done
            .held
            .as_ref()
            .is_some_and(|h| !h.is_empty() && h.iter().all(Option::is_some));
        let serves = done.proposal.serves_traced(&Lobe::Exact {
            gloss: found.x.exp() as f32,
        });
        let kept = (all_held && serves).then_some((done.proposal, done.held));
        (done.evaluations, done.failed, done.stopped, kept)
    };
    if let Some(modelled) = stopped {
        timings.push((
            "search (stopped at its first fit)".into(),
            t.elapsed().as_secs_f64(),
        ));
        return Ok(GlossEstimate {
            gloss: start_options.model.gloss,
            sigma_ln: None,
            evaluations: Vec::new(),
            lights: Vec::new(),
            uncertainty: Vec::new(),
            residual_variance: 0.0,
            start: paper.lights,
            skipped: paper.skipped,
            warnings,
            timings,
            modelled,
            pixels: 0,
            share: options.search_pixels,
            splits: Vec::new(),
            stopped_at_start: true,
            start_samples,
        });
    }
    timings.push((
        format!("search ({} evaluations)", evaluations.len()),
        t.elapsed().as_secs_f64(),
    ));
    let gloss = found.x.exp() as f32;
    if !failed.is_empty() {
        warnings.push(format!(
            "the joint fit broke down (no positive cost) at gloss {failed:?}; those were left out"
        ));
    }
    match found.stop {
        Stop::Converged | Stop::Abandoned => {}
        Stop::AtLimit => warnings.push(format!(
            "the gloss estimate lies at the search's limit ({gloss:.0}, searched {} to {}): \
             the photo fits best with a gloss at or beyond it",
            options.min_gloss, options.max_gloss
        )),
        Stop::OutOfEvaluations => warnings.push(format!(
            "the gloss search stopped after {} evaluations before converging; the estimate \
             {gloss:.0} may be off by more than its tolerance",
            options.max_evaluations
        )),
    }

    // The lights at the estimate, fitted in full from the same start.
    final_fit
        .progress
        .stage(&format!("gloss search: final joint fit at e = {gloss:.0}"));
    let t = Instant::now();
    let at_estimate = JointOptions {
        model: ReflectionModel {
            gloss,
            ..final_fit.model
        },
        // The gate was the search's first fit's to ask.
        start_gate: None,
        ..*final_fit
    };
    let resumed;
    let (from, fit_options) = match &kept {
        // The search's pixels and region, which its trace was made for.
        Some((cache, held)) => {
            resumed = JointOptions {
                pixels: options.search_pixels,
                region_gloss: Some(cost::region_gloss(options, search_fit.model.gloss)),
                close_regions: search_fit.close_regions,
                starts_placed: true,
                start_images: &start_images,
                reweight: Some(Reweight {
                    cache,
                    target: Lobe::Exact { gloss },
                }),
                resume: held.as_deref().unwrap_or(&[]),
                ..at_estimate
            };
            (&start[..], &resumed)
        }
        None => (&paper.lights[..], &at_estimate),
    };
    let final_fit = fit_joint(scene, photo, water, streaks, from, fit_options)?;
    drop(kept);
    timings.push(("final joint fit".to_string(), t.elapsed().as_secs_f64()));
    let lights = final_fit.lights_with_statuses();
    warnings.extend(final_fit.warnings);
    Ok(GlossEstimate {
        gloss,
        sigma_ln: found.sigma_ln.map(|s| s as f32),
        evaluations: evaluations
            .iter()
            .map(|&(x, s)| (x.exp() as f32, s))
            .collect(),
        lights,
        uncertainty: final_fit.uncertainty,
        residual_variance: final_fit.residual_variance,
        start: paper.lights,
        skipped: paper.skipped,
        warnings,
        timings,
        modelled: final_fit.modelled,
        pixels: final_fit.pixels,
        share: final_fit.share,
        splits: final_fit.splits,
        stopped_at_start: false,
        start_samples,
    })
}
