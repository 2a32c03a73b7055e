//! A rippled water height field for the sample scenes, meshed for the paper's camera.
//!
//! Ripples are a sum of sinusoids travelling mostly towards the camera, with wavelengths
//! from 3 to 50 cm: a light's reflection becomes a broken vertical streak, not a blurred
//! mirror image. The mesh is a grid whose rows and columns follow the camera's pixel rows
//! and columns on the water plane (about one vertex per pixel), so near water is finely
//! meshed and far water coarsely. Each ripple is attenuated where the grid is too coarse
//! to carry it (a Gaussian prefilter of the grid's spacing), as a photo's pixels would
//! average it, so the far water is not aliased noise.

use glam::DVec3;

use crate::random::Rng;

/// One sinusoidal ripple.
#[derive(Clone, Copy, Debug)]
struct Ripple {
    /// Wave vector (radians per metre) in (x, z).
    k: [f64; 2],
    amplitude: f64,
    phase: f64,
}

/// The height field h(x, z) of the water around y = 0.
#[derive(Clone, Debug)]
pub struct RippleField {
    ripples: Vec<Ripple>,
}

impl RippleField {
    /// A reproducible field of `count` ripples with a total root-mean-square slope of
    /// `rms_slope`, drawn from `seed`.
    pub fn new(seed: u64, count: usize, rms_slope: f64) -> Self {
        let mut rng = Rng::new(seed, 0x5249_5050);
        let (min_wavelength, max_wavelength) = (0.03f64, 0.5f64);
        let per_ripple_slope = rms_slope * (2.0 / count as f64).sqrt();
        let ripples = (0..count)
            .map(|_| {
                let wavelength =
                    min_wavelength * (max_wavelength / min_wavelength).powf(rng.next_f64());
                let k = std::f64::consts::TAU / wavelength;
                // Mostly travelling along z (towards the camera), spread by ~25 degrees.
                let angle = rng.next_gaussian() * 25f64.to_radians();
                Ripple {
                    k: [k * angle.sin(), k * angle.cos()],
                    amplitude: per_ripple_slope / k,
                    phase: rng.next_f64() * std::f64::consts::TAU,
                }
            })
            .collect();
        RippleField { ripples }
    }

    /// Height and its gradient (dh/dx, dh/dz) at (x, z), each ripple attenuated by a
    /// Gaussian prefilter of the local grid spacing (`dx`, `dz`).
    pub fn sample(&self, x: f64, z: f64, dx: f64, dz: f64) -> (f64, f64, f64) {
        let mut h = 0.0;
        let mut gx = 0.0;
        let mut gz = 0.0;
        for r in &self.ripples {
            let (kx, kz) = (r.k[0], r.k[1]);
            let blur = (-0.5 * ((kx * dx).powi(2) + (kz * dz).powi(2))).exp();
            let a = r.amplitude * blur;
            if a < 1e-9 {
                continue;
            }
            let arg = kx * x + kz * z + r.phase;
            let (s, c) = arg.sin_cos();
            h += a * s;
            gx += a * kx * c;
            gz += a * kz * c;
        }
        (h, gx, gz)
    }
}

/// A water grid: vertices row by row, with unit normals, and triangle indices.
pub struct WaterMesh {
    /// Vertex positions (world).
    pub positions: Vec<[f32; 3]>,
    /// Unit vertex normals.
    pub normals: Vec<[f32; 3]>,
    /// Triangle corner indices, counter-clockwise seen from above.
    pub indices: Vec<u32>,
}

/// Meshing parameters for a camera at height `eye_height` above the water at `eye_z`
/// looking down -z.
pub struct GridSpec {
    /// Camera height above the mean water level.
    pub eye_height: f64,
    /// The camera's z.
    pub eye_z: f64,
    /// Nearest and farthest row, as distances along -z from the camera.
    pub near: f64,
    /// Farthest row distance.
    pub far: f64,
    /// Half-width of the grid as a multiple of the distance (x / d).
    pub half_width_per_distance: f64,
    /// Number of row intervals.
    pub rows: usize,
    /// Number of column intervals.
    pub columns: usize,
}

