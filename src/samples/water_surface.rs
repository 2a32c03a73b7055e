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

/// One sinusoidal ripple: height `amplitude * sin(k . (x, z) + phase)`.
#[derive(Clone, Copy, Debug)]
pub struct Ripple {
    /// Wave vector (radians per metre) in (x, z).
    pub k: [f64; 2],
    /// Height amplitude (metres).
    pub amplitude: f64,
    /// Phase (radians).
    pub phase: f64,
}

/// Slope statistics of a water surface along a horizontal unit axis u = (u_x, u_z) and across
/// it, along v = (-u_z, u_x): the direction to the right of someone looking along u (for
/// u = -z, the samples' view direction, v = +x).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SlopeVariances {
    /// Variance of the slope dh/du.
    pub along: f64,
    /// Variance of the slope dh/dv.
    pub across: f64,
    /// Covariance of the two.
    pub covariance: f64,
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

    /// The field made of `ripples`.
    pub fn from_ripples(ripples: Vec<Ripple>) -> Self {
        RippleField { ripples }
    }

    /// The ripples, unfiltered.
    pub fn ripples(&self) -> &[Ripple] {
        &self.ripples
    }

    /// The exact slope variances of the unfiltered field along the horizontal unit axis
    /// `axis` = (u_x, u_z) and across it, over the whole plane: a ripple a sin(k . x + phase)
    /// has slope a (k . u) cos(k . x + phase) along u, of mean square a^2 (k . u)^2 / 2, and
    /// ripples with different wave vectors are uncorrelated over the plane.
    pub fn slope_variances(&self, axis: [f64; 2]) -> SlopeVariances {
        let norm = axis[0].hypot(axis[1]);
        let (ux, uz) = (axis[0] / norm, axis[1] / norm);
        let mut out = SlopeVariances {
            along: 0.0,
            across: 0.0,
            covariance: 0.0,
        };
        for r in &self.ripples {
            let ku = r.k[0] * ux + r.k[1] * uz;
            let kv = -r.k[0] * uz + r.k[1] * ux;
            let half_a2 = 0.5 * r.amplitude * r.amplitude;
            out.along += half_a2 * ku * ku;
            out.across += half_a2 * kv * kv;
            out.covariance += half_a2 * ku * kv;
        }
        out
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

/// One row of a water grid: `columns + 1` vertices at `z`, evenly spaced over
/// [-half_width, half_width].
#[derive(Clone, Copy, Debug)]
pub struct GridRow {
    /// The row's z.
    pub z: f64,
    /// The spacing to the neighbouring rows (the prefilter's scale along z).
    pub dz: f64,
    /// Half the row's width along x.
    pub half_width: f64,
}

/// Meshes `field` on the grid `spec`, with the prefilter's Gaussian as wide as the grid's
/// spacing.
pub fn mesh(field: &RippleField, spec: &GridSpec) -> WaterMesh {
    let rows: Vec<GridRow> = (0..=spec.rows)
        .map(|j| {
            let d = spec.row_distance(j as f64);
            GridRow {
                z: spec.eye_z - d,
                dz: spec.row_spacing(j as f64),
                half_width: spec.half_width_per_distance * d,
            }
        })
        .collect();
    mesh_rows(field, &rows, spec.columns, 1.0)
}

impl GridSpec {
    /// The distance from the camera of (fractional) row `j`: rows are uniform in the tangent
    /// of the angle below the horizon, as image rows are.
    fn row_distance(&self, j: f64) -> f64 {
        let (t_near, t_far) = self.tangents();
        self.eye_height / (t_near + (t_far - t_near) * j / self.rows as f64)
    }

    /// The tangents of the angles below the horizon of the nearest and the farthest row.
    fn tangents(&self) -> (f64, f64) {
        (self.eye_height / self.near, self.eye_height / self.far)
    }

    /// The spacing along z around (fractional) row `j`.
    fn row_spacing(&self, j: f64) -> f64 {
        (self.row_distance(j + 0.5) - self.row_distance(j - 0.5)).abs()
    }

    /// The scales (along x, along z) of the prefilter [`mesh`] applies at distance `d` from
    /// the camera: the grid's spacing there. It grows with the distance (along z as its
    /// square), so a mesh of this grid holds less of the short ripples' slope far from the
    /// camera than near it.
    pub fn prefilter_at(&self, d: f64) -> (f64, f64) {
        let (t_near, t_far) = self.tangents();
        let j = (self.eye_height / d - t_near) / (t_far - t_near) * self.rows as f64;
        (
            2.0 * self.half_width_per_distance * d / self.columns as f64,
            self.row_spacing(j),
        )
    }
}

/// Meshes `field` on `rows` (near to far, each with `columns` intervals), every ripple
/// attenuated by a Gaussian prefilter of `filter` times the local spacing along x and z.
pub fn mesh_rows(field: &RippleField, rows: &[GridRow], columns: usize, filter: f64) -> WaterMesh {
    let nc = columns + 1;
    let mut positions = Vec::with_capacity(rows.len() * nc);
    let mut normals = Vec::with_capacity(rows.len() * nc);
    for row in rows {
        let dx = 2.0 * row.half_width / columns as f64;
        for i in 0..nc {
            let x = -row.half_width + dx * i as f64;
            let (h, gx, gz) = field.sample(x, row.z, dx * filter, row.dz * filter);
            let n = DVec3::new(-gx, 1.0, -gz).normalize();
            positions.push([x as f32, h as f32, row.z as f32]);
            normals.push([n.x as f32, n.y as f32, n.z as f32]);
        }
    }
    let intervals = rows.len().saturating_sub(1);
    let mut indices = Vec::with_capacity(intervals * columns * 6);
    for j in 0..intervals {
        for i in 0..columns {
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

impl WaterMesh {
    /// The area-weighted slope variances of the mesh's shading normals along the horizontal
    /// unit axis `axis` and across it (as [`RippleField::slope_variances`]), over the
    /// triangles whose centroid `keep` accepts. Within a triangle the slopes (-n_x / n_y,
    /// -n_z / n_y) are taken as linear between its corners, whose mean square over the
    /// triangle is (sum of s_i^2 + sum over pairs of s_i s_j) / 6; the renderer interpolates
    /// the normals themselves, which differs from this by terms of third order in the slope.
    /// The variances are about the mean slope over the kept area.
    pub fn slope_variances(&self, axis: [f64; 2], keep: impl Fn(DVec3) -> bool) -> SlopeVariances {
        let norm = axis[0].hypot(axis[1]);
        let (ux, uz) = (axis[0] / norm, axis[1] / norm);
        let slopes = |i: u32| {
            let n = self.normals[i as usize].map(f64::from);
            let (sx, sz) = (-n[0] / n[1], -n[2] / n[1]);
            (sx * ux + sz * uz, -sx * uz + sz * ux)
        };
        // Sums of area, area * mean, area * mean square (u, v, u v).
        let mut sums = [0.0f64; 6];
        for t in self.indices.chunks_exact(3) {
            let p = |i: u32| DVec3::from(self.positions[i as usize].map(f64::from));
            let (p0, p1, p2) = (p(t[0]), p(t[1]), p(t[2]));
            if !keep((p0 + p1 + p2) / 3.0) {
                continue;
            }
            let e1 = p1 - p0;
            let e2 = p2 - p0;
            let area = 0.5 * (e1.z * e2.x - e1.x * e2.z).abs();
            let s = [slopes(t[0]), slopes(t[1]), slopes(t[2])];
            let second = |f: &dyn Fn((f64, f64)) -> f64| {
                let v = s.map(f);
                (v[0] * v[0] + v[1] * v[1] + v[2] * v[2] + v[0] * v[1] + v[0] * v[2] + v[1] * v[2])
                    / 6.0
            };
            let uu = second(&|(u, _)| u);
            let vv = second(&|(_, v)| v);
            // The mixed moment by polarisation: u v = ((u + v)^2 - u^2 - v^2) / 2.
            let uv = 0.5 * (second(&|(u, v)| u + v) - uu - vv);
            sums[0] += area;
            sums[1] += area * (s[0].0 + s[1].0 + s[2].0) / 3.0;
            sums[2] += area * (s[0].1 + s[1].1 + s[2].1) / 3.0;
            sums[3] += area * uu;
            sums[4] += area * vv;
            sums[5] += area * uv;
        }
        let a = sums[0].max(f64::MIN_POSITIVE);
        let (mu, mv) = (sums[1] / a, sums[2] / a);
        SlopeVariances {
            along: sums[3] / a - mu * mu,
            across: sums[4] / a - mv * mv,
            covariance: sums[5] / a - mu * mv,
        }
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

    /// The mesh's area-weighted slope variances against the exact ones of a single ripple
    /// at 30 degrees from z, meshed finely (25 vertices per wavelength along each axis) and
    /// unfiltered over a whole number of wavelengths: along z, across (x) and their
    /// covariance. A missing projection or a swapped axis would be off by a factor of 3.
    #[test]
    fn mesh_slope_variances_match_the_ripple() {
        let (k, angle) = (std::f64::consts::TAU / 0.5, 30f64.to_radians());
        let field = RippleField::from_ripples(vec![Ripple {
            k: [k * angle.sin(), k * angle.cos()],
            amplitude: 0.004,
            phase: 0.3,
        }]);
        // 20 m along z and 20 m across: whole numbers of the ripple's periods along both.
        let rows: Vec<GridRow> = (0..=2000)
            .map(|j| GridRow {
                z: -(j as f64) * 0.01,
                dz: 0.01,
                half_width: 10.0,
            })
            .collect();
        let mesh = mesh_rows(&field, &rows, 2000, 0.0);
        let exact = field.slope_variances([0.0, -1.0]);
        let measured = mesh.slope_variances([0.0, -1.0], |_| true);
        let s2 = 0.5 * (0.004 * k).powi(2);
        // Along -z: cos^2 30 of the slope variance; across (+x): sin^2 30.
        assert!((exact.along / (s2 * 0.75) - 1.0).abs() < 1e-12);
        assert!((exact.across / (s2 * 0.25) - 1.0).abs() < 1e-12);
        for (m, e) in [
            (measured.along, exact.along),
            (measured.across, exact.across),
            (measured.covariance, exact.covariance),
        ] {
            assert!(
                (m - e).abs() < 0.01 * s2,
                "mesh {measured:?}, exact {exact:?}"
            );
        }
        assert!(exact.covariance.abs() > 0.4 * s2);
    }

    /// A grid of the paper's camera with `rows` rows of 30 columns.
    fn grid(rows: usize) -> GridSpec {
        GridSpec {
            eye_height: 0.2,
            eye_z: 10.0,
            near: 0.3,
            far: 14.0,
            half_width_per_distance: 0.8,
            rows,
            columns: 30,
        }
    }

    #[test]
    fn triangles_face_up() {
        let field = RippleField::new(1, 8, 0.05);
        let m = mesh(&field, &grid(20));
        for t in m.indices.chunks_exact(3) {
            let p = |i: u32| DVec3::from(m.positions[i as usize].map(f64::from));
            let n = (p(t[1]) - p(t[0])).cross(p(t[2]) - p(t[0]));
            assert!(n.y > 0.0);
        }
    }

    /// The prefilter at a row's own distance is the spacing to its neighbours: along z
    /// half-way to each (the rows' own `dz`), along x the row's column spacing; checked
    /// against the vertices [`mesh`] lays out.
    #[test]
    fn the_prefilter_at_a_rows_distance_is_its_spacing() {
        let spec = grid(200);
        let m = mesh(&RippleField::new(1, 8, 0.05), &spec);
        let nc = spec.columns + 1;
        let z = |j: usize| spec.eye_z - m.positions[j * nc][2] as f64;
        for j in 1..spec.rows {
            let (dx, dz) = spec.prefilter_at(z(j));
            let row_dx = (m.positions[j * nc + 1][0] - m.positions[j * nc][0]) as f64;
            let between = 0.5 * (z(j + 1) - z(j - 1));
            assert!(
                (dx / row_dx - 1.0).abs() < 1e-5,
                "row {j}: {dx} vs {row_dx}"
            );
            // The row's own spacing, found from its distance alone (the mesh's f32 positions
            // hold that distance to about 1e-6 m).
            let exact = spec.prefilter_at(spec.row_distance(j as f64)).1;
            assert!(
                (exact / spec.row_spacing(j as f64) - 1.0).abs() < 1e-9,
                "row {j}"
            );
            assert!((dz / exact - 1.0).abs() < 1e-3, "row {j}: {dz} vs {exact}");
            // Half-way points against the neighbours' mean: equal to second order in the
            // spacing relative to the distance (under 1 % over the nearer half).
            if j < spec.rows / 2 {
                assert!(
                    (dz / between - 1.0).abs() < 0.01,
                    "row {j}: {dz} vs {between}"
                );
            }
            assert!(z(j + 1) > z(j) && dz > spec.prefilter_at(z(j - 1)).1);
        }
    }
}
