//! Step 1 of method §5: load the scene.
//!
//! The node hierarchy is baked to world space in f64, recentred on the camera, and only then
//! rounded to f32. Every triangle goes into the tracer ([`crate::tracing::Tracer`]: BVHs
//! over tiles of nearby triangles, each built when a ray first reaches it).

mod area_lights;
mod camera;
mod centre_hits;
pub mod document;
mod meshes;
mod nodes;
mod water;

use std::path::{Path, PathBuf};
use std::sync::OnceLock;

use glam::{DVec3, Vec3};
use rayon::prelude::*;

pub use area_lights::AreaLight;
pub use camera::Camera;
pub use centre_hits::{BoxHits, PixelBox, KEPT_PIXELS};
pub use meshes::{is_fallback_quad, TriangleSource};
pub use nodes::{world_instances, NodeInstance};
pub use water::{gloss_from_roughness, roughness_from_gloss, Water, DEFAULT_GLOSS, WATER_IOR};

use crate::settings::Setting;
use crate::tracing::{Hit, Tracer, Triangle};
use crate::{Error, Result};

/// What the user chose on the command line about the scene.
#[derive(Clone, Debug)]
pub struct LoadOptions {
    /// Camera node or camera name; the first camera of the default scene if `None`.
    pub camera: Option<String>,
    /// Water node or mesh name; found by name if `None` (method §3).
    pub water: Option<String>,
    /// Gloss e overriding the water material's.
    pub gloss: Option<f32>,
    /// IOR overriding the water material's.
    pub ior: Option<f32>,
    /// Divides light intensities to get radiance (method §7).
    pub nits_scale: f64,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            camera: None,
            water: None,
            gloss: None,
            ior: None,
            nits_scale: 1.0,
        }
    }
}

/// A loaded scene, ready to trace.
pub struct Scene {
    /// The scene file.
    pub path: PathBuf,
    /// World position of the scene frame's origin (the camera): every position here is
    /// relative to it.
    pub origin: DVec3,
    /// The camera of the photo.
    pub camera: Camera,
    /// The water and its optical constants.
    pub water: Water,
    /// Triangle corners, in the order the tracer's hits refer to.
    pub triangles: Vec<[Vec3; 3]>,
    /// Shading normals at the corners of each triangle.
    pub normals: Vec<[Vec3; 3]>,
    /// Where each triangle came from.
    pub sources: Vec<TriangleSource>,
    /// True for triangles of the water node.
    pub is_water: Vec<bool>,
    /// The BVH over `triangles`: a caller that changes them rebuilds it. (The BVH over the
    /// triangles that are not water, [`Scene::closest_hit_above_water`], is built once, on
    /// first use, from the triangles as they are then.)
    pub tracer: Tracer,
    /// Rect lights found in the scene.
    pub area_lights: Vec<AreaLight>,
    /// Degenerate or non-finite triangles left out.
    pub dropped_triangles: usize,
    /// Things the user should know (skipped primitives, defaults used).
    pub warnings: Vec<String>,
    /// Node names by index (`None` where unnamed), for messages and reports.
    pub node_names: Vec<Option<String>>,
    /// The BVH over every triangle but the water's, built on first use
    /// ([`Scene::closest_hit_above_water`]).
    above_water: OnceLock<AboveWater>,
    /// The camera's centre rays traced so far ([`Scene::centre_hits`]).
    centre_hit_cache: centre_hits::CentreHitCache,
}

/// A BVH over the triangles that are not water, and each one's index in [`Scene::triangles`].
struct AboveWater {
    tracer: Tracer,
    index: Vec<u32>,
}

