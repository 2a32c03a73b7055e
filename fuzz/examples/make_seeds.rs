//! Writes the seed corpus into `fuzz/seeds/{scene_loader,photo_decoder}`: small valid scenes
//! (`.gltf` with data: URIs, `.glb`, indexed, stripped, sparse, with a hierarchy and an area
//! light) and tiny photos in every format the decoder reads (one EXR with negative values, one
//! JPEG with the EXIF that `--exposure auto` reads). Run from `fuzz/`:
//! `cargo run --example make_seeds`. The seeds are committed; rerun only to change them.

use std::path::Path;

use base64::Engine;
use serde_json::{json, Value};

fn floats(v: &[f32]) -> Vec<u8> {
    v.iter().flat_map(|x| x.to_le_bytes()).collect()
}

/// A camera looking down -Z at a water grid of 2 x 2 quads, plus whatever `extra` adds.
fn base_scene(bin: &mut Vec<u8>) -> Value {
    let mut pos = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            pos.extend_from_slice(&[i as f32 - 1.0, 0.0, -(j as f32) - 2.0]);
        }
    }
    let normals: Vec<f32> = (0..9).flat_map(|_| [0.0f32, 1.0, 0.0]).collect();
    let mut idx: Vec<u16> = Vec::new();
    for j in 0..2u16 {
        for i in 0..2u16 {
            let a = j * 3 + i;
            idx.extend_from_slice(&[a, a + 3, a + 1, a + 1, a + 3, a + 4]);
        }
    }
    bin.extend(floats(&pos));
    bin.extend(floats(&normals));
    bin.extend(idx.iter().flat_map(|x| x.to_le_bytes()));
    json!({
        "asset": {"version": "2.0"},
        "extensionsUsed": ["KHR_materials_ior", "EXT_lights_area"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [
            {"name": "Camera", "camera": 0, "translation": [0.0, 0.5, 1.0]},
            {"name": "Water", "mesh": 0, "rotation": [0.0, 0.0, 0.0, 1.0], "scale": [1.0, 1.0, 1.0]}
        ],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.8, "znear": 0.1, "aspectRatio": 1.5}}],
        "materials": [{"pbrMetallicRoughness": {"roughnessFactor": 0.25},
                       "extensions": {"KHR_materials_ior": {"ior": 1.33}}}],
        "meshes": [{"name": "Water", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1},
                                                     "indices": 2, "material": 0}]}],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": 9, "type": "VEC3",
             "min": [-1.0, 0.0, -4.0], "max": [1.0, 0.0, -2.0]},
            {"bufferView": 1, "componentType": 5126, "count": 9, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5123, "count": 24, "type": "SCALAR"}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": 108},
            {"buffer": 0, "byteOffset": 108, "byteLength": 108},
            {"buffer": 0, "byteOffset": 216, "byteLength": 48}
        ],
        "buffers": [{"byteLength": 264}]
    })
}

fn with_data_uri(mut doc: Value, bin: &[u8]) -> Value {
    doc["buffers"][0]["uri"] = json!(format!(
        "data:application/octet-stream;base64,{}",
        base64::engine::general_purpose::STANDARD.encode(bin)
    ));
    doc["buffers"][0]["byteLength"] = json!(bin.len());
    doc
}

