//! Where the glTF writer's files go (`streaklight::scene_out`, method §7): the binary data
//! each output format gets, self-contained outputs (a `.glb` holds everything, a `.gltf`'s
//! folder holds copies of every file it needs), input files referred to where they are only
//! when asked, and refusals that write nothing.
//!
//! Needs `node` and `npm ci --prefix tests/validator` for the validator checks.

use std::collections::BTreeSet;
use std::path::{Path, PathBuf};

mod common;

use common::dirs::{sorted_paths, temp_dir};
use common::gltf_builder::glb;
use common::gltf_check::{assert_same_data, lights_by_name, load, resolve};
use common::scene_out_case::{generated_inputs, triangle_bytes, two_lights};
use common::scene_out_checks::{assert_self_contained, check_output};
use common::validator::{assert_validator_clean, validator_problems};
use serde_json::{json, Value};
use streaklight::scene_out::{
    write_lit_scene, write_lit_scene_with, CopiesAhead, InputFiles, NewData, ResourceKind,
    WriteOptions,
};

#[test]
fn new_data_goes_where_the_table_says() {
    let dir = temp_dir("placement");
    let inputs = generated_inputs(&dir);
    let lights = two_lights();
    let opts = WriteOptions::default();
    let write =
        |input: &Path, out: &str| write_lit_scene(input, &dir.join(out), &lights, &opts).unwrap();
    let (external, embedded, glb_in, bare) = (&inputs[0], &inputs[1], &inputs[2], &inputs[3]);
    // .glb -> .glb: appended to the BIN chunk at an aligned offset after the input's bytes.
    let s = write(glb_in, "a.glb");
    let in_len = load(glb_in).buffers[0].len();
    assert_eq!(
        s.resources.new_data,
        NewData::AppendedToBuffer {
            buffer: 0,
            byte_offset: in_len.div_ceil(4) * 4
        }
    );
    assert!(s.resources.embedded.is_empty());
    assert_eq!(load(&dir.join("a.glb")).buffers.len(), 1);
    assert_eq!(s.resources.files_written, vec![dir.join("a.glb")]);
    // .glb -> .gltf: the BIN chunk and our data become <out>.streaklight.bin.
    let s = write(glb_in, "b.gltf");
    assert_eq!(
        s.resources.bin_chunk_moved_to,
        Some(dir.join("b.streaklight.bin"))
    );
    assert_eq!(
        load(&dir.join("b.gltf")).json["buffers"][0]["uri"],
        "b.streaklight.bin"
    );
    assert_eq!(
        s.resources.files_written,
        vec![dir.join("b.streaklight.bin"), dir.join("b.gltf")]
    );
    // .gltf with an external buffer 0, a data: buffer 1 and an external image -> .glb: all
    // three in the BIN chunk, buffer 1 4-byte aligned after the 42 bytes of buffer 0, the image
    // after it; our data after those; nothing written but the .glb.
    let s = write(external, "c.glb");
    assert_eq!(
        s.resources.embedded,
        vec![
            (ResourceKind::Buffer, 0),
            (ResourceKind::Buffer, 1),
            (ResourceKind::Image, 0)
        ]
    );
    let c = load(&dir.join("c.glb"));
    assert_eq!(
        c.json["buffers"],
        json!([{ "byteLength": c.buffers[0].len() }])
    );
    assert_eq!(
        c.json["bufferViews"][2],
        json!({ "buffer": 0, "byteLength": 24, "target": 34962, "byteOffset": 44 })
    );
    let image_view = c.json["images"][0]["bufferView"].as_u64().unwrap() as usize;
    assert_eq!(c.json["bufferViews"][image_view]["byteOffset"], 68);
    assert_eq!(c.json["images"][0]["mimeType"], "image/png");
    let image_end = 68
        + c.json["bufferViews"][image_view]["byteLength"]
            .as_u64()
            .unwrap();
    assert_eq!(
        s.resources.new_data,
        NewData::AppendedToBuffer {
            buffer: 0,
            byte_offset: (image_end as usize).div_ceil(4) * 4
        }
    );
    assert_eq!(s.resources.files_written, vec![dir.join("c.glb")]);
    // .gltf with data: URIs only -> .glb: the same, and no DATA_URI_GLB warning left.
    let s = write(embedded, "c2.glb");
    assert_eq!(s.resources.embedded.len(), 3);
    assert!(validator_problems(&dir.join("c2.glb")).is_empty());
    // .gltf -> .gltf: its files copied beside the output, our data in a new buffer file.
    let s = write(external, "d.gltf");
    assert_eq!(
        s.resources.new_data,
        NewData::NewBuffer {
            buffer: 2,
            file: Some(dir.join("d.streaklight.bin"))
        }
    );
    assert_eq!(
        s.resources.files_written,
        vec![
            dir.join("d.buffer0.bin"),
            dir.join("d.image0.png"),
            dir.join("d.streaklight.bin"),
            dir.join("d.gltf")
        ]
    );
    let d = load(&dir.join("d.gltf"));
    assert_eq!(d.json["buffers"][0]["uri"], "d.buffer0.bin");
    assert_eq!(d.json["images"][0]["uri"], "d.image0.png");
    // No buffers at all -> .glb: a new BIN chunk as buffer 0; the new scene is the default.
    let s = write(bare, "e.glb");
    assert_eq!(
        s.resources.new_data,
        NewData::NewBuffer {
            buffer: 0,
            file: None
        }
    );
    let e = load(&dir.join("e.glb"));
    assert_eq!(e.json["scene"], json!(0));
    assert_eq!(e.json["scenes"][0]["nodes"], json!(s.node_indices));
    // Fallback quads off: no new binary data, no mesh, no emissive extension.
    let off = WriteOptions {
        fallback_quads: false,
        nits_scale: 683.0,
        ..WriteOptions::default()
    };
    let s = write_lit_scene(external, &dir.join("f.gltf"), &lights, &off).unwrap();
    assert_eq!(s.resources.new_data, NewData::Nothing);
    assert!(!dir.join("f.streaklight.bin").exists());
    check_output(external, &dir.join("f.gltf"), &lights, &off, &s);
    let f = load(&dir.join("f.gltf"));
    assert!(!f.json["extensionsUsed"]
        .as_array()
        .unwrap()
        .iter()
        .any(|e| e == "KHR_materials_emissive_strength"));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn outputs_stand_alone_and_never_share_a_file() {
    let dir = temp_dir("standalone");
    let inputs = generated_inputs(&dir.join("in"));
    let lights = two_lights();
    let opts = WriteOptions::default();
    // x.gltf then x.glb into one folder, from every input: no file written twice, and the
    // first output is still whole after the second.
    for input in &inputs {
        let out = dir.join("out").join(input.file_stem().unwrap());
        std::fs::create_dir_all(&out).unwrap();
        let gltf = out.join("x.gltf");
        let glb_out = out.join("x.glb");
        let a = write_lit_scene(input, &gltf, &lights, &opts).unwrap();
        let b = write_lit_scene(input, &glb_out, &lights, &opts).unwrap();
        let first: BTreeSet<&PathBuf> = a.resources.files_written.iter().collect();
        assert!(
            b.resources.files_written.iter().all(|f| !first.contains(f)),
            "{}: {:?} and {:?} share a file",
            input.display(),
            a.resources.files_written,
            b.resources.files_written
        );
        check_output(input, &gltf, &lights, &opts, &a);
        check_output(input, &glb_out, &lights, &opts, &b);
    }
    // Moved elsewhere without the input's folder: the .glb alone, and the .gltf's folder.
    let (input, moved) = (&inputs[0], dir.join("moved"));
    let out = dir.join("out").join("external");
    std::fs::create_dir_all(&moved).unwrap();
    for name in sorted_paths(&out) {
        std::fs::copy(&name, moved.join(name.file_name().unwrap())).unwrap();
    }
    // The input as it was, read from elsewhere once its folder is gone.
    let kept = dir.join("kept");
    std::fs::rename(input.parent().unwrap(), &kept).unwrap();
    std::fs::remove_dir_all(dir.join("in")).unwrap();
    let before = load(&kept.join(input.file_name().unwrap()));
    for name in ["x.gltf", "x.glb"] {
        let moved_out = moved.join(name);
        assert_validator_clean(&moved_out);
        assert_self_contained(&moved_out);
        assert_same_data(&before, &load(&moved_out));
    }
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn input_files_are_referred_to_where_they_are_only_when_asked() {
    let dir = temp_dir("reference");
    let input = generated_inputs(&dir.join("in")).remove(0);
    let lights = two_lights();
    let opts = WriteOptions {
        input_files: InputFiles::Reference,
        ..WriteOptions::default()
    };
    let out = dir.join("out").join("deeper");
    std::fs::create_dir_all(&out).unwrap();
    let output = out.join("r.gltf");
    let s = write_lit_scene(&input, &output, &lights, &opts).unwrap();
    check_output(&input, &output, &lights, &opts, &s);
    assert!(s.resources.copied.is_empty());
    assert_eq!(s.resources.rewritten_uris.len(), 2);
    assert_eq!(s.resources.warnings.len(), 1, "{:?}", s.resources.warnings);
    assert!(s.resources.warnings[0].contains("2 file(s)"));
    // Each URI reaches the input's own file, not a copy.
    let (a, b) = (load(&input), load(&output));
    for pointer in ["/buffers/0/uri", "/images/0/uri"] {
        let file = |doc: &Path, json: &Value| {
            resolve(doc, json.pointer(pointer).unwrap().as_str().unwrap())
                .unwrap()
                .canonicalize()
                .unwrap()
        };
        assert_eq!(file(&input, &a.json), file(&output, &b.json), "{pointer}");
    }
    assert_eq!(
        sorted_paths(&out),
        vec![out.join("r.gltf"), out.join("r.streaklight.bin")]
    );
    // A .glb holds everything: referring to files is refused, and nothing is written.
    let e = write_lit_scene(&input, &out.join("r.glb"), &lights, &opts).unwrap_err();
    assert!(
        e.to_string().contains("r.glb") && e.to_string().contains(".gltf"),
        "{e}"
    );
    assert!(!out.join("r.glb").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_meshopt_fallback_buffer_stays_a_buffer_of_its_own() {
    // glTF-Transform's `optimize` writes EXT_meshopt_compression: a fallback buffer without a
    // URI (readers decompress instead), and buffer views naming it, whose compressed bytes are
    // in another buffer.
    let dir = temp_dir("meshopt");
    std::fs::write(dir.join("data.bin"), triangle_bytes()).unwrap();
    let input = dir.join("m.gltf");
    let json = json!({
        "asset": { "version": "2.0" },
        "extensionsUsed": ["EXT_meshopt_compression"],
        "buffers": [
            { "byteLength": 24, "extensions": { "EXT_meshopt_compression": { "fallback": true } } },
            { "byteLength": 42, "uri": "data.bin" }
        ],
        "bufferViews": [
            { "buffer": 0, "byteLength": 24, "byteStride": 12,
              "extensions": { "EXT_meshopt_compression": {
                  "buffer": 1, "byteOffset": 4, "byteLength": 36, "byteStride": 12,
                  "count": 2, "mode": "ATTRIBUTES" } } },
            { "buffer": 1, "byteOffset": 36, "byteLength": 6 }
        ],
        "nodes": [{ "name": "n" }],
        "scenes": [{ "nodes": [0] }]
    });
    std::fs::write(&input, serde_json::to_vec(&json).unwrap()).unwrap();
    let lights = two_lights();
    let opts = WriteOptions::default();
    // .glb: data.bin is buffer 0 (its views and the compressed view moved there), the fallback
    // follows it, and its view names it at its new index.
    let s = write_lit_scene(&input, &dir.join("m.glb"), &lights, &opts).unwrap();
    assert_eq!(
        s.resources.new_data,
        NewData::AppendedToBuffer {
            buffer: 0,
            byte_offset: 44
        }
    );
    let loaded = load(&dir.join("m.glb"));
    assert_eq!(&loaded.buffers[0][..42], &triangle_bytes()[..]);
    let g = loaded.json;
    assert_eq!(g["buffers"].as_array().unwrap().len(), 2);
    assert_eq!(g["buffers"][1], json["buffers"][0]);
    assert_eq!(g["bufferViews"][0]["buffer"], 1);
    assert!(g["bufferViews"][0].get("byteOffset").is_none());
    let compressed = &g["bufferViews"][0]["extensions"]["EXT_meshopt_compression"];
    assert_eq!(
        (&compressed["buffer"], &compressed["byteOffset"]),
        (&json!(0), &json!(4))
    );
    assert_eq!(
        g["bufferViews"][1],
        json!({ "buffer": 0, "byteOffset": 36, "byteLength": 6 })
    );
    // .gltf: the fallback stays as it is; data.bin is copied.
    write_lit_scene(&input, &dir.join("n.gltf"), &lights, &opts).unwrap();
    let n = load(&dir.join("n.gltf")).json;
    assert_eq!(n["buffers"][0], json["buffers"][0]);
    assert_eq!(n["buffers"][1]["uri"], "n.buffer1.bin");
    assert_eq!(n["bufferViews"][0], json["bufferViews"][0]);
    assert_eq!(n["bufferViews"][1], json["bufferViews"][1]);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// Asserts `result` is an error whose message contains every one of `words`, and that the
/// folder `dir` holds exactly the files `before` (nothing written, no temporary left).
fn assert_refused<T: std::fmt::Debug>(
    result: streaklight::Result<T>,
    words: &[&str],
    dir: &Path,
    before: &[PathBuf],
) {
    let message = result.expect_err("must be refused").to_string();
    for w in words {
        assert!(
            message.contains(w),
            "message {message:?} should mention {w:?}"
        );
    }
    let now = sorted_paths(dir);
    assert_eq!(now, before, "files changed after: {message}");
}

#[test]
fn bad_inputs_are_refused_and_nothing_is_written() {
    let dir = temp_dir("bad");
    let good_json = json!({ "asset": { "version": "2.0" }, "buffers": [{ "byteLength": 42 }] });
    let good = glb(&good_json, Some(&triangle_bytes()), &[]);
    std::fs::write(dir.join("truncated.glb"), &good[..good.len() - 10]).unwrap();
    let mut magic = good.clone();
    magic[..4].copy_from_slice(b"glTX");
    std::fs::write(dir.join("magic.glb"), &magic).unwrap();
    let mut chunk = good.clone();
    chunk[12..16].copy_from_slice(&10_000u32.to_le_bytes());
    std::fs::write(dir.join("chunk.glb"), &chunk).unwrap();
    std::fs::write(dir.join("notgltf.gltf"), br#"{"hello": "world"}"#).unwrap();
    std::fs::write(dir.join("notjson.gltf"), b"solid cube\nendsolid\n").unwrap();
    std::fs::write(dir.join("gltf1.gltf"), br#"{"asset": {"version": "1.0"}}"#).unwrap();
    std::fs::write(dir.join("good.glb"), &good).unwrap();
    // A .gltf whose buffer file is named like our output's .bin.
    std::fs::write(dir.join("uses.gltf"), serde_json::to_vec(&json!({
        "asset": { "version": "2.0" }, "buffers": [{ "byteLength": 42, "uri": "out.streaklight.bin" }]
    })).unwrap()).unwrap();
    std::fs::write(dir.join("out.streaklight.bin"), triangle_bytes()).unwrap();
    // One whose buffer file is named like the copy a .gltf output would make of it.
    std::fs::write(dir.join("clash.gltf"), serde_json::to_vec(&json!({
        "asset": { "version": "2.0" }, "buffers": [{ "byteLength": 42, "uri": "out.buffer0.bin" }]
    })).unwrap()).unwrap();
    std::fs::write(dir.join("out.buffer0.bin"), triangle_bytes()).unwrap();
    // A .gltf buffer without a URI (only a meshopt fallback may have none), and one whose
    // file is missing.
    std::fs::write(
        dir.join("nouri.gltf"),
        serde_json::to_vec(&json!({
            "asset": { "version": "2.0" }, "buffers": [{ "byteLength": 42 }]
        }))
        .unwrap(),
    )
    .unwrap();
    std::fs::write(
        dir.join("nofile.gltf"),
        serde_json::to_vec(&json!({
            "asset": { "version": "2.0" }, "buffers": [{ "byteLength": 42, "uri": "gone.bin" }]
        }))
        .unwrap(),
    )
    .unwrap();
    let before = sorted_paths(&dir);
    let lights = two_lights();
    let o = WriteOptions::default();
    let out = dir.join("out.gltf");
    let cases: Vec<(&str, PathBuf, Vec<&str>)> = vec![
        ("missing.gltf", out.clone(), vec!["missing.gltf"]),
        (
            "truncated.glb",
            out.clone(),
            vec!["truncated.glb", "corrupt GLB"],
        ),
        ("magic.glb", out.clone(), vec!["magic.glb", "magic"]),
        ("chunk.glb", out.clone(), vec!["chunk.glb", "corrupt GLB"]),
        (
            "notgltf.gltf",
            out.clone(),
            vec!["notgltf.gltf", "not a glTF"],
        ),
        (
            "notjson.gltf",
            out.clone(),
            vec!["notjson.gltf", "not a glTF"],
        ),
        ("gltf1.gltf", out.clone(), vec!["gltf1.gltf", "2.x"]),
        ("good.glb", dir.join("good.glb"), vec!["good.glb", "input"]),
        ("good.glb", dir.join("good.obj"), vec!["good.obj", ".gltf"]),
        (
            "good.glb",
            dir.join("nowhere").join("x.glb"),
            vec!["nowhere", "does not exist"],
        ),
        ("clash.gltf", out.clone(), vec!["out.buffer0.bin", "input"]),
        (
            "nouri.gltf",
            out.clone(),
            vec!["nouri.gltf", "buffer 0", "uri"],
        ),
        ("nofile.gltf", out.clone(), vec!["gone.bin"]),
        (
            "nofile.gltf",
            dir.join("out.glb"),
            vec!["nofile.gltf", "gone.bin"],
        ),
        (
            "uses.gltf",
            out.clone(),
            vec!["out.streaklight.bin", "input"],
        ),
    ];
    for (input, output, words) in cases {
        assert_refused(
            write_lit_scene(&dir.join(input), &output, &lights, &o),
            &words,
            &dir,
            &before,
        );
    }
    // Output named like the input but spelled differently.
    let other_spelling = dir.join(".").join("good.glb");
    assert_refused(
        write_lit_scene(&dir.join("good.glb"), &other_spelling, &lights, &o),
        &["input"],
        &dir,
        &before,
    );
    // A light that is not a rectangle, a bad nits scale.
    let mut bad = two_lights();
    bad[1].width = -1.0;
    assert_refused(
        write_lit_scene(&dir.join("good.glb"), &out, &bad, &o),
        &["pole light", "width"],
        &dir,
        &before,
    );
    let zero = WriteOptions {
        nits_scale: 0.0,
        ..WriteOptions::default()
    };
    assert_refused(
        write_lit_scene(&dir.join("good.glb"), &out, &lights, &zero),
        &["nits"],
        &dir,
        &before,
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_failed_scene_write_leaves_no_stray_bin() {
    let dir = temp_dir("stray");
    let input = generated_inputs(&dir).remove(2); // the .glb
                                                  // The output's name is taken by a folder, so writing the scene fails after the .bin.
    let output = dir.join("blocked.gltf");
    std::fs::create_dir_all(&output).unwrap();
    let err = write_lit_scene(&input, &output, &two_lights(), &WriteOptions::default());
    assert!(err.is_err());
    assert!(!dir.join("blocked.streaklight.bin").exists());
    // A .bin that was there before gets its old content back.
    std::fs::write(dir.join("blocked.streaklight.bin"), b"old").unwrap();
    assert!(write_lit_scene(&input, &output, &two_lights(), &WriteOptions::default()).is_err());
    assert_eq!(
        std::fs::read(dir.join("blocked.streaklight.bin")).unwrap(),
        b"old"
    );
    let leftovers: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| e.file_name().to_string_lossy().contains("tmp-streaklight"))
        .collect();
    assert!(leftovers.is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn copies_written_ahead_are_the_files_written_at_the_end() {
    // Every input kind written as a .gltf (copies beside it), once at the end and once with
    // its copies written ahead: the same files, byte for byte, and no temporary left. A
    // start never finished removes what it wrote; a start whose copy would land on an input
    // is refused at the end as without it, the input untouched.
    let dir = temp_dir("ahead");
    let inputs = generated_inputs(&dir);
    let lights = two_lights();
    let opts = WriteOptions::default();
    // Every entry of a folder with its bytes (a folder by its name alone).
    let files = |d: &Path| -> Vec<(String, Vec<u8>)> {
        sorted_paths(d)
            .into_iter()
            .map(|p| {
                let bytes = if p.is_dir() {
                    Vec::new()
                } else {
                    std::fs::read(&p).unwrap()
                };
                (p.file_name().unwrap().to_string_lossy().into_owned(), bytes)
            })
            .collect()
    };
    let mut copied = 0;
    for (k, input) in inputs.iter().enumerate() {
        let (end, ahead) = (dir.join(format!("end{k}")), dir.join(format!("ahead{k}")));
        std::fs::create_dir_all(&end).unwrap();
        std::fs::create_dir_all(&ahead).unwrap();
        let at_end = write_lit_scene(input, &end.join("out.gltf"), &lights, &opts).unwrap();
        let out = ahead.join("out.gltf");
        let started = CopiesAhead::start(input, &out, InputFiles::Copy);
        let with = write_lit_scene_with(input, &out, &lights, &opts, Some(started)).unwrap();
        assert_eq!(files(&end), files(&ahead), "{}", input.display());
        assert_eq!(
            with.resources.files_written.len(),
            at_end.resources.files_written.len()
        );
        copied += with.resources.copied.len();
        // Started and dropped: nothing stays.
        let dropped = dir.join(format!("dropped{k}"));
        std::fs::create_dir_all(&dropped).unwrap();
        drop(CopiesAhead::start(
            input,
            &dropped.join("out.gltf"),
            InputFiles::Copy,
        ));
        assert!(files(&dropped).is_empty(), "{:?}", files(&dropped));
    }
    assert!(copied >= 2, "the inputs' copies: {copied}");
    // Started for one output and given to the write of another: not taken, and what it wrote
    // for the first is removed.
    let (first, second) = (dir.join("first"), dir.join("second"));
    std::fs::create_dir_all(&first).unwrap();
    std::fs::create_dir_all(&second).unwrap();
    let started = CopiesAhead::start(&inputs[0], &first.join("out.gltf"), InputFiles::Copy);
    write_lit_scene_with(
        &inputs[0],
        &second.join("out.gltf"),
        &lights,
        &opts,
        Some(started),
    )
    .unwrap();
    assert!(files(&first).is_empty(), "{:?}", files(&first));
    assert_eq!(files(&second), files(&dir.join("end0")));
    // The external input beside its output, its buffer named as the output's copy of it.
    let src = &inputs[0];
    let folder = src.parent().unwrap();
    std::fs::copy(folder.join("geometry.bin"), folder.join("lit.buffer0.bin")).unwrap();
    let text = std::fs::read_to_string(src).unwrap();
    let renamed = folder.join("renamed.gltf");
    std::fs::write(&renamed, text.replace("geometry.bin", "lit.buffer0.bin")).unwrap();
    let before = files(folder);
    let out = folder.join("lit.gltf");
    let started = CopiesAhead::start(&renamed, &out, InputFiles::Copy);
    let err = write_lit_scene_with(&renamed, &out, &lights, &opts, Some(started))
        .expect_err("the copy would overwrite an input");
    assert!(err.to_string().contains("lit.buffer0.bin"), "{err}");
    assert_eq!(files(folder), before);
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `doc` without `EXT_lights_area` anywhere, as a tool without the extension writes it.
fn strip_lights(doc: &mut Value) {
    doc["extensions"]
        .as_object_mut()
        .unwrap()
        .remove("EXT_lights_area");
    doc["extensionsUsed"]
        .as_array_mut()
        .unwrap()
        .retain(|e| e != "EXT_lights_area");
    for node in doc["nodes"].as_array_mut().unwrap() {
        if let Some(ext) = node.get_mut("extensions").and_then(Value::as_object_mut) {
            ext.remove("EXT_lights_area");
        }
    }
}

#[test]
fn restore_lights_rebuilds_dropped_lights_from_the_quads() {
    let dir = temp_dir("restore");
    let input = generated_inputs(&dir.join("in")).remove(0);
    let lit = dir.join("lit.gltf");
    let s = write_lit_scene(&input, &lit, &two_lights(), &WriteOptions::default()).unwrap();
    let want = lights_by_name(&lit);
    // The existing light of the input has no quad: only the two written ones can come back.
    assert_eq!(want.len(), 3);
    let want: Vec<_> = want.into_iter().filter(|l| l.0 != "existing").collect();
    let mut stripped = load(&lit).json;
    strip_lights(&mut stripped);
    // Hierarchy kept: the lights go back on their old nodes.
    let kept = dir.join("kept.gltf");
    std::fs::write(&kept, serde_json::to_vec(&stripped).unwrap()).unwrap();
    // Hierarchy flattened: the quads at the scene's root, the light nodes gone from it.
    let mut flat = stripped.clone();
    for &n in &s.node_indices {
        flat["nodes"][n].as_object_mut().unwrap().remove("children");
    }
    let scene_nodes = flat["scenes"][s.scene_index]["nodes"]
        .as_array_mut()
        .unwrap();
    scene_nodes.retain(|n| !s.node_indices.contains(&(n.as_u64().unwrap() as usize)));
    scene_nodes.extend(s.fallback_node_indices.iter().map(|&q| json!(q)));
    let flattened = dir.join("flat.gltf");
    std::fs::write(&flattened, serde_json::to_vec(&flat).unwrap()).unwrap();
    for (from, on_old_nodes) in [(&kept, true), (&flattened, false)] {
        for ext in ["gltf", "glb"] {
            let out = from.with_extension(format!("restored.{ext}"));
            let r = streaklight::scene_out::restore_lights(from, &out, InputFiles::Copy).unwrap();
            assert_eq!(r.already_present, 0);
            assert_eq!(
                r.restored_nodes == s.node_indices,
                on_old_nodes,
                "{}",
                out.display()
            );
            let got = lights_by_name(&out);
            let got: Vec<_> = got.into_iter().filter(|l| l.0 != "existing").collect();
            assert_eq!(got, want, "{}", out.display());
            assert_self_contained(&out);
            assert!(validator_problems(&out).is_empty(), "{}", out.display());
        }
    }
    // Nothing to restore: every light is there.
    let again = dir.join("again.gltf");
    let r = streaklight::scene_out::restore_lights(&lit, &again, InputFiles::Copy).unwrap();
    assert_eq!((r.restored_nodes.len(), r.already_present), (0, 2));
    assert_eq!(lights_by_name(&again).len(), 3);
    std::fs::remove_dir_all(&dir).unwrap();
}
