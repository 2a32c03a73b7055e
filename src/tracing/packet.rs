//! Rays that run close together traced together: a pixel's camera rays, a row's centre
//! rays, a water point's reflected rays.
//!
//! Each node of a compressed wide BVH stores its eight children's boxes quantised to bytes,
//! and turning them back into numbers is most of what testing a ray against a node costs
//! (obvhs's own note on `intersect_ray_simd`). Rays that start at one point and run close
//! together visit nearly the same nodes, so a packet decodes each node once and tests every
//! ray against it. Each ray keeps its own mask of the children it hits and tests only the
//! triangles of those: with the same box test as a single ray's ([`node_masks`]), every ray
//! meets the triangles it would meet alone, within its own closest distance so far, and ends
//! with the hit [`Tracer::closest_hit`] gives it.

use glam::{Vec3, Vec3A};
use obvhs::{
    cwbvh::{node::CwBvhNode, CwBvh},
    ray::Ray,
};

use super::{nudge_direction, tiles::Built, Hit, Tracer, WatertightRay};

/// The most rays a packet holds: one bit each in a byte.
pub const PACKET_RAYS: usize = 8;

/// obvhs's least entry distance into a child's box (`cwbvh::node::EPSILON`): a box left
/// before it is culled. The packet's test culls the same boxes.
const BOX_EPSILON: f32 = 0.0001;

/// The rays of one packet: a shared origin, each ray's direction, reciprocal and distance
/// limit, and its watertight triangle test.
struct Packet {
    rays: [Ray; PACKET_RAYS],
    wrays: [Option<WatertightRay>; PACKET_RAYS],
    len: usize,
}

/// `_mm_max_ps`'s choice (the second when either is NaN), which obvhs's box test makes.
#[inline(always)]
fn max_ps(a: f32, b: f32) -> f32 {
    if a > b {
        a
    } else {
        b
    }
}

/// `_mm_min_ps`'s choice.
#[inline(always)]
fn min_ps(a: f32, b: f32) -> f32 {
    if a < b {
        a
    } else {
        b
    }
}

/// Every ray's hit mask of `node`'s children (in the traversal's order `oct_inv4`) into
/// `masks`, and their union. Each ray's mask is the one `CwBvhNode::intersect_ray` gives it:
/// the same products and sums in the same order, only the children's bounds decoded once.
#[inline(always)]
fn node_masks(
    node: &CwBvhNode,
    oct_inv4: u32,
    packet: &Packet,
    active: u8,
    tmax: &[f32; PACKET_RAYS],
    masks: &mut [u32; PACKET_RAYS],
) -> u32 {
    let (child_bits8, bit_index8) = node.get_child_and_index_bits(oct_inv4);
    let decode = |q: &[u8; 8]| q.map(|v| v as f32);
    let (lo_x, hi_x) = (decode(&node.child_min_x), decode(&node.child_max_x));
    let (lo_y, hi_y) = (decode(&node.child_min_y), decode(&node.child_max_y));
    let (lo_z, hi_z) = (decode(&node.child_min_z), decode(&node.child_max_z));
    let extent = node.compute_extent();
    let p = Vec3A::from(node.p);
    // Each child's bits in the hit mask, for a hit.
    let child_mask: [u32; 8] = std::array::from_fn(|c| {
        obvhs::cwbvh::node::extract_byte64(child_bits8, c)
            << obvhs::cwbvh::node::extract_byte64(bit_index8, c)
    });
    let mut union = 0;
    for r in 0..packet.len {
        if active & (1 << r) == 0 {
            continue;
        }
        let ray = &packet.rays[r];
        let dir_inv = extent * ray.inv_direction;
        let orig = (p - ray.origin) * ray.inv_direction;
        let (x0, x1) = if ray.direction.x < 0.0 {
            (&hi_x, &lo_x)
        } else {
            (&lo_x, &hi_x)
        };
        let (y0, y1) = if ray.direction.y < 0.0 {
            (&hi_y, &lo_y)
        } else {
            (&lo_y, &hi_y)
        };
        let (z0, z1) = if ray.direction.z < 0.0 {
            (&hi_z, &lo_z)
        } else {
            (&lo_z, &hi_z)
        };
        let mut mask = 0;
        for c in 0..8 {
            let tmin_x = x0[c] * dir_inv.x + orig.x;
            let tmax_x = x1[c] * dir_inv.x + orig.x;
            let tmin_y = y0[c] * dir_inv.y + orig.y;
            let tmax_y = y1[c] * dir_inv.y + orig.y;
            let tmin_z = z0[c] * dir_inv.z + orig.z;
            let tmax_z = z1[c] * dir_inv.z + orig.z;
            let enter = max_ps(max_ps(tmin_x, max_ps(tmin_y, tmin_z)), BOX_EPSILON);
            let leave = min_ps(min_ps(tmax_x, min_ps(tmax_y, tmax_z)), tmax[r]);
            if enter <= leave {
                mask |= child_mask[c];
            }
        }
        masks[r] = mask;
        union |= mask;
    }
    union
}

