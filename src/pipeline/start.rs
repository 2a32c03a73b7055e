//! The paper's estimate that starts the exact model's fit (method §5 steps 7-9), and the
//! automatic choice's test of the exact model at a first estimate not kept.

use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Mutex;
use std::time::Instant;

use super::{light_name, Found, JointSettings, Run, FIRST_ESTIMATE_TEST_SAMPLES};
use crate::fitting::joint::{
    place_starts, start_estimate, ModelledPixel, PlacedStart, StartEstimate, StartGate,
};
use crate::fitting::{self, FitOptions, FittedLight};
use crate::pixel_scale::scaled_pixels;
use crate::progress::Reporter;
use crate::render::{self, RenderOptions};
use crate::scene_in::AreaLight;
use crate::water_model::ExactSurface;
use crate::Result;

impl Run<'_> {
    /// The paper's estimate (method §5 steps 7-9). Where it starts a joint fit `j` that reads
    /// the direct view, it is first made with few samples ([`start_estimate`]); returns its
    /// lights as placed on their lamps' images when that estimate was kept.
    ///
    /// `first_test`, given a joint fit `j`, is asked about the exact model's expected image
    /// at a first estimate that is not kept (`first_estimate_image`): where it says not to go
    /// on, the fit ends there as a joint fit whose start gate said so
    /// (`Found::stopped_at_start`), and neither the estimate at the full samples nor the
    /// joint fit is made.
    pub(super) fn paper(
        &self,
        found: &mut Found,
        j: Option<&JointSettings>,
        first_test: Option<StartGate<'_>>,
    ) -> Result<Option<PlacedStart>> {
        self.progress.stage(&format!(
            "fit of {} streak(s): the paper's estimate",
            self.observations.len()
        ));
        let quick = j.filter(|j| j.direct_view).and(self.quick_exact_samples);
        let estimates = fitting::PaperEstimates::new(
            &ExactSurface,
            self.scene,
            self.photo,
            self.water,
            self.observations,
        );
        let estimate = |samples: u32| {
            estimates.fit(&FitOptions {
                samples,
                ..self.paper
            })
        };
        let place = |fit: &fitting::FitOutcome, progress: Reporter<'_>| {
            Ok(place_starts(
                self.scene,
                self.photo,
                self.water,
                self.observations,
                &fit.lights,
                progress,
            ))
        };
        // The exact model's expected image at a first estimate not kept, and the seconds it
        // took, where `first_test` ended the fit there.
        let tested: Mutex<Option<(Vec<ModelledPixel>, f64)>> = Mutex::new(None);
        let test_made = AtomicBool::new(false);
        let unkept = |fit: &fitting::FitOutcome| -> Result<bool> {
            let (Some(_), Some(test)) = (j, first_test) else {
                return Ok(false);
            };
            let t = Instant::now();
            test_made.store(true, Ordering::Relaxed);
            let modelled = self.first_estimate_image(&fit.lights)?;
            let stop = !(test.0)(&modelled);
            if stop {
                if let Ok(mut kept) = tested.lock() {
                    *kept = Some((modelled, t.elapsed().as_secs_f64()));
                }
            }
            Ok(stop)
        };
        let t = Instant::now();
        let StartEstimate {
            fit,
            placed,
            samples,
            ended,
        } = start_estimate(
            self.scene,
            self.photo,
            self.water,
            quick,
            self.paper.samples,
            &estimate,
            &place,
            Some(&unkept),
            self.progress,
        )?;
        let tested = tested.into_inner().ok().flatten().filter(|_| ended);
        if let Some((modelled, seconds)) = tested {
            found.skipped = fit.skipped;
            found.warnings.extend(fit.warnings);
            found.timings = fit.timings;
            found.timings.push((
                format!(
                    "the exact model tested at the first estimate ({FIRST_ESTIMATE_TEST_SAMPLES} \
                     samples)"
                ),
                seconds,
            ));
            found.modelled = modelled;
            found.stopped_at_start = true;
            found.stopped_at_first_estimate = true;
            found.start_samples = samples;
            return Ok(None);
        }
        found.lights = fit.lights;
        found.skipped = fit.skipped;
        found.warnings.extend(fit.warnings);
        // The stage's time besides the kept estimate's own (its grouping counted once, where
        // both estimates shared it): placing its lights, or the first estimate that was not
        // kept.
        let rest = t.elapsed().as_secs_f64() - fit.timings.iter().map(|(_, s)| s).sum::<f64>();
        found.timings = fit.timings;
        if let Some(q) = quick.filter(|_| rest > 0.0) {
            found.timings.push((
                if placed.is_some() {
                    "starts placed on the lamps' images".into()
                } else if test_made.load(Ordering::Relaxed) {
                    format!(
                        "a first estimate at {q} samples, not kept, and the exact model tested \
                         there"
                    )
                } else {
                    format!("a first estimate at {q} samples, not kept")
                },
                rest,
            ));
        }
        found.start_samples = samples;
        Ok(placed)
    }

    /// The exact model's expected image of half the streaks' pixels under `lights` (rendered at
    /// [`FIRST_ESTIMATE_TEST_SAMPLES`] samples a pixel under the fit's reflection model, in
    /// radiance units, from random streams of their own: never the photo's, which a render
    /// with the fit's seed may have made).
    fn first_estimate_image(&self, lights: &[FittedLight]) -> Result<Vec<ModelledPixel>> {
        let lights: Vec<AreaLight> = lights
            .iter()
            .enumerate()
            .map(|(i, l)| l.area_light(light_name(i)))
            .collect();
        // The streaks' pixels on a checkerboard (half the render, the same correlations on
        // the samples to 0.03), of `k` x `k` blocks on a finer photo, one pixel each: the
        // glints span as many blocks as the samples' pixels, and the high-pass window, grown
        // by `k` (`high_pass_radius`), holds as many.
        let w = self.photo.width;
        let k = scaled_pixels(1, self.photo.height, self.scene.camera.yfov) as u32;
        let mut pixels: Vec<u32> = self
            .observations
            .iter()
            .flat_map(|o| o.pixels.iter().copied())
            .filter(|&p| {
                let (x, y) = (p % w, p / w);
                x.is_multiple_of(k) && y.is_multiple_of(k) && (x / k + y / k).is_multiple_of(2)
            })
            .collect();
        pixels.sort_unstable();
        pixels.dedup();
        let values = render::render_pixels(
            self.scene,
            &lights,
            &self.paper.model,
            &RenderOptions {
                width: self.photo.width,
                height: self.photo.height,
                samples_per_pixel: FIRST_ESTIMATE_TEST_SAMPLES,
                exposure: 1.0,
                seed: !self.paper.seed,
                shadowing: self.paper.model.shadowing,
                progress: Reporter::default(),
                water: None,
                environment: None,
            },
            &pixels,
        )?;
        Ok(pixels.into_iter().zip(values).collect())
    }
}
