//! The whole fit in memory (method §5): a loaded scene and a decoded photo in, the fitted
//! lights out, with every policy of the method applied in one call. The command line's `fit`
//! and a Rust caller get the same lights from the same [`fit`].
//!
//! The steps: the water mask (step 2), the streaks (steps 3-6), the paper's estimate (steps
//! 7-9), and for the joint method the refinement of all lights together (the last paragraph of
//! §5), with the gloss estimated first when asked ([`GlossFit::Estimate`]), lights that share
//! a streak fitted again ([`JointSettings::overlap_refit`]), and each edge's status taken from
//! its uncertainty. Files are [`crate::convert`]'s business.

mod photo_check;
mod settings;
mod start;
mod warnings;
mod water_choice;
mod water_fit;

use std::time::Instant;

pub use photo_check::{check_photo, ASPECT_TOLERANCE, MIN_PHOTO_SIDE};
pub use settings::{FitSettings, GlossFit, JointSettings, Method, Reading, THOROUGH};
pub use water_choice::{
    fine_structure, fine_structure_of, high_pass_radius, FineStructure, SlopesUsed, WaterChoice,
    WaterModelUsed, EXACT_MIN_CORRELATION, EXACT_MIN_EXPLAINED, FIRST_ESTIMATE_TEST_SAMPLES,
    FLAT_SHARE, HIGH_PASS_RADIUS, START_MAX_CORRELATION,
};

use crate::background::{self, Background};
use crate::fitting::gloss::estimate_gloss;
use crate::fitting::joint::{
    fit_joint_with, JointOptions, PixelShare, PlacedStart, Split, StartGate, Uncertainty,
};
use crate::fitting::{FitOptions, FittedLight, Skipped, StreakObservation};
use crate::optics::ReflectionModel;
use crate::photo_in::Photo;
use crate::progress::Reporter;
use crate::scene_in::Scene;
use crate::settings::Setting;
use crate::streaks::{self, Segmentation};
use crate::water_model::{ExactSurface, WaterModel, WaterStatistics};
use crate::{water_mask, Error, Result};

/// What a fit found.
#[derive(Clone, Debug)]
pub struct Lit {
    /// The fitted lights, in the scene frame of the loaded scene; empty when none was found
    /// ([`Lit::nothing_found`] says why).
    pub lights: Vec<FittedLight>,
    /// The joint fit's uncertainty of each light, in the order of `lights` (empty for the
    /// paper's method).
    pub uncertainties: Vec<Uncertainty>,
    /// Streaks that gave no light.
    pub skipped: Vec<Skipped>,
    /// Things the user should know: the scene's own warnings, the fit's, and one per set of
    /// lights that share a streak.
    pub warnings: Vec<String>,
    /// The water's gloss the lights were fitted with.
    pub gloss: f32,
    /// Where it came from ("material roughness 0.25", "estimated from the photo ...").
    pub gloss_source: String,
    /// What the final joint fit read (`None` for the paper's method).
    pub reading: Option<Reading>,
    /// Which of its region's pixels the final joint fit read, for the photo's size (`None`
    /// for the paper's method).
    pub pixel_share: Option<PixelShare>,
    /// The water model the lights were fitted with, and why.
    pub water_model: WaterModelUsed,
    /// The photo's water mask (method §5 step 2).
    pub water: Vec<bool>,
    /// The streak extraction, every stage of it.
    pub segmentation: Segmentation,
    /// Why no light was found, when `lights` is empty: which input it is about and what to
    /// tell the user.
    pub nothing_found: Option<(Input, String)>,
    /// Wall-clock seconds per stage, in the order run.
    pub timings: Vec<(String, f64)>,
    /// The smooth background measured on the photo and taken off it before the lights were
    /// fitted; `None` for a black night, a blank photo, a photo without streaks, or when
    /// [`FitSettings::background`] is off.
    pub background: Option<Background>,
    /// Lobe samples per traced pixel of the paper's estimate the fit started from (or that
    /// is the result, for the paper's method): [`FitSettings::paper_samples`], or fewer where
    /// [`FitSettings::quick_start_samples`]' first try was kept.
    pub start_samples: u32,
}

/// Which input a message is about.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Input {
    /// The scene.
    Scene,
    /// The photo.
    Photo,
}

/// The name of the `index`-th fitted light in the written scene and the report.
pub fn light_name(index: usize) -> String {
    format!("streaklight_light_{index}")
}

/// A streak as the fitters take it: its id and pixels, and the photo width they index.
pub fn observation(streak: &streaks::Streak, width: u32) -> StreakObservation {
    StreakObservation {
        id: streak.id,
        pixels: streak.pixels.clone(),
        brightest: streak.brightest.1 * width + streak.brightest.0,
        edges: streak.edges.clone(),
    }
}

