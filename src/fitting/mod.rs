//! Steps 7-9 of method §5 (the paper's §4.2-4.3): for each streak, the plane its light hangs
//! on, the light's radiance, and the rectangle's four edges.
//!
//! The forward model is exactly the renderer's ([`crate::render`]): a pixel is the mean over
//! jittered camera rays across its footprint of one lobe sample each, reflected from the water
//! with the same normals and offset. Each traced pixel's samples that land on the light's plane
//! are stored once ([`footprint::Footprint`]); every coefficient `c(p; rect)` afterwards is a
//! sum over them. Radiance and edges are then alternated until they agree:
//!
//! 1. plane: the face most of the brightest pixel's lobe rays hit first ([`light_plane`]);
//! 2. radiance: least squares over the brightest interior pixels with the current rectangle
//!    (the whole plane at first, as the paper does) ([`radiance`]);
//! 3. edges: each streak-edge pixel, assigned to the light edge its lobe's centre lies beyond,
//!    moves that edge until its modelled coefficient equals `I(p)/L`; the edge is the weighted
//!    mean of those solutions ([`edges`]).
//!
//! Fragments of one light are merged and refitted ([`fragments`]).

pub mod edges;
pub mod footprint;
pub mod fragments;
pub mod gloss;
pub mod joint;
pub mod light_plane;
mod linalg;
pub mod observation;
pub mod radiance;
pub mod rect;
mod single;
pub mod slopes;
pub mod threshold;

use std::time::Instant;

use glam::DVec3;

pub use light_plane::LightPlane;
pub use observation::{StreakObservation, StreakSide};
pub use rect::Rect;
pub use threshold::threshold_streaks;

use crate::optics::ReflectionModel;
use crate::photo_in::Photo;
use crate::scene_in::{AreaLight, Scene};
use crate::water_model::{ExactSurface, WaterModel};
use crate::{Error, Result};

/// How to fit.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FitOptions {
    /// Lobe samples per traced pixel (camera-ray jitter and lobe direction drawn together, as
    /// the renderer does). The edge solutions average over tens of pixels, so a few hundred
    /// suffice; more lowers the fit's own noise.
    pub samples: u32,
    /// Seed of every random number of the fit.
    pub seed: u64,
    /// The water's reflection model (gloss and IOR from the scene unless overridden).
    pub model: ReflectionModel,
}

impl FitOptions {
    /// Default options for a scene: its water's gloss and IOR, the paper's geometry term,
    /// [`DEFAULT_SAMPLES`] samples, seed 1.
    pub fn for_scene(scene: &Scene) -> Self {
        FitOptions {
            samples: DEFAULT_SAMPLES,
            seed: 1,
            model: ReflectionModel::new(scene.water.gloss, scene.water.ior),
        }
    }
}

/// Default lobe samples per traced pixel of the paper's estimate where it is the result (the
/// paper's method) or the statistical water model's start.
pub const DEFAULT_SAMPLES: u32 = 512;

/// Default lobe samples per traced pixel of the paper's estimate where it is the start of the
/// exact model's joint fit: the joint fit's descent moves every edge from there, and its
/// first search window spans half the light's size. On the samples the lights came out
/// within 0.1 % of those from 512 samples (at most 0.6 of a sigma apart), in a quarter of
/// the estimate's time (docs/decisions.md). The statistical model's start tries it first
/// ([`crate::pipeline::FitSettings::quick_start_samples`]).
pub const DEFAULT_START_SAMPLES: u32 = 128;

/// Lobe samples per traced pixel of the exact model's start where the joint fit reads the
/// direct view: the estimate is kept where every light it starts lies on a lamp's whole
/// direct image, which pins the light whatever the start's noise
/// ([`joint::start_estimate`]), and made again at [`DEFAULT_START_SAMPLES`] otherwise. On
/// the samples in frame the lights came out within 0.03 % of those from 128 samples, in a
/// quarter of the estimate's time (docs/decisions.md).
pub const QUICK_START_SAMPLES: u32 = 32;

/// The most pixels one parallel task traces. Rayon otherwise cuts a list into a few long
/// tasks per core; a pixel's cost varies many times over (those whose lobes reach a light
/// trace every sample, the rest few), so the core that drew the last long task worked on
/// alone: 0.02-0.06 s at the end of each of the joint fit's traces on Table 1. Tasks of this
/// many pixels cost nothing to hand out and end within microseconds of one another.
pub const PIXELS_PER_TASK: usize = 16;

