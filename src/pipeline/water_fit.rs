//! The fit under the chosen water model ([`WaterChoice`]): the exact model's steps, the
//! statistical model's, and the automatic choice between them (the water_choice module's
//! doc).

use super::water_choice::{
    fine_structure_of, FineStructure, SlopesUsed, WaterChoice, WaterModelUsed, EXACT_MIN_EXPLAINED,
    FIRST_ESTIMATE_TEST_SAMPLES, FLAT_SHARE, START_MAX_CORRELATION,
};
use super::{Found, GlossFit, Method, Run, EXACT_MIN_CORRELATION};
use crate::fitting::gloss::GlossSearch;
use crate::fitting::joint::{JointOptions, ModelledPixel, StartGate};
use crate::fitting::slopes::{estimate_slopes, water_with_total, MICROFACET_GLOSS};
use crate::fitting::{self, FitOptions};
use crate::optics::{GaussianSlopes, ReflectionModel};
use crate::settings::Setting;
use crate::water_model::{clearly_wavy, water_statistics, WaterStatistics};
use crate::{Error, Result};

impl WaterModelUsed {
    /// `model` as the settings asked for it.
    pub(super) fn forced(model: &'static str) -> Self {
        WaterModelUsed {
            model,
            chosen: "forced",
            reason: format!("asked for (--water-model {model})"),
            fine_structure_correlation: None,
            threshold: EXACT_MIN_CORRELATION,
            exact_explained: None,
            slopes: None,
        }
    }
}

/// Joint-fit samples per pixel of the slope search's fits: 128, with which every figure of
/// the statistical model's accuracy was measured (the gloss search's 72 are not measured
/// there).
const SLOPE_SEARCH_SAMPLES: u32 = 128;

/// The one-dimensional searches of the slope variances: in the logarithm of a variance
/// (twice that of the lobe's width), so the gloss search's steps doubled.
fn slope_search() -> GlossSearch {
    let gloss = GlossSearch::default();
    GlossSearch {
        search_samples: SLOPE_SEARCH_SAMPLES,
        first_step_ln: 2.0 * gloss.first_step_ln,
        max_step_ln: 2.0 * gloss.max_step_ln,
        tolerance_ln: 2.0 * gloss.tolerance_ln,
        max_bracket_ln: 2.0 * gloss.max_bracket_ln,
        max_evaluations: 10,
        ..gloss
    }
}

