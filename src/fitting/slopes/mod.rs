//! Estimating the waves' slope variances from the photo together with the lights, for the
//! statistical water model (method §10).
//!
//! Under the statistical model the lobe is set by two slope variances, along the camera's
//! view on the water and across it ([`StatisticalSurface`]): the streak's length follows the
//! first, its width the second. They are measured as the gloss is (the gloss module's doc):
//! the variances whose best lights explain the photo best,
//!
//! ```text
//! (v_a, v_c) = argmin min_{lights} S(v_a, v_c, lights)
//! ```
//!
//! with `S` the joint fit's noise-debiased residual sum of squares, by the same
//! one-dimensional search over the logarithm, one axis at a time: along, then across, then
//! along again when across moved (the two interact through the rectangle's corners only).
//! That last pass is first tried as one Newton step: the fit at the lowest point so far and
//! one a first step above it along give the gradient, the first along pass's parabola the
//! curvature, and where the step stays within the search's tolerance its end is the
//! estimate, one fit instead of two or more ([`newton_along`]); otherwise the pass runs
//! in full.
//! Each pass after the first searches from the lowest fit made so far, both axes (the
//! estimate of the axis it left lies within the search's tolerance of that fit), so the
//! middle of its first three points is a fit already made: two fits fewer of the eleven a
//! full search took on Table 1's photo over a flat quad, the estimates within 0.3 %.
//! Every fit starts from the same lights (the paper fit at the starting variances, placed on
//! the lamps' direct images once: [`super::joint::place_starts`]), reads the
//! same pixels (those the broadest lobe of the search can see: four times the starting
//! variances) with the same random numbers, so the costs are comparable. The fits weigh the
//! samples of one trace under a proposal lobe of [`PROPOSAL_OVER_START`] times the starting
//! variances (`joint::ProposalCache`); a fit above its reach on an axis is traced under a
//! proposal grown to [`PROPOSAL_OVER_START`] times its variance there, which the fits after
//! it share: over a flat quad whose material is smoother than the photo's waves
//! (`gloss1000.png`) the search left the first proposal's reach after three fits and traced
//! each of the six after anew. The pass's fits on the old trace are then made again on the
//! new one ([`Pass`], the search's rebase; the grown proposal still covers the pass's
//! lowest fit where it can), so that its parabola, and the variance's sigma
//! from its curvature, compare fits of one trace: the harbour pair's across pass over the
//! other waves, which mixed them, had a sigma of 2.9 % where its fits on one trace give
//! 14 %. A fit below its reach (the low end of a bracket) traces its own samples, as a
//! proposal moved down to it would leave the search's later fits uncovered again. A light the first
//! fit saw whole in the photo ([`super::joint::JointOutcome::seen_whole`]: every edge pinned
//! by its direct image within a pixel's footprint, or beyond what the photo tells, as where
//! the frame cuts the lamp) is pinned by it whatever the lobe, so
//! every later fit holds it there ([`JointOptions::held`]) and solves only its radiance: over the
//! harbour's lights in frame the search then took 2-3 s rather than 5-9 s, the lights the
//! same to 0.1 %, the variances along within 1 % and across within 14 % (docs/decisions.md).
//! Where the search held every light, the final fit at the estimate weighs the search's trace
//! too, over its pixels, and resumes each light where it was held ([`JointOptions::resume`]):
//! a weighting and a short descent instead of a trace and a descent from the start.
//! When the final fit
//! is weighted by the glitter's noise (`JointOptions::glitter_weights`), so is every fit of
//! the search, all by the weights the first one measured, so that their costs still compare.
//!
//! The variances are the lobe's whole: the water's microfacets are given a gloss of
//! [`MICROFACET_GLOSS`], finer than any wave, and the waves' variances carry the rest. So the
//! search starts from any estimate of the whole, the material's roughness of a flat quad or a
//! wave mesh's measured slopes plus its material's, and can move either way from it.
//!
//! Uncertainty: each axis's from the curvature of its last search (the gloss module's doc,
//! "Uncertainty"), and the lights' with the glitter's correlation and the slopes' own
//! uncertainty carried in (`uncertainty`).

mod fits;
mod newton;
mod uncertainty;

use std::time::Instant;

use fits::{last_on, Fit, Fits, Pass};
use newton::newton_along;