/// Times each stage and tells the reporter as one starts.
struct Stopwatch<'a> {
    timings: Vec<(String, f64)>,
    progress: Reporter<'a>,
}

impl Stopwatch<'_> {
    fn time<T>(&mut self, stage: &str, f: impl FnOnce() -> T) -> T {
        self.progress.stage(stage);
        let start = Instant::now();
        let out = f();
        self.timings
            .push((stage.into(), start.elapsed().as_secs_f64()));
        out
    }

    /// The fit's own stage times, under "fit: ".
    fn add_fit(&mut self, timings: &[(String, f64)]) {
        self.timings
            .extend(timings.iter().map(|(s, t)| (format!("fit: {s}"), *t)));
    }
}

/// Fits lights to the streaks of `photo`, taken by `scene`'s camera (method §5), telling
/// `progress` as each stage starts.
///
/// Fails on settings out of range, a photo that cannot have been taken by the camera (size,
/// aspect), a camera that sees no water, and inconsistent inputs. Finding no light is not a
/// failure here: [`Lit::nothing_found`] says why (the converter refuses it unless asked not
/// to).
pub fn fit(
    scene: &Scene,
    photo: &Photo,
    settings: &FitSettings,
    progress: Reporter<'_>,
) -> Result<Lit> {
    settings.validate()?;
    check_photo(scene, photo, std::path::Path::new("the photo"))?;
    let mut clock = Stopwatch {
        timings: Vec::new(),
        progress,
    };
    let water = clock.time("water mask", || {
        water_mask::water_mask(scene, photo.width, photo.height)
    });
    if !water.iter().any(|&w| w) {
        return Err(Error::scene(
            &scene.path,
            format!(
                "the camera \"{}\" sees no water: check {} and {}",
                scene.camera.name,
                Setting::Camera,
                Setting::Water
            ),
        ));
    }
    let mut segmentation = clock.time("streaks", || {
        streaks::extract_streaks(photo, &water, &settings.streaks)
    })?;
    // A blank photo (one value over all the water: black, grey, all clipped) shows no
    // reflection, however the streak extraction reads it.
    let uniform = warnings::uniform_water(photo, &water);
    // A night that is not black: its smooth background is measured away from the streaks
    // and taken off the photo, and the streaks are found again on what the lights alone lit.
    let taken_off = match uniform {
        Some(_) => None,
        None if !settings.background => None,
        None => clock.time("background", || {
            background::take_off(photo, &water, &segmentation)
        }),
    };
    let (background, cleaned) = taken_off.unzip();
    let photo = match &cleaned {
        None => photo,
        Some(less) => {
            segmentation = clock.time("streaks without the background", || {
                streaks::extract_streaks(less, &water, &settings.streaks)
            })?;
            less
        }
    };
    let observations: Vec<StreakObservation> = segmentation
        .streaks
        .iter()
        .filter(|_| uniform.is_none())
        .map(|s| observation(s, photo.width))
        .collect();
    let run = Run {
        scene,
        photo,
        water: &water,
        observations: &observations,
        statistical_samples: settings.paper_samples(true),
        quick_statistical_samples: settings.quick_start_samples(true),
        quick_exact_samples: settings.quick_start_samples(false),
        water_stats: std::cell::OnceCell::new(),
        paper: FitOptions {
            samples: settings.paper_samples(false),
            seed: settings.seed,
            model: ReflectionModel {
                gloss: scene.water.gloss,
                ior: scene.water.ior,
                shadowing: settings.shadowing,
            },
        },
        progress,
    };
    let mut found = Found {
        lights: Vec::new(),
        uncertainties: Vec::new(),
        skipped: Vec::new(),
        warnings: scene.warnings.clone(),
        gloss: (scene.water.gloss, scene.water.gloss_source.clone()),
        reading: match &settings.method {
            Method::Paper => None,
            Method::Joint(j) => Some(j.reading),
        },
        timings: Vec::new(),
        modelled: Vec::new(),
        splits: Vec::new(),
        stopped_at_start: false,
        stopped_at_first_estimate: false,
        ended_at_split: false,
        share: None,
        start_samples: settings.paper_samples(false),
    };
    let water_model = if observations.is_empty() {
        match settings.water {
            WaterChoice::Statistical => WaterModelUsed::forced("statistical"),
            WaterChoice::Exact => WaterModelUsed::forced("exact"),
            WaterChoice::Auto => WaterModelUsed {
                chosen: "detected",
                reason: "no streak to fit: nothing to compare".into(),
                ..WaterModelUsed::forced("exact")
            },
        }
    } else {
        run.fit_lights(settings, &mut found)?
    };
    clock.add_fit(&found.timings);
    if let Some(b) = &background {
        let seen = found.seen();
        b.restore_walls(scene, &water, &mut found.lights, &seen);
    }
    let nothing_found = found
        .lights
        .is_empty()
        .then(|| warnings::nothing_found(uniform, &segmentation, &found.skipped));
    let thorough = found
        .reading
        .is_some_and(|r| r.all_pixels && r.samples >= THOROUGH.samples);
    found.warnings.extend(warnings::shared_streak_warnings(
        &found.lights,
        &found.seen(),
        thorough,
    ));
    Ok(Lit {
        lights: found.lights,
        uncertainties: found.uncertainties,
        skipped: found.skipped,
        warnings: found.warnings,
        gloss: found.gloss.0,
        gloss_source: found.gloss.1,
        reading: found.reading,
        pixel_share: found
            .share
            .or_else(|| found.reading.map(|r| r.share(photo.len() as u64))),
        water_model,
        water,
        segmentation,
        nothing_found,
        timings: clock.timings,
        background,
        start_samples: found.start_samples,
    })
}

