//! The joint fit's direct view (the pixels that see a light itself, above the water) through
//! the whole pipeline: on the committed sample photos, against the truth lights and against
//! the same fit without it; and on a photo whose light is out of frame, where it must change
//! nothing.

mod common;

use std::path::Path;

use common::fit_case::{render_photo, water_material, EXPOSURE, SIDE};
use common::gltf_builder::{flat_grid, WALL, WALL_INDICES};
use common::pipeline::{convert_options, fit_settings, sample_photo_path, sample_scenes};
use common::{temp_dir, TestScene};
use streaklight::convert::{convert, ConvertOptions};
use streaklight::pipeline::{FitSettings, Method};
use streaklight::report::{LightReport, Report};
use streaklight::samples;

/// The default fit with the direct view on or off, both from the paper's estimate at 128
/// lobe samples a pixel: an edge's count of pixels is the reflections' count on the
/// estimate the fit started from plus the direct pixels it crosses, so the counts compare
/// only from one estimate (with the direct view and a whole lamp the default start reads
/// 32, `tests/joint.rs`).
fn settings(direct_view: bool) -> FitSettings {
    let mut s = fit_settings(Method::default(), 1, None, false);
    s.samples = Some(128);
    if let Method::Joint(j) = &mut s.method {
        j.direct_view = direct_view;
    }
    s
}

/// `streaklight fit` of `photo` against `scene` with the direct view on or off: the report.
fn fit(scene: &Path, photo: &Path, direct_view: bool, exposure: f32) -> Report {
    let output = format!(
        "direct-{}-{direct_view}.gltf",
        photo.file_stem().unwrap_or_default().to_string_lossy()
    );
    let options = ConvertOptions {
        fit: settings(direct_view),
        exposure,
        ..convert_options(scene, photo, &output)
    };
    convert(&options).expect("fit").report
}

/// Per edge (left, right, bottom, top) the error in metres, and the radiance's relative error
/// (largest channel), against a light of corner `corner`, size `size` and radiance `radiance`.
fn errors(l: &LightReport, corner: [f64; 2], size: [f64; 2], radiance: f64) -> ([f64; 4], f64) {
    let c = l.corner_left_bottom;
    let edges = [
        c[0] - corner[0],
        c[0] + l.width - corner[0] - size[0],
        c[1] - corner[1],
        c[1] + l.height - corner[1] - size[1],
    ];
    let peak = l.radiance.iter().cloned().fold(0.0, f64::max);
    (edges, (peak - radiance) / radiance)
}

/// The reported sigmas, metres (`None`: unconstrained).
fn sigmas(l: &LightReport) -> [Option<f64>; 4] {
    let u = l.uncertainty.as_ref().expect("uncertainties");
    [u.left, u.right, u.bottom, u.top]
}

/// Table 1's light is in the photo (clipped, above the water): with the direct view, every
/// edge is seen directly, the report counts the pixels that see it (its 3 x 3 m at 10 m, on
/// the checkerboard), the fit is at least as accurate and the sigmas of the edges the photo
/// measures directly shrink.
#[test]
fn the_direct_view_pins_table1s_light() {
    let truth = samples::table1_light();
    let photo = sample_photo_path("table1.png");
    let (corner, size) = (
        [truth.corner.x, truth.corner.y],
        [truth.width, truth.height],
    );
    let on = fit(sample_scenes(), &photo, true, samples::PHOTO_EXPOSURE);
    let off = fit(sample_scenes(), &photo, false, samples::PHOTO_EXPOSURE);
    assert_eq!((on.lights.len(), off.lights.len()), (1, 1));
    let (l_on, l_off) = (&on.lights[0], &off.lights[0]);
    let (e_on, r_on) = errors(l_on, corner, size, truth.radiance[0]);
    let (e_off, r_off) = errors(l_off, corner, size, truth.radiance[0]);
    let (s_on, s_off) = (sigmas(l_on), sigmas(l_off));
    eprintln!("direct view: errors (m) {e_on:?}, radiance {r_on:+.5}, sigmas {s_on:?}");
    eprintln!("without:     errors (m) {e_off:?}, radiance {r_off:+.5}, sigmas {s_off:?}");
    eprintln!(
        "direct pixels {:?}, edges {:?}",
        l_on.direct_pixels, l_on.edges
    );
    // 3 m at 10 m is 155.9 pixels of a 600-pixel, 60-degree photo: 24300 pixels, half read.
    let metres_per_pixel = 20.0 * (30f64).to_radians().tan() / samples::PHOTO_SIZE as f64;
    let seen = (3.0 / metres_per_pixel).powi(2) / 2.0;
    let counted = l_on
        .direct_pixels
        .expect("a joint fit counts direct pixels") as f64;
    assert!(
        (counted - seen).abs() < 0.02 * seen,
        "{counted} against {seen}"
    );
    assert_eq!(l_off.direct_pixels, Some(0));
    // Its image clips in every channel: only the reflections give its radiance, either way.
    assert_eq!(
        (l_on.radiance_seen, l_off.radiance_seen),
        (Some(false), Some(false))
    );
    // Every edge is seen directly: constrained, by more pixels than the reflections alone.
    for (on, off) in [
        (&l_on.edges.left, &l_off.edges.left),
        (&l_on.edges.right, &l_off.edges.right),
        (&l_on.edges.bottom, &l_off.edges.bottom),
        (&l_on.edges.top, &l_off.edges.top),
    ] {
        assert_eq!(on.status, "constrained");
        // Without the view an edge may be unconstrained, its count then the pixels read
        // anyway (which need not show it): only constrained counts compare.
        assert!(
            off.status != "constrained" || on.pixels > off.pixels + 50,
            "{} against {}",
            on.pixels,
            off.pixels
        );
    }
    // At least as accurate: the sum of the edges' errors no larger (to a tenth of a
    // millimetre), and the radiance within the bound the joint tests hold it to.
    let total = |e: [f64; 4]| e.iter().map(|x| x.abs()).sum::<f64>();
    assert!(
        total(e_on) <= total(e_off) + 1e-4,
        "{e_on:?} against {e_off:?}"
    );
    assert!(r_on.abs() < 0.005, "radiance off by {:.3} %", 100.0 * r_on);
    // The errors stay within the sigmas, which shrink for the top edge: the photo shows it
    // across a row of pixels the light covers 42 %, unclipped.
    for ((e, s), side) in e_on
        .iter()
        .zip(s_on)
        .zip(["left", "right", "bottom", "top"])
    {
        let s = s.unwrap_or_else(|| panic!("{side} has a sigma"));
        assert!(e.abs() < 5.0 * s, "{side}: {e} m off, sigma {s} m");
    }
    // Without the view the top edge may be unconstrained (no sigma): then being constrained
    // with it (checked above) is the gain; otherwise its sigma at least halves.
    if let (Some(top_on), Some(top_off)) = (s_on[3], s_off[3]) {
        assert!(
            top_on < 0.5 * top_off,
            "top sigma {top_on} against {top_off}"
        );
    }
}

