//! An orthonormal frame around a unit normal, for turning a sampled half vector given in
//! (theta, phi) about the normal into world space.

use glam::Vec3;

/// Two unit tangents `(t, b)` such that `(t, b, n)` is a right-handed orthonormal basis.
///
/// Duff, Burgess, Christensen, Hery, Kensler, Liani and Villemin 2017, "Building an
/// Orthonormal Basis, Revisited" (JCGT 6(1)): branchless apart from the sign, no trig, no
/// normalisation, and continuous everywhere except across the plane n.z = 0, which is
/// harmless here because only the distribution of the azimuth matters, not its origin.
/// `n` must be unit length.
#[inline]
pub fn orthonormal_basis(n: Vec3) -> (Vec3, Vec3) {
    let sign = 1.0f32.copysign(n.z);
    let a = -1.0 / (sign + n.z);
    let b = n.x * n.y * a;
    (
        Vec3::new(1.0 + sign * n.x * n.x * a, sign * b, -sign * n.x),
        Vec3::new(b, sign + n.y * n.y * a, -n.y),
    )
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn basis_is_orthonormal_and_right_handed() {
        let normals = [
            Vec3::Z,
            -Vec3::Z,
            Vec3::X,
            Vec3::Y,
            Vec3::new(0.3, -0.5, 0.8).normalize(),
            Vec3::new(-0.2, 0.1, -0.97).normalize(),
            Vec3::new(1e-7, 0.0, -1.0).normalize(),
        ];
        for n in normals {
            let (t, b) = orthonormal_basis(n);
            // f32 rounding of a handful of products: a few ulps.
            let tol = 1e-6;
            assert!((t.length() - 1.0).abs() < tol, "{n}: |t| = {}", t.length());
            assert!((b.length() - 1.0).abs() < tol, "{n}: |b| = {}", b.length());
            assert!(t.dot(b).abs() < tol && t.dot(n).abs() < tol && b.dot(n).abs() < tol);
            assert!(
                (t.cross(b) - n).length() < 1e-5,
                "{n}: t x b = {}",
                t.cross(b)
            );
        }
    }
}