/// What the fitters have found so far.
struct Found {
    lights: Vec<FittedLight>,
    uncertainties: Vec<Uncertainty>,
    skipped: Vec<Skipped>,
    warnings: Vec<String>,
    gloss: (f32, String),
    reading: Option<Reading>,
    timings: Vec<(String, f64)>,
    /// The last joint fit's expected image (its fitted pixels and their modelled radiance).
    modelled: Vec<(u32, [f32; 3])>,
    /// The start lights the last joint fit explained as two: an overlap refit from the same
    /// start tries each only that way.
    splits: Vec<Split>,
    /// Whether the last joint fit ended at its start (its start gate said so): no light,
    /// and `modelled` is the start lights' expected image.
    stopped_at_start: bool,
    /// Whether that start was the paper's first estimate, not kept, and its expected image
    /// had [`FIRST_ESTIMATE_TEST_SAMPLES`] samples a pixel over the streaks (`Run::paper`).
    stopped_at_first_estimate: bool,
    /// Whether the last joint fit ended at its first split
    /// ([`JointOptions::end_at_split`]): no light yet, the overlap refit follows.
    ended_at_split: bool,
    /// Which pixels the last joint fit read (`None`: as its reading gives them).
    share: Option<PixelShare>,
    /// Lobe samples per traced pixel of the paper's estimate the fit started from.
    start_samples: u32,
}

impl Found {
    /// For each light, whether the photo shows the light itself (its uncertainty counts
    /// direct pixels); false where no uncertainty was computed.
    fn seen(&self) -> Vec<bool> {
        (0..self.lights.len())
            .map(|k| {
                self.uncertainties
                    .get(k)
                    .is_some_and(|u| u.direct_pixels > 0)
            })
            .collect()
    }
}

/// The inputs every fitting stage of one run shares.
struct Run<'a> {
    scene: &'a Scene,
    photo: &'a Photo,
    water: &'a [bool],
    observations: &'a [StreakObservation],
    /// The paper's estimate's options under the exact model; their model and seed are every
    /// fit's.
    paper: FitOptions,
    /// The paper's estimate's samples per traced pixel under the statistical model
    /// ([`FitSettings::paper_samples`]).
    statistical_samples: u32,
    /// The samples of the statistical start's first try
    /// ([`FitSettings::quick_start_samples`]).
    quick_statistical_samples: Option<u32>,
    /// The samples of the exact model's start's first try, where a joint fit reading the
    /// direct view follows ([`FitSettings::quick_start_samples`]).
    quick_exact_samples: Option<u32>,
    /// What the camera sees of the scene's water, once asked for.
    water_stats: std::cell::OnceCell<Option<WaterStatistics>>,
    progress: Reporter<'a>,
}