impl Scene {
    /// The closest hit of a ray that runs above every water triangle between `tmin` and `tmax`
    /// (a statistical water model's reflected ray past the crests,
    /// [`crate::render::WaterPoint::reflected_hit`]): the same hit as [`Scene::tracer`] gives,
    /// found among the other triangles alone. A ray leaving a wave mesh at a grazing angle
    /// otherwise walks the mesh's boxes for metres, testing triangles it cannot hit.
    pub fn closest_hit_above_water(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<Hit> {
        let dry = self.above_water.get_or_init(|| {
            let index: Vec<u32> = (0..self.triangles.len() as u32)
                .filter(|&i| !self.is_water[i as usize])
                .collect();
            let triangles: Vec<Triangle> = index
                .iter()
                .map(|&i| Triangle {
                    vertices: self.triangles[i as usize],
                })
                .collect();
            AboveWater {
                tracer: Tracer::new(&triangles),
                index,
            }
        });
        dry.tracer
            .closest_hit(origin, dir, tmin, tmax)
            .map(|hit| Hit {
                triangle: dry.index[hit.triangle as usize],
                ..hit
            })
    }
}

fn check_override(value: Option<f32>, what: Setting, min_exclusive: f32) -> Result<()> {
    if let Some(v) = value {
        if !(v.is_finite() && v > min_exclusive) {
            return Err(Error::setting(
                what,
                format!("must be a number greater than {min_exclusive}, not {v}"),
            ));
        }
    }
    Ok(())
}

fn check_options(options: &LoadOptions) -> Result<()> {
    check_override(options.gloss, Setting::Gloss, 0.0)?;
    check_override(options.ior, Setting::Ior, 1.0)?;
    if !(options.nits_scale.is_finite() && options.nits_scale > 0.0) {
        return Err(Error::setting(
            Setting::NitsScale,
            format!("must be a positive number, not {}", options.nits_scale),
        ));
    }
    if options.nits_scale > MAX_NITS_SCALE {
        return Err(Error::setting(
            Setting::NitsScale,
            format!(
                "must be at most {MAX_NITS_SCALE:e} (683 turns W/(sr m^2) into nits), not {}: \
                 the lights' intensities would overflow",
                short(options.nits_scale)
            ),
        ));
    }
    Ok(())
}

/// Largest nits scale accepted: a light's intensity (its radiance times the scale) must stay a
/// finite number, and no unit conversion is anywhere near this.
pub const MAX_NITS_SCALE: f64 = 1e9;

/// Farthest a camera may be from the scene's origin along any axis, in scene units: the
/// geometry is traced relative to the camera in single precision, and beyond this it would
/// overflow or lose every detail (georeferenced scenes are well within it).
pub const MAX_CAMERA_DISTANCE: f64 = 1e9;

/// A coordinate for a message: in exponent form when large (1e308 has 309 digits).
fn short(v: f64) -> String {
    if v.abs() < 1e6 {
        format!("{v}")
    } else {
        format!("{v:e}")
    }
}

/// Loads the scene at `path` (`.gltf` or `.glb`).
pub fn load(path: &Path, options: &LoadOptions) -> Result<Scene> {
    // A bad option is reported before a missing file.
    check_options(options)?;
    let bytes = crate::input_file::read(path)?;
    load_from_bytes(
        &bytes,
        Some(path.parent().unwrap_or(Path::new("."))),
        path,
        options,
    )
}

/// Loads a scene from the bytes of a `.gltf` or `.glb` file. External buffers are read
/// relative to `base_dir` (with `None`, a scene that refers to a file is an error: the
/// fuzzer uses this so it never touches the file system); `path` names the scene in
/// messages and in [`Scene::path`].
pub fn load_from_bytes(
    bytes: &[u8],
    base_dir: Option<&Path>,
    path: &Path,
    options: &LoadOptions,
) -> Result<Scene> {
    check_options(options)?;
    let source = document::from_bytes(bytes, path, base_dir)?;
    let doc = &source.document;
    let err = |m: String| Error::scene(path, m);
    let instances = nodes::world_instances(doc, &source.json).map_err(err)?;

    let camera = choose_camera(doc, &instances, options.camera.as_deref()).map_err(err)?;
    let (cam_node, cam_world, yfov, aspect) = camera;
    let origin = cam_world.w_axis.truncate();
    if !(origin.is_finite() && origin.abs().max_element() <= MAX_CAMERA_DISTANCE) {
        let name = doc
            .nodes()
            .nth(cam_node)
            .and_then(|n| n.name().map(crate::names::escaped))
            .unwrap_or_else(|| format!("node {cam_node}"));
        return Err(Error::scene(
            path,
            format!(
                "the camera \"{name}\" is at ({}, {}, {}): a camera must be within \
                 {MAX_CAMERA_DISTANCE:e} of the scene's origin (and finite)",
                short(origin.x),
                short(origin.y),
                short(origin.z)
            ),
        ));
    }
    let node_names: Vec<Option<String>> =
        doc.nodes().map(|n| n.name().map(str::to_owned)).collect();
    let cam_name = node_names[cam_node]
        .clone()
        .or_else(|| {
            doc.nodes()
                .nth(cam_node)
                .and_then(|n| n.camera())
                .and_then(|c| c.name().map(str::to_owned))
        })
        .unwrap_or_else(|| format!("node {cam_node}"));
    let camera = Camera::from_world(cam_name, cam_node, &cam_world, origin, yfov, aspect)
        .ok_or_else(|| Error::scene(path, "the camera's node matrix is degenerate"))?;
    if !(yfov.is_finite() && yfov > 0.0 && yfov < std::f32::consts::PI) {
        return Err(Error::scene(
            path,
            format!("the camera's yfov {yfov} is not between 0 and pi"),
        ));
    }

    let mut warnings = Vec::new();
    let water_node =
        water::choose(doc, &source.json, &instances, options.water.as_deref()).map_err(err)?;
    let water =
        water::optics(doc, water_node, options.gloss, options.ior, &mut warnings).map_err(err)?;

    let tris =
        meshes::collect(doc, &source.json, &source.buffers, &instances, origin).map_err(err)?;
    warnings.extend(tris.warnings.iter().cloned());
    if tris.dropped > 0 {
        warnings.push(format!(
            "{} degenerate or non-finite (NaN or infinite vertex) triangles were left out",
            tris.dropped
        ));
    }
    let is_water: Vec<bool> = tris
        .sources
        .iter()
        .map(|s| s.node as usize == water_node)
        .collect();
    if !is_water.iter().any(|&w| w) {
        return Err(Error::scene(
            path,
            format!("the water node \"{}\" has no usable triangles", water.name),
        ));
    }
    let area_lights = area_lights::read(
        &source.json,
        &instances,
        origin,
        options.nits_scale,
        &mut warnings,
    );
    let tracer = Tracer::new(
        &tris
            .positions
            .par_iter()
            .map(|&vertices| Triangle { vertices })
            .collect::<Vec<_>>(),
    );
    // A camera under the water sees it from below, which the reflection model does not cover.
    if let Some(hit) = tracer.closest_hit(camera.position, glam::Vec3::Y, 0.0, f32::INFINITY) {
        if is_water.get(hit.triangle as usize) == Some(&true) {
            return Err(Error::scene(
                path,
                format!(
                    "the camera \"{}\" is below the water surface (the water \"{}\" is {:.3} above it): the photo must be taken from above the water",
                    camera.name, water.name, hit.t
                ),
            ));
        }
    }
    Ok(Scene {
        path: path.to_path_buf(),
        origin,
        camera,
        water,
        triangles: tris.positions,
        normals: tris.normals,
        sources: tris.sources,
        is_water,
        tracer,
        area_lights,
        dropped_triangles: tris.dropped,
        warnings,
        node_names,
        above_water: OnceLock::new(),
        centre_hit_cache: Default::default(),
    })
}

type CameraChoice = (usize, glam::DMat4, f32, Option<f32>);

fn choose_camera(
    doc: &gltf::Document,
    instances: &[NodeInstance],
    requested: Option<&str>,
) -> std::result::Result<CameraChoice, String> {
    let with_camera: Vec<(&NodeInstance, gltf::Camera)> = instances
        .iter()
        .filter_map(|i| {
            doc.nodes()
                .nth(i.node)
                .and_then(|n| n.camera())
                .map(|c| (i, c))
        })
        .collect();
    let label = |i: &NodeInstance, c: &gltf::Camera| {
        doc.nodes()
            .nth(i.node)
            .and_then(|n| n.name().map(str::to_owned))
            .or_else(|| c.name().map(str::to_owned))
            .unwrap_or_else(|| format!("node {}", i.node))
    };
    let chosen = match requested {
        Some(want) => with_camera
            .iter()
            .find(|(i, c)| {
                doc.nodes().nth(i.node).and_then(|n| n.name()) == Some(want)
                    || c.name() == Some(want)
            })
            .ok_or_else(|| {
                let names: Vec<String> = with_camera.iter().map(|(i, c)| label(i, c)).collect();
                if names.is_empty() {
                    format!("no camera named \"{want}\": the scene has no camera")
                } else {
                    format!(
                        "no camera named \"{want}\"; the cameras are: {}",
                        names.join(", ")
                    )
                }
            })?,
        None => with_camera.first().ok_or_else(|| {
            "the scene has no camera: add a perspective camera that sees the water as the photo was taken"
                .to_owned()
        })?,
    };
    let (instance, cam) = chosen;
    match cam.projection() {
        gltf::camera::Projection::Perspective(p) => {
            Ok((instance.node, instance.world, p.yfov(), p.aspect_ratio()))
        }
        gltf::camera::Projection::Orthographic(_) => Err(format!(
            "the camera \"{}\" is orthographic; a photo needs a perspective camera",
            label(instance, cam)
        )),
    }
}

impl Scene {
    /// The unit shading normal at a hit on `triangle` with barycentric weights `b`.
    pub fn shading_normal(&self, triangle: u32, b: [f32; 3]) -> Vec3 {
        let n = self.normals[triangle as usize];
        (n[0] * b[0] + n[1] * b[1] + n[2] * b[2]).normalize_or_zero()
    }

    /// The unit geometric normal of `triangle` (by its winding).
    pub fn face_normal(&self, triangle: u32) -> Vec3 {
        let [a, b, c] = self.triangles[triangle as usize];
        (b - a).cross(c - a).normalize_or_zero()
    }

    /// The name of node `index` for messages.
    pub fn node_label(&self, index: usize) -> String {
        self.node_names
            .get(index)
            .cloned()
            .flatten()
            .unwrap_or_else(|| format!("node {index}"))
    }
}
