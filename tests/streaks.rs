//! Streak extraction (method §5 steps 3-6) on the sample photos of the paper's setup.
//!
//! The water mask comes from the sample scene (written into a temporary folder, since its
//! water mesh is generated, not committed). Where a light's reflection falls is worked out from
//! geometry: the mirror image of the light in the water plane y = 0, projected by the camera.

mod common;

use std::sync::OnceLock;

use common::json::{read_json, schema_validator};
use common::pipeline::{sample_photo, sample_photo_path, sample_scene, sample_scenes};
use glam::{DVec3, Vec3};
use streaklight::fitting::{fragments, FitOptions};
use streaklight::photo_in::Photo;
use streaklight::random::Rng;
use streaklight::samples::{self, SampleLight};
use streaklight::scene_in::Scene;
use streaklight::streaks::{extract_streaks, BoundingBox, Segmentation, StreakParams, StreakSide};
use streaklight::water_mask::water_mask;
use streaklight::water_model::ExactSurface;

struct Setup {
    scene: Scene,
    water: Vec<bool>,
}

fn setup() -> &'static Setup {
    static SETUP: OnceLock<Setup> = OnceLock::new();
    SETUP.get_or_init(|| {
        let scene = sample_scene("scene.gltf", None);
        let water = water_mask(&scene, 600, 600);
        Setup { scene, water }
    })
}

fn segment(photo: &Photo) -> Segmentation {
    common::pipeline::segment(photo, &setup().water)
}

/// The pixel box where the mirror image of `light` in the water plane appears.
fn reflection_box(light: &SampleLight) -> BoundingBox {
    let s = setup();
    let (mut x0, mut y0, mut x1, mut y1) = (f32::MAX, f32::MAX, f32::MIN, f32::MIN);
    for (dx, dy) in [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0), (1.0, 1.0)] {
        let corner = light.corner + DVec3::new(dx * light.width, dy * light.height, 0.0);
        let mirrored = DVec3::new(corner.x, -corner.y, corner.z) - s.scene.origin;
        let (px, py) = s
            .scene
            .camera
            .project(
                Vec3::new(mirrored.x as f32, mirrored.y as f32, mirrored.z as f32),
                600,
                600,
            )
            .unwrap();
        x0 = x0.min(px);
        x1 = x1.max(px);
        y0 = y0.min(py);
        y1 = y1.max(py);
    }
    let clamp = |v: f32| v.clamp(0.0, 599.0) as u32;
    BoundingBox {
        x_min: clamp(x0),
        y_min: clamp(y0),
        x_max: clamp(x1),
        y_max: clamp(y1),
    }
}

fn grown(b: BoundingBox, by: u32) -> BoundingBox {
    BoundingBox {
        x_min: b.x_min.saturating_sub(by),
        y_min: b.y_min.saturating_sub(by),
        x_max: b.x_max + by,
        y_max: b.y_max + by,
    }
}

fn contains(b: &BoundingBox, p: (u32, u32)) -> bool {
    (b.x_min..=b.x_max).contains(&p.0) && (b.y_min..=b.y_max).contains(&p.1)
}

/// Checks that the streaks match the lights one to one, left to right, by geometry.
fn check_matches(seg: &Segmentation, lights: &[SampleLight]) {
    assert_eq!(
        seg.streaks.len(),
        lights.len(),
        "streak boxes: {:?}",
        seg.streaks.iter().map(|s| s.bbox).collect::<Vec<_>>()
    );
    for (streak, light) in seg.streaks.iter().zip(lights) {
        let region = reflection_box(light);
        assert!(
            streak.bbox.overlaps(&region),
            "{:?} vs {region:?}",
            streak.bbox
        );
        // The brightest pixel sits on the mirror image: within a few pixels across; along the
        // streak, ripples stretch the reflection (mostly towards the horizon, where the Fresnel
        // factor is larger), so allow 40 rows above the flat-water image.
        let near = BoundingBox {
            x_min: region.x_min.saturating_sub(15),
            x_max: region.x_max + 15,
            y_min: region.y_min.saturating_sub(40),
            y_max: region.y_max + 15,
        };
        assert!(
            contains(&near, streak.brightest),
            "brightest {:?} outside {region:?}",
            streak.brightest
        );
        // The streak is mostly inside the region, widened by the glossy spread.
        let inside = streak
            .pixels
            .iter()
            .filter(|&&p| contains(&grown(region, 60), (p % 600, p / 600)))
            .count();
        assert!(inside as f64 >= 0.9 * streak.pixels.len() as f64);
        assert!(streak.pixels.len() > 1000);
        for side in StreakSide::ALL.map(|s| &streak.edges[s]) {
            assert!(!side.is_empty());
        }
    }
}

