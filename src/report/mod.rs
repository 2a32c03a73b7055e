//! The machine-readable report of a fit (`--report`), described by `schema/report.schema.json`.

mod build;
mod light_warnings;
mod refusal;

pub use build::{build, light_report, Run};
pub use light_warnings::{light_warnings, LARGE_UNCERTAINTY};
pub use refusal::Refusal;
use serde::Serialize;

/// Version of the report's shape; bumped when a field changes meaning.
pub const REPORT_VERSION: u32 = 2;

/// [`Report::status`] of a run that wrote lights.
pub const LIGHTS_FOUND: &str = "lights found";
/// [`Report::status`] of a run that found no light and wrote the scene unchanged (allowed
/// empty).
pub const NO_LIGHT_FOUND: &str = "no light found";

/// Everything a pipeline needs to know about one run of `fit`.
#[derive(Clone, Debug, Serialize)]
pub struct Report {
    /// Version of this shape.
    pub report_version: u32,
    /// streaklight's version.
    pub tool_version: String,
    /// [`LIGHTS_FOUND`] or [`NO_LIGHT_FOUND`] (a refused run's report is a [`Refusal`]).
    pub status: String,
    /// The input scene, photo, and the output scene.
    pub files: Files,
    /// The model and sampling settings used.
    pub settings: Settings,
    /// The water model the lights were fitted with, why, and its slope estimate.
    pub water_model: crate::pipeline::WaterModelUsed,
    /// The night's smooth background taken off the photo before the fit; `None` (null) for
    /// a black night.
    pub background: Option<BackgroundReport>,
    /// One entry per light written.
    pub lights: Vec<LightReport>,
    /// Streaks that gave no light, and why.
    pub skipped_streaks: Vec<SkippedStreak>,
    /// Seconds per stage, in pipeline order.
    pub timings: Vec<Timing>,
    /// Things the user should know.
    pub warnings: Vec<String>,
}

/// The smooth background (dim sky, lit facades, their reflections) measured on the photo.
#[derive(Clone, Debug, Serialize)]
pub struct BackgroundReport {
    /// Mean radiance over the water's pixels, per channel.
    pub water_mean: [f32; 3],
    /// Its share of the light of the streaks' pixels (luminance, 0 to 1).
    pub streak_share: f32,
    /// Cells of the photo where it was measured, away from every light.
    pub cells_measured: usize,
    /// All cells (the water and the rest counted apart).
    pub cells: usize,
}

/// Paths of the files involved.
#[derive(Clone, Debug, Serialize)]
pub struct Files {
    /// Input scene.
    pub scene: String,
    /// Input photo.
    pub photo: String,
    /// Output scene (absent when nothing was written).
    pub output: Option<String>,
}

/// The model and sampling settings.
#[derive(Clone, Debug, Serialize)]
pub struct Settings {
    /// Blinn-Phong gloss e.
    pub gloss: f32,
    /// Where the gloss came from ("`LoadOptions::gloss`", "material roughness 0.25", ...).
    pub gloss_source: String,
    /// Index of refraction of the water.
    pub ior: f32,
    /// Shadowing term: "none" (G = 1, capped at grazing) or "smith".
    pub shadowing: String,
    /// Lobe samples per traced pixel of the paper's estimate the fit started from, under the
    /// water model used ([`crate::pipeline::FitSettings::paper_samples`],
    /// [`crate::pipeline::FitSettings::quick_start_samples`]).
    pub samples: u32,
    /// Seed of every random number.
    pub seed: u64,
    /// Independent joint fits averaged (1 for the paper method).
    pub repeats: u32,
    /// Lobe samples per pixel of the (final) joint fit, as taken (`None` for the paper
    /// method).
    pub joint_samples: Option<u32>,
    /// Which pixels of its region the (final) joint fit read: "checkerboard" (every second
    /// one, the default up to a megapixel), "one water pixel of each B x B block" (and those
    /// that see a light on every B-th diagonal: the default on a larger photo,
    /// [`crate::fitting::joint::PixelShare::water_blocks`]), "all"
    /// ([`crate::pipeline::Reading::all_pixels`]) or "quarter"
    /// ([`crate::fitting::joint::PixelShare`]); `None` for the paper method.
    pub joint_pixels: Option<String>,
    /// Divisor applied to the photo's linear values: linear value per unit of radiance.
    pub exposure: f32,
    /// Where the exposure came from: "given" (the caller's value), or "EXIF: 1/30 s, f/2.8,
    /// ISO 800, ..." when computed from the photo's camera settings
    /// ([`crate::photo_exif`]; the radiance is then in W/(sr m^2)).
    pub exposure_source: String,
    /// Intensity units per unit of radiance in the written lights.
    pub nits_scale: f64,
    /// How far (metres) each light's node was written in front of its fitted rectangle,
    /// along its normal, off its wall (`None` when no scene was written).
    pub light_offset: Option<f64>,
    /// Fitting method.
    pub method: String,
    /// Whether a night's smooth background was to be taken off (`--no-background` says no).
    pub background: bool,
    /// Camera node used.
    pub camera: String,
    /// Water node used.
    pub water: String,
}

