//! A night that is not black: the renderer's dim sky and diffuse walls against their
//! closed forms, and the fit's smooth background term against the truth of a render.

mod common;

use glam::Vec3;
use serde_json::json;

use common::fit_case::water_material;
use common::gltf_builder::push_area_light;
use common::pipeline::{convert_options, sample_photo, sample_photo_path, sample_scene, segment};
use common::truth::{assert_light_within, nearest, RadianceBar::OfChannel};
use common::{flat_grid, TestScene};
use streaklight::background;
use streaklight::environment::Environment;
use streaklight::render::{render, RenderOptions};
use streaklight::samples::{self, harbour::NIGHT, PHOTO_EXPOSURE, PHOTO_SIZE};
use streaklight::water_mask::water_mask;

/// A wall (z = 0, x within 50 m, y from 0 to 6 m) standing on water that reaches 2 km, a
/// camera 5 m up and 10 m away, and a 0.1 x 0.1 m light at (0, 3, 2) facing the wall.
fn wall_scene() -> TestScene {
    let mut s = TestScene::new();
    s.add_camera("Camera", [0.0, 5.0, 10.0], 60.0);
    let (p, n, i) = flat_grid(-2e3, 2e3, -2e3, 2e3, 200, 200, 0.0);
    s.add_mesh("Water", &p, Some(&n), Some(&i), 4, Some(water_material()));
    let wall = [
        [-50.0, 0.0, 0.0],
        [50.0, 0.0, 0.0],
        [50.0, 6.0, 0.0],
        [-50.0, 6.0, 0.0],
    ];
    s.add_mesh("Wall", &wall, None, Some(&[0, 1, 2, 0, 2, 3]), 4, None);
    let light = json!({"name": "lamp", "type": "rect", "color": [1.0, 1.0, 1.0],
        "intensity": LAMP, "size": 0.1, "rect": {"aspect": 1.0}});
    let index = push_area_light(&mut s.json, light);
    // Unrotated, a light emits along its node's -Z: towards the wall.
    s.add_root_node(json!({"name": "lamp", "translation": [0.0, 3.0, 2.0],
        "extensions": {"EXT_lights_area": {"light": index}}}));
    s
}

/// The lamp's radiance; its area is 0.01 m^2.
const LAMP: f32 = 2000.0;

/// A diffuse wall under a uniform sky, with water to the horizon below: the water hides
/// half of the cosine-weighted hemisphere of a vertical wall (less the rays within 0.2
/// degrees of the horizontal, which pass over its edge 2 km away: under 0.2 %), so the wall's radiance
/// is albedo x sky / 2, plus albedo / pi times the small lamp's irradiance L A cos cos' / d^2.
/// Above the wall the camera sees the sky itself. Held: the sky exactly, the wall's mean
/// over its pixels within 1 %, and the 5 x 5 pixels where the lamp shines brightest within
/// 2 %.
#[test]
fn a_wall_under_the_sky_shows_its_albedo_times_half_the_sky_and_the_lamp() {
    let dir = common::temp_dir("background-wall");
    let path = dir.join("wall.gltf");
    wall_scene().write_gltf(&path);
    let scene = streaklight::scene_in::load(&path, &Default::default()).expect("scene");
    let env = Environment {
        sky: [0.4, 0.2, 0.1],
        albedo: 0.5,
    };
    let side = 200u32;
    let image = render(
        &scene,
        &RenderOptions {
            width: side,
            height: side,
            samples_per_pixel: 64,
            environment: Some(env),
            ..Default::default()
        },
    )
    .expect("render");
    // The scene frame is the world's less the scene's origin.
    let world = |v: Vec3| v - scene.origin.as_vec3();
    let lamp = world(Vec3::new(0.0, 3.0, 2.0));
    let wall_z = world(Vec3::ZERO).z;
    // The closed form at the wall point a pixel's centre sees, if it sees the wall away from
    // its edges (the lamp's back, which some camera rays pass, is open: a light emits and
    // stops rays on its front only).
    let expected = |x: u32, y: u32| -> Option<[f32; 3]> {
        let origin = scene.camera.position;
        let d = scene
            .camera
            .direction(x as f32 + 0.5, y as f32 + 0.5, side, side);
        let t = (wall_z - origin.z) / d.z;
        let p = origin + d * t;
        let height = p.y - world(Vec3::ZERO).y;
        if !(t > 0.0 && height > 0.3 && height < 5.7) {
            return None;
        }
        let to = lamp - p;
        let d2 = to.length_squared();
        let cos = 2.0 / d2.sqrt();
        let lit = env.albedo / std::f32::consts::PI * LAMP * 0.01 * cos * cos / d2;
        Some(env.sky.map(|s| env.albedo * s / 2.0 + lit))
    };
    let at = |x: u32, y: u32| image.pixels[(y * side + x) as usize];
    // The top row looks 30 degrees up, over the wall's top at 6 m.
    for x in 0..side {
        assert_eq!(at(x, 0), env.sky, "pixel ({x}, 0)");
    }
    let (mut sum, mut count) = ([0f64; 3], 0);
    for y in 0..side {
        for x in 0..side {
            if let Some(e) = expected(x, y) {
                let p = at(x, y);
                for c in 0..3 {
                    sum[c] += (p[c] / e[c]) as f64;
                }
                count += 1;
            }
        }
    }
    assert!(count > 5000, "{count} wall pixels");
    for (c, s) in sum.iter().enumerate() {
        let ratio = s / count as f64;
        eprintln!("channel {c}: wall / closed form {ratio:.4} over {count} pixels");
        assert!((ratio - 1.0).abs() < 0.01, "channel {c}: {ratio}");
    }
    let (cx, cy) = scene
        .camera
        .project(world(Vec3::new(0.0, 3.0, 0.0)), side, side)
        .expect("the lamp's spot is in view");
    let (cx, cy) = (cx as u32, cy as u32);
    let (mut got, mut want) = (0f64, 0f64);
    for y in cy - 2..=cy + 2 {
        for x in cx - 2..=cx + 2 {
            let e = expected(x, y).expect("the spot is on the wall");
            got += at(x, y)[0] as f64;
            want += e[0] as f64;
        }
    }
    eprintln!("lamp spot: {got:.4} against {want:.4}");
    assert!((got / want - 1.0).abs() < 0.02, "{got} against {want}");
    let _ = std::fs::remove_dir_all(&dir);
}

