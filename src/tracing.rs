//! Ray tracing against the scene: obvhs BVHs over tiles of nearby triangles, each built when
//! a ray first reaches it (`tiles`), under a BVH over the tiles' boxes, with a watertight
//! ray/triangle test (Woop, Benthin and Wald 2013).
//!
//! obvhs's own Möller-Trumbore test lets rays along shared edges of the water grid leak
//! through (method §8), which would show as bright dots where a reflected ray escapes the
//! water. The watertight test decides every edge consistently for both triangles that share
//! it. Boxes are padded a little so that a hit exactly on a box face is not culled.

mod packet;
mod tiles;

use glam::{Vec3, Vec3A};
use obvhs::{
    aabb::Aabb,
    cwbvh::CwBvh,
    ray::{Ray, RayHit},
    Boundable,
};

pub use packet::PACKET_RAYS;
use tiles::Tile;

/// The most triangles a tile holds: small enough that the tiles no ray reaches are left
/// unbuilt (on the Table 1 scene 30 of 129 tiles; the camera sees about 40 % of its water),
/// large enough that the top level stays a few nodes deep. From 2048 to 32768 the default
/// fit of Table 1 took the same time to within the machine's noise (docs/decisions.md).
pub const TILE_TRIANGLES: usize = 4096;

/// A triangle as the tracer stores it.
#[derive(Clone, Copy, Debug)]
pub struct Triangle {
    /// The three corners, in the scene's camera-centred frame.
    pub vertices: [Vec3; 3],
}

impl Boundable for Triangle {
    fn aabb(&self) -> Aabb {
        let [a, b, c] = self.vertices;
        let min = a.min(b).min(c);
        let max = a.max(b).max(c);
        // Relative padding: the box test and the triangle test round differently, and a
        // flat triangle gives a box of zero thickness.
        let pad = (max - min)
            .max_element()
            .max(max.abs().max(min.abs()).max_element())
            * 1e-5
            + 1e-7;
        Aabb::new(Vec3A::from(min - pad), Vec3A::from(max + pad))
    }
}

/// The closest hit of a ray.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Hit {
    /// Distance along the (unit) ray direction.
    pub t: f32,
    /// Index of the triangle in the list the tracer was built from.
    pub triangle: u32,
    /// Barycentric weights of the three corners at the hit point (they sum to 1).
    pub barycentric: [f32; 3],
}

/// BVHs over triangles with closest-hit and occlusion queries.
pub struct Tracer {
    /// The BVH over the tiles' boxes (`None` when there is no triangle).
    top: Option<CwBvh>,
    /// The tiles, in the top level's leaf order.
    tiles: Vec<Tile>,
    /// How many triangles there are.
    len: usize,
    /// This tracer's own number, unique in the process ([`Tracer::id`]).
    id: u64,
}

/// The number the next tracer built takes.
static NEXT_TRACER: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

fn next_id() -> u64 {
    NEXT_TRACER.fetch_add(1, std::sync::atomic::Ordering::Relaxed)
}

/// Per-ray constants of the watertight test: the axis permutation and the shear, as the
/// three rows that take a vertex (less the origin) to the sheared frame.
///
/// A row holds 1 at the permuted axis, the shear at the ray's major axis and 0 elsewhere, so
/// its dot product rounds exactly as `a[kx] - sx a[kz]` does (a product by 1 or 0 is exact,
/// adding 0 changes nothing, and the two terms that remain are added once), without
/// indexing a vector by an axis known only at run time on every vertex.
struct WatertightRay {
    origin: Vec3,
    /// Gives the sheared x: `a[kx] - sx a[kz]`.
    row_x: Vec3,
    /// Gives the sheared y: `a[ky] - sy a[kz]`.
    row_y: Vec3,
    /// Gives the sheared z: `sz a[kz]`.
    row_z: Vec3,
}

impl WatertightRay {
    fn new(origin: Vec3, dir: Vec3) -> Self {
        let abs = dir.abs();
        let kz = if abs.x > abs.y {
            if abs.x > abs.z {
                0
            } else {
                2
            }
        } else if abs.y > abs.z {
            1
        } else {
            2
        };
        let mut kx = (kz + 1) % 3;
        let mut ky = (kx + 1) % 3;
        // Keep the winding so that the sign of the determinant is meaningful.
        if dir[kz] < 0.0 {
            std::mem::swap(&mut kx, &mut ky);
        }
        let (sx, sy, sz) = (dir[kx] / dir[kz], dir[ky] / dir[kz], 1.0 / dir[kz]);
        let row = |axis: usize, shear: f32| {
            let mut r = Vec3::ZERO;
            r[axis] = 1.0;
            r[kz] = -shear;
            r
        };
        let mut row_z = Vec3::ZERO;
        row_z[kz] = sz;
        WatertightRay {
            origin,
            row_x: row(kx, sx),
            row_y: row(ky, sy),
            row_z,
        }
    }