pub use uncertainty::{
    correlation_area, parameter_slopes, realisation_floor, widen, MAX_LAG, REALISATION_FLUX,
    SLOPE_REALISATION_LN,
};

use super::gloss::search::{search, Point, Stop};
use super::gloss::{placed_search_start, GlossSearch};
use super::joint::{
    fit_joint_with, start_estimate, JointOptions, Lobe, PixelShare, ProposalCache, Reweight, Split,
    StartEstimate, Uncertainty, TARGET_OVER_PROPOSAL,
};
use super::{
    FitOptions, FitOutcome, FittedLight, PaperEstimates, Rect, Skipped, StreakObservation,
};
use crate::optics::{GaussianSlopes, ReflectionModel};
use crate::photo_in::Photo;
use crate::pixel_scale::scaled_pixels;
use crate::progress::Reporter;
use crate::scene_in::Scene;
use crate::water_model::{MeanSurface, StatisticalSurface};
use crate::Result;

/// The gloss of the water's microfacets under the statistical model: slope variance
/// `1 / (e + 2)` = 5e-5, below any the photos show, so the waves' variances hold the lobe.
pub const MICROFACET_GLOSS: f32 = 20000.0;

/// The slope search's proposal (`joint::ProposalCache`), per axis, as a multiple of the
/// start's variances: it covers fits from a quarter of it up to it, 0.4 to 1.6 times the
/// start's, where the searches of the samples stay.
pub const PROPOSAL_OVER_START: f32 = 1.6;

/// The smallest and largest total slope variance searched.
pub const VARIANCE_RANGE: (f32, f32) = (1e-4, 0.05);

/// The total slope variances (microfacets and waves) of the lobe of gloss `gloss` under waves
/// of variances `waves`.
pub fn total_variance(gloss: f32, waves: [f32; 2]) -> [f32; 2] {
    GaussianSlopes::microfacets_and_waves(gloss, waves).variance
}

/// The statistical water over `surface` whose lobe has total slope variances `total` (with
/// [`MICROFACET_GLOSS`] microfacets).
pub fn water_with_total(surface: MeanSurface, total: [f32; 2]) -> StatisticalSurface {
    let micro = GaussianSlopes::from_gloss(MICROFACET_GLOSS).variance[0];
    StatisticalSurface {
        surface,
        waves: total.map(|v| (v - micro).max(0.0)),
    }
}

/// The estimated slope variances and the lights fitted with them.
#[derive(Clone, Debug)]
pub struct SlopeEstimate {
    /// The statistical water at the estimate.
    pub water: StatisticalSurface,
    /// The total slope variances along and across (dimensionless).
    pub variance: [f32; 2],
    /// One-sigma uncertainty of the natural logarithm of each (about the relative
    /// uncertainty), from the cost's curvature grown by the residual's correlation, and at
    /// least [`SLOPE_REALISATION_LN`]; `None` where the minimum was not bracketed.
    pub sigma_ln: [Option<f32>; 2],
    /// Where the search started.
    pub start_variance: [f32; 2],
    /// Every evaluation: (variances along and across, cost).
    pub evaluations: Vec<([f32; 2], f64)>,
    /// The lights fitted at the estimate with the final fit's options, edge statuses from
    /// their uncertainties.
    pub lights: Vec<FittedLight>,
    /// Their uncertainties.
    pub uncertainty: Vec<Uncertainty>,
    /// The paper fit's lights at the start: every fit's start.
    pub start: Vec<FittedLight>,
    /// Streaks the paper fit could not turn into a light.
    pub skipped: Vec<Skipped>,
    /// Things the user should know.
    pub warnings: Vec<String>,
    /// Wall-clock seconds per stage.
    pub timings: Vec<(String, f64)>,
    /// The final fit's cost (comparable between fits of the same pixels).
    pub cost: f64,
    /// The final fit's residual correlation area, pixels per independent residual
    /// ([`correlation_area`]): the uncertainties are grown by its square root.
    pub correlation_area: f64,
    /// The start lights the final fit explained as two
    /// ([`super::joint::JointOutcome::splits`]).
    pub splits: Vec<Split>,
    /// Lobe samples per traced pixel of the paper's estimate every fit started from.
    pub start_samples: u32,
    /// Which pixels the final fit read ([`super::joint::JointOutcome::share`]).
    pub share: PixelShare,
}

