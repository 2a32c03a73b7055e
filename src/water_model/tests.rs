//! A second water model plugs into the fitters unchanged: one that delegates to the exact
//! surface (and counts that it was asked) gives the paper fit and the joint fit exactly the
//! exact model's results.

use std::sync::atomic::{AtomicUsize, Ordering};

use glam::{Vec2, Vec3};

use super::{ExactSurface, WaterModel};
use crate::fitting::joint::{fit_joint, fit_joint_with, JointOptions};
use crate::fitting::{fit_paper, fit_paper_with, FitOptions};
use crate::optics::{LobeSample, ReflectionModel};
use crate::render::WaterPoint;
use crate::scene_in::Scene;

/// The exact model behind another type, counting the questions it is asked.
#[derive(Debug, Default)]
struct Delegating {
    water_points: AtomicUsize,
    reflections: AtomicUsize,
    directions: AtomicUsize,
}

impl WaterModel for Delegating {
    fn water_point(
        &self,
        scene: &Scene,
        x: f32,
        y: f32,
        width: u32,
        height: u32,
    ) -> Option<WaterPoint> {
        self.water_points.fetch_add(1, Ordering::Relaxed);
        ExactSurface.water_point(scene, x, y, width, height)
    }

    fn reflect(&self, point: &WaterPoint, model: &ReflectionModel, u: Vec2) -> Option<LobeSample> {
        self.reflections.fetch_add(1, Ordering::Relaxed);
        ExactSurface.reflect(point, model, u)
    }

    fn reflect_direction(
        &self,
        point: &WaterPoint,
        model: &ReflectionModel,
        u: Vec2,
    ) -> Option<Vec3> {
        self.directions.fetch_add(1, Ordering::Relaxed);
        ExactSurface.reflect_direction(point, model, u)
    }
}

#[test]
fn a_delegating_model_gives_the_exact_models_fits() {
    let crate::samples::Fixture {
        scene,
        photo,
        water,
        observations,
    } = crate::samples::fixture("table1.png");
    let model = ReflectionModel::new(scene.water.gloss, scene.water.ior);
    let options = FitOptions {
        samples: 64,
        seed: 1,
        model,
    };

    let delegating = Delegating::default();
    let exact = fit_paper(scene, photo, water, observations, &options).expect("paper fit");
    let other = fit_paper_with(&delegating, scene, photo, water, observations, &options)
        .expect("paper fit");
    assert!(!exact.lights.is_empty(), "the paper fit finds the light");
    assert_eq!(other.lights, exact.lights);
    assert_eq!(other.skipped, exact.skipped);
    assert!(delegating.water_points.load(Ordering::Relaxed) > 0);
    assert!(delegating.reflections.load(Ordering::Relaxed) > 0);

    let delegating = Delegating::default();
    let joint_options = JointOptions {
        samples: 8,
        sweeps: 3,
        split: false,
        ..JointOptions::new(model, 1)
    };
    let exact_joint = fit_joint(
        scene,
        photo,
        water,
        observations,
        &exact.lights,
        &joint_options,
    )
    .expect("joint fit");
    let other_joint = fit_joint_with(
        &delegating,
        scene,
        photo,
        water,
        observations,
        &exact.lights,
        &joint_options,
    )
    .expect("joint fit");
    assert_eq!(other_joint.lights, exact_joint.lights);
    assert_eq!(other_joint.uncertainty, exact_joint.uncertainty);
    assert_eq!(other_joint.pixels, exact_joint.pixels);
    assert_eq!(other_joint.cost, exact_joint.cost);
    // Every question of the joint fit went to the model: the region's probes, the samples
    // and their cells, the control variates' grids.
    assert!(delegating.water_points.load(Ordering::Relaxed) > 0);
    assert!(delegating.reflections.load(Ordering::Relaxed) > 0);
    assert!(delegating.directions.load(Ordering::Relaxed) > 0);
}
