//! The scene's triangles cut into tiles of nearby triangles, each with a BVH of its own built
//! the first time a ray reaches its box.
//!
//! A photo's camera sees part of the water mesh, and the rays the fit traces (camera rays,
//! and reflected rays that leave the water upwards) reach only the tiles around what it sees:
//! the tiles out of view are never built. The tiles come from halving the triangles at the
//! median of their centres along the widest axis until each holds at most a tile's worth,
//! so they stay balanced whatever the scene's layout. Triangles much larger than the usual
//! one (a wall's quad over a fine water grid) go into tiles of their own, so that they do
//! not stretch a water tile's box over the whole scene.

use std::ops::Range;
use std::sync::{Mutex, OnceLock};
use std::time::Duration;

use glam::Vec3A;
use obvhs::{
    aabb::Aabb,
    cwbvh::{builder::build_cwbvh, CwBvh},
    Boundable, BvhBuildParams,
};

use super::Triangle;

/// A triangle is large, and kept out of the ordinary tiles, when its box's largest side is
/// this many times the median triangle's.
const LARGE_FACTOR: f32 = 16.0;

/// The triangles of one tile and, once a ray has reached its box, their BVH.
pub(super) struct Tile {
    /// The box around every triangle of the tile (their padded boxes).
    pub(super) aabb: Aabb,
    /// The tile's triangles and their indices in the tracer's list, until the BVH takes them.
    pending: Mutex<Option<(Vec<Triangle>, Vec<u32>)>>,
    built: OnceLock<Built>,
}

/// A tile's BVH with its triangles in the BVH's leaf order.
pub(super) struct Built {
    pub(super) bvh: CwBvh,
    /// Triangles reordered to the BVH's leaf order, so that the traversal's primitive id
    /// indexes them directly (5-15 % faster than an indirection, method §8).
    pub(super) ordered: Vec<Triangle>,
    /// For each entry of `ordered`, its index in the tracer's list.
    pub(super) original_index: Vec<u32>,
}

impl Boundable for Tile {
    fn aabb(&self) -> Aabb {
        self.aabb
    }
}

impl Tile {
    fn new(triangles: Vec<Triangle>, index: Vec<u32>) -> Self {
        let aabb = triangles
            .iter()
            .fold(Aabb::INVALID, |b, t| b.union(&t.aabb()));
        Tile {
            aabb,
            pending: Mutex::new(Some((triangles, index))),
            built: OnceLock::new(),
        }
    }

    /// The tile's BVH, built by the first caller (others wait for it).
    pub(super) fn built(&self) -> &Built {
        self.built.get_or_init(|| {
            let (triangles, index) = self
                .pending
                .lock()
                .unwrap_or_else(|poisoned| poisoned.into_inner())
                .take()
                .unwrap_or_default();
            build(&triangles, &index)
        })
    }

    /// Whether the tile's BVH has been built.
    pub(super) fn is_built(&self) -> bool {
        self.built.get().is_some()
    }
}

fn build(triangles: &[Triangle], index: &[u32]) -> Built {
    // The cheapest preset: on the sample scene (518k triangles, mostly the water's regular
    // grid) it builds in 0.32 s instead of medium's 0.56 s and traces as fast (reflected rays
    // 6.51 against 6.44 M/s; docs/decisions.md, "The BVH built with obvhs's
    // `very_fast_build`").
    let mut bvh = build_cwbvh(
        triangles,
        BvhBuildParams::very_fast_build(),
        &mut Duration::default(),
    );
    // obvhs reserves a node for every triangle, about eight times what the tree uses: over
    // many tiles the spare room, in memory the builds touched, added up to tens of MiB.
    bvh.nodes.shrink_to_fit();
    bvh.primitive_indices.shrink_to_fit();
    let ordered = bvh
        .primitive_indices
        .iter()
        .map(|&i| triangles[i as usize])
        .collect();
    let original_index = bvh
        .primitive_indices
        .iter()
        .map(|&i| index[i as usize])
        .collect();
    Built {
        bvh,
        ordered,
        original_index,
    }
}