#[test]
fn table1_white_light_gives_one_streak_where_geometry_puts_it() {
    let seg = segment(&sample_photo("table1.png"));
    check_matches(&seg, &[samples::table1_light()]);
    // A white light: the streak's mean colour is grey (channels within 10 %).
    let c = seg.streaks[0].mean_colour;
    let (max, min) = (c[0].max(c[1]).max(c[2]), c[0].min(c[1]).min(c[2]));
    assert!(min > 0.9 * max, "{c:?}");
}

#[test]
fn table3_yellow_lights_give_two_streaks_left_to_right() {
    let seg = segment(&sample_photo("table3.png"));
    let lights = samples::table3_lights();
    check_matches(&seg, &lights);
    assert!(seg.streaks[0].bbox.x_max < seg.streaks[1].bbox.x_min);
    // Yellow lights (no blue): the streaks are yellow.
    for s in &seg.streaks {
        let c = s.mean_colour;
        assert!(c[2] < 0.2 * c[0] && c[2] < 0.2 * c[1], "{c:?}");
    }
}

/// Mean V (sRGB-encoded, as displayed) of the photo over a box.
fn mean_display_value(photo: &Photo, b: &BoundingBox) -> f32 {
    let mut sum = 0.0;
    let mut n = 0;
    for y in b.y_min..=b.y_max {
        for x in b.x_min..=b.x_max {
            let p = photo.display[photo.index(x, y)];
            sum += p[0].max(p[1]).max(p[2]);
            n += 1;
        }
    }
    sum / n as f32
}

#[test]
fn stacked_lights_overlap_into_one_streak_with_both_parts_visible() {
    check_stacked_streak("stacked.png");
}

/// The same lights over smoother water (e = 1000): narrower reflections, still one streak.
#[test]
fn stacked_lights_over_smooth_water_still_make_one_streak() {
    check_stacked_streak("stacked1000.png");
}

/// The stacked lights' photo `name` gives one streak that covers both reflections, each
/// clearly visible.
fn check_stacked_streak(name: &str) {
    let photo = sample_photo(name);
    let seg = segment(&photo);
    let boxes: Vec<BoundingBox> = seg.streaks.iter().map(|s| s.bbox).collect();
    // One streak: the two reflections are not told apart by the segmentation, which is
    // what makes this the overlapping case.
    assert_eq!(seg.streaks.len(), 1, "streak boxes: {boxes:?}");
    let streak = &seg.streaks[0];
    let lights = samples::stacked_lights();
    for light in &lights {
        let region = reflection_box(light);
        // The streak covers each light's flat-water reflection...
        assert!(
            streak.bbox.x_min <= region.x_min + 5
                && streak.bbox.x_max + 5 >= region.x_max
                && streak.bbox.y_min <= region.y_min
                && streak.bbox.y_max >= region.y_max,
            "{:?} does not cover {} at {region:?}",
            streak.bbox,
            light.name
        );
        // ... and each part is clearly visible: the dark water around is near 0.
        let value = mean_display_value(&photo, &region);
        assert!(value > 0.2, "{}: mean V {value} in {region:?}", light.name);
    }
    // The two reflections do not touch on flat water; the ripples make them one streak.
    let (lower, upper) = (reflection_box(&lights[0]), reflection_box(&lights[1]));
    assert!(lower.y_max < upper.y_min, "{lower:?} {upper:?}");
    assert!(streak.pixels.len() > 1000);
    let c = streak.mean_colour;
    let (max, min) = (c[0].max(c[1]).max(c[2]), c[0].min(c[1]).min(c[2]));
    assert!(min > 0.9 * max, "{c:?}");
}

#[test]
fn table1_light_over_rough_water_gives_one_streak() {
    let (_, photo) = samples::gloss_sample_files(samples::SAMPLE_GLOSSES[0]);
    assert_eq!(photo, "gloss200.png");
    let seg = segment(&sample_photo(&photo));
    let boxes: Vec<BoundingBox> = seg.streaks.iter().map(|s| s.bbox).collect();
    assert_eq!(seg.streaks.len(), 1, "streak boxes: {boxes:?}");
    let streak = &seg.streaks[0];
    let region = reflection_box(&samples::table1_light());
    assert!(
        streak.bbox.overlaps(&region),
        "{:?} vs {region:?}",
        streak.bbox
    );
    // Rougher water spreads the reflection wider than at e = 500 (check_matches allows 60
    // pixels around the flat-water image; here 100).
    let inside = streak
        .pixels
        .iter()
        .filter(|&&p| contains(&grown(region, 100), (p % 600, p / 600)))
        .count();
    assert!(inside as f64 >= 0.9 * streak.pixels.len() as f64);
    assert!(streak.pixels.len() > 1000);
}