/// Estimates the slope variances over `surface` from the start `start_variance` (totals,
/// along and across) and fits the lights with them (module doc). `paper` and `final_fit` as
/// for [`super::gloss::estimate_gloss`] (their models' gloss is replaced by
/// [`MICROFACET_GLOSS`]); `options` the one-dimensional search's settings, in the logarithm
/// of a variance. With `quick_samples`, the paper's estimate reads that many lobe samples a
/// pixel first, and is kept when the direct view places every light it starts on a lamp's
/// whole direct image (each such light is then pinned by its image whatever the start's
/// noise); otherwise it is made again with `paper`'s samples.
#[allow(clippy::too_many_arguments)]
pub fn estimate_slopes(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    surface: MeanSurface,
    start_variance: [f32; 2],
    paper: &FitOptions,
    quick_samples: Option<u32>,
    final_fit: &JointOptions,
    options: &GlossSearch,
) -> Result<SlopeEstimate> {
    let (lo, hi) = VARIANCE_RANGE;
    let start_variance = start_variance.map(|v| v.clamp(lo, hi));
    let model = ReflectionModel {
        gloss: MICROFACET_GLOSS,
        ..paper.model
    };
    let mut timings = Vec::new();
    let t = Instant::now();
    let start_water = water_with_total(surface, start_variance);
    final_fit.progress.stage(&format!(
        "fit of {} streak(s): the paper's estimate over the statistical water (the slope \
         search's start)",
        streaks.len()
    ));
    let estimates = PaperEstimates::new(&start_water, scene, photo, water, streaks);
    let estimate = |samples: u32| {
        estimates.fit(&FitOptions {
            model,
            samples,
            ..*paper
        })
    };
    let placed = |fit: &FitOutcome, progress: Reporter<'_>| {
        let placing = final_fit.direct_view.then_some(progress);
        placed_search_start(scene, photo, water, streaks, fit, "waves' slope", placing)
    };
    // Out of frame the reflections alone place the lights, every fit of the search descends
    // from the start, and a noisier start moves them (docs/decisions.md).
    let StartEstimate {
        fit: paper_fit,
        placed: placed_start,
        samples: start_samples,
        ..
    } = start_estimate(
        scene,
        photo,
        water,
        quick_samples.filter(|_| final_fit.direct_view),
        paper.samples,
        &estimate,
        &placed,
        None,
        final_fit.progress,
    )?;
    timings.push(("paper fit".to_string(), t.elapsed().as_secs_f64()));
    if paper_fit.lights.is_empty() {
        // No light to estimate the slopes with: the caller reports the streaks skipped, as
        // the exact model's fit does.
        return Ok(SlopeEstimate {
            water: start_water,
            variance: start_variance,
            sigma_ln: [None, None],
            start_variance,
            evaluations: Vec::new(),
            lights: Vec::new(),
            uncertainty: Vec::new(),
            start: Vec::new(),
            skipped: paper_fit.skipped,
            warnings: paper_fit.warnings,
            timings,
            cost: 0.0,
            correlation_area: 1.0,
            splits: Vec::new(),
            start_samples,
            share: final_fit.pixels,
        });
    }
    let (start, start_images) = match placed_start {
        Some(p) => (p.lights, p.images),
        None => (placed(&paper_fit, final_fit.progress)?, Vec::new()),
    };
    let mut warnings = paper_fit.warnings.clone();
    let broad = water_with_total(surface, start_variance.map(|v| (4.0 * v).min(hi)));
    let search_options = JointOptions {
        samples: options.search_samples,
        sweeps: options.search_sweeps,
        // A wrong lobe leaves a structured residual too: splitting there would fit the
        // lobe's error, not a second light.
        split: false,
        region_water: Some(&broad),
        progress: final_fit.progress,
        stacked_as_one: final_fit.stacked_as_one,
        direct_view: final_fit.direct_view,
        close_regions: final_fit.close_regions,
        edges_by_image: final_fit.edges_by_image,
        // The final fit's share, so that its residual's correlation area, counted over the
        // pixels it read, grows the curvature of fits over the same share.
        pixels: final_fit.pixels,
        // Every fit of the search starts alike, so each thins alike.
        thin_seen_whole: final_fit.thin_seen_whole,
        starts_placed: true,
        start_images: &start_images,
        ..JointOptions::new(model, paper.seed)
    };
    // Each axis's last pass: (ln variance, the lights fitted there).
    let mut passes: [Vec<(f64, Vec<FittedLight>)>; 2] = [Vec::new(), Vec::new()];
    let mut variance = start_variance;
    // Every fit made so far (the evaluations reported), and the one of lowest cost: each
    // pass after the first searches from there (its axis's estimate lies within the
    // tolerance of it), so the middle of its first three points is a fit already made, read
    // again rather than made again (on the present proposal's trace).
    let mut made = Fits::default();
    let mut anchor = start_variance;
    let mut sigma_ln = [None, None];
    let t = Instant::now();
    // The weights of the first fit's rows, which every later fit of the search takes.
    let search_scales: std::cell::OnceCell<Vec<f32>> = std::cell::OnceCell::new();
    // Every fit of the search the proposal covers weighs the samples of its one trace
    // (`ProposalCache`): their costs compare as fits from one set of samples do. A fit the
    // search takes above its reach gets a proposal grown to cover it, which the fits after
    // it share (module doc).
    let proposal_over = |total: [f32; 2]| {
        ProposalCache::new(Lobe::Statistical {
            water: water_with_total(surface, total.map(|v| v.min(hi))),
            gloss: model.gloss,
        })
    };
    let proposal = std::cell::RefCell::new(proposal_over(
        start_variance.map(|v| PROPOSAL_OVER_START * v),
    ));
    // How many times the proposal has grown: the fits on one generation compare.
    let generation = std::cell::Cell::new(0u32);
    // Whether a fit at `v` lies above the proposal's reach on some axis, where the proposal
    // grows to it rather than the fit tracing its own samples.
    let above_reach = |v: [f32; 2]| {
        let lobe = Lobe::Statistical {
            water: water_with_total(surface, v),
            gloss: model.gloss,
        };
        let cache = proposal.borrow();
        let p = cache.proposal.variance();
        !cache.covers(&lobe) && (0..2).any(|a| v[a] > p[a])
    };
    // Grows the proposal to [`PROPOSAL_OVER_START`] times `v`, but on each axis no higher
    // than still covers `keep` (the lowest variance of the fits to be made again on it) and
    // no lower than `v`; the old trace is freed before the new one is made.
    let grow_to = |v: [f32; 2], keep: [f32; 2]| {
        let p = proposal.borrow().proposal.variance();
        let reach = TARGET_OVER_PROPOSAL.0;
        let grown =
            [0, 1].map(|a| p[a].max((PROPOSAL_OVER_START * v[a]).min(keep[a] / reach).max(v[a])));
        drop(proposal.replace(proposal_over(grown)));
        generation.set(generation.get() + 1);
    };
    // The lights the first fit saw whole in the photo, by start light: every later fit holds
    // them there (module doc).
    let whole: std::cell::OnceCell<Vec<Option<Rect>>> = std::cell::OnceCell::new();
    // The pixels the first fit read (thinned or not, `JointOptions::thin_seen_whole`): the
    // final fit reads the same share, so that the residual's correlation area it measures
    // grows the search's curvature over the pixels that made it.
    let search_share: std::cell::OnceCell<PixelShare> = std::cell::OnceCell::new();
    // The `number`-th fit, at variances `v`, with the generation of the proposal it weighed
    // (`None`: it traced its own samples).
    let eval = |v: [f32; 2], number: usize| -> Result<Fit> {
        final_fit.progress.stage(&format!(
            "slope search: joint fit {number} at variances {:.2e} along, {:.2e} across",
            v[0], v[1]
        ));
        // Weighted as the final fit is, every fit by the first one's weights (`row_scales`).
        let weighted = final_fit.glitter_weights;
        let target = water_with_total(surface, v);
        let lobe = Lobe::Statistical {
            water: target,
            gloss: model.gloss,
        };
        if above_reach(v) {
            // A fit below its reach (a bracket's low end) traces its own.
            grow_to(v, [f32::INFINITY; 2]);
        }
        let cache = proposal.borrow();
        let basis = cache.covers(&lobe).then(|| generation.get());
        let fit = fit_joint_with(
            &target,
            scene,
            photo,
            water,
            streaks,
            &start,
            &JointOptions {
                glitter_weights: weighted,
                row_scales: search_scales.get().map(|s| &s[..]),
                held: whole.get().map_or(&[], |h| &h[..]),
                reweight: Some(Reweight {
                    cache: &cache,
                    target: lobe,
                }),
                ..search_options
            },
        )?;
        if whole.get().is_none() {
            let _ = whole.set(fit.to_hold("slope search", final_fit.progress));
            let _ = search_share.set(fit.share);
        }
        if weighted && search_scales.get().is_none() {
            if let Some(s) = fit.row_scales.clone() {
                let _ = search_scales.set(s);
            }
        }
        let s = if fit.cost.is_finite() && fit.cost > 0.0 {
            fit.cost
        } else {
            f64::INFINITY
        };
        Ok((
            Point {
                x: 0.0,
                s,
                variance: fit.residual_variance,
            },
            fit.lights,
            basis,
        ))
    };
    let (lo_ln, hi_ln) = ((lo as f64).ln(), (hi as f64).ln());
    let show: &dyn Fn(f64) -> String = &|v| format!("{v:.2e}");
    let mut along_curvature: Option<f64> = None;
    for (pass, axis) in [0usize, 1, 0].into_iter().enumerate() {
        if pass == 2 {
            // Along again only when across moved enough to matter.
            let moved = (variance[1] / start_variance[1]).ln().abs();
            if moved < options.tolerance_ln {
                break;
            }
        }
        let name = ["slope variance along", "slope variance across"][axis];
        // The fit at variances `v`, made again only if not made yet on the present trace.
        let mut made_at = |v: [f32; 2]| made.at(v, generation.get(), eval);
        if pass == 2 {
            let mut point_at = |v: [f32; 2]| made_at(v).map(|(p, lights, _)| (p, lights));
            if let Some(v) = newton_along(&mut point_at, anchor, along_curvature, options)? {
                variance[0] = v;
                continue;
            }
        }
        let at = |x: f64| {
            let mut v = anchor;
            v[axis] = x.exp() as f32;
            v
        };
        // The pass's fits: (ln variance, lights, proposal generation); and the lowest
        // variance of those on the present proposal, which a proposal grown for the pass
        // covers still, so that they are made again on its trace rather than each on its own.
        let mut pass_points = Vec::new();
        let lowest = std::cell::Cell::new(f32::INFINITY);
        let found = search(
            options,
            (anchor[axis] as f64).ln(),
            (lo_ln, hi_ln),
            (name, show),
            Pass {
                point: |x: f64| {
                    let (p, lights, basis) = made_at(at(x))?;
                    if basis.is_some() {
                        lowest.set(lowest.get().min(at(x)[axis]));
                    }
                    if p.s.is_finite() {
                        pass_points.push((x, lights, basis));
                    }
                    Ok(Point { x, ..p })
                },
                serves: |x: f64| !above_reach(at(x)),
                rebase: |next: f64| {
                    let mut keep = [f32::INFINITY; 2];
                    keep[axis] = lowest.replace(f32::INFINITY);
                    grow_to(at(next), keep)
                },
            },
        )?;
        passes[axis] = last_on(pass_points, generation.get());
        variance[axis] = found.x.exp() as f32;
        if let Some(best) = made.best(generation.get()) {
            anchor = best.0;
            if pass == 0 {
                // The curvature of the along pass's parabola, from its sigma and its best
                // fit's residual variance (`search`'s doc: sigma = sqrt(variance / k)).
                along_curvature = found
                    .sigma_ln
                    .filter(|&sigma| sigma > 0.0)
                    .map(|sigma| best.1.variance / (sigma * sigma));
            }
        }
        sigma_ln[axis] = found.sigma_ln.map(|s| s as f32);
        match found.stop {
            // Its fits take no start gate: never abandoned.
            Stop::Converged | Stop::Abandoned => {}
            Stop::AtLimit => warnings.push(format!(
                "the {name} lies at the search's limit ({:.2e}, searched {lo:.0e} to {hi:.0e})",
                variance[axis]
            )),
            Stop::OutOfEvaluations => warnings.push(format!(
                "the search of the {name} stopped after {} evaluations before converging",
                options.max_evaluations
            )),
        }
    }
    let evaluations = made.evaluations();
    timings.push((
        format!("slope search ({} evaluations)", evaluations.len()),
        t.elapsed().as_secs_f64(),
    ));
    let failed = evaluations.iter().filter(|e| !e.1.is_finite()).count();
    if failed > 0 {
        warnings.push(format!(
            "the joint fit broke down (no positive cost) at {failed} of the slope search's \
             evaluations; those were left out"
        ));
    }
    final_fit.progress.stage(&format!(
        "slope search: final joint fit of {} light(s) at variances {:.2e} along, {:.2e} across",
        start.len(),
        variance[0],
        variance[1]
    ));
    let t = Instant::now();
    let at = water_with_total(surface, variance);
    // Where the search held every light (each seen whole: its image pins it), the final fit
    // weighs the search's own trace for its lobe, over the search's pixels, and resumes
    // each light where the search's first fit put it: a search of a fraction of a footprint
    // around it instead of a trace and a descent from the start (module doc). Otherwise it
    // traces its own samples from the start, and the kept trace is freed first: the peak
    // memory is the larger of the two, not their sum.
    let target = Lobe::Statistical {
        water: at,
        gloss: model.gloss,
    };
    let resume = whole
        .get()
        .filter(|h| !h.is_empty() && h.iter().all(Option::is_some))
        .map_or(&[][..], |h| &h[..]);
    let proposal = proposal.into_inner();
    let kept = (!resume.is_empty() && proposal.serves_traced(&target)).then_some(proposal);
    let common = JointOptions {
        model,
        pixels: search_share.get().copied().unwrap_or(final_fit.pixels),
        thin_seen_whole: false,
        ..*final_fit
    };
    let resumed;
    let (from, fit_options) = match &kept {
        Some(cache) => {
            resumed = JointOptions {
                region_water: Some(&broad),
                starts_placed: true,
                start_images: &start_images,
                resume,
                reweight: Some(Reweight { cache, target }),
                ..common
            };
            (&start[..], &resumed)
        }
        None => (&paper_fit.lights[..], &common),
    };
    let fit = fit_joint_with(&at, scene, photo, water, streaks, from, fit_options)?;
    drop(kept);
    timings.push(("final joint fit".to_string(), t.elapsed().as_secs_f64()));
    warnings.extend(fit.warnings.iter().cloned());
    let area = correlation_area(
        &photo.radiance,
        photo.width,
        &fit.modelled,
        scaled_pixels(MAX_LAG, photo.height, scene.camera.yfov),
        fit.share,
    );
    let sigma_ln = sigma_ln.map(|s| s.map(|s| s * area.sqrt() as f32));
    let lights = fit.lights_with_statuses();
    let mut uncertainty = fit.uncertainty;
    let by_axis = passes.map(|p| parameter_slopes(&p));
    widen(
        &mut uncertainty,
        area,
        [by_axis[0].as_ref(), by_axis[1].as_ref()],
        sigma_ln,
    );
    let radiance: Vec<[f32; 3]> = lights.iter().map(|l| l.radiance).collect();
    realisation_floor(&mut uncertainty, &radiance);
    // Reported as what the photo tells of the water under its streaks.
    let sigma_ln = [0, 1].map(|a| sigma_ln[a].map(|s| s.max(SLOPE_REALISATION_LN[a])));
    Ok(SlopeEstimate {
        water: at,
        variance,
        sigma_ln,
        start_variance,
        evaluations,
        lights,
        uncertainty,
        start: paper_fit.lights,
        skipped: paper_fit.skipped,
        warnings,
        timings,
        cost: fit.cost,
        correlation_area: area,
        splits: fit.splits,
        start_samples,
        share: fit.share,
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn totals_and_waves_convert_both_ways() {
        let surface = MeanSurface::new(
            glam::Vec3::new(0.0, -1.0, -5.0),
            glam::Vec3::Y,
            glam::Vec3::NEG_Z,
            glam::Vec3::Y,
        );
        let w = water_with_total(surface, [0.003, 0.001]);
        let back = total_variance(MICROFACET_GLOSS, w.waves);
        assert!((back[0] - 0.003).abs() < 1e-9 && (back[1] - 0.001).abs() < 1e-9);
        // A total below the microfacets' own is the microfacets alone.
        assert_eq!(water_with_total(surface, [1e-6, 1e-6]).waves, [0.0, 0.0]);
    }
}