/// Traverses `bvh` with the rays of the packet in the bit set `active`, calling
/// `leaf(primitive, rays)` for each primitive some ray's own box tests reach, with the bit
/// set of those rays. `tmax` holds each ray's current limit, which `leaf` lowers as it finds
/// hits.
#[inline(always)]
fn traverse(
    bvh: &CwBvh,
    packet: &Packet,
    active: u8,
    tmax: &mut [f32; PACKET_RAYS],
    mut leaf: impl FnMut(usize, u8, &mut [f32; PACKET_RAYS]),
) {
    use glam::UVec2;
    let first = active.trailing_zeros() as usize;
    let mut state = bvh.new_traversal(packet.rays[first.min(PACKET_RAYS - 1)].direction);
    let mut masks = [0u32; PACKET_RAYS];
    let mut node;
    let mut base = 0u32;
    obvhs::traverse!(
        bvh,
        node,
        state,
        {
            base = node.primitive_base_idx;
            node_masks(node, state.oct_inv4, packet, active, tmax, &mut masks)
        },
        {
            let shift = state.primitive_id - base;
            // Bit r set where ray r's own mask holds the primitive (inactive rays' masks
            // are 0).
            let mut rays = 0u8;
            for (r, mask) in masks.iter().enumerate() {
                rays |= (((mask >> shift) & 1) as u8) << r;
            }
            if rays != 0 {
                leaf(state.primitive_id as usize, rays, tmax);
            }
        }
    );
}

impl Tracer {
    /// The closest hit of each ray `origin + t dirs[i]` with `tmin < t < tmax[i]`, written
    /// to `hits[i]`: for every ray the hit [`Tracer::closest_hit`] gives it. The directions
    /// must be unit length; `tmax` and `hits` must be as long as `dirs`. Rays that run close
    /// together (a pixel's camera rays, a row's centre rays, a point's reflected rays) cost
    /// less this way than one by one.
    pub fn closest_hits(
        &self,
        origin: Vec3,
        dirs: &[Vec3],
        tmin: f32,
        tmax: &[f32],
        hits: &mut [Option<Hit>],
    ) {
        for ((dirs, tmax), hits) in dirs
            .chunks(PACKET_RAYS)
            .zip(tmax.chunks(PACKET_RAYS))
            .zip(hits.chunks_mut(PACKET_RAYS))
        {
            self.closest_hits_of_packet(|_| origin, dirs, tmin, tmax, hits);
        }
    }

    /// [`Tracer::closest_hits`] of rays with origins of their own, `origins[i] + t dirs[i]`
    /// (`origins` as long as `dirs`): rays that leave points close together in nearly one
    /// direction (the reflected rays of a pixel's camera rays) still run close together.
    pub fn closest_hits_from(
        &self,
        origins: &[Vec3],
        dirs: &[Vec3],
        tmin: f32,
        tmax: &[f32],
        hits: &mut [Option<Hit>],
    ) {
        for (((origins, dirs), tmax), hits) in origins
            .chunks(PACKET_RAYS)
            .zip(dirs.chunks(PACKET_RAYS))
            .zip(tmax.chunks(PACKET_RAYS))
            .zip(hits.chunks_mut(PACKET_RAYS))
        {
            self.closest_hits_of_packet(|r| origins[r], dirs, tmin, tmax, hits);
        }
    }