/// The streaks of the smooth-water sample lie on the light's reflection. The extraction
/// finds two: a band of brighter ripples (columns 97-264, rows 380-421) grows from its own
/// seed inside the main streak (columns 61-272, rows 330-599).
#[test]
fn table1_light_over_smooth_water_gives_streaks_only_on_its_reflection() {
    let (_, photo) = samples::gloss_sample_files(samples::SAMPLE_GLOSSES[1]);
    assert_eq!(photo, "gloss1000.png");
    let seg = segment(&sample_photo(&photo));
    assert!(!seg.streaks.is_empty());
    let region = grown(reflection_box(&samples::table1_light()), 60);
    for s in &seg.streaks {
        let inside = s
            .pixels
            .iter()
            .filter(|&&p| contains(&region, (p % 600, p / 600)))
            .count();
        assert!(inside as f64 >= 0.9 * s.pixels.len() as f64, "{:?}", s.bbox);
    }
}

/// The extraction's streaks with the fragments of one light merged, as `segment` and `fit`
/// merge them (the scene's water at gloss `gloss`).
fn lights_segment(photo: &Photo, gloss: f32) -> Segmentation {
    let scene = sample_scene("scene.gltf", Some(gloss));
    let pieces = segment(photo);
    let observations: Vec<_> = pieces
        .streaks
        .iter()
        .map(|s| streaklight::pipeline::observation(s, photo.width))
        .collect();
    let (groups, _) = fragments::lights(
        &ExactSurface,
        &scene,
        photo,
        &setup().water,
        &observations,
        &FitOptions::for_scene(&scene),
    );
    pieces.merged(photo, &groups)
}

/// Both streaks of the smooth-water sample are one light's: merged, they are one streak where
/// geometry puts the light's reflection, made of both.
#[test]
fn table1_light_over_smooth_water_gives_one_streak() {
    let photo = sample_photo("gloss1000.png");
    let seg = lights_segment(&photo, 1000.0);
    check_matches(&seg, &[samples::table1_light()]);
    assert_eq!(seg.streaks[0].fragments, vec![0, 1]);
    // One streak holds both fragments' pixels, and its edges are the union's.
    let pieces = segment(&photo);
    let total: usize = pieces.streaks.iter().map(|s| s.pixels.len()).sum();
    assert_eq!(seg.streaks[0].pixels.len(), total);
}

/// Merging leaves streaks of different lights apart.
#[test]
fn table3_lights_stay_two_streaks_when_fragments_are_merged() {
    let seg = lights_segment(&sample_photo("table3.png"), 500.0);
    check_matches(&seg, &samples::table3_lights());
    let fragments: Vec<&[usize]> = seg.streaks.iter().map(|s| &s.fragments[..]).collect();
    assert_eq!(fragments, [&[0][..], &[1][..]]);
}

#[test]
fn a_photo_without_lights_gives_no_streak_and_says_why() {
    let seg = segment(&sample_photo("dark.png"));
    assert!(seg.streaks.is_empty());
    let message = seg.require_streaks().unwrap_err().to_string();
    assert!(message.contains("no streak found"), "{message}");
    assert!(message.contains("t = 0.350"), "{message}");
}

fn with_noise(photo: &Photo, sigma: f32, seed: u64) -> Photo {
    let mut rng = Rng::new(seed, 0x401);
    let display = photo
        .display
        .iter()
        .map(|p| {
            p.map(|c| {
                let v = c + sigma * rng.next_gaussian() as f32;
                (v.clamp(0.0, 1.0) * 255.0).round() / 255.0
            })
        })
        .collect();
    Photo::from_display(photo.width, photo.height, display, samples::PHOTO_EXPOSURE)
}

#[test]
fn noise_of_two_levels_adds_no_streak() {
    let sigma = 2.0 / 255.0;
    let seg = segment(&with_noise(&sample_photo("dark.png"), sigma, 1));
    assert!(seg.streaks.is_empty());
    let seg = segment(&with_noise(&sample_photo("table1.png"), sigma, 2));
    check_matches(&seg, &[samples::table1_light()]);
    let seg = segment(&with_noise(&sample_photo("table3.png"), sigma, 3));
    check_matches(&seg, &samples::table3_lights());
}