/// Cuts `triangles` into tiles of at most `per_tile` triangles (the large ones apart).
pub(super) fn tiles(triangles: &[Triangle], per_tile: usize) -> Vec<Tile> {
    let per_tile = per_tile.max(1);
    let n = triangles.len();
    let mut order: Vec<u32> = (0..n as u32).collect();
    let centres: Vec<Vec3A> = triangles
        .iter()
        .map(|t| Vec3A::from((t.vertices[0] + t.vertices[1] + t.vertices[2]) / 3.0))
        .collect();
    let mut ranges = Vec::new();
    let mut ordinary = 0..n;
    if n > per_tile {
        let size = |t: &Triangle| {
            let [a, b, c] = t.vertices;
            (a.max(b).max(c) - a.min(b).min(c)).max_element()
        };
        let mut sizes: Vec<f32> = triangles.iter().map(size).collect();
        let median = *sizes.select_nth_unstable_by(n / 2, |a, b| a.total_cmp(b)).1;
        let large = if median > 0.0 {
            median * LARGE_FACTOR
        } else {
            f32::INFINITY
        };
        // Large triangles to the end of the order, in tiles of their own.
        let mut ends = order.len();
        let mut k = 0;
        while k < ends {
            if size(&triangles[order[k] as usize]) > large {
                ends -= 1;
                order.swap(k, ends);
            } else {
                k += 1;
            }
        }
        // Many large ones (a city's facades) are cut into tiles among themselves.
        split(&mut order, ends..n, &centres, per_tile, &mut ranges);
        ordinary = 0..ends;
    }
    split(&mut order, ordinary, &centres, per_tile, &mut ranges);
    ranges
        .into_iter()
        .filter(|r| !r.is_empty())
        .map(|r| {
            let index = order[r].to_vec();
            let tris = index.iter().map(|&i| triangles[i as usize]).collect();
            Tile::new(tris, index)
        })
        .collect()
}

/// Halves `order[range]` at the median of the centres along their widest axis until each
/// part holds at most `per_tile`.
fn split(
    order: &mut [u32],
    range: Range<usize>,
    centres: &[Vec3A],
    per_tile: usize,
    out: &mut Vec<Range<usize>>,
) {
    if range.len() <= per_tile {
        out.push(range);
        return;
    }
    let part = &mut order[range.clone()];
    let (lo, hi) = part.iter().fold(
        (Vec3A::splat(f32::INFINITY), Vec3A::splat(f32::NEG_INFINITY)),
        |(lo, hi), &i| (lo.min(centres[i as usize]), hi.max(centres[i as usize])),
    );
    let extent = hi - lo;
    if extent.max_element().partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        // Every centre at one point: nothing to cut along.
        out.push(range);
        return;
    }
    let axis = if extent.x >= extent.y && extent.x >= extent.z {
        0
    } else if extent.y >= extent.z {
        1
    } else {
        2
    };
    let mid = part.len() / 2;
    part.select_nth_unstable_by(mid, |&a, &b| {
        centres[a as usize][axis].total_cmp(&centres[b as usize][axis])
    });
    let cut = range.start + mid;
    split(order, range.start..cut, centres, per_tile, out);
    split(order, cut..range.end, centres, per_tile, out);
}

/// The tiles' top level: a BVH over their boxes (the tiles in its leaf order).
pub(super) fn top_level(tiles: Vec<Tile>) -> (CwBvh, Vec<Tile>) {
    let bvh = build_cwbvh(
        &tiles,
        BvhBuildParams::very_fast_build(),
        &mut Duration::default(),
    );
    let mut slots: Vec<Option<Tile>> = tiles.into_iter().map(Some).collect();
    let ordered = bvh
        .primitive_indices
        .iter()
        .filter_map(|&i| slots.get_mut(i as usize).and_then(Option::take))
        .collect();
    (bvh, ordered)
}