/// Meshes `field` on the grid `spec`.
pub fn mesh(field: &RippleField, spec: &GridSpec) -> WaterMesh {
    // Rows uniform in the tangent of the angle below the horizon, as image rows are.
    let (t_near, t_far) = (spec.eye_height / spec.near, spec.eye_height / spec.far);
    let row_distance =
        |j: f64| spec.eye_height / (t_near + (t_far - t_near) * j / spec.rows as f64);
    let (nr, nc) = (spec.rows + 1, spec.columns + 1);
    let mut positions = Vec::with_capacity(nr * nc);
    let mut normals = Vec::with_capacity(nr * nc);
    for j in 0..nr {
        let d = row_distance(j as f64);
        let dz = (row_distance(j as f64 + 0.5) - row_distance(j as f64 - 0.5)).abs();
        let half_width = spec.half_width_per_distance * d;
        let dx = 2.0 * half_width / spec.columns as f64;
        let z = spec.eye_z - d;
        for i in 0..nc {
            let x = -half_width + dx * i as f64;
            let (h, gx, gz) = field.sample(x, z, dx, dz);
            let n = DVec3::new(-gx, 1.0, -gz).normalize();
            positions.push([x as f32, h as f32, z as f32]);
            normals.push([n.x as f32, n.y as f32, n.z as f32]);
        }
    }
    let mut indices = Vec::with_capacity(spec.rows * spec.columns * 6);
    for j in 0..spec.rows {
        for i in 0..spec.columns {
            let a = (j * nc + i) as u32; // near row, left
            let b = a + 1; // near row, right
            let c = a + nc as u32; // far row, left
            let d = c + 1;
            // Seen from above (+y), x to the right and far (-z) up: a, b, d is counter-clockwise.
            indices.extend_from_slice(&[a, b, d, a, d, c]);
        }
    }
    WaterMesh {
        positions,
        normals,
        indices,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn gradient_matches_finite_differences_and_slope_is_as_asked() {
        let field = RippleField::new(3, 24, 0.05);
        let e = 1e-6;
        let mut sum_sq = 0.0;
        let n = 400;
        let mut rng = Rng::new(9, 9);
        for _ in 0..n {
            let (x, z) = (rng.next_f64() * 4.0 - 2.0, rng.next_f64() * 4.0);
            let (_, gx, gz) = field.sample(x, z, 0.0, 0.0);
            let fx = (field.sample(x + e, z, 0.0, 0.0).0 - field.sample(x - e, z, 0.0, 0.0).0)
                / (2.0 * e);
            let fz = (field.sample(x, z + e, 0.0, 0.0).0 - field.sample(x, z - e, 0.0, 0.0).0)
                / (2.0 * e);
            assert!((gx - fx).abs() < 1e-6 && (gz - fz).abs() < 1e-6);
            sum_sq += gx * gx + gz * gz;
        }
        let rms = (sum_sq / n as f64).sqrt();
        // 400 samples of a sum of 24 sinusoids: the estimate is within ~20 % of the target.
        assert!((rms - 0.05).abs() < 0.01, "rms slope {rms}");
    }

    #[test]
    fn triangles_face_up() {
        let field = RippleField::new(1, 8, 0.05);
        let spec = GridSpec {
            eye_height: 0.2,
            eye_z: 10.0,
            near: 0.3,
            far: 14.0,
            half_width_per_distance: 0.8,
            rows: 20,
            columns: 30,
        };
        let m = mesh(&field, &spec);
        for t in m.indices.chunks_exact(3) {
            let p = |i: u32| DVec3::from(m.positions[i as usize].map(f64::from));
            let n = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
            assert!(n.y > 0.0);
        }
    }
}