#[test]
fn a_mask_of_the_wrong_size_or_without_water_is_refused() {
    let photo = sample_photo("table1.png");
    let params = StreakParams::default();
    assert!(extract_streaks(&photo, &[true; 10], &params).is_err());
    let dry = vec![false; 600 * 600];
    let e = extract_streaks(&photo, &dry, &params)
        .unwrap_err()
        .to_string();
    assert!(e.contains("water covers no pixel"), "{e}");
    let mut bad = StreakParams::default();
    bad.seeds.row_step = 0;
    assert!(extract_streaks(&photo, &setup().water, &bad).is_err());
}

#[test]
fn segment_command_writes_pictures_and_a_report_that_matches_its_schema() {
    let out = common::temp_dir("segment-cli");
    let photo = sample_photo_path("table3.png");
    let scene = sample_scenes().join("scene.gltf");
    let (ok, stdout, stderr) = common::run_cli(&[
        "segment",
        scene.to_str().unwrap(),
        photo.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--exposure",
        "0.1",
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("streak 1 (fragments 1):"), "{stdout}");
    for name in ["superpixels.png", "seeds.png", "streaks.png", "edges.png"] {
        // The photo's size, under a title and a key.
        let img = image::open(out.join(name)).unwrap();
        assert_eq!(img.width(), 600);
        assert!(img.height() > 600, "{name}: {}", img.height());
    }
    let report = read_json(&out.join("streaks.json"));
    let validator = schema_validator("streaks.schema.json");
    let errors: Vec<String> = validator
        .iter_errors(&report)
        .map(|e| e.to_string())
        .collect();
    assert!(errors.is_empty(), "{errors:?}");
    assert_eq!(report["streaks"].as_array().unwrap().len(), 2);
    assert_eq!(report["fragments"].as_array().unwrap().len(), 2);
    // The schema is not vacuous: a report missing a field fails it.
    let mut broken = report.clone();
    broken["streaks"][0].as_object_mut().unwrap().remove("bbox");
    assert!(!validator.is_valid(&broken));

    // Fragments of one light are one streak, which lists them; the report keeps them too.
    let out_smooth = common::temp_dir("segment-cli-smooth");
    let (ok, stdout, stderr) = common::run_cli(&[
        "segment",
        scene.to_str().unwrap(),
        sample_photo_path("gloss1000.png").to_str().unwrap(),
        "--out-dir",
        out_smooth.to_str().unwrap(),
        "--exposure",
        "0.1",
        "--gloss",
        "1000",
    ]);
    assert!(ok, "{stderr}");
    assert!(stdout.contains("streak 0 (fragments 0, 1):"), "{stdout}");
    assert!(!stdout.contains("streak 1"), "{stdout}");
    let report = read_json(&out_smooth.join("streaks.json"));
    assert!(validator.is_valid(&report));
    assert_eq!(report["streaks"].as_array().unwrap().len(), 1);
    assert_eq!(report["streaks"][0]["fragments"], serde_json::json!([0, 1]));
    let pieces = report["fragments"].as_array().unwrap();
    assert_eq!(pieces.len(), 2);
    let pixels = |v: &serde_json::Value| v["pixel_count"].as_u64().unwrap();
    assert_eq!(
        pixels(&report["streaks"][0]),
        pieces.iter().map(pixels).sum::<u64>()
    );

    // No lights: the command fails clearly and writes nothing (a refused run leaves no file).
    let dark = sample_photo_path("dark.png");
    let out_dark = common::temp_dir("segment-cli-dark");
    let (ok, _, stderr) = common::run_cli(&[
        "segment",
        scene.to_str().unwrap(),
        dark.to_str().unwrap(),
        "--out-dir",
        out_dark.to_str().unwrap(),
    ]);
    assert!(!ok);
    assert!(
        stderr.contains("dark.png") && stderr.contains("no streak found"),
        "{stderr}"
    );
    assert!(
        !out_dark.join("streaks.json").exists(),
        "a run that found no streak wrote its report"
    );

    // A bad setting is refused as it is parsed, naming the option and its range.
    let (ok, _, stderr) = common::run_cli(&[
        "segment",
        scene.to_str().unwrap(),
        photo.to_str().unwrap(),
        "--out-dir",
        out.to_str().unwrap(),
        "--seed-threshold",
        "2",
    ]);
    assert!(
        !ok && stderr.contains("--seed-threshold") && stderr.contains("not including, 1"),
        "{stderr}"
    );
}
