//! Round trips of the fit (method §5 steps 7-9) on the committed sample photos, whose truth
//! comes from `samples::table1_light()` and `samples::table3_lights()`, and a check of the
//! fit's forward model against the renderer.
//!
//! The photos are 600 x 600, 256 spp, 8-bit sRGB: per-pixel noise of several percent at a
//! streak's edge, which the edge solutions average over 100-300 pixels per edge.

mod common;

use common::fit_helpers::fit_photo;
use common::pipeline::{sample_photo, sample_scene};
use glam::{DVec3, Vec3};
use streaklight::fitting::footprint::footprint;
use streaklight::fitting::{EdgeSide, EdgeStatus, FitOutcome, FittedLight, LightPlane, Rect};
use streaklight::optics::ReflectionModel;
use streaklight::render::{render, RenderOptions};
use streaklight::samples::{self, SampleLight};
use streaklight::scene_in;

/// The fitted light's four edges in world coordinates on a wall facing +z (u = +x, v = +y):
/// left x, right x, bottom y, top y.
fn world_edges(l: &FittedLight, origin: DVec3) -> [f64; 4] {
    let c = l.corner_left_bottom_world(origin);
    [c.x, c.x + l.width() as f64, c.y, c.y + l.height() as f64]
}

fn truth_edges(t: &SampleLight) -> [f64; 4] {
    [
        t.corner.x,
        t.corner.x + t.width,
        t.corner.y,
        t.corner.y + t.height,
    ]
}

fn report(name: &str, l: &FittedLight, origin: DVec3, truth: Option<&SampleLight>) {
    let e = world_edges(l, origin);
    let c = l.corner_left_bottom_world(origin);
    eprintln!(
        "{name}: corner ({:.4}, {:.4}, {:.4}), {:.4} x {:.4}, L {:?}",
        c.x,
        c.y,
        c.z,
        l.width(),
        l.height(),
        l.radiance
    );
    if let Some(t) = truth {
        let te = truth_edges(t);
        for side in EdgeSide::ALL {
            let i = side as usize;
            eprintln!(
                "  {:6} truth {:8.4} fitted {:8.4} error {:+.4} m  {:?}",
                side.name(),
                te[i],
                e[i],
                e[i] - te[i],
                l.edges[i]
            );
        }
    }
}

/// The light's plane must be the wall at `wall_z`, facing the camera, with u = +x.
fn assert_on_wall(l: &FittedLight, origin: DVec3, wall_z: f64) {
    let c = l.center_world(origin);
    assert!(
        (c.z - wall_z).abs() < 1e-3,
        "light centre {c} is not on z = {wall_z}"
    );
    assert!(
        l.plane.normal.dot(Vec3::Z) > 0.9999,
        "normal {}",
        l.plane.normal
    );
    assert!(l.plane.u.dot(Vec3::X) > 0.9999, "u {}", l.plane.u);
    assert!(
        l.plane.hit_fraction > 0.9,
        "hit fraction {}",
        l.plane.hit_fraction
    );
}

fn sorted_left_to_right(out: &FitOutcome, origin: DVec3) -> Vec<FittedLight> {
    let mut lights = out.lights.clone();
    lights.sort_by(|a, b| {
        a.center_world(origin)
            .x
            .total_cmp(&b.center_world(origin).x)
    });
    lights
}

fn assert_edges_within(l: &FittedLight, origin: DVec3, truth: &SampleLight, tolerance: f64) {
    let (e, t) = (world_edges(l, origin), truth_edges(truth));
    for side in EdgeSide::ALL {
        let i = side as usize;
        assert!(
            (e[i] - t[i]).abs() <= tolerance,
            "{} edge: fitted {:.4}, truth {:.4}, tolerance {tolerance}",
            side.name(),
            e[i],
            t[i]
        );
    }
}

#[test]
fn table1_round_trip_within_one_percent() {
    let scene = sample_scene("scene.gltf", None);
    let out = fit_photo(&scene, &sample_photo("table1.png"));
    assert_eq!(out.lights.len(), 1, "{:?}", out.lights);
    assert!(out.skipped.is_empty(), "{:?}", out.skipped);
    let l = &out.lights[0];
    let truth = samples::table1_light();
    report("Table 1", l, scene.origin, Some(&truth));
    eprintln!("timings {:?}", out.timings);
    assert_on_wall(l, scene.origin, 0.0);
    assert!(l
        .edges
        .iter()
        .all(|e| matches!(e, EdgeStatus::Constrained { .. })));
    // 1 % of the light's 3 m.
    assert_edges_within(l, scene.origin, &truth, 0.03);
    for c in 0..3 {
        let rel = l.radiance[c] as f64 / truth.radiance[c] - 1.0;
        assert!(rel.abs() < 0.02, "radiance {:?}", l.radiance);
    }
}

