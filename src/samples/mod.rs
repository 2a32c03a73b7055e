//! The sample scenes of the paper's setup (method §6), generated deterministically.
//!
//! Camera at (0, 0.2, 10) looking down -z, vertical fov 60 degrees, 600 x 600; a wall at
//! z = 0 (or moved, for Table 2); a rippled water height field in front of it. The shared
//! water mesh is large (about 12 MB), so it is generated rather than committed; the
//! scenes are small JSON files and the photos small PNGs.
//!
//! Besides the paper's Tables 1 to 3, truth scenes with photos for cases the paper does not
//! show: Table 1's light over rougher and smoother water ([`SAMPLE_GLOSSES`]:
//! `gloss200.png`, `gloss1000.png`), and two lights one above the other whose reflections
//! overlap into a single streak ([`stacked_lights`]: `stacked.png`, and over smoother water
//! [`STACKED_SMOOTH_GLOSS`]: `stacked1000.png`). `table1.exr` is
//! Table 1's photo as linear float, from the same render as `table1.png` (large, so not
//! committed).

pub mod shapes;
pub mod water_surface;

use std::path::{Path, PathBuf};

use base64::Engine;
use glam::DVec3;
use serde_json::{json, Value};

use crate::output_file::write_atomically;
use crate::scene_in::roughness_from_gloss;
use crate::{Error, Result};

use water_surface::{GridSpec, RippleField};

/// The paper's camera position.
pub const CAMERA_POSITION: [f64; 3] = [0.0, 0.2, 10.0];
/// The paper's vertical field of view, in degrees.
pub const CAMERA_YFOV_DEGREES: f64 = 60.0;
/// Size of the sample photos.
pub const PHOTO_SIZE: u32 = 600;
/// Exposure of the sample photos: the lights' reflections (radiance 20 times a Fresnel
/// factor of 0.05 to 0.25) stay below the 8-bit maximum, while the lights seen directly clip.
pub const PHOTO_EXPOSURE: f32 = 0.1;
/// Camera rays per pixel of the sample photos.
pub const PHOTO_SPP: u32 = 256;
/// File name of the generated water mesh.
pub const WATER_BIN: &str = "water.bin";
/// Gloss (Phong exponent e) of the samples' water, unless a scene says otherwise.
pub const DEFAULT_GLOSS: f64 = 500.0;
/// Water gloss of the gloss samples `gloss200-truth.gltf` (`gloss200.png`) and
/// `gloss1000-truth.gltf` (`gloss1000.png`): Table 1's light over rougher and smoother water
/// than the other samples' [`DEFAULT_GLOSS`].
pub const SAMPLE_GLOSSES: [f64; 2] = [200.0, 1000.0];

/// Water gloss of the second stacked sample, `stacked1000-truth.gltf` (`stacked1000.png`):
/// the stacked lights over smoother water. Their reflections still merge into one streak,
/// but the lobes are narrower than over the default water, and the 256-spp photo pins the
/// edges where the two lights meet to about 0.5 % of their heights (the fit's sigmas with
/// every pixel and 576 samples), where over the default water (`stacked.png`) its own
/// noise leaves them about 5 % uncertain, beyond what any fit can recover (the spread bench,
/// BENCHMARKS.md).
pub const STACKED_SMOOTH_GLOSS: f64 = 1000.0;

/// A rectangle light on the wall, as the paper's tables give it.
#[derive(Clone, Debug)]
pub struct SampleLight {
    /// Name written into the scene.
    pub name: String,
    /// Left-bottom corner (world), on the wall.
    pub corner: DVec3,
    /// Width along +x.
    pub width: f64,
    /// Height along +y.
    pub height: f64,
    /// Linear radiance per channel.
    pub radiance: [f64; 3],
}

impl SampleLight {
    fn new(name: &str, corner: [f64; 3], size: [f64; 2], radiance: [f64; 3]) -> Self {
        SampleLight {
            name: name.into(),
            corner: DVec3::from(corner),
            width: size[0],
            height: size[1],
            radiance,
        }
    }

    /// The light's centre.
    pub fn center(&self) -> DVec3 {
        self.corner + DVec3::new(self.width / 2.0, self.height / 2.0, 0.0)
    }