    /// Returns (t, barycentric) for a hit in (tmin, tmax), two-sided.
    #[inline]
    fn intersect(&self, tri: &Triangle, tmin: f32, tmax: f32) -> Option<(f32, [f32; 3])> {
        let a = tri.vertices[0] - self.origin;
        let b = tri.vertices[1] - self.origin;
        let c = tri.vertices[2] - self.origin;
        let (ax, ay) = (a.dot(self.row_x), a.dot(self.row_y));
        let (bx, by) = (b.dot(self.row_x), b.dot(self.row_y));
        let (cx, cy) = (c.dot(self.row_x), c.dot(self.row_y));
        let mut u = cx * by - cy * bx;
        let mut v = ax * cy - ay * cx;
        let mut w = bx * ay - by * ax;
        // On an edge the single-precision result is exactly zero; recompute in double so
        // the two triangles sharing the edge agree on which one owns it.
        if u == 0.0 || v == 0.0 || w == 0.0 {
            let (cxd, cyd, bxd, byd, axd, ayd) = (
                cx as f64, cy as f64, bx as f64, by as f64, ax as f64, ay as f64,
            );
            u = (cxd * byd - cyd * bxd) as f32;
            v = (axd * cyd - ayd * cxd) as f32;
            w = (bxd * ayd - byd * axd) as f32;
        }
        if (u < 0.0 || v < 0.0 || w < 0.0) && (u > 0.0 || v > 0.0 || w > 0.0) {
            return None;
        }
        let det = u + v + w;
        if det == 0.0 {
            return None;
        }
        let (az, bz, cz) = (a.dot(self.row_z), b.dot(self.row_z), c.dot(self.row_z));
        let t_scaled = u * az + v * bz + w * cz;
        let inv_det = 1.0 / det;
        let t = t_scaled * inv_det;
        if !(t > tmin && t < tmax) {
            return None;
        }
        // The computed distance is exact only to a bound that grows with the triangle's
        // size seen from the ray's origin (Pharr, Jakob and Humphreys, Physically Based
        // Rendering, 3rd ed., §3.9.6): a ray leaving a kilometre-wide quad from a tenth of a
        // millimetre above it computes distances of either sign up to centimetres. A hit no
        // farther than the bound is no hit.
        if t <= t_error_bound([ax, bx, cx], [ay, by, cy], [az, bz, cz], [u, v, w], inv_det) {
            return None;
        }
        Some((t, [u * inv_det, v * inv_det, w * inv_det]))
    }
}

/// The closest hit of `ray` (its `wray` for the triangle test) in one tile's BVH.
#[inline]
fn closest_in(built: &tiles::Built, wray: &WatertightRay, ray: Ray) -> Option<Hit> {
    let mut hit = RayHit::none();
    let mut bary = [0.0f32; 3];
    let ordered = &built.ordered;
    let tmin = ray.tmin;
    built.bvh.ray_traverse(ray, &mut hit, |r, id| {
        match wray.intersect(&ordered[id], tmin, r.tmax) {
            Some((t, b)) => {
                bary = b;
                t
            }
            None => f32::INFINITY,
        }
    });
    // `bary` belongs to the last accepted candidate, which is the closest one because each
    // accepted hit shrinks tmax.
    (hit.t < ray.tmax).then(|| Hit {
        t: hit.t,
        triangle: built.original_index[hit.primitive_id as usize],
        barycentric: bary,
    })
}

/// The distance of some hit of `ray` in one tile's BVH, if there is one.
#[inline]
fn occluded_in(built: &tiles::Built, wray: &WatertightRay, ray: Ray) -> Option<f32> {
    let ordered = &built.ordered;
    let mut found = None;
    built.bvh.ray_traverse_miss(ray, |_, id| {
        let t = wray
            .intersect(&ordered[id], ray.tmin, ray.tmax)
            .map_or(f32::INFINITY, |(t, _)| t);
        if t < ray.tmax {
            found = Some(t);
        }
        t
    });
    found
}

/// gamma(n) of the floating-point error analysis: n units of roundoff, n u / (1 - n u).
fn gamma(n: f32) -> f32 {
    let u = f32::EPSILON * 0.5;
    n * u / (1.0 - n * u)
}