/// A light above the top of the photo: the camera looks down 25 degrees, so the top of the
/// frame meets the wall at 1.07 m and the 3 x 3 m light from 2 to 5 m is out of frame, while
/// its reflection is in. The direct view sees only dark wall: the report counts no pixel that
/// sees the light, and the fit is the one without the direct view.
#[test]
fn a_light_out_of_frame_is_fitted_as_without_the_direct_view() {
    let dir = temp_dir("direct-view-out-of-frame");
    let scene = |light: bool| {
        let mut s = TestScene::new();
        // Looking down: a rotation of -25 degrees about +x.
        let half = (-25f64).to_radians() / 2.0;
        let cam = common::gltf_builder::push(
            &mut s.json,
            "cameras",
            serde_json::json!({"type": "perspective", "perspective": {"yfov": 60f64.to_radians(), "aspectRatio": 1.0, "znear": 0.01}}),
        );
        s.add_root_node(serde_json::json!({"name": "Camera", "camera": cam,
            "translation": [0.0, 0.2, 10.0], "rotation": [half.sin(), 0.0, 0.0, half.cos()]}));
        let (p, n, i) = flat_grid(-12.0, 12.0, -1.0, 10.5, 48, 23, 0.0);
        s.add_mesh("Water", &p, Some(&n), Some(&i), 4, Some(water_material()));
        s.add_mesh("Wall", &WALL, None, Some(&WALL_INDICES), 4, None);
        if light {
            common::fit_case::add_truth_light(&mut s);
        }
        s
    };
    let truth = dir.join("truth.gltf");
    scene(true).write_gltf(&truth);
    let photo = dir.join("photo.png");
    render_photo(&truth, &photo, SIDE, SIDE, 16);
    scene(false).write_gltf(&dir.join("scene.gltf"));
    let on = fit(&dir, &photo, true, EXPOSURE);
    let off = fit(&dir, &photo, false, EXPOSURE);
    assert_eq!(on.lights.len(), off.lights.len());
    assert!(!on.lights.is_empty(), "the reflection gives a light");
    for (a, b) in on.lights.iter().zip(&off.lights) {
        eprintln!(
            "with: corner {:?} {} x {} L {:?}; without: corner {:?} {} x {} L {:?}",
            a.corner_left_bottom,
            a.width,
            a.height,
            a.radiance,
            b.corner_left_bottom,
            b.width,
            b.height,
            b.radiance
        );
        assert_eq!(a.direct_pixels, Some(0));
        let (ea, ra) = errors(
            a,
            [b.corner_left_bottom[0], b.corner_left_bottom[1]],
            [b.width, b.height],
            b.radiance.iter().cloned().fold(0.0, f64::max),
        );
        // The same fit: within a tenth of a millimetre and 0.01 % of the radiance.
        assert!(ea.iter().all(|e| e.abs() < 1e-4), "{ea:?}");
        assert!(ra.abs() < 1e-4, "{ra}");
    }
    let _ = std::fs::remove_dir_all(&dir);
}