    /// A fitted light's error per edge (left, right, bottom, top) as a fraction of this
    /// light's size along the edge's axis, from its left-bottom corner and size (on the same
    /// wall, width along +x).
    pub fn edge_errors(&self, corner_left_bottom: [f64; 3], width: f64, height: f64) -> [f64; 4] {
        let c = corner_left_bottom;
        [
            (c[0] - self.corner.x) / self.width,
            (c[0] + width - self.corner.x - self.width) / self.width,
            (c[1] - self.corner.y) / self.height,
            (c[1] + height - self.corner.y - self.height) / self.height,
        ]
    }
}

/// One sample scene file.
#[derive(Clone, Debug)]
pub struct SampleScene {
    /// File name (`.gltf`).
    pub file: String,
    /// What it is for.
    pub description: String,
    /// z of the wall plane.
    pub wall_z: f64,
    /// Gloss of the water.
    pub gloss: f64,
    /// Lights (truth scenes only).
    pub lights: Vec<SampleLight>,
    /// Photo rendered from this scene, if any (8-bit sRGB PNG).
    pub photo: Option<String>,
    /// The same render written as linear float OpenEXR too, if any (radiance times the
    /// exposure, unclipped).
    pub photo_exr: Option<String>,
}

/// Table 1's light (corner (-4, 2, 0), 3 x 3, L = 20).
pub fn table1_light() -> SampleLight {
    SampleLight::new("light0", [-4.0, 2.0, 0.0], [3.0, 3.0], [20.0; 3])
}

/// Table 3's two lights.
pub fn table3_lights() -> Vec<SampleLight> {
    vec![
        SampleLight::new("light0", [-4.0, 2.0, 0.0], [3.0, 3.0], [20.0, 20.0, 0.0]),
        SampleLight::new("light1", [5.0, 2.0, 0.0], [2.0, 2.0], [10.0, 10.0, 0.0]),
    ]
}

/// The stacked sample's two white lights, one above the other on the wall z = 0 with the
/// same horizontal span and a gap of 0.8 m between them: lower corner (-2, 1.2, 0), 3 x 1.0,
/// L = 16; upper corner (-2, 3, 0), 3 x 1.4, L = 14. The ripples stretch each reflection
/// over most of the other's, so on the water they make one streak: the lower light's
/// reflection is its brighter part, next to the horizon, the upper light's its dimmer part,
/// nearer the camera.
pub fn stacked_lights() -> Vec<SampleLight> {
    vec![
        SampleLight::new("lower", [-2.0, 1.2, 0.0], [3.0, 1.0], [16.0; 3]),
        SampleLight::new("upper", [-2.0, 3.0, 0.0], [3.0, 1.4], [14.0; 3]),
    ]
}

/// The truth scene and photo file names of the gloss sample with water gloss `gloss`
/// (one of [`SAMPLE_GLOSSES`]): `("gloss200-truth.gltf", "gloss200.png")` for e = 200.
pub fn gloss_sample_files(gloss: f64) -> (String, String) {
    (
        format!("gloss{gloss}-truth.gltf"),
        format!("gloss{gloss}.png"),
    )
}

/// The catalogue entry whose photo (PNG or EXR) is named `photo`, if any: its truth lights
/// and water gloss.
pub fn by_photo(photo: &str) -> Option<SampleScene> {
    catalogue()
        .into_iter()
        .find(|s| s.photo.as_deref() == Some(photo) || s.photo_exr.as_deref() == Some(photo))
}