/// The bound on the error of a watertight hit's distance, from the sheared vertices' x, y
/// and z, the edge functions and the inverse determinant (PBRT, 3rd ed., §3.9.6).
#[inline]
fn t_error_bound(x: [f32; 3], y: [f32; 3], z: [f32; 3], e: [f32; 3], inv_det: f32) -> f32 {
    let max_abs = |v: [f32; 3]| v[0].abs().max(v[1].abs()).max(v[2].abs());
    let (max_x, max_y, max_z, max_e) = (max_abs(x), max_abs(y), max_abs(z), max_abs(e));
    let delta_z = gamma(3.0) * max_z;
    let delta_x = gamma(5.0) * (max_x + max_z);
    let delta_y = gamma(5.0) * (max_y + max_z);
    let delta_e = 2.0 * (gamma(2.0) * max_x * max_y + delta_y * max_x + delta_x * max_y);
    3.0 * (gamma(3.0) * max_e * max_z + delta_e * max_z + delta_z * max_e) * inv_det.abs()
}

/// Replaces exactly-zero direction components by a tiny value of the same sign convention:
/// the BVH's slab test divides by them.
fn nudge_direction(dir: Vec3) -> Vec3 {
    dir.map(|c| if c == 0.0 { 1e-20 } else { c })
}

impl Tracer {
    /// Builds the tiles' top level over `triangles` (in any order; hits report indices into
    /// this list); each tile's BVH is built when a ray first reaches its box.
    pub fn new(triangles: &[Triangle]) -> Self {
        Self::with_tiles_of(triangles, TILE_TRIANGLES)
    }

    /// As [`Tracer::new`], with at most `per_tile` triangles a tile.
    pub fn with_tiles_of(triangles: &[Triangle], per_tile: usize) -> Self {
        let (top, tiles) = if triangles.is_empty() {
            (None, Vec::new())
        } else {
            let (top, tiles) = tiles::top_level(tiles::tiles(triangles, per_tile));
            (Some(top), tiles)
        };
        Tracer {
            top,
            tiles,
            len: triangles.len(),
            id: next_id(),
        }
    }

    /// How many tiles there are, and how many of them have been built so far.
    pub fn tiles_built(&self) -> (usize, usize) {
        let built = self.tiles.iter().filter(|t| t.is_built()).count();
        (self.tiles.len(), built)
    }

    /// Number of triangles.
    pub fn len(&self) -> usize {
        self.len
    }

    /// True when there is nothing to hit.
    pub fn is_empty(&self) -> bool {
        self.len == 0
    }

    /// A number no other tracer of this process has: what is cached from its hits is kept
    /// under it, so a rebuilt tracer never reads a cache of the old one.
    pub fn id(&self) -> u64 {
        self.id
    }

    /// The closest hit along `origin + t dir` with `tmin < t < tmax`; `dir` must be unit length.
    pub fn closest_hit(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> Option<Hit> {
        let top = self.top.as_ref()?;
        let dir = nudge_direction(dir);
        let wray = WatertightRay::new(origin, dir);
        let ray = Ray::new(origin.into(), dir.into(), tmin, tmax);
        if let [tile] = self.tiles.as_slice() {
            return closest_in(tile.built(), &wray, ray);
        }
        let mut top_hit = RayHit::none();
        let mut best = None;
        top.ray_traverse(ray, &mut top_hit, |r, tile| {
            // A later tile is searched only closer than the best hit so far.
            let ray = Ray {
                tmax: r.tmax,
                ..ray
            };
            match closest_in(self.tiles[tile].built(), &wray, ray) {
                Some(hit) => {
                    best = Some(hit);
                    hit.t
                }
                None => f32::INFINITY,
            }
        });
        best
    }

    /// True when something lies along `origin + t dir` with `tmin < t < tmax`.
    pub fn occluded(&self, origin: Vec3, dir: Vec3, tmin: f32, tmax: f32) -> bool {
        let Some(top) = self.top.as_ref() else {
            return false;
        };
        let dir = nudge_direction(dir);
        let wray = WatertightRay::new(origin, dir);
        let ray = Ray::new(origin.into(), dir.into(), tmin, tmax);
        if let [tile] = self.tiles.as_slice() {
            return occluded_in(tile.built(), &wray, ray).is_some();
        }
        !top.ray_traverse_miss(ray, |_, tile| {
            occluded_in(self.tiles[tile].built(), &wray, ray).unwrap_or(f32::INFINITY)
        })
    }

    /// Closest hit by testing every triangle: the reference the BVH is checked against.
    pub fn closest_hit_brute_force(
        &self,
        origin: Vec3,
        dir: Vec3,
        tmin: f32,
        tmax: f32,
    ) -> Option<Hit> {
        let dir = nudge_direction(dir);
        let wray = WatertightRay::new(origin, dir);
        let mut best: Option<Hit> = None;
        for built in self.tiles.iter().map(Tile::built) {
            for (k, tri) in built.ordered.iter().enumerate() {
                let limit = best.map_or(tmax, |b| b.t);
                if let Some((t, b)) = wray.intersect(tri, tmin, limit) {
                    best = Some(Hit {
                        t,
                        triangle: built.original_index[k],
                        barycentric: b,
                    });
                }
            }
        }
        best
    }
}