fn glb(doc: &Value, bin: &[u8]) -> Vec<u8> {
    let mut json = serde_json::to_vec(doc).unwrap();
    while json.len() % 4 != 0 {
        json.push(b' ');
    }
    let mut bin = bin.to_vec();
    while bin.len() % 4 != 0 {
        bin.push(0);
    }
    let total = 12 + 8 + json.len() + 8 + bin.len();
    let mut out = Vec::new();
    out.extend_from_slice(b"glTF");
    out.extend_from_slice(&2u32.to_le_bytes());
    out.extend_from_slice(&(total as u32).to_le_bytes());
    out.extend_from_slice(&(json.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x4E4F_534Au32.to_le_bytes());
    out.extend_from_slice(&json);
    out.extend_from_slice(&(bin.len() as u32).to_le_bytes());
    out.extend_from_slice(&0x004E_4942u32.to_le_bytes());
    out.extend_from_slice(&bin);
    out
}

fn write(dir: &Path, name: &str, bytes: &[u8]) {
    std::fs::write(dir.join(name), bytes).unwrap();
}

fn scenes(dir: &Path) {
    let mut bin = Vec::new();
    let doc = base_scene(&mut bin);
    write(
        dir,
        "grid.gltf",
        &serde_json::to_vec_pretty(&with_data_uri(doc.clone(), &bin)).unwrap(),
    );
    let mut glb_doc = doc.clone();
    glb_doc["buffers"][0]["byteLength"] = json!(bin.len());
    write(dir, "grid.glb", &glb(&glb_doc, &bin));

    // Triangle strip without indices, under a parent with a matrix, plus an area light and a
    // fallback quad.
    let mut d = doc.clone();
    d["meshes"][0]["primitives"][0] = json!({"attributes": {"POSITION": 0}, "mode": 5});
    d["nodes"] = json!([
        {"name": "Camera", "camera": 0, "translation": [0.0, 0.5, 1.0]},
        {"name": "Rig", "matrix": [1,0,0,0, 0,1,0,0, 0,0,1,0, 0,0,-1,1], "children": [2, 3]},
        {"name": "Water", "mesh": 0},
        {"name": "Lamp", "translation": [0.0, 2.0, -3.0],
         "extensions": {"EXT_lights_area": {"light": 0}}},
        {"name": "Quad", "mesh": 0, "extras": {"streaklight": {"role": "fallback-quad"}}}
    ]);
    d["nodes"][3]["children"] = json!([4]);
    d["extensions"] = json!({"EXT_lights_area": {"lights": [
        {"type": "rect", "size": 1.0, "rect": {"aspect": 2.0}, "intensity": 50.0, "color": [1.0, 0.9, 0.8]}
    ]}});
    d["extensionsRequired"] = json!(["EXT_lights_area"]);
    write(
        dir,
        "strip_hierarchy_light.gltf",
        &serde_json::to_vec(&with_data_uri(d, &bin)).unwrap(),
    );

    // A sparse accessor: positions all zero but for two, and u8 indices in a fan.
    let mut d = doc.clone();
    let mut b = bin.clone();
    let sparse_at = b.len();
    b.extend_from_slice(&[0, 4]);
    b.extend_from_slice(&[0, 0]);
    b.extend(floats(&[1.0, 0.0, -2.0, 0.0, 0.0, -3.0]));
    let fan_at = b.len();
    b.extend_from_slice(&[0, 1, 4, 8, 2]);
    d["accessors"][0] = json!({"componentType": 5126, "count": 9, "type": "VEC3",
        "min": [0.0, 0.0, -3.0], "max": [1.0, 0.0, 0.0],
        "sparse": {"count": 2, "indices": {"bufferView": 3, "componentType": 5121},
                   "values": {"bufferView": 4}}});
    d["accessors"][2] =
        json!({"bufferView": 5, "componentType": 5121, "count": 5, "type": "SCALAR"});
    d["bufferViews"].as_array_mut().unwrap().extend([
        json!({"buffer": 0, "byteOffset": sparse_at, "byteLength": 2}),
        json!({"buffer": 0, "byteOffset": sparse_at + 4, "byteLength": 24}),
        json!({"buffer": 0, "byteOffset": fan_at, "byteLength": 5}),
    ]);
    d["meshes"][0]["primitives"][0]["mode"] = json!(6);
    write(
        dir,
        "sparse_fan.glb",
        &glb(
            &{
                let mut g = d.clone();
                g["buffers"][0]["byteLength"] = json!(b.len());
                g
            },
            &b,
        ),
    );

    // Strided interleaved positions and normals, u32 indices, several scenes.
    let mut d = doc;
    let mut b = Vec::new();
    for j in 0..3 {
        for i in 0..3 {
            b.extend(floats(&[
                i as f32 - 1.0,
                0.0,
                -(j as f32) - 2.0,
                0.0,
                1.0,
                0.0,
            ]));
        }
    }
    let idx_at = b.len();
    for i in [0u32, 3, 1, 1, 3, 4, 4, 7, 5] {
        b.extend_from_slice(&i.to_le_bytes());
    }
    d["bufferViews"] = json!([
        {"buffer": 0, "byteOffset": 0, "byteLength": idx_at, "byteStride": 24},
        {"buffer": 0, "byteOffset": idx_at, "byteLength": 36}
    ]);
    d["accessors"] = json!([
        {"bufferView": 0, "componentType": 5126, "count": 9, "type": "VEC3",
         "min": [-1.0, 0.0, -4.0], "max": [1.0, 0.0, -2.0]},
        {"bufferView": 0, "byteOffset": 12, "componentType": 5126, "count": 9, "type": "VEC3"},
        {"bufferView": 1, "componentType": 5125, "count": 9, "type": "SCALAR"}
    ]);
    d["scenes"] = json!([{"nodes": [0]}, {"nodes": [0, 1]}]);
    d["scene"] = json!(1);
    write(
        dir,
        "interleaved.gltf",
        &serde_json::to_vec(&with_data_uri(d, &b)).unwrap(),
    );
}

fn photos(dir: &Path, samples: &Path) {
    use image::{DynamicImage, ImageFormat};
    let big = image::open(samples.join("table1.png")).unwrap();
    let small = big.resize_exact(24, 16, image::imageops::FilterType::Triangle);
    let save = |img: &DynamicImage, name: &str, format: ImageFormat| {
        let mut bytes = std::io::Cursor::new(Vec::new());
        img.write_to(&mut bytes, format).unwrap();
        write(dir, name, bytes.get_ref());
    };
    save(&small, "table1-small.png", ImageFormat::Png);
    save(
        &DynamicImage::ImageRgb8(small.to_rgb8()),
        "table1-small.jpg",
        ImageFormat::Jpeg,
    );
    save(
        &DynamicImage::ImageRgb16(small.to_rgb16()),
        "table1-small-16bit.png",
        ImageFormat::Png,
    );
    save(
        &DynamicImage::ImageRgba8(small.to_rgba8()),
        "table1-small.tiff",
        ImageFormat::Tiff,
    );
    let dark = image::open(samples.join("dark.png")).unwrap();
    save(
        &dark
            .resize_exact(16, 16, image::imageops::FilterType::Nearest)
            .to_luma8()
            .into(),
        "dark-small-gray.png",
        ImageFormat::Png,
    );
    let float = DynamicImage::ImageRgb32F(small.to_rgb32f());
    save(&float, "table1-small.hdr", ImageFormat::Hdr);
    save(
        &DynamicImage::ImageRgba32F(small.to_rgba32f()),
        "table1-small.exr",
        ImageFormat::OpenExr,
    );
    // Below zero in places (a denoiser's undershoot): the decoder reads them as 0 and warns.
    let mut negative = small.to_rgb32f();
    negative
        .pixels_mut()
        .step_by(5)
        .for_each(|p| p.0[1] = -0.25);
    save(
        &DynamicImage::ImageRgb32F(negative),
        "table1-small-negative.exr",
        ImageFormat::OpenExr,
    );
    // `--exposure auto` reads these from the EXIF: a JPEG with it in an APP1 segment.
    let mut jpeg = std::io::Cursor::new(Vec::new());
    small
        .to_rgb8()
        .write_to(&mut jpeg, ImageFormat::Jpeg)
        .unwrap();
    let jpeg = jpeg.into_inner();
    let mut payload = b"Exif\0\0".to_vec();
    payload.extend(camera_exif());
    let mut with_exif = vec![0xff, 0xd8, 0xff, 0xe1];
    with_exif.extend(u16::try_from(payload.len() + 2).unwrap().to_be_bytes());
    with_exif.extend(payload);
    with_exif.extend(&jpeg[2..]);
    write(dir, "table1-small-exif.jpg", &with_exif);
}

/// TIFF-structured EXIF of a night shot: 1/30 s, f/2.8, ISO 800.
fn camera_exif() -> Vec<u8> {
    use exif::{Field, In, Rational, Tag, Value};
    let field = |tag, value| Field {
        tag,
        ifd_num: In::PRIMARY,
        value,
    };
    let rational = |num, denom| Value::Rational(vec![Rational { num, denom }]);
    let fields = [
        field(
            Tag::Software,
            Value::Ascii(vec![b"streaklight seeds".to_vec()]),
        ),
        field(Tag::ExposureTime, rational(1, 30)),
        field(Tag::FNumber, rational(28, 10)),
        field(Tag::PhotographicSensitivity, Value::Short(vec![800])),
    ];
    let mut writer = exif::experimental::Writer::new();
    for f in &fields {
        writer.push_field(f);
    }
    let mut out = std::io::Cursor::new(Vec::new());
    writer.write(&mut out, false).unwrap();
    out.into_inner()
}

fn main() {
    let fuzz = Path::new(env!("CARGO_MANIFEST_DIR"));
    let scene_dir = fuzz.join("seeds/scene_loader");
    let photo_dir = fuzz.join("seeds/photo_decoder");
    std::fs::create_dir_all(&scene_dir).unwrap();
    std::fs::create_dir_all(&photo_dir).unwrap();
    scenes(&scene_dir);
    // The sample scenes too: their water.bin is not there, so they reach the buffer checks.
    for name in ["table1-truth.gltf", "table3-truth.gltf"] {
        std::fs::copy(fuzz.join("../samples").join(name), scene_dir.join(name)).unwrap();
    }
    photos(&photo_dir, &fuzz.join("../samples"));
}