/// Every sample scene.
pub fn catalogue() -> Vec<SampleScene> {
    let scene = |file: &str,
                 description: &str,
                 wall_z: f64,
                 lights: Vec<SampleLight>,
                 photo: Option<&str>| {
        SampleScene {
            file: file.into(),
            description: description.into(),
            wall_z,
            gloss: DEFAULT_GLOSS,
            lights,
            photo: photo.map(str::to_owned),
            photo_exr: None,
        }
    };
    let gloss_samples = SAMPLE_GLOSSES.map(|gloss| {
        let (file, photo) = gloss_sample_files(gloss);
        SampleScene {
            gloss,
            ..scene(
                &file,
                &format!("Table 1's light over water of gloss e = {gloss}"),
                0.0,
                vec![table1_light()],
                Some(&photo),
            )
        }
    });
    let mut scenes = vec![
        scene(
            "scene.gltf",
            "the paper's setup without lights: the input of a fit",
            0.0,
            vec![],
            Some("dark.png"),
        ),
        scene(
            "table1-truth.gltf",
            "Table 1: one white light, corner (-4, 2, 0), 3 x 3, L = 20",
            0.0,
            vec![table1_light()],
            Some("table1.png"),
        )
        .with_exr("table1.exr"),
        scene(
            "table3-truth.gltf",
            "Table 3: lights (-4, 2, 0) 3 x 3 L = (20, 20, 0) and (5, 2, 0) 2 x 2 L = (10, 10, 0)",
            0.0,
            table3_lights(),
            Some("table3.png"),
        ),
        scene(
            "table2-wall-minus3.gltf",
            "Table 2: the setup with the wall moved to z = -3 (fit table1.png against it)",
            -3.0,
            vec![],
            None,
        ),
        scene(
            "table2-wall-plus3.gltf",
            "Table 2: the setup with the wall moved to z = +3 (fit table1.png against it)",
            3.0,
            vec![],
            None,
        ),
    ];
    scenes.extend(gloss_samples);
    scenes.push(scene(
        "stacked-truth.gltf",
        "two white lights one above the other, (-2, 1.2, 0) 3 x 1 L = 16 and (-2, 3, 0) 3 x 1.4 L = 14: their reflections overlap into one streak",
        0.0,
        stacked_lights(),
        Some("stacked.png"),
    ));
    scenes.push(SampleScene {
        gloss: STACKED_SMOOTH_GLOSS,
        ..scene(
            "stacked1000-truth.gltf",
            "the stacked lights over smoother water, e = 1000: their reflections still overlap into one streak",
            0.0,
            stacked_lights(),
            Some("stacked1000.png"),
        )
    });
    scenes
}

impl SampleScene {
    fn with_exr(self, exr: &str) -> Self {
        SampleScene {
            photo_exr: Some(exr.into()),
            ..self
        }
    }
}

/// The water grid of every sample.
pub fn water_grid() -> GridSpec {
    GridSpec {
        eye_height: CAMERA_POSITION[1],
        eye_z: CAMERA_POSITION[2],
        near: 0.25,
        far: 14.0,
        half_width_per_distance: 0.75,
        rows: 360,
        columns: 720,
    }
}

/// The ripples of every sample.
pub fn ripples() -> RippleField {
    RippleField::new(2018, 24, 0.05)
}

/// Byte layout of the water buffer.
struct WaterBuffer {
    bytes: Vec<u8>,
    vertex_count: usize,
    index_count: usize,
    min: [f32; 3],
    max: [f32; 3],
}

