//! A plane seen from its front side, and where a ray meets it: the one ray/plane hit that a
//! light's plane ([`crate::fitting::LightPlane::hit`]) and the scene's area lights
//! ([`crate::scene_in::AreaLight::intersect`]) share.

use glam::Vec3;

/// The plane through `point` whose front side faces along the unit `normal`.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Plane {
    /// A point of the plane.
    pub point: Vec3,
    /// Unit normal, on the front side.
    pub normal: Vec3,
}

impl Plane {
    /// How far along `dir` from `origin` the ray's line meets the plane, in units of `dir`'s
    /// length, when the ray travels against the normal (it comes from the front side); `None`
    /// for a ray parallel to the plane or leaving its front. The distance is signed (negative:
    /// the plane is behind `origin`); each caller keeps the range it needs.
    #[inline]
    pub fn front_distance(&self, origin: Vec3, dir: Vec3) -> Option<f32> {
        let denom = dir.dot(self.normal);
        if denom >= 0.0 {
            return None;
        }
        Some((self.point - origin).dot(self.normal) / denom)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn a_ray_meets_the_front_side_only() {
        // The plane z = 2, facing -z (towards the origin).
        let plane = Plane {
            point: Vec3::new(5.0, -3.0, 2.0),
            normal: Vec3::NEG_Z,
        };
        assert_eq!(plane.front_distance(Vec3::ZERO, Vec3::Z), Some(2.0));
        // Twice as long a direction: half the distance.
        assert_eq!(plane.front_distance(Vec3::ZERO, 2.0 * Vec3::Z), Some(1.0));
        // Behind the origin: negative.
        assert_eq!(
            plane.front_distance(Vec3::new(0.0, 0.0, 3.0), Vec3::Z),
            Some(-1.0)
        );
        // Leaving the front side, or parallel.
        assert_eq!(plane.front_distance(Vec3::ZERO, Vec3::NEG_Z), None);
        assert_eq!(plane.front_distance(Vec3::ZERO, Vec3::X), None);
    }
}
