//! Inputs that crashed, hung or exhausted memory in the scene loader or the photo decoder
//! (found by `cargo fuzz`, see fuzz/README.md, or by reading the code the fuzzer pointed at),
//! and the classes of bad input the loaders were hardened against. Each must give a clean
//! `Err` with a message a person can act on: never a panic, an abort or a huge allocation.

mod common;

use std::path::Path;

use common::gltf_builder::{data_uri, glb, vec3_bytes};
use serde_json::{json, Value};
use streaklight::scene_in::{load, load_from_bytes, LoadOptions};
use streaklight::{photo_exif, photo_in, Error};

/// A camera and a water triangle, with `bin` as the one buffer (a data: URI).
fn scene(bin: &[u8]) -> Value {
    json!({
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"name": "Camera", "camera": 0, "translation": [0.0, 0.5, 1.0]},
            {"name": "Water", "mesh": 0}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1}}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}}]}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
                       "min": [-1.0, 0.0, -4.0], "max": [1.0, 0.0, -2.0]}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": 36}],
        "buffers": [{"byteLength": bin.len(), "uri": data_uri(bin)}]
    })
}

/// Three vertices of a triangle on the water plane, then `extra` bytes.
fn triangle_bin(extra: &[u8]) -> Vec<u8> {
    let mut bin = vec3_bytes(&[[-1.0, 0.0, -2.0], [1.0, 0.0, -2.0], [0.0, 0.0, -4.0]]);
    bin.extend_from_slice(extra);
    bin
}

fn load_bytes(bytes: &[u8]) -> streaklight::Result<streaklight::scene_in::Scene> {
    load_from_bytes(bytes, None, Path::new("fuzz.gltf"), &LoadOptions::default())
}

/// The message of the error the scene gives; fails the test if it loads.
fn scene_error(doc: &Value) -> String {
    match load_bytes(&serde_json::to_vec(doc).unwrap()) {
        Ok(_) => panic!("the scene loaded"),
        Err(e @ Error::Scene { .. }) => e.to_string(),
        Err(e) => panic!("not a scene error: {e}"),
    }
}

fn assert_scene_error(doc: &Value, expect: &str) {
    let message = scene_error(doc);
    assert!(message.contains(expect), "{message:?} lacks {expect:?}");
}

fn glb_scene() -> Vec<u8> {
    let bin = triangle_bin(&[]);
    let mut doc = scene(&bin);
    doc["buffers"] = json!([{"byteLength": bin.len()}]);
    glb(&doc, Some(&bin), &[])
}

#[test]
fn the_base_scenes_load() {
    let s = load_bytes(&serde_json::to_vec(&scene(&triangle_bin(&[]))).unwrap()).unwrap();
    assert_eq!(s.triangles.len(), 1);
    let s = load_bytes(&glb_scene()).unwrap();
    assert_eq!(s.triangles.len(), 1);
}

#[test]
fn every_truncation_of_a_glb_is_a_clean_error() {
    let bytes = glb_scene();
    for len in 0..bytes.len() {
        assert!(load_bytes(&bytes[..len]).is_err(), "prefix of {len} bytes");
    }
}

#[test]
fn glb_lengths_past_the_end_are_refused() {
    let good = glb_scene();
    // The JSON chunk's length near u32::MAX: 12 + 8 + len must not wrap.
    let mut bad = good.clone();
    bad[12..16].copy_from_slice(&0xFFFF_FFF0u32.to_le_bytes());
    let e = load_bytes(&bad).err().unwrap().to_string();
    assert!(e.contains("truncated GLB"), "{e}");
    // The header's total length past the end of the file.
    let mut bad = good.clone();
    bad[8..12].copy_from_slice(&u32::MAX.to_le_bytes());
    let e = load_bytes(&bad).err().unwrap().to_string();
    assert!(e.contains("truncated GLB"), "{e}");
    // A BIN chunk that claims more than the file holds.
    let json_len = u32::from_le_bytes([good[12], good[13], good[14], good[15]]) as usize;
    let mut bad = good;
    let at = 20 + json_len;
    bad[at..at + 4].copy_from_slice(&0x7FFF_FFFFu32.to_le_bytes());
    let e = load_bytes(&bad).err().unwrap().to_string();
    assert!(e.contains("truncated GLB"), "{e}");
}