#[test]
fn table3_two_lights_colour_and_edges() {
    let scene = sample_scene("scene.gltf", None);
    let out = fit_photo(&scene, &sample_photo("table3.png"));
    assert_eq!(out.lights.len(), 2, "{:?}", out.lights);
    let lights = sorted_left_to_right(&out, scene.origin);
    let truth = samples::table3_lights();
    for (i, (l, t)) in lights.iter().zip(&truth).enumerate() {
        report(&format!("Table 3 light{i}"), l, scene.origin, Some(t));
        assert_on_wall(l, scene.origin, 0.0);
        // The light is yellow: blue must come out near zero (the paper reports it equal to
        // red), red and green equal.
        let [r, g, b] = l.radiance;
        assert!(b < 0.02 * r, "radiance {:?}", l.radiance);
        assert!((r - g).abs() < 0.01 * r, "radiance {:?}", l.radiance);
    }
    eprintln!("timings {:?}", out.timings);
    // light0, 3 x 3, L (20, 20, 0): as Table 1.
    assert_edges_within(&lights[0], scene.origin, &truth[0], 0.03);
    assert!((lights[0].radiance[0] / 20.0 - 1.0).abs() < 0.02);
    // light1, 2 x 2, L (10, 10, 0), reflected partly outside the photo's right border: its
    // right edge cannot be seen and must be flagged; its reflection also runs into the
    // photo's bottom (the light's top edge), which may be flagged too. Edges the photo shows
    // are within 2 % of its 2 m.
    let l1 = &lights[1];
    assert!(
        matches!(
            l1.edges[EdgeSide::Right as usize],
            EdgeStatus::Unconstrained { .. }
        ),
        "{:?}",
        l1.edges
    );
    let (e, t) = (world_edges(l1, scene.origin), truth_edges(&truth[1]));
    for side in [EdgeSide::Left, EdgeSide::Bottom, EdgeSide::Top] {
        let i = side as usize;
        let tolerance = match l1.edges[i] {
            EdgeStatus::Constrained { .. } => 0.04,
            // Flagged: fitted from the pixels left, which need not reach the edge; still
            // within 5 % on this sample.
            EdgeStatus::Unconstrained { .. } => 0.10,
        };
        assert!(
            (e[i] - t[i]).abs() <= tolerance,
            "{} edge {} vs {}",
            side.name(),
            e[i],
            t[i]
        );
    }
    // "A few percent": the right edge the photo cannot show is placed as far as the traced
    // lobes reach, which lowers L for the pixels next to the border.
    assert!(
        (l1.radiance[0] / 10.0 - 1.0).abs() < 0.05,
        "{:?}",
        l1.radiance
    );
}

/// Table 2 of the paper: table1.png fitted against the scene with the wall moved to z = -3 and
/// z = +3. The light lands on the moved wall, and the fit reproduces the streak's angular
/// extent as seen from the camera's mirror image (0, -0.2, 10): the reflected rays leave the
/// water close to where the camera's rays hit it and, for a flat mean surface, diverge from
/// that mirror point. A wall at distance d from it must carry a light of about d / 10 times
/// the true size: 1.3 x 3 m = 3.9 m at z = -3, 0.7 x 3 m = 2.1 m at z = +3 (the paper got
/// 3.67 x 3.81 and 2.21 x 2.21). The ripples and the lobe (whose angular width does not
/// change) make this approximate; 10 % separates it clearly from no scaling (30 %).
#[test]
fn table2_moved_walls_scale_the_light_with_distance() {
    let photo = sample_photo("table1.png");
    let truth = samples::table1_light();
    for (file, wall_z) in [
        ("table2-wall-minus3.gltf", -3.0),
        ("table2-wall-plus3.gltf", 3.0),
    ] {
        let scene = sample_scene(file, None);
        let out = fit_photo(&scene, &photo);
        assert_eq!(out.lights.len(), 1, "{file}: {:?}", out.lights);
        let l = &out.lights[0];
        report(&format!("Table 2 wall z = {wall_z}"), l, scene.origin, None);
        assert_on_wall(l, scene.origin, wall_z);
        let scale = (10.0 - wall_z) / 10.0;
        for (what, size) in [("width", l.width()), ("height", l.height())] {
            let expected = truth.width * scale;
            assert!(
                (size as f64 / expected - 1.0).abs() < 0.1,
                "{file}: {what} {size}, expected about {expected}"
            );
        }
        // The centre scales about the mirror point too.
        let c = l.center_world(scene.origin);
        let mirror = DVec3::new(0.0, -0.2, 10.0);
        let expected = mirror + (truth.center() - mirror) * scale;
        assert!(
            (c - expected).length() < 0.1 * 3.0,
            "{file}: centre {c}, expected {expected}"
        );
    }
}

