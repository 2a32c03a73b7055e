//! The sample scenes of the paper's setup (method §6) and of a harbour ([`harbour`]),
//! generated deterministically.
//!
//! Camera at (0, 0.2, 10) looking down -z, vertical fov 60 degrees, 600 x 600; a wall at
//! z = 0 (or moved, for Table 2); a rippled water height field in front of it. The water
//! meshes are large (about 12 MB each), so they are generated rather than committed; the
//! scenes are small JSON files and the photos small PNGs. Fitting scenes whose water is not
//! the photos' come with both setups: another realisation of the same waves
//! ([`SampleWater::OtherWaves`]) and one flat quad with a matching roughness
//! ([`SampleWater::Flat`], [`flat_gloss`]).
//!
//! Besides the paper's Tables 1 to 3, truth scenes with photos for cases the paper does not
//! show: Table 1's light over rougher and smoother water ([`SAMPLE_GLOSSES`]:
//! `gloss200.png`, `gloss1000.png`), and two lights one above the other whose reflections
//! overlap into a single streak ([`stacked_lights`]: `stacked.png`, and over smoother water
//! [`STACKED_SMOOTH_GLOSS`]: `stacked1000.png`; an orange lamp under a blue one,
//! [`orange_and_blue_lights`]: `orange-blue.png`). `table1.exr` is
//! Table 1's photo as linear float, from the same render as `table1.png` (large, so not
//! committed).

#[cfg(test)]
mod fixture;
pub mod gltf_doc;
pub mod harbour;
pub mod harbour_waves;
mod mesh_size;
pub mod realisation;
#[cfg(test)]
pub(crate) use fixture::{fixture, load_fixture, Fixture};
pub mod shapes;
pub mod streak_slopes;
pub mod water_surface;

use std::path::{Path, PathBuf};

use glam::DVec3;

use crate::output_file::write_atomically;
use crate::{Error, Result};

use gltf_doc::{CameraPose, Quad, SceneParts, Solid, WaterBuffer, WaterGeometry};
use harbour::Framing;
pub use mesh_size::{finer_water_grid, write_paper_scenes_on_grid};
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
/// File name of the generated water mesh of the other ripples ([`other_ripples`]).
pub const OTHER_WATER_BIN: &str = "water-other.bin";
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
    /// A light named `name` with left-bottom corner `corner`, `size` = (width, height) and
    /// linear radiance `radiance`.
    pub fn new(name: &str, corner: [f64; 3], size: [f64; 2], radiance: [f64; 3]) -> Self {
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
    /// Which camera and surroundings.
    pub setup: Setup,
    /// Which water.
    pub water: SampleWater,
    /// The night the photo is rendered under: `None` for a black one.
    pub environment: Option<crate::environment::Environment>,
}

/// The geometry a sample scene is set in.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Setup {
    /// The paper's: camera 0.2 m above the water, 10 m from the wall.
    Paper,
    /// The harbour's ([`harbour`]), in one of its framings.
    Harbour(Framing),
}

/// The water of a sample scene.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SampleWater {
    /// The setup's waves: the ones its photos are rendered over.
    Waves,
    /// Another realisation of the same wave statistics (what an artist's scene would hold).
    OtherWaves,
    /// One flat quad, its roughness matching the waves' slopes (what a game scene holds).
    Flat,
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

