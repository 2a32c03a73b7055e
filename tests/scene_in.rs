//! Loading scenes: formats, transforms, roles, and what is skipped or refused.

mod common;

use glam::Vec3;
use serde_json::json;
use streaklight::scene_in::{load, LoadOptions};

fn opts() -> LoadOptions {
    LoadOptions::default()
}

#[test]
fn gltf_embedded_external_and_glb_load_the_same_triangles() {
    let dir = common::temp_dir("formats");
    let s = common::paper_setup(None);
    s.write_gltf(&dir.join("a.gltf"));
    s.write_gltf_external(&dir.join("b.gltf"), "b data.bin");
    s.write_glb(&dir.join("c.glb"));
    // The external buffer's URI is percent-encoded as URIs must be.
    let text = std::fs::read_to_string(dir.join("b.gltf")).unwrap();
    std::fs::write(
        dir.join("b.gltf"),
        text.replace("b data.bin", "b%20data.bin"),
    )
    .unwrap();
    let a = load(&dir.join("a.gltf"), &opts()).unwrap();
    let b = load(&dir.join("b.gltf"), &opts()).unwrap();
    let c = load(&dir.join("c.glb"), &opts()).unwrap();
    // 48 x 23 cells of two triangles, plus the wall's two.
    assert_eq!(a.triangles.len(), 48 * 23 * 2 + 2);
    assert_eq!(a.triangles, b.triangles);
    assert_eq!(a.triangles, c.triangles);
    assert_eq!(a.water.name, "Water");
    assert_eq!(a.camera.name, "Camera");
    // No material: the default gloss with a warning; IOR of water, not glTF's 1.5.
    assert_eq!(a.water.gloss, 500.0);
    assert!(a.warnings.iter().any(|w| w.contains("no material")));
    assert!((a.water.ior - 1.33).abs() < 1e-6);
}

#[test]
fn gloss_and_ior_come_from_the_material_unless_overridden() {
    let dir = common::temp_dir("material");
    let s = common::paper_setup(Some(
        json!({"pbrMetallicRoughness": {"roughnessFactor": 0.2512},
        "extensions": {"KHR_materials_ior": {"ior": 1.34}}}),
    ));
    s.write_gltf(&dir.join("m.gltf"));
    let scene = load(&dir.join("m.gltf"), &opts()).unwrap();
    assert!(
        (scene.water.gloss - 500.0).abs() < 1.0,
        "{}",
        scene.water.gloss
    );
    assert!((scene.water.ior - 1.34).abs() < 1e-6);
    let scene = load(
        &dir.join("m.gltf"),
        &LoadOptions {
            gloss: Some(200.0),
            ior: Some(1.5),
            ..opts()
        },
    )
    .unwrap();
    assert_eq!(scene.water.gloss, 200.0);
    assert_eq!(scene.water.ior, 1.5);
}

#[test]
fn node_hierarchy_is_baked_in_f64_and_recentred_on_the_camera() {
    let dir = common::temp_dir("hierarchy");
    let mut s = common::TestScene::new();
    // Everything 100 km from the origin: f32 world coordinates would be 8 mm apart there.
    let far = 100_000.0;
    let parent_cam = s.add_root_node(json!({"name": "Rig", "translation": [far, 0.0, 0.0]}));
    let cam = s.add_camera("Camera", [0.0, 0.2, 10.0], 60.0);
    // Move the camera node under the rig.
    s.json["scenes"][0]["nodes"] = json!([parent_cam]);
    s.json["nodes"][parent_cam]["children"] = json!([cam]);
    // A water triangle under a parent that translates, rotates 90 degrees about y and scales 2.
    let tri = [[0.0f32, 0.0, 0.0], [0.001, 0.0, 0.0], [0.0, 0.0, -0.001]];
    let water = s.add_mesh("Water", &tri, None, None, 4, None);
    let rot = (
        std::f64::consts::FRAC_PI_4.sin(),
        std::f64::consts::FRAC_PI_4.cos(),
    );
    let parent = s.add_root_node(
        json!({"name": "Parent", "translation": [far + 1.0, 0.0, 5.0],
        "rotation": [0.0, rot.0, 0.0, rot.1], "scale": [2.0, 2.0, 2.0], "children": [water]}),
    );
    s.json["scenes"][0]["nodes"] = json!([parent_cam, parent]);
    s.write_gltf(&dir.join("h.gltf"));
    let scene = load(&dir.join("h.gltf"), &opts()).unwrap();
    assert_eq!(scene.origin.x, far);
    assert!(scene.camera.position.length() < 1e-6);
    // Rotation by +90 degrees about y maps x to -z and -z to -x; scale 2; then translate.
    // World minus camera (far, 0.2, 10): (1, -0.2, -5) + rotated/scaled corners.
    let v = scene.triangles[0];
    let expect = [
        Vec3::new(1.0, -0.2, -5.0),
        Vec3::new(1.0, -0.2, -5.0 - 0.002),
        Vec3::new(1.0 - 0.002, -0.2, -5.0),
    ];
    for k in 0..3 {
        assert!(
            (v[k] - expect[k]).length() < 1e-6,
            "corner {k}: {:?} vs {:?}",
            v[k],
            expect[k]
        );
    }
}