/// One fitted light.
#[derive(Clone, Debug, Serialize)]
pub struct LightReport {
    /// Name written into the scene.
    pub name: String,
    /// Streaks (ids in streaks.json) that this light explains.
    pub streak_ids: Vec<usize>,
    /// The plane the light sits on.
    pub plane: PlaneReport,
    /// Centre, world coordinates.
    pub center: [f64; 3],
    /// Left-bottom corner, world coordinates.
    pub corner_left_bottom: [f64; 3],
    /// Unit axis along the width (horizontal).
    pub u_axis: [f64; 3],
    /// Unit axis along the height (up on a wall).
    pub v_axis: [f64; 3],
    /// Width along u, metres.
    pub width: f64,
    /// Height along v, metres.
    pub height: f64,
    /// Linear RGB radiance.
    pub radiance: [f64; 3],
    /// Status of each edge of the light.
    pub edges: EdgesReport,
    /// One-sigma uncertainties of the joint fit (`None` with `--method paper`).
    pub uncertainty: Option<UncertaintyReport>,
    /// Pixels of the photo outside the water that see this light itself, among those the
    /// joint fit read (every second one unless it read all): a count of pixels; 0 when the
    /// light is out of frame or hidden, or the direct view was off; `None` with
    /// `--method paper`.
    pub direct_pixels: Option<usize>,
    /// Whether the photo shows the light whole in a channel it did not clip, so that its
    /// radiance is read off its image (the other channels from its colour); `false` when only
    /// its reflections give it (out of frame, hidden, or clipped in every channel), whose
    /// radiance sigma under the statistical water model is then at least 10 % of it; `None`
    /// with `--method paper`.
    pub radiance_seen: Option<bool>,
    /// Index of the light in the output's `EXT_lights_area.lights`.
    pub light_index: Option<usize>,
    /// Index of the light's node in the output.
    pub node_index: Option<usize>,
    /// The translation of the light's node in the output: `center` moved
    /// `settings.light_offset` along the plane's normal.
    pub node_translation: Option<[f64; 3]>,
}

/// One-sigma uncertainties of a light's parameters, from the joint fit's full covariance of
/// all lights' free edges and radiances (correlated errors included).
#[derive(Clone, Debug, Serialize)]
pub struct UncertaintyReport {
    /// Left edge, metres (`None`: the photo does not constrain it; always so for an edge
    /// whose status is "unconstrained").
    pub left: Option<f64>,
    /// Right edge, metres.
    pub right: Option<f64>,
    /// Bottom edge, metres.
    pub bottom: Option<f64>,
    /// Top edge, metres.
    pub top: Option<f64>,
    /// Radiance per channel.
    pub radiance: [f64; 3],
}

/// The plane a light sits on.
#[derive(Clone, Debug, Serialize)]
pub struct PlaneReport {
    /// Index of the node whose mesh holds the plane.
    pub node: usize,
    /// That node's name, if it has one.
    pub node_name: Option<String>,
    /// A point of the plane, world coordinates.
    pub point: [f64; 3],
    /// Unit normal, pointing towards the water.
    pub normal: [f64; 3],
    /// Fraction of the brightest pixel's lobe rays that hit this plane.
    pub hit_fraction: f64,
}

/// Per-edge status.
#[derive(Clone, Debug, Serialize)]
pub struct EdgesReport {
    /// Left edge (min u).
    pub left: EdgeReport,
    /// Right edge (max u).
    pub right: EdgeReport,
    /// Bottom edge (min v).
    pub bottom: EdgeReport,
    /// Top edge (max v).
    pub top: EdgeReport,
}

/// One edge's status.
#[derive(Clone, Debug, Serialize)]
pub struct EdgeReport {
    /// "constrained" (measured from streak-edge pixels, or seen directly) or "unconstrained"
    /// (the streak's side touches the photo's border or the water's end, so the value is a
    /// guess; or the edge faces another light split from the same streak; `reason` says
    /// which), where the photo does not show the edge directly either.
    pub status: String,
    /// Pixels it was estimated from: the streak-edge pixels that constrained it (for an
    /// unconstrained edge those read anyway, which may not show the real edge; 0 if none),
    /// plus the pixels that see the edge itself (the joint fit's direct view).
    pub pixels: usize,
    /// Why it is unconstrained, if it is.
    pub reason: Option<String>,
}

/// A streak that gave no light.
#[derive(Clone, Debug, Serialize)]
pub struct SkippedStreak {
    /// Streak id.
    pub streak: usize,
    /// Why.
    pub reason: String,
}

/// Time spent in one stage.
#[derive(Clone, Debug, Serialize)]
pub struct Timing {
    /// Stage name.
    pub stage: String,
    /// Wall-clock seconds.
    pub seconds: f64,
}
