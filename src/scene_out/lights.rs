//! The `EXT_lights_area` JSON of a light (method §7): the top-level light object, the node that
//! places it, and the node's rotation from the light's frame.

use glam::{DMat3, DQuat, DVec3};
use serde_json::{json, Value};

use super::LightToWrite;
use crate::{Error, Result};

/// The extension's name, as listed in `extensionsUsed`.
pub const EXTENSION: &str = "EXT_lights_area";

/// How far from unit length / perpendicular the fitter's axes may be before we refuse them:
/// a looser frame would mean the fitter has a bug, and we would silently write another light.
const AXIS_TOLERANCE: f64 = 1e-6;

/// A light checked and converted to what the file stores.
#[derive(Debug, Clone)]
pub(crate) struct PreparedLight {
    pub name: String,
    pub translation: [f64; 3],
    /// Unit quaternion `[x, y, z, w]`, w >= 0.
    pub rotation: [f64; 4],
    pub width: f64,
    pub height: f64,
    /// Radiance divided by its largest component, in [0, 1].
    pub color: [f64; 3],
    /// Largest radiance component times the nits scale.
    pub intensity: f64,
    pub streak: Option<usize>,
    /// How far the node sits in front of the fitted rectangle (metres, along `normal`).
    pub offset: f64,
}

/// Checks `light` and converts it, its node `offset` metres in front of it; `index` is its
/// position in the caller's list, for messages.
pub(crate) fn prepare(
    light: &LightToWrite,
    index: usize,
    nits_scale: f64,
    offset: f64,
) -> Result<PreparedLight> {
    let bad = |msg: String| {
        Error::Usage(format!(
            "light {index} (\"{}\") cannot be written: {msg}",
            light.name
        ))
    };
    if !light.center.is_finite() {
        return Err(bad(format!("its centre {} is not finite", light.center)));
    }
    for (what, v) in [("normal", light.normal), ("up", light.up)] {
        if !v.is_finite() || (v.length() - 1.0).abs() > AXIS_TOLERANCE {
            return Err(bad(format!("its {what} {v} is not a unit vector")));
        }
    }
    if light.normal.dot(light.up).abs() > AXIS_TOLERANCE {
        return Err(bad(format!(
            "its up {} is not perpendicular to its normal {}",
            light.up, light.normal
        )));
    }
    for (what, v) in [("width", light.width), ("height", light.height)] {
        if !(v.is_finite() && v > 0.0) {
            return Err(bad(format!("its {what} {v} is not a positive number")));
        }
    }
    if light.radiance.iter().any(|c| !(c.is_finite() && *c >= 0.0)) {
        return Err(bad(format!(
            "its radiance {:?} is not finite and non-negative",
            light.radiance
        )));
    }
    let max = light.radiance.iter().copied().fold(0.0_f64, f64::max);
    if !(max * nits_scale).is_finite() {
        return Err(bad(format!(
            "its intensity, radiance {max} times the nits scale {nits_scale}, is too large for \
             a number (a glTF file would hold null); use a nits scale of at most {}",
            crate::scene_in::MAX_NITS_SCALE
        )));
    }
    let color = if max > 0.0 {
        light.radiance.map(|c| c / max)
    } else {
        [1.0; 3]
    };
    Ok(PreparedLight {
        name: light.name.clone(),
        translation: (light.center + light.normal * offset).to_array(),
        rotation: rotation(light.normal, light.up),
        width: light.width,
        height: light.height,
        color,
        intensity: max * nits_scale,
        streak: light.streak_id,
        offset,
    })
}

/// The node rotation whose local -Z is `normal` and local +Y is `up` (local X = Y x Z), as a
/// glTF `[x, y, z, w]` quaternion.
fn rotation(normal: DVec3, up: DVec3) -> [f64; 4] {
    let z = -normal.normalize();
    // Re-orthogonalise within the tolerance accepted above, so the matrix is a rotation.
    let y = (up - up.dot(z) * z).normalize();
    let x = y.cross(z);
    let q = DQuat::from_mat3(&DMat3::from_cols(x, y, z)).normalize();
    // q and -q are the same rotation; pick w >= 0 so the output does not depend on rounding.
    let q = if q.w < 0.0 { -q } else { q };
    // Adding +0.0 turns -0.0 into 0.0, so the file never shows a "-0.0".
    q.to_array().map(|c| c + 0.0)
}