#[test]
fn nan_vertices_are_left_out_not_traced() {
    let mut bin = triangle_bin(&[]);
    bin[0..4].copy_from_slice(&f32::NAN.to_le_bytes());
    assert_scene_error(&scene(&bin), "no usable triangles");
    // With a good triangle beside it, the NaN one is dropped and counted.
    let mut bin = triangle_bin(&triangle_bin(&[]));
    bin[4..8].copy_from_slice(&f32::INFINITY.to_le_bytes());
    let mut doc = scene(&bin);
    doc["accessors"][0]["count"] = json!(6);
    doc["bufferViews"][0]["byteLength"] = json!(72);
    let s = load_bytes(&serde_json::to_vec(&doc).unwrap()).unwrap();
    assert_eq!((s.triangles.len(), s.dropped_triangles), (1, 1));
}

#[test]
fn an_empty_accessor_is_refused() {
    let mut doc = scene(&triangle_bin(&[]));
    doc["accessors"][0]["count"] = json!(0);
    assert!(!scene_error(&doc).is_empty());
}

#[test]
fn an_accessor_past_the_end_of_its_view_or_buffer_is_refused() {
    let mut doc = scene(&triangle_bin(&[]));
    doc["accessors"][0]["count"] = json!(4);
    assert_scene_error(&doc, "reach past the end of buffer view 0");
    let mut doc = scene(&triangle_bin(&[]));
    doc["accessors"][0]["byteOffset"] = json!(4);
    assert_scene_error(&doc, "reach past the end of buffer view 0");
    // The view inside its declared byteLength but past the data.
    let mut doc = scene(&triangle_bin(&[]));
    doc["bufferViews"][0]["byteOffset"] = json!(8);
    assert_scene_error(&doc, "reaches past the end of buffer 0");
}

#[test]
fn huge_counts_and_offsets_do_not_overflow() {
    // count * stride wraps around usize in the `gltf` reader's arithmetic.
    for count in [1u64 << 62, u64::MAX / 12 + 2, u64::MAX] {
        let mut doc = scene(&triangle_bin(&[]));
        doc["accessors"][0]["count"] = json!(count);
        assert!(!scene_error(&doc).is_empty(), "count {count}");
    }
    let mut doc = scene(&triangle_bin(&[]));
    doc["accessors"][0]["byteOffset"] = json!(u64::MAX - 4);
    assert!(!scene_error(&doc).is_empty());
    let mut doc = scene(&triangle_bin(&[]));
    doc["bufferViews"][0]["byteOffset"] = json!(u64::MAX - 4);
    assert!(!scene_error(&doc).is_empty());
}

#[test]
fn a_huge_byte_length_is_refused_without_allocating_it() {
    let mut doc = scene(&triangle_bin(&[]));
    doc["buffers"][0]["byteLength"] = json!(1u64 << 60);
    assert_scene_error(&doc, "buffer 0 is too short");
    let mut doc = scene(&triangle_bin(&[]));
    doc["bufferViews"][0]["byteLength"] = json!(1u64 << 60);
    assert!(!scene_error(&doc).is_empty());
}

#[test]
fn a_stride_smaller_than_an_element_is_refused() {
    // Was: the `gltf` reader's `assert!(slice.len() >= 3 * size_of::<f32>())` panicked.
    let mut doc = scene(&triangle_bin(&[]));
    doc["bufferViews"][0]["byteStride"] = json!(4);
    assert_scene_error(&doc, "byteStride 4, smaller than one element");
}

#[test]
fn indices_and_positions_of_the_wrong_type_are_refused() {
    // Was: `unreachable!()` in the `gltf` reader's `read_indices` for float indices.
    let mut bin = triangle_bin(&[]);
    bin.extend(
        [0.0f32, 1.0, 2.0]
            .iter()
            .flat_map(|f| f.to_le_bytes())
            .collect::<Vec<_>>(),
    );
    let mut doc = scene(&bin);
    doc["bufferViews"]
        .as_array_mut()
        .unwrap()
        .push(json!({"buffer": 0, "byteOffset": 36, "byteLength": 12}));
    doc["accessors"]
        .as_array_mut()
        .unwrap()
        .push(json!({"bufferView": 1, "componentType": 5126, "count": 3, "type": "SCALAR"}));
    doc["meshes"][0]["primitives"][0]["indices"] = json!(1);
    assert_scene_error(&doc, "indices must be unsigned integer scalars");
    // Positions as unsigned shorts were read as floats from the wrong bytes.
    let mut doc = scene(&triangle_bin(&[]));
    doc["accessors"][0]["componentType"] = json!(5123);
    assert_scene_error(&doc, "positions and normals must be Vec3 of F32");
}