/// An edge of the light's rectangle (of the light, not of the streak).
///
/// An array of four indexed by `EdgeSide` (`array[EdgeSide::Top]`) is one value per edge in
/// the order Left, Right, Bottom, Top: the order of [`EdgeSide::ALL`], of [`Rect`]'s fields and
/// of the reports. [`StreakSide`] (a side of the streak in the image) has the same order; the
/// two meet only in [`EdgeSide::streak_side`].
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EdgeSide {
    /// Smallest u.
    Left = 0,
    /// Largest u.
    Right = 1,
    /// Smallest v.
    Bottom = 2,
    /// Largest v.
    Top = 3,
}

impl EdgeSide {
    /// All four, in the order of arrays indexed by edge ([`FittedLight::edges`]).
    pub const ALL: [EdgeSide; 4] = [
        EdgeSide::Left,
        EdgeSide::Right,
        EdgeSide::Bottom,
        EdgeSide::Top,
    ];

    /// "left", "right", "bottom" or "top".
    pub fn name(self) -> &'static str {
        match self {
            EdgeSide::Left => "left",
            EdgeSide::Right => "right",
            EdgeSide::Bottom => "bottom",
            EdgeSide::Top => "top",
        }
    }

    /// True for the left and right edges (positions along `u`), false for bottom and top
    /// (along `v`).
    pub fn along_u(self) -> bool {
        matches!(self, EdgeSide::Left | EdgeSide::Right)
    }

    /// True for the left and bottom edges (the smaller coordinate), false for right and top.
    pub fn is_min(self) -> bool {
        matches!(self, EdgeSide::Left | EdgeSide::Bottom)
    }

    /// The side of the streak that shows this edge in the paper's fixed mapping: left to
    /// left, right to right, and, the reflection flipping the vertical order, the light's
    /// bottom edge on the streak's top side and its top edge on the streak's bottom side.
    /// Only the first rectangle uses it; the fit then assigns each edge pixel to an edge by
    /// where its lobe lands ([`edges::assign`]).
    pub fn streak_side(self) -> StreakSide {
        match self {
            EdgeSide::Left => StreakSide::Left,
            EdgeSide::Right => StreakSide::Right,
            EdgeSide::Bottom => StreakSide::Top,
            EdgeSide::Top => StreakSide::Bottom,
        }
    }
}

impl<T> std::ops::Index<EdgeSide> for [T; 4] {
    type Output = T;
    fn index(&self, side: EdgeSide) -> &T {
        &self[side as usize]
    }
}

impl<T> std::ops::IndexMut<EdgeSide> for [T; 4] {
    fn index_mut(&mut self, side: EdgeSide) -> &mut T {
        &mut self[side as usize]
    }
}

/// Whether the photo determines an edge.
#[derive(Clone, Debug, PartialEq)]
pub enum EdgeStatus {
    /// Fitted from this many streak-edge pixels.
    Constrained {
        /// Pixels whose solutions were combined.
        pixels: usize,
    },
    /// The photo does not show this edge (the streak runs out of the photo or off the water,
    /// or no edge pixel looks past it). The edge is placed as far out as any traced pixel's
    /// lobe reaches: the photo cannot tell it apart from any position beyond.
    Unconstrained {
        /// Why, for a person.
        reason: String,
        /// Streak-edge pixels the edge was estimated from anyway (they may not show the real
        /// edge, `reason` says why); 0 when none was.
        pixels: usize,
        /// No pixel of the streak's edge looks at this edge at all (rather than a few, or
        /// ones cut by the photo's border): it was placed at the lobes' farthest reach, and
        /// the joint refinement keeps it there instead of letting it trade against the
        /// others.
        unseen: bool,
    },
}

/// A fitted rectangle light.
#[derive(Clone, Debug, PartialEq)]
pub struct FittedLight {
    /// The streaks (fragments) it explains.
    pub streak_ids: Vec<usize>,
    /// The face it lies on and the (u, v) frame of the rectangle.
    pub plane: LightPlane,
    /// Left edge, along `plane.u` from `plane.point`.
    pub u_min: f32,
    /// Right edge.
    pub u_max: f32,
    /// Bottom edge, along `plane.v`.
    pub v_min: f32,
    /// Top edge.
    pub v_max: f32,
    /// Linear RGB radiance (the photo's units, after exposure), emitted along `plane.normal`.
    pub radiance: [f32; 3],
    /// Status of each edge, indexed by [`EdgeSide`] (left, right, bottom, top).
    pub edges: [EdgeStatus; 4],
}

impl FittedLight {
    /// The rectangle in plane coordinates.
    pub fn rect(&self) -> Rect {
        Rect {
            u_min: self.u_min,
            u_max: self.u_max,
            v_min: self.v_min,
            v_max: self.v_max,
        }
    }

    /// Width along `plane.u`.
    pub fn width(&self) -> f32 {
        self.u_max - self.u_min
    }

    /// Height along `plane.v`.
    pub fn height(&self) -> f32 {
        self.v_max - self.v_min
    }