impl Run<'_> {
    /// The joint fit's options for `reading`.
    fn joint_options(&self, j: &JointSettings, reading: Reading) -> JointOptions<'_> {
        JointOptions {
            progress: self.progress,
            repeats: j.repeats,
            samples: reading.samples,
            pixels: reading.share(self.photo.len() as u64),
            direct_view: j.direct_view,
            thin_seen_whole: true,
            ..JointOptions::new(self.paper.model, self.paper.seed)
        }
    }

    /// One joint fit from `start` with `options`, its timings added under `label`; each
    /// light's edge statuses from its uncertainty.
    fn joint(
        &self,
        water_model: &dyn WaterModel,
        start: &[FittedLight],
        options: &JointOptions,
        label: &str,
        found: &mut Found,
    ) -> Result<()> {
        let outcome = fit_joint_with(
            water_model,
            self.scene,
            self.photo,
            self.water,
            self.observations,
            start,
            options,
        )?;
        found.timings.extend(
            outcome
                .timings
                .iter()
                .map(|(stage, s)| (format!("{label} {stage}"), *s)),
        );
        found.lights = outcome.lights_with_statuses();
        found.uncertainties = outcome.uncertainty;
        found.modelled = outcome.modelled;
        found.splits = outcome.splits;
        found.share = Some(outcome.share);
        found.stopped_at_start = outcome.stopped_at_start;
        found.ended_at_split = outcome.ended_at_split;
        found.warnings.extend(outcome.warnings);
        Ok(())
    }

    /// The joint fit from the paper's lights in `found` (or from `placed`, those lights placed
    /// on their lamps' images already), then the refit of lights that share a streak; `gate`
    /// may end the fit at its start ([`JointOptions::start_gate`]).
    fn refine(
        &self,
        j: &JointSettings,
        found: &mut Found,
        gate: Option<StartGate<'_>>,
        placed: Option<PlacedStart>,
    ) -> Result<()> {
        let paper_lights = std::mem::take(&mut found.lights);
        let starts_placed = placed.is_some();
        let (start, images) = match placed {
            Some(p) => (p.lights, p.images),
            None => (paper_lights, Vec::new()),
        };
        self.progress
            .stage(&format!("joint fit of {} light(s)", start.len()));
        let options = JointOptions {
            starts_placed,
            start_images: &images,
            ..self.joint_options(j, j.reading)
        };
        // Where lights that share a streak are fitted again, the first fit's work past its
        // split would be thrown away: it ends there.
        let first = JointOptions {
            start_gate: gate,
            end_at_split: j.overlap_refit.is_some(),
            ..options
        };
        self.joint(&ExactSurface, &start, &first, "joint", found)?;
        if found.stopped_at_start {
            return Ok(());
        }
        self.refit_overlaps(&ExactSurface, &start, &options, j, found)
    }

    /// Fits the lights again from `start` with [`JointSettings::overlap_refit`] when the fit
    /// in `found` ended with lights that share a streak.
    fn refit_overlaps(
        &self,
        water_model: &dyn WaterModel,
        start: &[FittedLight],
        options: &JointOptions,
        j: &JointSettings,
        found: &mut Found,
    ) -> Result<()> {
        let Some(reading) = j.overlap_refit else {
            return Ok(());
        };
        if !found.ended_at_split && !warnings::shares_a_streak(&found.lights, &found.seen()) {
            return Ok(());
        }
        self.progress.stage(&format!(
            "lights share a streak: joint fit again with {} samples (pixels read: {})",
            reading.samples,
            reading.share(self.photo.len() as u64).name()
        ));
        let known = std::mem::take(&mut found.splits);
        let refit = JointOptions {
            samples: reading.samples,
            pixels: reading.share(self.photo.len() as u64),
            known_splits: &known,
            end_at_split: false,
            ..*options
        };
        found.reading = Some(reading);
        self.joint(water_model, start, &refit, "joint refit of overlaps", found)
    }

    /// The joint fit with the gloss estimated first ([`GlossFit::Estimate`]); `gate` may end
    /// the search at its first fit ([`JointOptions::start_gate`]).
    fn with_gloss_search(
        &self,
        j: &JointSettings,
        found: &mut Found,
        gate: Option<StartGate<'_>>,
    ) -> Result<()> {
        let GlossFit::Estimate(search) = &j.gloss else {
            return Ok(());
        };
        self.progress.stage(&format!(
            "gloss search and fit of {} streak(s) (each step a joint fit)",
            self.observations.len()
        ));
        let final_fit = self.joint_options(j, j.reading);
        let estimate = estimate_gloss(
            self.scene,
            self.photo,
            self.water,
            self.observations,
            &self.paper,
            self.quick_exact_samples,
            &JointOptions {
                start_gate: gate,
                ..final_fit
            },
            search,
        )?;
        found.start_samples = estimate.start_samples;
        if estimate.stopped_at_start {
            found.skipped = estimate.skipped;
            found.warnings.extend(estimate.warnings);
            found.timings = estimate.timings;
            found.modelled = estimate.modelled;
            found.stopped_at_start = true;
            return Ok(());
        }
        found.gloss = (
            estimate.gloss,
            format!(
                "estimated from the photo ({}, {} fits from e = {})",
                Setting::GlossEstimate,
                estimate.evaluations.len(),
                self.scene.water.gloss
            ),
        );
        found.lights = estimate.lights;
        found.uncertainties = estimate.uncertainty;
        found.skipped = estimate.skipped;
        found.warnings.extend(estimate.warnings);
        found.timings = estimate.timings;
        found.modelled = estimate.modelled;
        found.share = Some(estimate.share);
        found.splits = estimate.splits;
        let at_estimate = JointOptions {
            model: ReflectionModel {
                gloss: estimate.gloss,
                ..final_fit.model
            },
            ..final_fit
        };
        self.refit_overlaps(&ExactSurface, &estimate.start, &at_estimate, j, found)
    }
}