/// A sparse POSITION accessor without a buffer view: zeros but for element 0.
fn sparse_scene(count: u64, sparse: Value) -> Value {
    let mut bin = vec![0u8; 4];
    bin.extend(triangle_bin(&[]));
    let mut doc = scene(&bin);
    doc["bufferViews"] = json!([
        {"buffer": 0, "byteOffset": 0, "byteLength": 4},
        {"buffer": 0, "byteOffset": 4, "byteLength": 12}
    ]);
    doc["accessors"][0] = json!({"componentType": 5126, "count": count, "type": "VEC3",
        "min": [-1.0, 0.0, -2.0], "max": [0.0, 0.0, 0.0], "sparse": sparse});
    doc
}

fn sparse(count: u64, index_type: u32) -> Value {
    json!({"count": count, "indices": {"bufferView": 0, "componentType": index_type},
           "values": {"bufferView": 1}})
}

#[test]
fn bad_sparse_accessors_are_refused() {
    // A well-formed one reaches the geometry checks (one corner off the origin: degenerate).
    assert_scene_error(&sparse_scene(3, sparse(1, 5121)), "no usable triangles");
    // Float sparse indices would hit `unreachable!()` in `Indices::index_type`; validation
    // refuses them first, and the loader checks again.
    assert_scene_error(&sparse_scene(3, sparse(1, 5126)), "componentType");
    // Was: `sparse_count - 1` underflowed in the `gltf` reader.
    assert_scene_error(&sparse_scene(3, sparse(0, 5121)), "sparse count 0");
    assert_scene_error(&sparse_scene(3, sparse(5, 5121)), "sparse count 5");
    // No data behind a huge count: refused rather than allocated.
    assert_scene_error(&sparse_scene(1 << 40, sparse(1, 5121)), "no buffer view");
}

#[test]
fn nodes_reached_twice_are_refused_not_multiplied() {
    // Each node lists the next one twice: 2^200 instances from a few kilobytes.
    let mut doc = scene(&triangle_bin(&[]));
    let mut nodes = doc["nodes"].as_array().unwrap().clone();
    let first = nodes.len();
    for i in 0..200 {
        nodes.push(json!({"children": [first + i + 1, first + i + 1]}));
    }
    nodes.push(json!({"mesh": 0}));
    doc["nodes"] = json!(nodes);
    doc["scenes"][0]["nodes"] = json!([0, 1, first]);
    assert_scene_error(&doc, "reached more than once");
    // A cycle.
    let mut doc = scene(&triangle_bin(&[]));
    doc["nodes"][1]["children"] = json!([2]);
    doc["nodes"]
        .as_array_mut()
        .unwrap()
        .push(json!({"children": [1]}));
    assert_scene_error(&doc, "reached more than once");
    // A root listed twice.
    let mut doc = scene(&triangle_bin(&[]));
    doc["scenes"][0]["nodes"] = json!([0, 1, 1]);
    assert_scene_error(&doc, "node 1 is reached more than once");
}