    /// The point at plane coordinates (u, v), in world coordinates (`origin` is the scene
    /// frame's origin, [`Scene::origin`]).
    pub fn world_at(&self, origin: DVec3, u: f32, v: f32) -> DVec3 {
        origin
            + self.plane.point.as_dvec3()
            + self.plane.u.as_dvec3() * u as f64
            + self.plane.v.as_dvec3() * v as f64
    }

    /// The light as a renderable area light named `name` (scene frame).
    pub fn area_light(&self, name: String) -> AreaLight {
        let c = self.rect().center();
        let plane = &self.plane;
        AreaLight {
            name,
            node: plane.node,
            center: plane.point + plane.u * c.x + plane.v * c.y,
            half_width: plane.u * (self.width() * 0.5),
            half_height: plane.v * (self.height() * 0.5),
            normal: plane.normal,
            radiance: self.radiance,
        }
    }

    /// The rectangle's centre in world coordinates.
    pub fn center_world(&self, origin: DVec3) -> DVec3 {
        let c = self.rect().center();
        self.world_at(origin, c.x, c.y)
    }

    /// The corner at (u_min, v_min) in world coordinates: the left-bottom corner as seen from
    /// in front of the light (the paper's tables give this corner).
    pub fn corner_left_bottom_world(&self, origin: DVec3) -> DVec3 {
        self.world_at(origin, self.u_min, self.v_min)
    }
}

/// A streak that gave no light.
#[derive(Clone, Debug, PartialEq)]
pub enum Skipped {
    /// The reflected rays at the streak's brightest pixel hit no geometry.
    NoPlane {
        /// The streak's id.
        streak: usize,
        /// What to do about it.
        message: String,
    },
    /// A plane was found but no rectangle could be fitted (no usable pixel).
    NoSolution {
        /// The streak's id.
        streak: usize,
        /// Why.
        message: String,
    },
}

/// The fit of a photo.
#[derive(Clone, Debug)]
pub struct FitOutcome {
    /// One light per streak, fragments of one light merged; in the order of their first
    /// streak.
    pub lights: Vec<FittedLight>,
    /// Streaks that gave no light.
    pub skipped: Vec<Skipped>,
    /// Things the user should know.
    pub warnings: Vec<String>,
    /// Wall-clock seconds per stage: "plane", "footprints", "solve", "fragments".
    pub timings: Vec<(String, f64)>,
}

/// Refuses a photo and water mask of different sizes (the fitters index one by the other).
pub(crate) fn check_sizes(photo: &Photo, water: &[bool]) -> Result<()> {
    let n = photo.width as usize * photo.height as usize;
    if photo.radiance.len() != n || photo.clipped.len() != n || water.len() != n {
        return Err(Error::Usage(format!(
            "the photo ({} x {}) and its water mask ({} pixels) do not match",
            photo.width,
            photo.height,
            water.len()
        )));
    }
    Ok(())
}

/// Fits one rectangle light per streak (method §5 steps 7-9), merging fragments of one light.
///
/// `water` is the water mask of the photo ([`crate::water_mask::water_mask`]); `streaks` come
/// from the streak extraction. Fails only on inconsistent inputs (sizes that do not match);
/// a streak that cannot be fitted is reported in [`FitOutcome::skipped`]. The water is the
/// scene's water mesh ([`ExactSurface`]; [`fit_paper_with`] takes another model).
pub fn fit_paper(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    options: &FitOptions,
) -> Result<FitOutcome> {
    fit_paper_with(&ExactSurface, scene, photo, water, streaks, options)
}

/// [`fit_paper`] with the water as `water_model` has it: the plane search and the footprints
/// ask it where each camera ray meets the water and how its lobe leaves.
pub fn fit_paper_with(
    water_model: &dyn WaterModel,
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    options: &FitOptions,
) -> Result<FitOutcome> {
    PaperEstimates::new(water_model, scene, photo, water, streaks).fit(options)
}

/// The paper's estimates of one photo's streaks with several options (a first try at fewer
/// samples, then the full estimate: [`joint::start_estimate`]): the fragments' grouping
/// ([`fragments::group`]), which reads its own coarse options, is made once for every
/// estimate whose coarse options are the same, and a group's coarse fit is its fit where
/// those options are the estimate's own.
pub struct PaperEstimates<'a> {
    water_model: &'a dyn WaterModel,
    scene: &'a Scene,
    photo: &'a Photo,
    water: &'a [bool],
    streaks: &'a [StreakObservation],
    /// The last grouping made, with the coarse options it was made with and the seconds it
    /// took.
    grouped: std::cell::RefCell<Option<(FitOptions, fragments::Grouping, f64)>>,
}

