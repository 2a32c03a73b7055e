//! Test fixture of the joint fit's unit tests: Table 3's photo and scene, light0 as the paper
//! fits it, and every 8th pixel of its fitted region, for the tests that trace samples
//! (in `samples`, `ramps` and `control_variate`); a start light on a plane (in
//! `direct_start` and `lamp_starts`).

use super::region::{region, region_of_interest};
use super::samples::PlaneSamples;
use super::trace::trace_samples;
use crate::fitting::rect::Rect;
use crate::fitting::{FittedLight, StreakObservation};
use crate::optics::ReflectionModel;
use crate::water_model::ExactSurface;

/// Table 3's photo and scene, light0 as the paper fits it, and every 8th pixel of its
/// fitted region: what the tests that trace samples read.
pub(super) struct Table3Light0 {
    pub(super) scene: &'static crate::scene_in::Scene,
    pub(super) model: ReflectionModel,
    pub(super) light: FittedLight,
    pub(super) roi: Rect,
    pub(super) pixels: Vec<u32>,
    pub(super) width: u32,
    pub(super) height: u32,
}

/// The fixture, made once per test process and shared by the tests that read it.
pub(super) fn table3_light0() -> &'static Table3Light0 {
    static MADE: std::sync::OnceLock<Table3Light0> = std::sync::OnceLock::new();
    MADE.get_or_init(make_table3_light0)
}

fn make_table3_light0() -> Table3Light0 {
    let crate::samples::Fixture {
        scene,
        photo,
        water,
        observations,
    } = crate::samples::fixture("table3.png");
    let model = ReflectionModel::new(scene.water.gloss, scene.water.ior);
    let options = crate::fitting::FitOptions {
        samples: 256,
        seed: 1,
        model,
    };
    let paper =
        crate::fitting::fit_paper(scene, photo, water, observations, &options).expect("paper fit");
    let light = paper.lights[0].clone();
    let roi = region_of_interest(&light, None);
    let used: Vec<&StreakObservation> = observations.iter().collect();
    let pixels: Vec<u32> = region(
        &ExactSurface,
        scene,
        &model,
        &[&light.plane],
        &[roi],
        photo,
        water,
        &used,
        6,
        super::PixelShare::Checkerboard,
    )
    .into_iter()
    .step_by(8)
    .collect();
    Table3Light0 {
        scene,
        model,
        light,
        roi,
        pixels,
        width: photo.width,
        height: photo.height,
    }
}

impl Table3Light0 {
    pub(super) fn trace(
        &self,
        samples: u32,
        seed: u64,
        draw: u32,
        cv: bool,
    ) -> (Vec<PlaneSamples>, u32) {
        trace_samples(
            &ExactSurface,
            self.scene,
            &self.model,
            &[&self.light.plane],
            &[self.roi],
            &self.pixels,
            self.width,
            self.height,
            samples,
            seed,
            0,
            draw,
            cv,
            self.pixels.len(),
            crate::progress::Reporter::default(),
        )
    }
}

impl Table3Light0 {
    /// A problem over the traced pixels (`planes`, `inv_samples` as [`Self::trace`] gives
    /// them) whose photo is what light0 over `truth` gives, at radiance 1, 0.6 and 0.3 per
    /// channel: a photo the model reproduces up to its samples' noise. No pixel is clipped.
    pub(super) fn problem(
        &self,
        planes: Vec<PlaneSamples>,
        inv_samples: f32,
        truth: &Rect,
    ) -> super::problem::Problem {
        let n = self.pixels.len();
        let obs = (0..n)
            .map(|i| {
                let c = planes[0].coefficient(i, truth, inv_samples).0;
                [c, 0.6 * c, 0.3 * c]
            })
            .collect();
        super::problem::Problem {
            width: self.width,
            pixel_ids: self.pixels.clone(),
            obs,
            clipped: vec![false; n],
            clipped_channels: vec![[false; 3]; n],
            planes,
            set_origin: vec![0],
            inv_samples,
            first_direct: n,
            encoding: (crate::photo_rounding::Rounding::Float, 1.0),
            edges_by_image: false,
        }
    }
}

/// A light on `plane` over `rect` explaining streak `streak`, radiance 1, every edge
/// constrained: a start as the joint fit receives one.
pub(super) fn start_light(
    plane: &crate::fitting::light_plane::LightPlane,
    rect: Rect,
    streak: usize,
) -> FittedLight {
    let free = || crate::fitting::EdgeStatus::Constrained { pixels: 1 };
    FittedLight {
        streak_ids: vec![streak],
        plane: plane.clone(),
        u_min: rect.u_min,
        u_max: rect.u_max,
        v_min: rect.v_min,
        v_max: rect.v_max,
        radiance: [1.0; 3],
        edges: [free(), free(), free(), free()],
    }
}

/// The rectangle from its four edges.
pub(super) fn rect(u_min: f32, u_max: f32, v_min: f32, v_max: f32) -> Rect {
    Rect {
        u_min,
        u_max,
        v_min,
        v_max,
    }
}