    /// At most [`PACKET_RAYS`] rays, ray `r` leaving `origin(r)`.
    fn closest_hits_of_packet(
        &self,
        origin: impl Fn(usize) -> Vec3,
        dirs: &[Vec3],
        tmin: f32,
        tmax: &[f32],
        hits: &mut [Option<Hit>],
    ) {
        hits.iter_mut().for_each(|h| *h = None);
        let Some(top) = self.top.as_ref() else {
            return;
        };
        let len = dirs.len().min(tmax.len()).min(PACKET_RAYS);
        let mut packet = Packet {
            rays: [Ray::new(Vec3A::ZERO, Vec3A::X, tmin, 0.0); PACKET_RAYS],
            wrays: [const { None }; PACKET_RAYS],
            len,
        };
        let mut limits = [0.0; PACKET_RAYS];
        for (r, (&dir, &tmax)) in dirs.iter().zip(tmax).take(len).enumerate() {
            let (origin, dir) = (origin(r), nudge_direction(dir));
            packet.rays[r] = Ray::new(origin.into(), dir.into(), tmin, tmax);
            packet.wrays[r] = Some(WatertightRay::new(origin, dir));
            limits[r] = tmax;
        }
        let all = ((1u16 << len) - 1) as u8;
        if let [tile] = self.tiles.as_slice() {
            closest_in_packet(tile.built(), &packet, all, &mut limits, hits);
            return;
        }
        traverse(top, &packet, all, &mut limits, |tile, rays, limits| {
            // A later tile is searched only closer than each ray's best hit so far.
            closest_in_packet(self.tiles[tile].built(), &packet, rays, limits, hits);
        });
    }
}