impl<'a> PaperEstimates<'a> {
    /// The estimates of `streaks` on `photo` (whose water covers `water`) over `water_model`.
    pub fn new(
        water_model: &'a dyn WaterModel,
        scene: &'a Scene,
        photo: &'a Photo,
        water: &'a [bool],
        streaks: &'a [StreakObservation],
    ) -> Self {
        PaperEstimates {
            water_model,
            scene,
            photo,
            water,
            streaks,
            grouped: std::cell::RefCell::new(None),
        }
    }

    /// The paper's estimate with `options` ([`fit_paper`]).
    pub fn fit(&self, options: &FitOptions) -> Result<FitOutcome> {
        let (water_model, scene, photo, water, streaks) = (
            self.water_model,
            self.scene,
            self.photo,
            self.water,
            self.streaks,
        );
        check_sizes(photo, water)?;
        let n = water.len();
        if options.samples == 0 {
            return Err(Error::Usage(
                "the fit needs at least one sample per pixel".into(),
            ));
        }
        for s in streaks {
            let bad = s
                .pixels
                .iter()
                .chain(s.edges.iter().flatten())
                .chain(std::iter::once(&s.brightest))
                .find(|&&p| p as usize >= n);
            if let Some(p) = bad {
                return Err(Error::Usage(format!(
                    "streak {} holds pixel index {p}, outside the {} x {} photo",
                    s.id, photo.width, photo.height
                )));
            }
        }
        let mut times = single::StageTimes::default();
        let coarse = fragments::coarse_options(options);
        let kept = self
            .grouped
            .borrow()
            .as_ref()
            .filter(|(made_with, ..)| *made_with == coarse)
            .map(|(_, grouping, seconds)| (grouping.clone(), *seconds));
        // A grouping made for an earlier estimate counts the time it took then.
        let (grouping, fragments_seconds) = kept.unwrap_or_else(|| {
            let t = Instant::now();
            let grouping = fragments::group(water_model, scene, photo, water, streaks, options);
            let seconds = t.elapsed().as_secs_f64();
            *self.grouped.borrow_mut() = Some((coarse, grouping.clone(), seconds));
            (grouping, seconds)
        });
        let fragments::Grouping {
            groups,
            mut skipped,
            mut warnings,
            coarse: coarse_fits,
        } = grouping;
        // A group's coarse fit is the same fit where the coarse options are these.
        let coarse_fits = if coarse == *options {
            coarse_fits
        } else {
            Vec::new()
        };
        let mut lights = Vec::new();
        for (k, (obs, ids)) in groups.iter().enumerate() {
            let fit = match coarse_fits.get(k) {
                Some(light) => Ok(light.clone()),
                None => {
                    single::fit_streak(water_model, scene, photo, water, obs, options, &mut times)
                }
            };
            match fit {
                Ok(mut light) => {
                    light.streak_ids = ids.clone();
                    lights.push(light);
                }
                Err(s) => skipped.push(s),
            }
        }
        for light in &lights {
            if light.plane.hit_fraction < 0.5 {
                warnings.push(format!(
                    "streak {:?}: only {:.0} % of the brightest pixel's reflected rays hit the \
                     light's plane; the plane may be wrong",
                    light.streak_ids,
                    100.0 * light.plane.hit_fraction
                ));
            }
        }
        Ok(FitOutcome {
            lights,
            skipped,
            warnings,
            timings: vec![
                ("plane".into(), times.plane),
                ("footprints".into(), times.footprints),
                ("solve".into(), times.solve),
                ("fragments (coarse fit and merge)".into(), fragments_seconds),
            ],
        })
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The paper's estimate of Table 3's two streaks at 32 samples (the coarse fits' own) and
    /// then at 128, from one [`PaperEstimates`] that groups once and reads its coarse fits,
    /// gives the lights two separate estimates give, each grouping and fitting anew.
    #[test]
    fn estimates_that_share_a_grouping_are_the_estimates_made_apart() {
        let crate::samples::Fixture {
            scene,
            photo,
            water,
            observations,
        } = crate::samples::fixture("table3.png");
        assert_eq!(observations.len(), 2);
        let at = |samples| FitOptions {
            samples,
            ..FitOptions::for_scene(scene)
        };
        let shared = PaperEstimates::new(&ExactSurface, scene, photo, water, observations);
        for samples in [32, 128] {
            let kept = shared.fit(&at(samples)).unwrap();
            let apart = fit_paper(scene, photo, water, observations, &at(samples)).unwrap();
            assert_eq!(kept.lights.len(), 2);
            assert_eq!(kept.lights, apart.lights, "at {samples} samples");
            assert_eq!(kept.skipped, apart.skipped);
        }
        // At the coarse fits' own samples the estimate traced nothing past the grouping.
        let again = shared.fit(&at(32)).unwrap();
        let traced: f64 = again.timings[..3].iter().map(|(_, s)| s).sum();
        assert_eq!(traced, 0.0, "{:?}", again.timings);
    }
}
