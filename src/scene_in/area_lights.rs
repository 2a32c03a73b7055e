//! Rectangle lights already in a scene, in the `EXT_lights_area` shape of method §7, so that a
//! lit scene can be rendered.
//!
//! A light is centred on its node's origin, its width along local X, its height along local
//! Y, and it emits towards local -Z. Radiance = color x intensity / nits scale.

use glam::{DVec3, Vec3};
use serde_json::Value;

use super::nodes::NodeInstance;
use crate::plane::Plane;

/// The draft's default intensity, used when a light omits it.
const DEFAULT_INTENSITY: f64 = 1000.0;

/// A one-sided emitting rectangle.
#[derive(Clone, Debug)]
pub struct AreaLight {
    /// The light's name (or "light N").
    pub name: String,
    /// Index of the node that carries it.
    pub node: usize,
    /// Centre in the scene frame.
    pub center: Vec3,
    /// Half the width, as a vector along the rectangle.
    pub half_width: Vec3,
    /// Half the height, as a vector along the rectangle.
    pub half_height: Vec3,
    /// Unit normal on the emitting side.
    pub normal: Vec3,
    /// Linear radiance per channel.
    pub radiance: [f32; 3],
}

impl AreaLight {
    /// Distance along the unit ray to the light's emitting face, if the ray hits it from the
    /// front within `(tmin, tmax)`.
    #[inline]
    pub fn intersect(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<f32> {
        let t = self.plane().front_distance(origin, dir)?;
        if !(t > tmin && t < tmax) {
            return None;
        }
        let d = origin + dir * t - self.center;
        let u = d.dot(self.half_width) / self.half_width.length_squared();
        let v = d.dot(self.half_height) / self.half_height.length_squared();
        (u.abs() <= 1.0 && v.abs() <= 1.0).then_some(t)
    }

    /// The plane of the emitting face, its front the emitting side.
    pub fn plane(&self) -> Plane {
        Plane {
            point: self.center,
            normal: self.normal,
        }
    }

    /// Width (full).
    pub fn width(&self) -> f32 {
        2.0 * self.half_width.length()
    }

    /// Height (full).
    pub fn height(&self) -> f32 {
        2.0 * self.half_height.length()
    }
}

fn number(v: Option<&Value>) -> Option<f64> {
    v.and_then(Value::as_f64).filter(|x| x.is_finite())
}

/// Reads every rect light instanced by a node of the scene.
pub fn read(
    json: &Value,
    instances: &[NodeInstance],
    origin: DVec3,
    nits_scale: f64,
    warnings: &mut Vec<String>,
) -> Vec<AreaLight> {
    let Some(lights) = json
        .pointer("/extensions/EXT_lights_area/lights")
        .and_then(Value::as_array)
    else {
        return Vec::new();
    };
    let mut out = Vec::new();
    for instance in instances {
        let Some(index) = json
            .pointer(&format!(
                "/nodes/{}/extensions/EXT_lights_area/light",
                instance.node
            ))
            .and_then(Value::as_u64)
        else {
            continue;
        };
        let Some(light) = lights.get(index as usize) else {
            warnings.push(format!(
                "node {} refers to EXT_lights_area light {index}, which does not exist: ignored",
                instance.node
            ));
            continue;
        };
        let kind = light.get("type").and_then(Value::as_str).unwrap_or("rect");
        if kind != "rect" {
            warnings.push(format!(
                "EXT_lights_area light {index} is a \"{kind}\" light; only \"rect\" lights are rendered"
            ));
            continue;
        }
        let height = number(light.get("size")).unwrap_or(1.0);
        let aspect = number(light.pointer("/rect/aspect")).unwrap_or(1.0);
        let width = height * aspect;
        let intensity = number(light.get("intensity")).unwrap_or(DEFAULT_INTENSITY);
        let color: Vec<f64> = light
            .get("color")
            .and_then(Value::as_array)
            .map(|c| c.iter().filter_map(|x| number(Some(x))).collect())
            .filter(|c: &Vec<f64>| c.len() == 3)
            .unwrap_or_else(|| vec![1.0, 1.0, 1.0]);
        let world = instance.world;
        let center = world.transform_point3(DVec3::ZERO);
        let half_width = world.transform_vector3(DVec3::X * (width * 0.5));
        let half_height = world.transform_vector3(DVec3::Y * (height * 0.5));
        let Some(normal) = half_height.cross(half_width).try_normalize() else {
            warnings.push(format!(
                "EXT_lights_area light {index} on node {} has zero size: ignored",
                instance.node
            ));
            continue;
        };
        let name = light
            .get("name")
            .and_then(Value::as_str)
            .map(str::to_owned)
            .unwrap_or_else(|| format!("light {index}"));
        let scale = intensity / nits_scale;
        out.push(AreaLight {
            name,
            node: instance.node,
            center: (center - origin).as_vec3(),
            half_width: half_width.as_vec3(),
            half_height: half_height.as_vec3(),
            normal: normal.as_vec3(),
            radiance: [
                (color[0] * scale) as f32,
                (color[1] * scale) as f32,
                (color[2] * scale) as f32,
            ],
        });
    }
    out
}