/// The closest hits of the packet's rays in the bit set `active` in one tile's BVH, each
/// within its limit in `limits`, which it lowers as it finds them; a ray that finds none
/// keeps its entry of `hits`.
fn closest_in_packet(
    built: &Built,
    packet: &Packet,
    active: u8,
    limits: &mut [f32; PACKET_RAYS],
    hits: &mut [Option<Hit>],
) {
    let tmin = packet.rays[0].tmin;
    let mut bary = [[0.0f32; 3]; PACKET_RAYS];
    let mut found = [None::<(f32, u32)>; PACKET_RAYS];
    traverse(&built.bvh, packet, active, limits, |id, rays, limits| {
        let triangle = &built.ordered[id];
        let mut left = rays;
        while left != 0 {
            let r = left.trailing_zeros() as usize;
            left &= left - 1;
            let Some(wray) = &packet.wrays[r] else {
                continue;
            };
            if let Some((t, b)) = wray.intersect(triangle, tmin, limits[r]) {
                limits[r] = t;
                bary[r] = b;
                found[r] = Some((t, id as u32));
            }
        }
    });
    for (r, hit) in hits.iter_mut().enumerate().take(packet.len) {
        if let Some((t, id)) = found[r] {
            *hit = Some(Hit {
                t,
                triangle: built.original_index[id as usize],
                barycentric: bary[r],
            });
        }
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::random::Rng;
    use crate::tracing::Triangle;

    /// A wavy grid of 2 x n x n triangles over [0, n] x [0, n], with a few walls standing on
    /// it, shuffled.
    fn wavy_scene(n: usize) -> Vec<Triangle> {
        let height = |x: usize, z: usize| {
            let (x, z) = (x as f32, z as f32);
            0.3 * (0.7 * x).sin() * (0.45 * z).cos() + 0.1 * (1.9 * x + 0.3 * z).sin()
        };
        let mut triangles = Vec::new();
        for z in 0..n {
            for x in 0..n {
                let p = |dx: usize, dz: usize| {
                    Vec3::new((x + dx) as f32, height(x + dx, z + dz), (z + dz) as f32)
                };
                triangles.push(Triangle {
                    vertices: [p(0, 0), p(1, 0), p(0, 1)],
                });
                triangles.push(Triangle {
                    vertices: [p(1, 0), p(1, 1), p(0, 1)],
                });
            }
        }
        for k in 1..4 {
            let z = (n * k / 4) as f32;
            let x0 = (n / 8) as f32;
            let (a, b, c, d) = (
                Vec3::new(x0, -1.0, z),
                Vec3::new(x0 + n as f32 / 3.0, -1.0, z),
                Vec3::new(x0 + n as f32 / 3.0, 4.0, z),
                Vec3::new(x0, 4.0, z),
            );
            triangles.push(Triangle {
                vertices: [a, b, c],
            });
            triangles.push(Triangle {
                vertices: [a, c, d],
            });
        }
        let mut rng = Rng::new(11, 0);
        for i in (1..triangles.len()).rev() {
            let j = (rng.next_u32() as usize) % (i + 1);
            triangles.swap(i, j);
        }
        triangles
    }

    fn unit(rng: &mut Rng) -> Vec3 {
        loop {
            let v = Vec3::new(
                2.0 * rng.next_f32() - 1.0,
                2.0 * rng.next_f32() - 1.0,
                2.0 * rng.next_f32() - 1.0,
            );
            let l = v.length();
            if l > 0.1 && l <= 1.0 {
                return v / l;
            }
        }
    }

    /// Packets of rays close together (a pixel's camera rays, grazing the waves from above)
    /// and far apart (a water point's reflected rays, every direction), from one point and
    /// from points of their own: each ray's hit is the one it gets alone, to the bit, and the
    /// one testing every triangle finds.
    #[test]
    fn each_ray_of_a_packet_gets_its_own_closest_hit() {
        let n = 96;
        let triangles = wavy_scene(n);
        // Tiles of 512: many tiles under the top level; and one tile alone.
        for tracer in [
            Tracer::with_tiles_of(&triangles, 512),
            Tracer::with_tiles_of(&triangles, 1 << 20),
        ] {
            let mut rng = Rng::new(5, 1);
            let (mut hit_some, mut hit_none) = (0, 0);
            for packet in 0..400 {
                let (origin, dirs): (Vec3, Vec<Vec3>) = if packet % 2 == 0 {
                    // A camera 1.5 m up at one side, looking along the waves.
                    let origin = Vec3::new(n as f32 * 0.5, 1.5, -2.0);
                    let centre =
                        Vec3::new(n as f32 * rng.next_f32(), 0.0, n as f32 * rng.next_f32());
                    let axis = (centre - origin).normalize();
                    let spread = 0.002;
                    let count = 1 + packet % PACKET_RAYS + 8 * (packet % 3);
                    let dirs = (0..count)
                        .map(|_| (axis + spread * (unit(&mut rng) * rng.next_f32())).normalize())
                        .collect();
                    (origin, dirs)
                } else {
                    // A point just above the waves, rays in every direction.
                    let x = n as f32 * rng.next_f32();
                    let z = n as f32 * rng.next_f32();
                    let origin = Vec3::new(x, 0.45, z);
                    let dirs = (0..PACKET_RAYS).map(|_| unit(&mut rng)).collect();
                    (origin, dirs)
                };
                // Limits of their own: none, or some short of what the ray would hit.
                let tmax: Vec<f32> = (0..dirs.len())
                    .map(|_| {
                        if packet % 3 == 0 {
                            2.0 + 30.0 * rng.next_f32()
                        } else {
                            f32::INFINITY
                        }
                    })
                    .collect();
                // Every third packet from points of its own, a few centimetres apart.
                let origins: Vec<Vec3> = (0..dirs.len())
                    .map(|r| {
                        if packet % 3 == 1 {
                            origin + 0.05 * unit(&mut rng) * (r % 3) as f32
                        } else {
                            origin
                        }
                    })
                    .collect();
                let mut hits = vec![None; dirs.len()];
                if packet % 3 == 1 {
                    tracer.closest_hits_from(&origins, &dirs, 0.0, &tmax, &mut hits);
                } else {
                    tracer.closest_hits(origin, &dirs, 0.0, &tmax, &mut hits);
                }
                for (((dir, hit), &tmax), &origin) in
                    dirs.iter().zip(&hits).zip(&tmax).zip(&origins)
                {
                    let alone = tracer.closest_hit(origin, *dir, 0.0, tmax);
                    assert_eq!(*hit, alone, "packet {packet}, ray {dir}");
                    let brute = tracer.closest_hit_brute_force(origin, *dir, 0.0, tmax);
                    assert_eq!(hit.map(|h| h.triangle), brute.map(|h| h.triangle));
                    if hit.is_some() {
                        hit_some += 1;
                    } else {
                        hit_none += 1;
                    }
                }
            }
            // Both outcomes were met many times.
            assert!(
                hit_some > 1000 && hit_none > 200,
                "{hit_some} hits, {hit_none} misses"
            );
        }
    }
}
