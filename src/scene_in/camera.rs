//! The perspective camera the photo was taken with, and the rays through its pixels.
//!
//! Pixel (i = column, j = row, row 0 at the top) covers [i, i+1] x [j, j+1] in continuous
//! pixel coordinates; its centre is (i + 0.5, j + 0.5) (method §2).

use glam::{DMat4, DVec3, Vec3};

/// A perspective camera in the scene's camera-centred frame.
#[derive(Clone, Debug)]
pub struct Camera {
    /// The camera node's name (or the camera's own name when the node has none).
    pub name: String,
    /// Index of the camera's node in the glTF document.
    pub node: usize,
    /// Position in the scene frame (zero up to rounding: the frame is centred on the camera).
    pub position: Vec3,
    /// Unit vector to the right of the image.
    pub right: Vec3,
    /// Unit vector to the top of the image.
    pub up: Vec3,
    /// Unit viewing direction (the node's local -Z).
    pub forward: Vec3,
    /// Vertical field of view in radians.
    pub yfov: f32,
    /// Width / height, when the file states it.
    pub aspect_ratio: Option<f32>,
}

impl Camera {
    /// Builds a camera from its node's world matrix; `origin` is the scene frame's origin.
    /// Scale in the node's matrix is removed: only position and orientation matter.
    pub fn from_world(
        name: String,
        node: usize,
        world: &DMat4,
        origin: DVec3,
        yfov: f32,
        aspect_ratio: Option<f32>,
    ) -> Option<Self> {
        let y = world.y_axis.truncate();
        let position = (world.w_axis.truncate() - origin).as_vec3();
        let forward = (-world.z_axis.truncate()).try_normalize()?;
        // Re-orthogonalise: a sheared or scaled parent should not skew the rays.
        let right = forward.cross(y).try_normalize()?;
        let up = right.cross(forward);
        Some(Camera {
            name,
            node,
            position,
            right: right.as_vec3(),
            up: up.as_vec3(),
            forward: forward.as_vec3(),
            yfov,
            aspect_ratio,
        })
    }

    /// The aspect ratio used for an image of `width` x `height`: the camera's own if it has
    /// one, else the image's.
    pub fn aspect_for(&self, width: u32, height: u32) -> f32 {
        self.aspect_ratio.unwrap_or(width as f32 / height as f32)
    }

    /// The unit direction of the ray through continuous pixel coordinates (`x`, `y`) of an
    /// image of `width` x `height`.
    pub fn direction(&self, x: f32, y: f32, width: u32, height: u32) -> Vec3 {
        let tan_half = (self.yfov * 0.5).tan();
        let aspect = self.aspect_for(width, height);
        let sx = (2.0 * x / width as f32 - 1.0) * tan_half * aspect;
        let sy = (1.0 - 2.0 * y / height as f32) * tan_half;
        (self.forward + self.right * sx + self.up * sy).normalize()
    }

    /// Continuous pixel coordinates where the point `p` (scene frame) appears, or `None` if it
    /// is behind the camera.
    pub fn project(&self, p: Vec3, width: u32, height: u32) -> Option<(f32, f32)> {
        let d = p - self.position;
        let z = d.dot(self.forward);
        if z <= 0.0 {
            return None;
        }
        let tan_half = (self.yfov * 0.5).tan();
        let aspect = self.aspect_for(width, height);
        let sx = d.dot(self.right) / z / (tan_half * aspect);
        let sy = d.dot(self.up) / z / tan_half;
        Some((
            (sx + 1.0) * 0.5 * width as f32,
            (1.0 - sy) * 0.5 * height as f32,
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn paper_camera() -> Camera {
        let world = DMat4::from_translation(DVec3::new(0.0, 0.2, 10.0));
        Camera::from_world(
            "cam".into(),
            0,
            &world,
            DVec3::new(0.0, 0.2, 10.0),
            60f32.to_radians(),
            Some(1.0),
        )
        .unwrap()
    }

    #[test]
    fn centre_pixel_looks_forward_and_corners_span_the_fov() {
        let c = paper_camera();
        let d = c.direction(300.0, 300.0, 600, 600);
        assert!((d - Vec3::NEG_Z).length() < 1e-6);
        let top = c.direction(300.0, 0.0, 600, 600);
        let angle = top.dot(Vec3::NEG_Z).acos().to_degrees();
        assert!((angle - 30.0).abs() < 1e-3, "{angle}");
        assert!(top.y > 0.0);
        let right = c.direction(600.0, 300.0, 600, 600);
        assert!(right.x > 0.0);
    }

    #[test]
    fn project_inverts_direction() {
        let c = paper_camera();
        for &(x, y) in &[(10.5f32, 20.5f32), (599.0, 300.0), (123.25, 456.75)] {
            let p = c.position + c.direction(x, y, 600, 600) * 7.0;
            let (px, py) = c.project(p, 600, 600).unwrap();
            assert!((px - x).abs() < 1e-3 && (py - y).abs() < 1e-3);
        }
    }
}
