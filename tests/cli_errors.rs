//! Bad input gets a clear message naming the file, a non-zero exit, no panic and no output.

mod common;

use serde_json::json;

fn expect_failure(args: &[&str], must_contain: &[&str], output: &std::path::Path) {
    let (ok, _, stderr) = common::run_cli(args);
    assert!(!ok, "{args:?} should fail");
    assert!(!stderr.contains("panicked"), "panic: {stderr}");
    for text in must_contain {
        assert!(
            stderr.contains(text),
            "stderr of {args:?} lacks {text:?}: {stderr}"
        );
    }
    assert!(!output.exists(), "{} was written", output.display());
}

#[test]
fn render_refuses_bad_scenes_clearly() {
    let dir = common::temp_dir("cli-errors");
    let out = dir.join("out.png");
    let o = out.to_str().unwrap();
    let path = |n: &str| dir.join(n).to_str().unwrap().to_owned();

    expect_failure(
        &["render", &path("missing.gltf"), "-o", o],
        &["missing.gltf", "No such file"],
        &out,
    );

    std::fs::write(dir.join("garbage.gltf"), b"\x00\x01 not json").unwrap();
    expect_failure(
        &["render", &path("garbage.gltf"), "-o", o],
        &["garbage.gltf", "not a glTF"],
        &out,
    );

    let good = common::paper_setup(None);
    good.write_glb(&dir.join("good.glb"));
    let bytes = std::fs::read(dir.join("good.glb")).unwrap();
    std::fs::write(dir.join("truncated.glb"), &bytes[..bytes.len() / 2]).unwrap();
    expect_failure(
        &["render", &path("truncated.glb"), "-o", o],
        &["truncated.glb", "truncated"],
        &out,
    );

    let mut no_camera = common::paper_setup(None);
    no_camera.json["scenes"][0]["nodes"] = json!([1, 2]);
    no_camera.write_gltf(&dir.join("nocam.gltf"));
    expect_failure(
        &["render", &path("nocam.gltf"), "-o", o],
        &["nocam.gltf", "no camera"],
        &out,
    );

    let mut no_water = common::paper_setup(None);
    no_water.json["nodes"][1]["name"] = json!("Sea");
    no_water.json["meshes"][0]["name"] = json!("Sea");
    no_water.write_gltf(&dir.join("nowater.gltf"));
    expect_failure(
        &["render", &path("nowater.gltf"), "-o", o],
        &["nowater.gltf", "no water", "\"Sea\"", "\"Wall\""],
        &out,
    );

    let mut two = common::paper_setup(None);
    let (p, n, i) = common::flat_grid(-1.0, 1.0, -1.0, 1.0, 1, 1, 0.0);
    two.add_mesh("Water2", &p, Some(&n), Some(&i), 4, None);
    two.write_gltf(&dir.join("two.gltf"));
    expect_failure(
        &["render", &path("two.gltf"), "-o", o],
        &["two.gltf", "\"Water\"", "\"Water2\"", "--water"],
        &out,
    );

    // A buffer that declares more bytes than its file holds.
    good.write_gltf_external(&dir.join("short.gltf"), "short.bin");
    let bin = std::fs::read(dir.join("short.bin")).unwrap();
    std::fs::write(dir.join("short.bin"), &bin[..bin.len() - 100]).unwrap();
    expect_failure(
        &["render", &path("short.gltf"), "-o", o],
        &["short.gltf", "too short"],
        &out,
    );

    // A buffer view that reaches past its (correctly sized) buffer.
    let mut views = common::paper_setup(None);
    views.json["bufferViews"][0]["byteLength"] = json!(10_000_000);
    views.write_gltf(&dir.join("view.gltf"));
    expect_failure(
        &["render", &path("view.gltf"), "-o", o],
        &["view.gltf"],
        &out,
    );

    // An index beyond the vertices.
    let mut bad_index = common::TestScene::new();
    bad_index.add_camera("Camera", [0.0, 0.2, 10.0], 60.0);
    bad_index.add_mesh(
        "Water",
        &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        None,
        Some(&[0, 1, 7]),
        4,
        None,
    );
    bad_index.write_gltf(&dir.join("index.gltf"));
    expect_failure(
        &["render", &path("index.gltf"), "-o", o],
        &["index.gltf", "out of range"],
        &out,
    );

    // The output path is the input.
    good.write_gltf(&dir.join("same.gltf"));
    let before = std::fs::read(dir.join("same.gltf")).unwrap();
    let (ok, _, stderr) =
        common::run_cli(&["render", &path("same.gltf"), "-o", &path("same.gltf")]);
    assert!(!ok && !stderr.contains("panicked"));
    assert_eq!(std::fs::read(dir.join("same.gltf")).unwrap(), before);
    // Also spelled differently and with a supported extension.
    std::fs::copy(dir.join("same.gltf"), dir.join("same.png")).unwrap();
    let (ok, _, stderr) = common::run_cli(&[
        "render",
        &path("same.png"),
        "-o",
        &format!("{}/./same.png", dir.display()),
    ]);
    assert!(!ok && stderr.contains("input"), "{stderr}");

    // An output format we cannot write.
    expect_failure(
        &["render", &path("good.glb"), "-o", &path("out.bmp")],
        &["out.bmp", ".png"],
        &dir.join("out.bmp"),
    );
    // Nonsense numbers.
    expect_failure(
        &["render", &path("good.glb"), "-o", o, "--exposure=-1"],
        &["--exposure"],
        &out,
    );
    expect_failure(
        &["render", &path("good.glb"), "-o", o, "--gloss", "0"],
        &["--gloss"],
        &out,
    );
    expect_failure(
        &["render", &path("good.glb"), "-o", o, "--spp", "0"],
        &["--spp"],
        &out,
    );
    // No leftover temporary files.
    for entry in std::fs::read_dir(&dir).unwrap() {
        let name = entry.unwrap().file_name();
        assert!(
            !name.to_string_lossy().contains("tmp-streaklight"),
            "{name:?}"
        );
    }
}