/// The orange-and-blue sample's lamps, one above the other on the wall z = 0 with 1.5 m of
/// dark wall between them: lower (orange) corner (-2, 1, 0), 3 x 1.5, L = (20, 10, 2.5);
/// upper (blue) corner (-2, 4, 0), 3 x 1.5, L = (3, 7, 20). Over the default water their
/// reflections merge into one streak, orange nearer the horizon, blue nearer the camera,
/// and every pixel's colour says how much of it each lamp lit.
pub fn orange_and_blue_lights() -> Vec<SampleLight> {
    vec![
        SampleLight::new("orange", [-2.0, 1.0, 0.0], [3.0, 1.5], [20.0, 10.0, 2.5]),
        SampleLight::new("blue", [-2.0, 4.0, 0.0], [3.0, 1.5], [3.0, 7.0, 20.0]),
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
            setup: Setup::Paper,
            water: SampleWater::Waves,
            environment: None,
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
    scenes.push(scene(
        "orange-blue-truth.gltf",
        "an orange lamp under a blue one, (-2, 1, 0) 3 x 1.5 L = (20, 10, 2.5) and (-2, 4, 0) 3 x 1.5 L = (3, 7, 20): their reflections overlap into one streak",
        0.0,
        orange_and_blue_lights(),
        Some("orange-blue.png"),
    ));
    scenes.push(SampleScene {
        water: SampleWater::OtherWaves,
        ..scene(
            "scene-other-waves.gltf",
            "the paper's setup over another realisation of its ripples, without lights: the input of a fit",
            0.0,
            vec![],
            None,
        )
    });
    scenes.push(SampleScene {
        water: SampleWater::Flat,
        gloss: flat_gloss(&ripples(), DEFAULT_GLOSS),
        ..scene(
            "scene-flat.gltf",
            "the paper's setup over a flat quad whose roughness matches the ripples' slopes, without lights: the input of a fit",
            0.0,
            vec![],
            None,
        )
    });
    scenes.extend(harbour::catalogue(flat_gloss(
        &harbour::harbour_waves(0),
        harbour::HARBOUR_GLOSS,
    )));
    scenes
}

/// The gloss e of flat water whose isotropic roughness matches `field`'s slopes on top of
/// a micro-roughness of gloss `gloss` (method §3): a Beckmann alpha has slope variance
/// alpha^2 / 2 per axis, and e = 2 / alpha^2 - 2; the flat water's alpha^2 is the
/// micro-roughness's plus the field's slope variance over both axes.
pub fn flat_gloss(field: &RippleField, gloss: f64) -> f64 {
    let slopes = field.slope_variances([0.0, 1.0]);
    let alpha2 = 2.0 / (gloss + 2.0) + slopes.along + slopes.across;
    2.0 / alpha2 - 2.0
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

/// The ripples of every sample photo.
pub fn ripples() -> RippleField {
    ripples_of(2018)
}

/// Another realisation of the same ripples: the water of `scene-other-waves.gltf`.
pub fn other_ripples() -> RippleField {
    ripples_of(1202)
}

/// The realisation of the samples' ripples (24 of rms slope 0.05) drawn from `seed`.
pub fn ripples_of(seed: u64) -> RippleField {
    RippleField::new(seed, 24, 0.05)
}

/// The wall of the paper's setup at `z`, facing +z.
fn paper_wall(z: f64) -> Solid {
    let (x0, x1, y0, y1) = (-40.0f32, 40.0f32, -1.0f32, 25.0f32);
    let z = z as f32;
    Solid {
        name: "Wall".into(),
        quads: vec![Quad {
            corners: [[x0, y0, z], [x1, y0, z], [x1, y1, z], [x0, y1, z]],
            normal: [0.0, 0.0, 1.0],
        }],
    }
}

/// The flat water of the paper's setup: one quad over the water grid's extent.
fn paper_flat_water() -> Quad {
    let grid = water_grid();
    Quad::level_water(
        (grid.eye_z - grid.near) as f32,
        (grid.eye_z - grid.far) as f32,
        (grid.half_width_per_distance * grid.far) as f32,
    )
}

/// The generated water meshes, by setup and realisation.
struct WaterBuffers {
    paper: [WaterBuffer; 2],
    harbour: [WaterBuffer; 2],
}

impl WaterBuffers {
    fn new() -> Self {
        let paper =
            |field: &RippleField| WaterBuffer::new(&water_surface::mesh(field, &water_grid()));
        WaterBuffers {
            paper: [paper(&ripples()), paper(&other_ripples())],
            harbour: [0, 1].map(|r| WaterBuffer::new(&harbour::water_mesh(r))),
        }
    }

    /// The files the buffers are written to, with their bytes.
    fn files(&self) -> [(&'static str, &WaterBuffer); 4] {
        [
            (WATER_BIN, &self.paper[0]),
            (OTHER_WATER_BIN, &self.paper[1]),
            (harbour::HARBOUR_WATER_BIN, &self.harbour[0]),
            (harbour::HARBOUR_OTHER_WATER_BIN, &self.harbour[1]),
        ]
    }
}

/// The parts of `spec`'s scene file, its water meshes taken from `paper` or `harbour` (each
/// the photos' own waves, then the other realisation) by its setup.
fn scene_parts<'a>(
    spec: &'a SampleScene,
    paper: &'a [WaterBuffer],
    harbour: &'a [WaterBuffer],
) -> SceneParts<'a> {
    let (camera, solids, flat, meshes, uris) = match spec.setup {
        Setup::Paper => (
            CameraPose {
                name: "PaperCamera".into(),
                translation: CAMERA_POSITION,
                pitch_degrees: 0.0,
                yfov_degrees: CAMERA_YFOV_DEGREES,
            },
            vec![paper_wall(spec.wall_z)],
            paper_flat_water(),
            paper,
            [WATER_BIN, OTHER_WATER_BIN],
        ),
        Setup::Harbour(framing) => (
            harbour::camera(framing),
            harbour::solids(),
            harbour::flat_water(),
            harbour,
            [harbour::HARBOUR_WATER_BIN, harbour::HARBOUR_OTHER_WATER_BIN],
        ),
    };
    let mesh = |i: usize| WaterGeometry::Mesh {
        uri: uris[i],
        buffer: &meshes[i],
    };
    SceneParts {
        description: &spec.description,
        camera,
        water: match spec.water {
            SampleWater::Waves => mesh(0),
            SampleWater::OtherWaves => mesh(1),
            SampleWater::Flat => WaterGeometry::Flat(flat),
        },
        gloss: spec.gloss,
        solids,
        lights: &spec.lights,
    }
}

/// Writes the water meshes and every sample scene into `dir`; returns the files written.
pub fn write_scenes(dir: &Path) -> Result<Vec<PathBuf>> {
    crate::output_file::create_dir_all(dir)?;
    let buffers = WaterBuffers::new();
    let mut written = Vec::new();
    for (file, buffer) in buffers.files() {
        let bin = dir.join(file);
        write_atomically(&bin, &buffer.bytes)?;
        written.push(bin);
    }
    for spec in catalogue() {
        let path = dir.join(&spec.file);
        let text = serde_json::to_string_pretty(&gltf_doc::scene_json(&scene_parts(
            &spec,
            &buffers.paper,
            &buffers.harbour,
        )))
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
        environment: spec.environment,
        ..Default::default()
    };
    crate::render::render(&scene, &options)
}

/// Renders the photo of every sample scene that has one (the scenes must be written
/// already), or only those named in `only` when it is not empty, with `spp` camera rays per
/// pixel; returns the files written.
pub fn render_photos(
    dir: &Path,
    spp: u32,
    only: &[String],
    progress: crate::progress::Reporter<'_>,
) -> Result<Vec<PathBuf>> {
    let catalogue = catalogue();
    if let Some(unknown) = only
        .iter()
        .find(|name| !catalogue.iter().any(|s| s.photo.as_ref() == Some(name)))
    {
        return Err(Error::Usage(format!(
            "no sample photo is named {unknown}; the photos are: {}",
            catalogue
                .iter()
                .filter_map(|s| s.photo.as_deref())
                .collect::<Vec<_>>()
                .join(", ")
        )));
    }
    let mut written = Vec::new();
    for spec in catalogue {
        let Some(photo) = &spec.photo else { continue };
        if !only.is_empty() && !only.contains(photo) {
            continue;
        }
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