#[test]
fn buffer_files_are_only_read_from_a_folder_and_only_regular_files() {
    let mut doc = scene(&triangle_bin(&[]));
    doc["buffers"][0]["uri"] = json!("water.bin");
    assert_scene_error(&doc, "not read from a folder");
    // A device would be read without end.
    let dir = std::env::temp_dir().join(format!("streaklight-fuzz-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    doc["buffers"][0]["uri"] = json!("/dev/zero");
    std::fs::write(dir.join("dev.gltf"), serde_json::to_vec(&doc).unwrap()).unwrap();
    let e = load(&dir.join("dev.gltf"), &LoadOptions::default())
        .err()
        .unwrap()
        .to_string();
    assert!(
        e.contains("is a device; streaklight reads only regular files"),
        "{e}"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every file under tests/data/fuzz/scene_loader: inputs the fuzzer found. Each panicked;
/// now each gives an error, or a scene without the triangles that caused the panic.
#[test]
fn fuzzer_found_scenes_do_not_panic() {
    for_each_file("scene_loader", |name, bytes| {
        if let Ok(scene) = load_bytes(bytes) {
            // crash-34c0...: triangles 1e30 m away overflowed the BVH builder's areas.
            let far = scene
                .triangles
                .iter()
                .flatten()
                .map(|p| p.abs().max_element());
            assert!(far.fold(0.0, f32::max) <= 1e7, "{name}");
        }
    });
}

/// Every file under tests/data/fuzz/photo_decoder: inputs the fuzzer found, read as `fit`
/// reads a photo (its EXIF for `--exposure auto`, then the pixels).
#[test]
fn fuzzer_found_photos_give_clean_errors() {
    for_each_file("photo_decoder", |name, bytes| {
        let _ = exposure(bytes);
        assert!(decode(bytes).is_err(), "{name} decoded");
    });
}

fn for_each_file(target: &str, check: impl Fn(&str, &[u8])) {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/fuzz")
        .join(target);
    let Ok(entries) = std::fs::read_dir(&dir) else {
        return;
    };
    for entry in entries {
        let path = entry.unwrap().path();
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        if name.ends_with(".md") {
            continue;
        }
        check(&name, &std::fs::read(&path).unwrap());
    }
}

fn decode(bytes: &[u8]) -> streaklight::Result<photo_in::Photo> {
    photo_in::decode(bytes, 1.0, Path::new("fuzz.png"))
}

fn exposure(bytes: &[u8]) -> streaklight::Result<(f32, String)> {
    photo_exif::exposure_from_bytes(bytes, Path::new("fuzz.png"))
}

fn crc32(bytes: &[u8]) -> u32 {
    let mut crc = !0u32;
    for &b in bytes {
        crc ^= u32::from(b);
        for _ in 0..8 {
            crc = if crc & 1 != 0 {
                (crc >> 1) ^ 0xEDB8_8320
            } else {
                crc >> 1
            };
        }
    }
    !crc
}

fn png_chunk(png: &mut Vec<u8>, kind: &[u8; 4], data: &[u8]) {
    png.extend_from_slice(&(data.len() as u32).to_be_bytes());
    let mut body = kind.to_vec();
    body.extend_from_slice(data);
    png.extend_from_slice(&body);
    png.extend_from_slice(&crc32(&body).to_be_bytes());
}

/// A PNG whose IHDR (with a valid CRC) declares `width` x `height` pixels of
/// `bit_depth`-bit colour type `color`, followed by a few bytes of IDAT: the header is
/// all a decoder needs to decide how much to allocate.
fn png_header(width: u32, height: u32, bit_depth: u8, color: u8) -> Vec<u8> {
    let mut ihdr = Vec::new();
    ihdr.extend_from_slice(&width.to_be_bytes());
    ihdr.extend_from_slice(&height.to_be_bytes());
    ihdr.extend_from_slice(&[bit_depth, color, 0, 0, 0]);
    let mut png = b"\x89PNG\r\n\x1a\n".to_vec();
    png_chunk(&mut png, b"IHDR", &ihdr);
    png_chunk(&mut png, b"IDAT", &[0x78, 0x9c, 0x03, 0x00]);
    png_chunk(&mut png, b"IEND", &[]);
    png
}

#[test]
fn huge_image_dimensions_are_refused_before_allocating() {
    for (w, h, depth, color) in [
        (100_000u32, 100_000u32, 8u8, 2u8),
        (40_000, 10, 8, 2),
        (10, 40_000, 8, 0),
        // Within the side limit, but 900 megapixels of 16-bit RGBA: 7 GiB.
        (30_000, 30_000, 16, 6),
    ] {
        let e = decode(&png_header(w, h, depth, color))
            .err()
            .unwrap()
            .to_string();
        assert!(e.contains("too large"), "{w} x {h}: {e}");
    }
    // A small header without data is a decoding error, not a size error.
    let e = decode(&png_header(4, 4, 8, 2)).err().unwrap().to_string();
    assert!(e.contains("cannot decode"), "{e}");
}

#[test]
fn truncated_and_unknown_photos_are_clean_errors() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/photo_decoder");
    for entry in std::fs::read_dir(&seeds).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        assert!(decode(&bytes).is_ok(), "{} does not decode", path.display());
        for len in (0..bytes.len()).step_by(7) {
            let _ = decode(&bytes[..len]);
            let _ = exposure(&bytes[..len]);
        }
    }
    assert!(decode(b"").is_err());
    assert!(decode(b"not an image at all").is_err());
    // The seed with EXIF: 1/30 s, f/2.8, ISO 800.
    let (_, source) =
        exposure(&std::fs::read(seeds.join("table1-small-exif.jpg")).unwrap()).unwrap();
    assert!(source.contains("1/30 s, f/2.8, ISO 800"), "{source}");
}

#[test]
fn the_seed_scenes_load_or_fail_cleanly() {
    let seeds = Path::new(env!("CARGO_MANIFEST_DIR")).join("fuzz/seeds/scene_loader");
    for entry in std::fs::read_dir(&seeds).unwrap() {
        let path = entry.unwrap().path();
        let bytes = std::fs::read(&path).unwrap();
        let name = path.file_name().unwrap().to_string_lossy();
        let result = load_bytes(&bytes);
        // The published samples refer to water.bin, which the byte-level loader cannot read.
        if name.starts_with("table") {
            assert!(result.is_err(), "{name}");
        } else {
            let scene = result.unwrap_or_else(|e| panic!("{name}: {e}"));
            assert!(!scene.triangles.is_empty(), "{name}");
        }
    }
}
