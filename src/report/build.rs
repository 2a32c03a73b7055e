//! How the report is built from a fit ([`crate::pipeline::Lit`]) and the run's settings.

use super::{
    light_warnings, BackgroundReport, EdgeReport, EdgesReport, Files, LightReport, PlaneReport,
    Report, Settings, SkippedStreak, Timing, UncertaintyReport, REPORT_VERSION,
};
use crate::fitting::joint::{effective_samples, PixelShare, Uncertainty};
use crate::fitting::{EdgeSide, EdgeStatus, FittedLight, Skipped};
use crate::optics::Shadowing;
use crate::pipeline::{light_name, FitSettings, Lit, Method};
use crate::scene_in::Scene;

/// What the report says about the run beyond the fit: its files and the photo's settings.
pub struct Run<'a> {
    /// The files read and written.
    pub files: Files,
    /// The fit's settings.
    pub settings: &'a FitSettings,
    /// Divisor applied to the photo's linear values.
    pub exposure: f32,
    /// Where the exposure came from: "given", or the photo's EXIF settings.
    pub exposure_source: String,
    /// Intensity units per unit of radiance in the written lights.
    pub nits_scale: f64,
    /// Wall-clock seconds of the stages outside the fit, before it and after it.
    pub timings_before: Vec<(String, f64)>,
    /// Wall-clock seconds of the stages outside the fit that ran after it.
    pub timings_after: Vec<(String, f64)>,
}

/// The report of `lit`, fitted in `scene` with `run`'s settings; every light named by
/// [`light_name`] of its index. Texts are as the library words them (the caller may reword
/// them, [`crate::settings::reword`]).
pub fn build(scene: &Scene, lit: &Lit, run: Run<'_>) -> Report {
    let settings = run.settings;
    let joint = match &settings.method {
        Method::Joint(j) => Some(j),
        Method::Paper => None,
    };
    let timing = |(stage, seconds): &(String, f64)| Timing {
        stage: stage.clone(),
        seconds: *seconds,
    };
    let mut report = Report {
        report_version: REPORT_VERSION,
        tool_version: env!("CARGO_PKG_VERSION").into(),
        status: if lit.lights.is_empty() {
            super::NO_LIGHT_FOUND
        } else {
            super::LIGHTS_FOUND
        }
        .into(),
        files: run.files,
        settings: Settings {
            gloss: lit.gloss,
            gloss_source: lit.gloss_source.clone(),
            ior: scene.water.ior,
            shadowing: match settings.shadowing {
                Shadowing::None => "none".into(),
                Shadowing::Smith => "smith".into(),
            },
            samples: lit.start_samples,
            seed: settings.seed,
            repeats: joint.map_or(1, |j| j.repeats),
            joint_samples: lit.reading.map(|r| effective_samples(r.samples)),
            joint_pixels: lit.pixel_share.map(PixelShare::name),
            exposure: run.exposure,
            exposure_source: run.exposure_source,
            nits_scale: run.nits_scale,
            light_offset: None,
            method: settings.method.name().into(),
            background: settings.background,
            camera: scene.camera.name.clone(),
            water: scene.water.name.clone(),
        },
        water_model: lit.water_model.clone(),
        background: lit.background.as_ref().map(|b| BackgroundReport {
            water_mean: b.water_mean,
            streak_share: b.streak_share,
            cells_measured: b.cells_measured,
            cells: b.cells,
        }),
        lights: lit
            .lights
            .iter()
            .enumerate()
            .map(|(i, l)| light_report(scene, l, lit.uncertainties.get(i), light_name(i)))
            .collect(),
        skipped_streaks: lit.skipped.iter().map(skipped_report).collect(),
        timings: run
            .timings_before
            .iter()
            .chain(&lit.timings)
            .chain(&run.timings_after)
            .map(timing)
            .collect(),
        warnings: lit.warnings.clone(),
    };
    let light_warnings: Vec<String> = report.lights.iter().filter_map(light_warnings).collect();
    report.warnings.extend(light_warnings);
    report
}

fn edge_report(status: &EdgeStatus) -> EdgeReport {
    match status {
        EdgeStatus::Constrained { pixels } => EdgeReport {
            status: "constrained".into(),
            pixels: *pixels,
            reason: None,
        },
        EdgeStatus::Unconstrained { reason, pixels, .. } => EdgeReport {
            status: "unconstrained".into(),
            pixels: *pixels,
            reason: Some(reason.clone()),
        },
    }
}

/// The uncertainties of `light`'s parameters. An edge the photo does not constrain has none,
/// whatever the cost's curvature says there: its sigma would measure the noise about a
/// position the photo does not show, not the error of the edge.
fn uncertainty_report(light: &FittedLight, u: &Uncertainty) -> Option<UncertaintyReport> {
    // A light whose radiance cannot be told apart from another's has no finite uncertainty:
    // report none rather than a number a pipeline might trust.
    if !u.radiance.iter().all(|r| r.is_finite()) {
        return None;
    }
    let e = |side: EdgeSide| {
        u.edges[side]
            .filter(|s| s.is_finite())
            .filter(|_| matches!(light.edges[side], EdgeStatus::Constrained { .. }))
            .map(f64::from)
    };
    Some(UncertaintyReport {
        left: e(EdgeSide::Left),
        right: e(EdgeSide::Right),
        bottom: e(EdgeSide::Bottom),
        top: e(EdgeSide::Top),
        radiance: u.radiance.map(f64::from),
    })
}

pub fn light_report(
    scene: &Scene,
    light: &FittedLight,
    uncertainty: Option<&Uncertainty>,
    name: String,
) -> LightReport {
    let origin = scene.origin;
    let v3 = |v: glam::Vec3| v.as_dvec3().to_array();
    let radiance = light.radiance.map(f64::from);
    LightReport {
        name,
        streak_ids: light.streak_ids.clone(),
        plane: PlaneReport {
            node: light.plane.node,
            node_name: scene.node_names.get(light.plane.node).cloned().flatten(),
            point: (origin + light.plane.point.as_dvec3()).to_array(),
            normal: v3(light.plane.normal),
            hit_fraction: light.plane.hit_fraction as f64,
        },
        center: light.center_world(origin).to_array(),
        corner_left_bottom: light.corner_left_bottom_world(origin).to_array(),
        u_axis: v3(light.plane.u),
        v_axis: v3(light.plane.v),
        width: light.width() as f64,
        height: light.height() as f64,
        radiance,
        edges: EdgesReport {
            left: edge_report(&light.edges[EdgeSide::Left]),
            right: edge_report(&light.edges[EdgeSide::Right]),
            bottom: edge_report(&light.edges[EdgeSide::Bottom]),
            top: edge_report(&light.edges[EdgeSide::Top]),
        },
        uncertainty: uncertainty.and_then(|u| uncertainty_report(light, u)),
        direct_pixels: uncertainty.map(|u| u.direct_pixels),
        radiance_seen: uncertainty.map(|u| u.radiance_seen),
        light_index: None,
        node_index: None,
        node_translation: None,
    }
}

fn skipped_report(s: &Skipped) -> SkippedStreak {
    match s {
        Skipped::NoPlane { streak, message } | Skipped::NoSolution { streak, message } => {
            SkippedStreak {
                streak: *streak,
                reason: message.clone(),
            }
        }
    }
}