fn water_buffer() -> WaterBuffer {
    let mesh = water_surface::mesh(&ripples(), &water_grid());
    let mut bytes = Vec::with_capacity(mesh.positions.len() * 24 + mesh.indices.len() * 4);
    let mut min = [f32::INFINITY; 3];
    let mut max = [f32::NEG_INFINITY; 3];
    for p in &mesh.positions {
        for c in 0..3 {
            min[c] = min[c].min(p[c]);
            max[c] = max[c].max(p[c]);
            bytes.extend_from_slice(&p[c].to_le_bytes());
        }
    }
    for n in &mesh.normals {
        for c in n {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in &mesh.indices {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    WaterBuffer {
        bytes,
        vertex_count: mesh.positions.len(),
        index_count: mesh.indices.len(),
        min,
        max,
    }
}

/// A quad for the wall at `z`, facing +z, as a data URI buffer.
fn wall_buffer(z: f64) -> (String, usize) {
    let (x0, x1, y0, y1) = (-40.0f32, 40.0f32, -1.0f32, 25.0f32);
    let z = z as f32;
    let positions = [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]];
    let mut bytes = Vec::new();
    for p in positions {
        for c in p {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for _ in 0..4 {
        for c in [0f32, 0.0, 1.0] {
            bytes.extend_from_slice(&c.to_le_bytes());
        }
    }
    for i in [0u16, 1, 2, 0, 2, 3] {
        bytes.extend_from_slice(&i.to_le_bytes());
    }
    let len = bytes.len();
    (
        format!(
            "data:application/octet-stream;base64,{}",
            base64::engine::general_purpose::STANDARD.encode(&bytes)
        ),
        len,
    )
}

fn scene_json(spec: &SampleScene, water: &WaterBuffer) -> Value {
    let (wall_uri, wall_len) = wall_buffer(spec.wall_z);
    let wz = spec.wall_z as f32;
    let (vc, ic) = (water.vertex_count, water.index_count);
    let mut nodes = vec![
        json!({"name": "Camera", "camera": 0, "translation": CAMERA_POSITION}),
        json!({"name": "Water", "mesh": 0}),
        json!({"name": "Wall", "mesh": 1}),
    ];
    let mut root_nodes: Vec<usize> = vec![0, 1, 2];
    let mut lights = Vec::new();
    for (i, light) in spec.lights.iter().enumerate() {
        let max = light.radiance.iter().cloned().fold(0.0, f64::max);
        let color = if max > 0.0 {
            light.radiance.map(|c| c / max)
        } else {
            [1.0; 3]
        };
        lights.push(json!({
            "name": light.name, "type": "rect", "color": color, "intensity": max,
            "size": light.height, "rect": {"aspect": light.width / light.height}
        }));
        root_nodes.push(nodes.len());
        // Emission is along local -Z; a half turn about Y makes it face +z, the water.
        nodes.push(json!({
            "name": light.name,
            "translation": light.center().to_array(),
            "rotation": [0.0, 1.0, 0.0, 0.0],
            "extensions": {"EXT_lights_area": {"light": i}}
        }));
    }
    let mut doc = json!({
        "asset": {"version": "2.0", "generator": "streaklight samples"},
        "extensionsUsed": ["KHR_materials_ior"],
        "scene": 0,
        "scenes": [{"name": spec.description, "nodes": root_nodes}],
        "nodes": nodes,
        "cameras": [{"name": "PaperCamera", "type": "perspective", "perspective": {
            "yfov": CAMERA_YFOV_DEGREES.to_radians(), "aspectRatio": 1.0, "znear": 0.01, "zfar": 200.0}}],
        "materials": [
            {"name": "Water", "pbrMetallicRoughness": {"baseColorFactor": [0.02, 0.03, 0.04, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": roughness_from_gloss(spec.gloss as f32)},
             "extensions": {"KHR_materials_ior": {"ior": crate::scene_in::WATER_IOR}}},
            {"name": "Wall", "pbrMetallicRoughness": {"baseColorFactor": [0.05, 0.05, 0.05, 1.0],
                "metallicFactor": 0.0, "roughnessFactor": 1.0}}
        ],
        "meshes": [
            {"name": "Water", "primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1}, "indices": 2, "material": 0}]},
            {"name": "Wall", "primitives": [{"attributes": {"POSITION": 3, "NORMAL": 4}, "indices": 5, "material": 1}]}
        ],
        "buffers": [
            {"uri": WATER_BIN, "byteLength": water.bytes.len()},
            {"uri": wall_uri, "byteLength": wall_len}
        ],
        "bufferViews": [
            {"buffer": 0, "byteOffset": 0, "byteLength": vc * 12, "target": 34962},
            {"buffer": 0, "byteOffset": vc * 12, "byteLength": vc * 12, "target": 34962},
            {"buffer": 0, "byteOffset": vc * 24, "byteLength": ic * 4, "target": 34963},
            {"buffer": 1, "byteOffset": 0, "byteLength": 48, "target": 34962},
            {"buffer": 1, "byteOffset": 48, "byteLength": 48, "target": 34962},
            {"buffer": 1, "byteOffset": 96, "byteLength": 12, "target": 34963}
        ],
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": vc, "type": "VEC3", "min": water.min, "max": water.max},
            {"bufferView": 1, "componentType": 5126, "count": vc, "type": "VEC3"},
            {"bufferView": 2, "componentType": 5125, "count": ic, "type": "SCALAR"},
            {"bufferView": 3, "componentType": 5126, "count": 4, "type": "VEC3", "min": [-40.0, -1.0, wz], "max": [40.0, 25.0, wz]},
            {"bufferView": 4, "componentType": 5126, "count": 4, "type": "VEC3"},
            {"bufferView": 5, "componentType": 5123, "count": 6, "type": "SCALAR"}
        ]
    });
    if !lights.is_empty() {
        if let Some(root) = doc.as_object_mut() {
            root.insert(
                "extensions".into(),
                json!({"EXT_lights_area": {"lights": lights}}),
            );
            if let Some(used) = root.get_mut("extensionsUsed").and_then(Value::as_array_mut) {
                used.push(json!("EXT_lights_area"));
            }
        }
    }
    doc
}

/// Writes the water mesh and every sample scene into `dir`; returns the files written.
pub fn write_scenes(dir: &Path) -> Result<Vec<PathBuf>> {
    std::fs::create_dir_all(dir).map_err(|e| Error::io(dir, e))?;
    let water = water_buffer();
    let mut written = Vec::new();
    let bin = dir.join(WATER_BIN);
    write_atomically(&bin, &water.bytes)?;
    written.push(bin);
    for spec in catalogue() {
        let path = dir.join(&spec.file);
        let text = serde_json::to_string_pretty(&scene_json(&spec, &water))
            .map_err(|e| Error::output(&path, e.to_string()))?;
        write_atomically(&path, text.as_bytes())?;
        written.push(path);
    }
    Ok(written)
}

/// Renders the photo of the sample scene `spec` (written in `dir` already) as `samples` does,
/// with `spp` camera rays per pixel.
pub fn render_photo(
    dir: &Path,
    spec: &SampleScene,
    spp: u32,
    progress: crate::progress::Reporter<'_>,
) -> Result<crate::render::Rendered> {
    let scene = crate::scene_in::load(&dir.join(&spec.file), &Default::default())?;
    let options = crate::render::RenderOptions {
        width: PHOTO_SIZE,
        height: PHOTO_SIZE,
        samples_per_pixel: spp,
        exposure: PHOTO_EXPOSURE,
        seed: 1,
        progress,
        ..Default::default()
    };
    crate::render::render(&scene, &options)
}

/// Renders the photo of every sample scene that has one (the scenes must be written
/// already), with `spp` camera rays per pixel; returns the files written.
pub fn render_photos(
    dir: &Path,
    spp: u32,
    progress: crate::progress::Reporter<'_>,
) -> Result<Vec<PathBuf>> {
    let mut written = Vec::new();
    for spec in catalogue() {
        let Some(photo) = &spec.photo else { continue };
        progress.stage(&format!("rendering {photo}"));
        let image = render_photo(dir, &spec, spp, progress)?;
        let path = dir.join(photo);
        crate::photo_out::write(&path, image.width, image.height, &image.pixels)?;
        written.push(path);
        if let Some(exr) = &spec.photo_exr {
            let path = dir.join(exr);
            crate::photo_out::write(&path, image.width, image.height, &image.pixels)?;
            written.push(path);
        }
    }
    Ok(written)
}

/// Unit-test fixture: the sample scene (written to a temporary folder and loaded), the
/// committed sample photo `photo` at the samples' exposure, its water mask and its streaks as
/// the fitters take them.
#[cfg(test)]
pub(crate) fn fixture(
    photo: &str,
) -> (
    crate::scene_in::Scene,
    crate::photo_in::Photo,
    Vec<bool>,
    Vec<crate::fitting::StreakObservation>,
) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let dir = std::env::temp_dir().join(format!(
        "streaklight-fixture-{}-{:?}",
        std::process::id(),
        std::thread::current().id()
    ));
    write_scenes(&dir).expect("sample scenes");
    let scene = crate::scene_in::load(&dir.join("scene.gltf"), &Default::default()).expect("scene");
    let _ = std::fs::remove_dir_all(&dir);
    let photo =
        crate::photo_in::load(&root.join("samples").join(photo), PHOTO_EXPOSURE).expect("photo");
    let water = crate::water_mask::water_mask(&scene, photo.width, photo.height);
    let segmented =
        crate::streaks::extract_streaks(&photo, &water, &Default::default()).expect("streaks");
    let observations = segmented
        .streaks
        .iter()
        .map(|s| crate::pipeline::observation(s, photo.width))
        .collect();
    (scene, photo, water, observations)
}