/// Fitted with too low a gloss (e = 200 instead of 500), the model's lobe is wider than the
/// photo's, so a smaller light explains the same streak (the paper: 2.15 x 2.41 for 3 x 3).
/// Here the consistent fit runs away (no rectangle explains the photo with that lobe) and the
/// fitter falls back to the paper's fixed whole-plane radiance; the light comes out smaller in
/// area, mostly in height (the lobe's extra width is mostly vertical at grazing views).
#[test]
fn wrong_gloss_gives_a_smaller_light() {
    let scene = sample_scene("scene.gltf", Some(200.0));
    let out = fit_photo(&scene, &sample_photo("table1.png"));
    assert_eq!(out.lights.len(), 1, "{:?}", out.lights);
    let l = &out.lights[0];
    report(
        "Table 1 with e = 200",
        l,
        scene.origin,
        Some(&samples::table1_light()),
    );
    // The right answer is 3 x 3 within 3 cm (1 % in area); 5 % less area and 5 % less
    // height are the paper's effect, well outside the fit's own error. (The width does not
    // shrink here: the consistent fit runs away with this lobe and the fitter falls back to
    // the paper's fixed whole-plane radiance; the lobe's extra width is mostly vertical.)
    let area = l.width() * l.height();
    assert!(area < 0.95 * 9.0, "{} x {}", l.width(), l.height());
    assert!(l.height() < 0.95 * 3.0, "{} x {}", l.width(), l.height());
    assert!(
        l.width() > 1.0 && l.height() > 1.0,
        "{} x {}",
        l.width(),
        l.height()
    );
}

/// The fit's forward model is the renderer's: for pixels across a light's reflection on flat
/// water, `L c(p; light)` from the footprint samples matches the rendered pixel within Monte
/// Carlo error.
#[test]
fn footprint_matches_the_renderer() {
    let dir = common::temp_dir("fit-footprint");
    let material = serde_json::json!({"pbrMetallicRoughness": {
        "roughnessFactor": scene_in::roughness_from_gloss(500.0), "metallicFactor": 0.0}});
    let mut s = common::paper_setup(Some(material));
    s.add_light_facing_z("light", [-2.5, 3.5, 0.0], 3.0, 3.0, [20.0, 20.0, 20.0]);
    let path = dir.join("flat.gltf");
    s.write_gltf(&path);
    let scene = scene_in::load(&path, &Default::default()).unwrap();
    let (w, h) = (60u32, 60u32);
    let spp = 2048;
    let image = render(
        &scene,
        &RenderOptions {
            width: w,
            height: h,
            samples_per_pixel: spp,
            seed: 7,
            ..Default::default()
        },
    )
    .unwrap();
    // The wall: node 2, mesh 1, primitive 0 of paper_setup; world z = 0, so scene z = -10.
    let plane = LightPlane::with_frame(
        (2, 1, 0),
        Vec3::new(0.0, -0.2, -10.0),
        Vec3::Z,
        scene.camera.right,
        1.0,
    )
    .unwrap();
    let light = Rect {
        u_min: -4.0,
        u_max: -1.0,
        v_min: 2.0,
        v_max: 5.0,
    };
    let model = ReflectionModel::new(scene.water.gloss, scene.water.ior);
    // Across the reflection of the light's left edge (column ~9) and inside it, on a row that
    // sees its middle (row ~47).
    let samples = 20_000;
    let mut checked = 0;
    for x in [6u32, 8, 9, 10, 12, 16] {
        let p = 47 * w + x;
        let fp = footprint(&scene, &model, &plane, (p, 0), w, h, samples, 3);
        let c = fp.coefficient(&light) as f64;
        let predicted = 20.0 * c;
        let rendered = image.pixels[p as usize][0] as f64;
        // Variance of one sample's L w 1_in, from the footprint's own samples.
        let second: f64 = fp
            .points
            .iter()
            .zip(&fp.weights)
            .filter(|(q, _)| light.contains(**q))
            .map(|(_, &wt)| (20.0 * wt as f64).powi(2))
            .sum::<f64>()
            / samples as f64;
        let var = (second - predicted * predicted).max(0.0);
        let sigma = (var / spp as f64 + var / samples as f64).sqrt();
        eprintln!(
            "pixel ({x}, 47): rendered {rendered:.5}, predicted {predicted:.5} +- {sigma:.5}"
        );
        assert!(
            (rendered - predicted).abs() <= 4.0 * sigma + 1e-6,
            "pixel ({x}, 47): rendered {rendered}, predicted {predicted} +- {sigma}"
        );
        if predicted > 0.0 {
            checked += 1;
        }
    }
    assert!(
        checked >= 4,
        "too few pixels see the light: pick another row"
    );
}