#[test]
fn unknown_required_extensions_and_animation_pointers_do_not_stop_loading() {
    let dir = common::temp_dir("extensions");
    let mut s = common::paper_setup(None);
    s.json["extensionsUsed"] = json!(["EXT_something_new", "KHR_animation_pointer"]);
    s.json["extensionsRequired"] = json!(["EXT_something_new"]);
    s.json["animations"] = json!([{"channels": [{"sampler": 0, "target": {"path": "pointer",
        "extensions": {"KHR_animation_pointer": {"pointer": "/materials/0/emissiveFactor"}}}}],
        "samplers": [{"input": 0, "output": 0}]}]);
    s.write_gltf(&dir.join("e.gltf"));
    let scene = load(&dir.join("e.gltf"), &opts()).unwrap();
    assert_eq!(scene.water.name, "Water");
}

#[test]
fn non_triangles_are_skipped_and_degenerate_triangles_counted() {
    let dir = common::temp_dir("skips");
    let mut s = common::paper_setup(None);
    let pts = [[0.0f32, 1.0, 0.0], [1.0, 1.0, 0.0], [1.0, 2.0, 0.0]];
    s.add_mesh("Lines", &pts, None, None, 1, None);
    // Two degenerate triangles (a repeated corner, collinear corners) and one good one.
    let tris = [
        [0.0f32, 0.0, 1.0],
        [0.0, 0.0, 1.0],
        [1.0, 0.0, 1.0],
        [0.0, 0.0, 2.0],
        [1.0, 0.0, 2.0],
        [2.0, 0.0, 2.0],
        [0.0, 0.0, 3.0],
        [1.0, 0.0, 3.0],
        [0.0, 1.0, 3.0],
    ];
    s.add_mesh("Junk", &tris, None, None, 4, None);
    s.write_gltf(&dir.join("s.gltf"));
    let scene = load(&dir.join("s.gltf"), &opts()).unwrap();
    assert_eq!(scene.dropped_triangles, 2);
    assert_eq!(scene.triangles.len(), 48 * 23 * 2 + 2 + 1);
    // The good one is kept last, its corners and its (face) normals together.
    let (t, n) = (
        scene.triangles.last().unwrap(),
        scene.normals.last().unwrap(),
    );
    assert_eq!((t[1] - t[0], t[2] - t[0]), (glam::Vec3::X, glam::Vec3::Y));
    assert_eq!(*n, [glam::Vec3::Z; 3]);
    assert!(scene.warnings.iter().any(|w| w.contains("not triangles")));
    assert!(scene.warnings.iter().any(|w| w.contains("2 degenerate")));
}

#[test]
fn camera_and_water_can_be_chosen_by_name() {
    let dir = common::temp_dir("choose");
    let mut s = common::paper_setup(None);
    s.add_camera("Second", [1.0, 2.0, 3.0], 40.0);
    let (p, n, i) = common::flat_grid(-1.0, 1.0, -1.0, 1.0, 2, 2, -5.0);
    s.add_mesh("Pond", &p, Some(&n), Some(&i), 4, None);
    s.write_gltf(&dir.join("c.gltf"));
    let scene = load(&dir.join("c.gltf"), &opts()).unwrap();
    assert_eq!(scene.camera.name, "Camera");
    let scene = load(
        &dir.join("c.gltf"),
        &LoadOptions {
            camera: Some("Second".into()),
            water: Some("Pond".into()),
            ..opts()
        },
    )
    .unwrap();
    assert_eq!(scene.camera.name, "Second");
    assert!((scene.camera.yfov - 40f32.to_radians()).abs() < 1e-6);
    assert_eq!(scene.water.name, "Pond");
    assert_eq!(scene.is_water.iter().filter(|&&w| w).count(), 8);
}

#[test]
fn area_lights_are_read_and_fallback_quads_ignored() {
    let dir = common::temp_dir("lights");
    let mut s = common::paper_setup(None);
    let light = s.add_light_facing_z("L", [-2.5, 3.5, 0.0], 3.0, 2.0, [20.0, 10.0, 0.0]);
    // A fallback quad under the light, as `fit` writes it: not geometry.
    let quad = [
        [-1.5f32, -1.0, 0.0],
        [1.5, -1.0, 0.0],
        [1.5, 1.0, 0.0],
        [-1.5, 1.0, 0.0],
    ];
    let q = s.add_mesh("Quad", &quad, None, Some(&[0, 1, 2, 0, 2, 3]), 4, None);
    s.json["scenes"][0]["nodes"]
        .as_array_mut()
        .unwrap()
        .retain(|n| n != &json!(q));
    s.json["nodes"][q]["extras"] = json!({"streaklight": {"role": "fallback-quad"}});
    s.json["nodes"][light]["children"] = json!([q]);
    s.write_gltf(&dir.join("l.gltf"));
    let scene = load(
        &dir.join("l.gltf"),
        &LoadOptions {
            nits_scale: 2.0,
            ..opts()
        },
    )
    .unwrap();
    assert_eq!(scene.triangles.len(), 48 * 23 * 2 + 2);
    assert_eq!(scene.area_lights.len(), 1);
    let l = &scene.area_lights[0];
    assert!((l.width() - 3.0).abs() < 1e-5 && (l.height() - 2.0).abs() < 1e-5);
    assert!(
        (l.normal - Vec3::Z).length() < 1e-6,
        "emits towards +z: {:?}",
        l.normal
    );
    // Centre relative to the camera at (0, 0.2, 10); radiance = colour x intensity / 2.
    assert!((l.center - Vec3::new(-2.5, 3.3, -10.0)).length() < 1e-5);
    assert_eq!(l.radiance, [10.0, 5.0, 0.0]);
}