/// The committed photos of black nights measure a black background, so that their fits
/// are what they were without the background term: the paper's Table 1 (one large streak
/// with long faint tails) and the harbour's pair (lamps and fragmented streaks).
#[test]
fn a_black_night_measures_black() {
    for (scene_file, photo_file) in [
        ("scene.gltf", "table1.png"),
        ("harbour.gltf", "harbour-pair.png"),
    ] {
        let scene = sample_scene(scene_file, None);
        let photo = sample_photo(photo_file);
        let water = water_mask(&scene, photo.width, photo.height);
        let pixels: Vec<u32> = segment(&photo, &water)
            .streaks
            .iter()
            .flat_map(|s| s.pixels.iter().copied())
            .collect();
        let b = background::estimate(&photo, &water, &pixels);
        assert!(b.is_black(), "{photo_file}: {:?}", b.water_mean);
    }
}

/// `harbour-night.png`: the harbour pair (an orange and a blue lamp 40 m away, in the photo)
/// under a dim sky that lights the facades, which the water reflects. Held, at the defaults:
/// two lights, every edge within 1 % of its size and every radiance channel within 1 %
/// (measured: 0.09 % and 0.5 %); the report's background within 5 % of the water's mean in a
/// render of the scene under that sky without the lamps. Without the background term the
/// same fit was 10-14 % low in the lamps' strong channels (the grey background pulled the
/// colour their reflections give towards grey); without giving each lamp back the radiance
/// of the wall it hides, 1-2 % low in their weak ones.
#[test]
fn a_dim_sky_and_lit_facades_are_taken_off_before_the_fit() {
    let dir = common::pipeline::sample_scenes();
    let debug = common::temp_dir("night-debug");
    let options = streaklight::convert::ConvertOptions {
        scene: dir.join("harbour.gltf"),
        debug_dir: Some(debug.clone()),
        ..convert_options(
            dir,
            sample_photo_path("harbour-night.png"),
            "night-fit.gltf",
        )
    };
    let report = streaklight::convert::convert(&options).expect("fit").report;
    // The debug pictures show the background measured (brightened: grey, not black, on the
    // left panel's water) and the page shows the picture.
    let html = std::fs::read_to_string(debug.join("index.html")).expect("index.html");
    assert!(html.contains("src=\"background.png\""));
    let picture = image::open(debug.join("background.png"))
        .expect("background.png")
        .to_rgb8();
    let (w, h) = (picture.width(), picture.height());
    let water = picture.get_pixel(w / 4, h - h / 8);
    assert!(water[0] > 20 && water[0] == water[2], "{water:?}");
    let _ = std::fs::remove_dir_all(&debug);
    assert_eq!(report.lights.len(), 2, "{:?}", report.warnings);
    for truth in &samples::harbour::layouts()[0].2 {
        let light = nearest(&report.lights, truth);
        assert_light_within("night", light, truth, 0.01, OfChannel(0.01));
    }
    // The report, as written, holds the background in the shape its schema gives.
    let value = serde_json::to_value(&report).expect("the report as JSON");
    let errors: Vec<String> = common::json::schema_validator("report.schema.json")
        .iter_errors(&value)
        .map(|e| format!("{e} at {}", e.instance_path))
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    assert!(value["background"].is_object());
    let measured = report.background.expect("a background");
    assert!(
        measured.streak_share > 0.0 && measured.streak_share < 0.2,
        "{}",
        measured.streak_share
    );

    let scene = sample_scene("harbour.gltf", None);
    let alone = render(
        &scene,
        &RenderOptions {
            width: PHOTO_SIZE,
            height: PHOTO_SIZE,
            samples_per_pixel: 64,
            exposure: PHOTO_EXPOSURE,
            environment: Some(NIGHT),
            ..Default::default()
        },
    )
    .expect("render");
    let water = water_mask(&scene, PHOTO_SIZE, PHOTO_SIZE);
    let on_water = water.iter().filter(|&&w| w).count() as f64;
    for c in 0..3 {
        let truth: f64 = alone
            .pixels
            .iter()
            .zip(&water)
            .filter(|(_, &w)| w)
            .map(|(p, _)| (p[c] / PHOTO_EXPOSURE) as f64)
            .sum::<f64>()
            / on_water;
        let got = measured.water_mean[c] as f64;
        eprintln!("background on the water, channel {c}: {got:.5} against {truth:.5}");
        assert!(
            (got / truth - 1.0).abs() < 0.05,
            "channel {c}: {got} against {truth}"
        );
    }
}