#[test]
fn restore_lights_refuses_bad_input_clearly() {
    let dir = common::temp_dir("cli-restore");
    let out = dir.join("out.gltf");
    let o = out.to_str().unwrap();
    let path = |n: &str| dir.join(n).to_str().unwrap().to_owned();
    expect_failure(
        &["restore-lights", &path("missing.gltf"), "-o", o],
        &["missing.gltf", "No such file"],
        &out,
    );
    // No fallback quad to read the lights from.
    common::paper_setup(None).write_gltf(&dir.join("plain.gltf"));
    expect_failure(
        &["restore-lights", &path("plain.gltf"), "-o", o],
        &["plain.gltf", "nothing to restore"],
        &out,
    );
    // A quad whose recorded light is not a rectangle, or has no transform to put it at.
    let mut bad = common::paper_setup(None);
    bad.json["nodes"].as_array_mut().unwrap().push(json!({
        "name": "quad",
        "extras": { "streaklight": { "role": "fallback-quad", "light": { "type": "disk" } } }
    }));
    bad.write_gltf(&dir.join("bad.gltf"));
    expect_failure(
        &["restore-lights", &path("bad.gltf"), "-o", o],
        &["bad.gltf", "not a rect light"],
        &out,
    );
    let mut lost = bad;
    let quad = lost.json["nodes"].as_array().unwrap().len() - 1;
    lost.json["nodes"][quad]["extras"]["streaklight"]["light"] = json!({
        "type": "rect", "color": [1.0, 1.0, 1.0], "intensity": 1.0, "size": 1.0,
        "rect": { "aspect": 1.0 }, "name": "l"
    });
    lost.write_gltf(&dir.join("lost.gltf"));
    expect_failure(
        &["restore-lights", &path("lost.gltf"), "-o", o],
        &["lost.gltf", "translation and rotation"],
        &out,
    );
    // Never over the input.
    let input = dir.join("lost.gltf");
    let before = std::fs::read(&input).unwrap();
    let (ok, _, stderr) = common::run_cli(&[
        "restore-lights",
        &path("lost.gltf"),
        "-o",
        &path("lost.gltf"),
    ]);
    assert!(!ok && stderr.contains("input"), "{stderr}");
    assert_eq!(std::fs::read(&input).unwrap(), before);
}