/// The top-level light object. Every field is written: importers' defaults differ (Babylon
/// takes intensity 1, the draft 1000).
pub(crate) fn light_json(light: &PreparedLight) -> Value {
    json!({
        "type": "rect",
        "color": light.color,
        "intensity": light.intensity,
        "size": light.height,
        "rect": { "aspect": light.width / light.height },
        "name": light.name,
    })
}

/// The node that places light `light_index`: at the scene root, no scale, marked so the scene
/// loader and later runs know it is ours.
pub(crate) fn node_json(light: &PreparedLight, light_index: usize, child: Option<usize>) -> Value {
    let mut marker = json!({ "role": "light", "wall_offset": light.offset });
    if let Some(streak) = light.streak {
        marker["streak"] = Value::from(streak);
    }
    let mut node = json!({
        "name": light.name,
        "translation": light.translation,
        "rotation": light.rotation,
    });
    if let Some(child) = child {
        node["children"] = json!([child]);
    }
    node["extensions"] = json!({ EXTENSION: { "light": light_index } });
    node["extras"] = json!({ "streaklight": marker });
    node
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light(normal: DVec3, up: DVec3) -> LightToWrite {
        LightToWrite {
            name: "l".into(),
            center: DVec3::new(1.0, 2.0, 3.0),
            normal,
            up,
            width: 2.0,
            height: 1.0,
            radiance: [4.0, 2.0, 0.0],
            streak_id: Some(7),
        }
    }

    #[test]
    fn rotation_maps_local_axes_to_the_light_frame() {
        let normal = DVec3::new(1.0, -1.0, 0.5).normalize();
        let up = normal.any_orthonormal_vector();
        let p = prepare(&light(normal, up), 0, 1.0, 0.0).unwrap();
        let q = DQuat::from_array(p.rotation);
        assert!((q * DVec3::NEG_Z - normal).length() < 1e-12);
        assert!((q * DVec3::Y - up).length() < 1e-12);
        assert!((q * DVec3::X - up.cross(-normal)).length() < 1e-12);
        assert!(p.rotation[3] >= 0.0);
        // A half turn about an axis in the XY plane has w = 0: written as 0.0, not -0.0.
        let half = prepare(
            &light(DVec3::new(0.0, -0.6, 0.8), DVec3::new(0.0, 0.8, 0.6)),
            0,
            1.0,
            0.0,
        );
        assert!(half
            .unwrap()
            .rotation
            .iter()
            .all(|c| !(*c == 0.0 && c.is_sign_negative())));
    }

    #[test]
    fn the_node_sits_the_offset_in_front_of_the_rectangle() {
        let normal = DVec3::new(0.0, -0.6, 0.8);
        let l = light(normal, DVec3::new(0.0, 0.8, 0.6));
        let p = prepare(&l, 0, 1.0, 0.001).unwrap();
        let moved = DVec3::from_array(p.translation) - l.center;
        assert!((moved - normal * 0.001).length() < 1e-15, "{moved}");
        assert_eq!(
            node_json(&p, 0, None)["extras"]["streaklight"]["wall_offset"],
            0.001
        );
    }

    #[test]
    fn identity_frame_is_the_identity_quaternion() {
        let p = prepare(&light(DVec3::NEG_Z, DVec3::Y), 0, 1.0, 0.0).unwrap();
        assert_eq!(p.rotation, [0.0, 0.0, 0.0, 1.0]);
    }

    #[test]
    fn colour_is_normalised_and_intensity_scaled() {
        let p = prepare(&light(DVec3::NEG_Z, DVec3::Y), 0, 683.0, 0.0).unwrap();
        assert_eq!(p.color, [1.0, 0.5, 0.0]);
        assert_eq!(p.intensity, 4.0 * 683.0);
        let mut dark = light(DVec3::NEG_Z, DVec3::Y);
        dark.radiance = [0.0; 3];
        let p = prepare(&dark, 0, 1.0, 0.0).unwrap();
        assert_eq!((p.color, p.intensity), ([1.0; 3], 0.0));
    }

    #[test]
    fn refuses_bad_frames_and_sizes() {
        assert!(prepare(&light(DVec3::NEG_Z, DVec3::Z), 0, 1.0, 0.0).is_err());
        assert!(prepare(&light(DVec3::new(0.0, 0.0, -2.0), DVec3::Y), 0, 1.0, 0.0).is_err());
        let mut l = light(DVec3::NEG_Z, DVec3::Y);
        l.height = 0.0;
        assert!(prepare(&l, 0, 1.0, 0.0).is_err());
        l.height = 1.0;
        l.radiance[1] = f64::NAN;
        assert!(prepare(&l, 0, 1.0, 0.0).is_err());
    }
}