/// `segment` takes the night's background off as `fit` does, so it lists the streaks the fit
/// fits: on `harbour-night.png`, two streaks, one per lamp, each made of the fragments the
/// fit's report names for its light.
#[test]
fn segment_takes_the_background_off_as_fit_does() {
    let dir = common::pipeline::sample_scenes();
    let out = common::temp_dir("night-segment");
    let (ok, stdout, stderr) = common::run_cli(&[
        "segment".to_string(),
        common::cli::arg(&dir.join("harbour.gltf")),
        common::cli::arg(&sample_photo_path("harbour-night.png")),
        "--exposure".into(),
        "0.1".into(),
        "--out-dir".into(),
        common::cli::arg(&out),
    ]);
    assert!(ok, "{stderr}");
    assert!(stderr.contains("smooth background"), "{stderr}");
    let streaks: Vec<&str> = stdout
        .lines()
        .filter(|l| l.starts_with("streak "))
        .collect();
    assert_eq!(streaks.len(), 2, "{stdout}");
    let options = streaklight::convert::ConvertOptions {
        scene: dir.join("harbour.gltf"),
        ..convert_options(
            dir,
            sample_photo_path("harbour-night.png"),
            "night-ids.gltf",
        )
    };
    let report = streaklight::convert::convert(&options).expect("fit").report;
    let mut fitted: Vec<Vec<usize>> = report.lights.iter().map(|l| l.streak_ids.clone()).collect();
    fitted.sort();
    let mut listed: Vec<Vec<usize>> = streaks
        .iter()
        .map(|l| {
            let inside = l.split("(fragments ").nth(1).expect("fragments");
            let list = inside.split(')').next().expect("a closing parenthesis");
            list.split(", ")
                .map(|n| n.parse().expect("a number"))
                .collect()
        })
        .collect();
    listed.sort();
    assert_eq!(listed, fitted, "{stdout}");
    let _ = std::fs::remove_dir_all(&out);
}

/// `render --sky` takes one value or R,G,B of 0 or more, `--albedo` 0 to 1; anything else is
/// refused at once with the accepted range and exit code 2, before anything is read.
#[test]
fn render_refuses_a_sky_or_albedo_out_of_range() {
    let dir = common::pipeline::sample_scenes();
    let out = common::temp_dir("night-render-args").join("x.png");
    for (option, value, range) in [
        ("--sky", "1,2", "R,G,B"),
        ("--sky", "-0.5", "R,G,B"),
        ("--albedo", "1.5", "from 0 to 1"),
    ] {
        let (code, _, stderr) = common::cli::run_cli_code(&[
            "render".to_string(),
            common::cli::arg(&dir.join("harbour.gltf")),
            "-o".into(),
            common::cli::arg(&out),
            option.into(),
            value.into(),
        ]);
        assert_eq!(code, 2, "{option} {value}: {stderr}");
        assert!(
            stderr.contains(range) && stderr.contains(option),
            "{stderr}"
        );
        assert!(!out.exists());
    }
}

/// `--no-background` fits the photo as it is: on `harbour-night.png` the report has no
/// background, says it was not asked for, and the lamps' strong channels come out low by
/// more than 5 % (measured: the orange lamp's red 11.6 %, the blue lamp's blue 13.8 %), which
/// is what the background term removes.
#[test]
fn without_the_background_term_the_lamps_read_grey() {
    let dir = common::pipeline::sample_scenes();
    let mut options = streaklight::convert::ConvertOptions {
        scene: dir.join("harbour.gltf"),
        ..convert_options(
            dir,
            sample_photo_path("harbour-night.png"),
            "night-raw.gltf",
        )
    };
    options.fit.background = false;
    let report = streaklight::convert::convert(&options).expect("fit").report;
    assert!(report.background.is_none());
    assert!(!report.settings.background);
    let lights = samples::harbour::layouts().swap_remove(0).2;
    let (orange, blue) = (&lights[0], &lights[1]);
    let low = |truth: &samples::SampleLight, channel: usize| {
        let light = nearest(&report.lights, truth);
        1.0 - light.radiance[channel] / truth.radiance[channel]
    };
    assert!(low(orange, 0) > 0.05, "orange red {}", low(orange, 0));
    assert!(low(blue, 2) > 0.05, "blue blue {}", low(blue, 2));
}