impl Run<'_> {
    /// The lights of the streaks under the water model `settings` choose (or the one the
    /// photo asks for), into `found`; says which model and why.
    pub(super) fn fit_lights(
        &self,
        settings: &super::FitSettings,
        found: &mut Found,
    ) -> Result<WaterModelUsed> {
        match (settings.water, &settings.method) {
            (WaterChoice::Statistical, method) => self.statistical(method, found, "forced", None),
            (WaterChoice::Exact, method) => {
                self.exact(method, found, None)?;
                // Measured all the same, for the report.
                let fine = fine_structure_of(self.photo, self.scene.camera.yfov, &found.modelled);
                Ok(WaterModelUsed {
                    fine_structure_correlation: fine.and_then(|f| f.correlation),
                    exact_explained: fine.and_then(|f| f.explained),
                    ..WaterModelUsed::forced("exact")
                })
            }
            // The paper's per-streak estimate has no expected image to compare.
            (WaterChoice::Auto, method @ Method::Paper) => {
                self.exact(method, found, None)?;
                Ok(WaterModelUsed {
                    chosen: "detected",
                    reason: "the paper's method has no expected image to compare with the \
                             photo: the exact model unless the statistical one is asked for"
                        .into(),
                    ..WaterModelUsed::forced("exact")
                })
            }
            (WaterChoice::Auto, method @ Method::Joint(_)) => {
                if let Some(reason) = self.flat_water() {
                    self.progress.stage(&format!(
                        "{reason}: fitting with the statistical water model"
                    ));
                    let mut used = self.statistical(method, found, "detected", None)?;
                    used.reason = reason;
                    return Ok(used);
                }
                let warnings = found.warnings.len();
                // The exact fit as it would be made alone (with the gloss search when asked),
                // then the test on its expected image: where it passes, nothing is done twice.
                // Where the start lights' expected image already shows fine structure
                // unrelated to the photo's, the fit ends there (`clearly_not_exact`).
                let (photo, yfov) = (self.photo, self.scene.camera.yfov);
                let gate = |modelled: &[ModelledPixel]| {
                    !fine_structure_of(photo, yfov, modelled).is_some_and(|f| f.clearly_not_exact())
                };
                // Where the paper's first estimate is not kept, the same test is made there
                // first, on the streaks' pixels alone, before the estimate at the full samples
                // and the joint fit's trace are made (`Run::paper`).
                self.exact(method, found, Some(StartGate(&gate)))?;
                if found.lights.is_empty() && !found.stopped_at_start {
                    return Ok(WaterModelUsed {
                        chosen: "detected",
                        reason: "no light to fit: nothing to compare".into(),
                        ..WaterModelUsed::forced("exact")
                    });
                }
                let fine = fine_structure_of(self.photo, self.scene.camera.yfov, &found.modelled);
                let correlation = fine.and_then(|f| f.correlation);
                let exact_explained = fine.and_then(|f| f.explained);
                if fine.is_none_or(|f| f.exact_fits()) {
                    return Ok(WaterModelUsed {
                        chosen: "detected",
                        reason: choice_reason(fine),
                        fine_structure_correlation: correlation,
                        exact_explained,
                        ..WaterModelUsed::forced("exact")
                    });
                }
                self.progress.stage(&format!(
                    "the photo's fine structure does not match the scene's waves \
                     (correlation {:.2}): fitting with the statistical water model",
                    correlation.unwrap_or(0.0)
                ));
                found.warnings.truncate(warnings);
                found.lights.clear();
                found.uncertainties.clear();
                found.skipped.clear();
                let at_start = found.stopped_at_start;
                let at_first_estimate = found.stopped_at_first_estimate;
                found.stopped_at_start = false;
                found.stopped_at_first_estimate = false;
                let mut used = self.statistical(method, found, "detected", correlation)?;
                used.exact_explained = exact_explained;
                used.reason = choice_reason(fine);
                if at_first_estimate {
                    used.reason.push_str(&format!(
                        ", both measured at the paper's first estimate of the lights (its \
                         expected image of the streaks at {FIRST_ESTIMATE_TEST_SAMPLES} samples \
                         a pixel), already far from the exact model there (correlation under \
                         {START_MAX_CORRELATION}): neither the full estimate nor the exact fit \
                         was made"
                    ));
                } else if at_start {
                    used.reason.push_str(&format!(
                        ", both measured at the paper's estimate of the lights, already far \
                         from the exact model there (correlation under \
                         {START_MAX_CORRELATION}): the exact fit was not made"
                    ));
                }
                Ok(used)
            }
        }
    }

    /// Why the scene's water is flat (module doc of `water_choice`), or `None` when it holds
    /// waves (or the camera sees none of it: the fit then says so).
    /// What the camera sees of the scene's water ([`water_statistics`]), measured once.
    fn water_statistics(&self) -> Option<WaterStatistics> {
        *self
            .water_stats
            .get_or_init(|| water_statistics(self.scene, self.photo.width, self.photo.height))
    }

    fn flat_water(&self) -> Option<String> {
        let gloss = self.paper.model.gloss;
        let micro = GaussianSlopes::from_gloss(gloss).variance;
        // A mesh clearly wavy is told by a quarter of the rays, before the full statistics.
        let threshold = micro.map(|v| FLAT_SHARE * v);
        if clearly_wavy(self.scene, self.photo.width, self.photo.height, threshold) {
            return None;
        }
        let stats = self.water_statistics()?;
        let mesh = stats.slope_variance;
        (mesh[0] < FLAT_SHARE * micro[0] && mesh[1] < FLAT_SHARE * micro[1]).then(|| {
            format!(
                "the scene's water is flat (slope variances {:.1e} along the view, {:.1e} \
                 across, under a tenth of its material's {:.1e}): it holds no waves to match \
                 the photo's, so their slopes are estimated from the photo",
                mesh[0], mesh[1], micro[0]
            )
        })
    }

    /// The exact model's fit: the paper's estimate, the joint fit (the gloss estimated first
    /// when asked). `gate` may end the joint fit at its start ([`JointOptions::start_gate`]),
    /// or the gloss search at its first fit; without the gloss search, it is asked first at a
    /// first estimate of the paper's that is not kept, before the estimate is made again
    /// (`Run::paper`).
    fn exact(&self, method: &Method, found: &mut Found, gate: Option<StartGate<'_>>) -> Result<()> {
        match method {
            Method::Joint(j) if matches!(j.gloss, GlossFit::Estimate(_)) => {
                self.with_gloss_search(j, found, gate)
            }
            method => {
                let joint = match method {
                    Method::Joint(j) => Some(j),
                    Method::Paper => None,
                };
                let placed = self.paper(found, joint, gate)?;
                if let Some(j) = joint {
                    if !found.lights.is_empty() && !found.stopped_at_start {
                        self.refine(j, found, gate, placed)?;
                    }
                }
                Ok(())
            }
        }
    }

    /// The statistical model's fit: the mean surface and the start of the slopes from the
    /// scene's water, then the paper's estimate (the paper's method) or the slope search
    /// with its joint fits (the joint method, whatever its gloss setting: the slopes are the
    /// lobe).
    fn statistical(
        &self,
        method: &Method,
        found: &mut Found,
        chosen: &'static str,
        correlation: Option<f64>,
    ) -> Result<WaterModelUsed> {
        let stats = self.water_statistics().ok_or_else(|| {
            Error::scene(
                &self.scene.path,
                format!("the camera sees no water: check {}", Setting::Water),
            )
        })?;
        let gloss = self.paper.model.gloss;
        let micro = GaussianSlopes::from_gloss(gloss).variance;
        let mesh = stats.slope_variance;
        let start = [micro[0] + mesh[0], micro[1] + mesh[1]];
        let start_source = if mesh[0].max(mesh[1]) < 1e-6 {
            format!("the water's gloss ({gloss:.0}): its mesh is flat")
        } else {
            format!(
                "the water mesh's slopes ({:.2e} along, {:.2e} across) and its gloss ({gloss:.0})",
                mesh[0], mesh[1]
            )
        };
        let model = ReflectionModel {
            gloss: MICROFACET_GLOSS,
            ..self.paper.model
        };
        found.gloss = (
            MICROFACET_GLOSS,
            "the statistical water model's microfacets (its slope variances carry the lobe)".into(),
        );
        let slopes = match method {
            Method::Paper => {
                self.progress.stage(&format!(
                    "fit of {} streak(s): the paper's estimate over the statistical water",
                    self.observations.len()
                ));
                let f = fitting::fit_paper_with(
                    &water_with_total(stats.surface, start),
                    self.scene,
                    self.photo,
                    self.water,
                    self.observations,
                    &FitOptions {
                        model,
                        samples: self.statistical_samples,
                        ..self.paper
                    },
                )?;
                found.lights = f.lights;
                found.skipped = f.skipped;
                found.warnings.extend(f.warnings);
                found.timings.extend(f.timings);
                found.start_samples = self.statistical_samples;
                SlopesUsed {
                    variance: start,
                    sigma_ln: [None, None],
                    start_variance: start,
                    start_source,
                    estimated: false,
                    correlation_area: None,
                    start_samples: self.statistical_samples,
                }
            }
            Method::Joint(j) => {
                self.progress.stage(&format!(
                    "slope search and fit of {} streak(s) over the statistical water (each \
                     step a joint fit)",
                    self.observations.len()
                ));
                // Out of frame the reflections alone cannot tell stacked lights of one colour
                // from one (joint fit's `stacked_as_one`), and the residual is the glitter,
                // whose noise weights the final fit (`glitter_weights`).
                let final_fit = JointOptions {
                    model,
                    stacked_as_one: true,
                    glitter_weights: true,
                    edges_by_image: true,
                    close_regions: false,
                    ..self.joint_options(j, j.reading)
                };
                let est = estimate_slopes(
                    self.scene,
                    self.photo,
                    self.water,
                    self.observations,
                    stats.surface,
                    start,
                    &FitOptions {
                        samples: self.statistical_samples,
                        ..self.paper
                    },
                    self.quick_statistical_samples,
                    &final_fit,
                    &slope_search(),
                )?;
                found.lights = est.lights;
                found.uncertainties = est.uncertainty;
                found.skipped = est.skipped;
                found.warnings.extend(est.warnings);
                found.timings.extend(est.timings);
                found.splits = est.splits;
                found.reading = Some(j.reading);
                found.share = Some(est.share);
                found.start_samples = est.start_samples;
                let estimated = !found.lights.is_empty();
                if estimated {
                    self.refit_overlaps(&est.water, &est.start, &final_fit, j, found)?;
                }
                SlopesUsed {
                    variance: est.variance,
                    sigma_ln: est.sigma_ln,
                    start_variance: est.start_variance,
                    start_source,
                    estimated,
                    correlation_area: Some(est.correlation_area),
                    start_samples: est.start_samples,
                }
            }
        };
        Ok(WaterModelUsed {
            model: "statistical",
            chosen,
            reason: "asked for (--water-model statistical)".into(),
            fine_structure_correlation: correlation,
            threshold: EXACT_MIN_CORRELATION,
            exact_explained: None,
            slopes: Some(slopes),
        })
    }
}

/// Why the automatic choice went as it did, from the measured fine structure (`None`: too
/// few pixels to measure, which keeps the exact model).
fn choice_reason(fine: Option<FineStructure>) -> String {
    let Some(f) = fine else {
        return "too few fitted pixels to compare fine structures: the exact model".into();
    };
    let correlation = f
        .correlation
        .map_or("unmeasured".into(), |c| format!("{c:.2}"));
    let explained = f
        .explained
        .map_or("unmeasured".into(), |e| format!("{e:.2}"));
    if f.exact_fits() {
        format!(
            "the photo's fine structure matches the scene's waves (correlation {correlation}, \
             threshold {EXACT_MIN_CORRELATION}) or the exact fit explains the photo \
             ({explained} of its variance, threshold {EXACT_MIN_EXPLAINED})"
        )
    } else {
        format!(
            "the photo's fine structure does not match the scene's waves (correlation \
             {correlation}, under {EXACT_MIN_CORRELATION}) and the exact fit explains only \
             {explained} of the photo's variance (under {EXACT_MIN_EXPLAINED})"
        )
    }
}
