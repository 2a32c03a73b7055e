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

use rayon::prelude::*;

use obvhs::{
    aabb::Aabb,
    cwbvh::{builder::build_cwbvh, CwBvh},
    Boundable, BvhBuildParams,
};

use super::Triangle;

/// A triangle is large, and kept out of the ordinary tiles, when its box's largest side is
/// this many times the median triangle's (the median of an evenly spread sample).
const LARGE_FACTOR: f32 = 16.0;

/// The triangles of one tile and, once a ray has reached its box, their BVH.
pub(super) struct Tile {
    /// The box around every triangle of the tile (their padded boxes).
    aabb: Aabb,
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

    /// The tile's BVH, built by the first caller (others wait for it). obvhs builds on the
    /// calling thread (its `parallel` feature is off), so a rayon worker building a tile
    /// never takes up another task of its loop meanwhile, one that could wait for this very
    /// tile.
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

/// A triangle's centre and its index, as the cuts move them: kept together so that cutting
/// reads memory in order (with indices into a separate list of centres, cutting a grid of
/// 8.29 M triangles into tiles took 0.95 s; this way 0.76 s).
#[derive(Clone, Copy)]
struct Item {
    centre: [f32; 3],
    index: u32,
}

/// Cuts `triangles` into tiles of at most `per_tile` triangles (the large ones apart).
pub(super) fn tiles(triangles: &[Triangle], per_tile: usize) -> Vec<Tile> {
    let per_tile = per_tile.max(1);
    let n = triangles.len();
    let size = |t: &Triangle| {
        let [a, b, c] = t.vertices;
        (a.max(b).max(c) - a.min(b).min(c)).max_element()
    };
    let large = if n > per_tile {
        // The median of a sample of at most 65536, evenly spread over the list.
        let step = n.div_ceil(1 << 16);
        let mut sizes: Vec<f32> = triangles.iter().step_by(step).map(size).collect();
        let half = sizes.len() / 2;
        let median = *sizes.select_nth_unstable_by(half, |a, b| a.total_cmp(b)).1;
        if median > 0.0 {
            median * LARGE_FACTOR
        } else {
            f32::INFINITY
        }
    } else {
        f32::INFINITY
    };
    let item = |(k, t): (usize, &Triangle)| Item {
        centre: ((t.vertices[0] + t.vertices[1] + t.vertices[2]) / 3.0).to_array(),
        index: k as u32,
    };
    // On every core only outside rayon's workers: a tracer may be built lazily inside a
    // parallel loop (`Scene::closest_hit_above_water`), where a worker waiting for a half
    // could take up a task of that loop which asks for this very tracer, and wait on
    // itself. Either way the same tiles, in the same order.
    let parallel = rayon::current_thread_index().is_none();
    // The ordinary triangles first, the large ones after them, in tiles of their own; many
    // large ones (a city's facades) are cut into tiles among themselves.
    let (is_large, mut items): (Vec<bool>, Vec<Item>) = if parallel {
        let is_large = triangles.par_iter().map(|t| size(t) > large).collect();
        (
            is_large,
            triangles.par_iter().enumerate().map(item).collect(),
        )
    } else {
        let is_large = triangles.iter().map(|t| size(t) > large).collect();
        (is_large, triangles.iter().enumerate().map(item).collect())
    };
    let mut ordinary = n;
    let mut k = 0;
    while k < ordinary {
        if is_large[items[k].index as usize] {
            ordinary -= 1;
            items.swap(k, ordinary);
        } else {
            k += 1;
        }
    }
    let (first, rest) = items.split_at_mut(ordinary);
    let mut ranges = Vec::new();
    split(first, 0, per_tile, parallel, &mut ranges);
    split(rest, ordinary, per_tile, parallel, &mut ranges);
    let tile = |r: Range<usize>| {
        let index: Vec<u32> = items[r].iter().map(|it| it.index).collect();
        let tris = index.iter().map(|&i| triangles[i as usize]).collect();
        Tile::new(tris, index)
    };
    let ranges = ranges.into_iter().filter(|r| !r.is_empty());
    if parallel {
        ranges
            .collect::<Vec<_>>()
            .into_par_iter()
            .map(tile)
            .collect()
    } else {
        ranges.map(tile).collect()
    }
}

/// Halves `items` at the median of their centres along their widest axis until each part
/// holds at most `per_tile`, and puts the parts' ranges, offset by `start`, in `out` (in the
/// same order whether the halves are cut one after the other or, `parallel`, at once).
fn split(
    items: &mut [Item],
    start: usize,
    per_tile: usize,
    parallel: bool,
    out: &mut Vec<Range<usize>>,
) {
    let whole = start..start + items.len();
    if items.len() <= per_tile {
        out.push(whole);
        return;
    }
    let (lo, hi) = items.iter().fold(
        ([f32::INFINITY; 3], [f32::NEG_INFINITY; 3]),
        |(mut lo, mut hi), it| {
            for a in 0..3 {
                lo[a] = lo[a].min(it.centre[a]);
                hi[a] = hi[a].max(it.centre[a]);
            }
            (lo, hi)
        },
    );
    let extent = [hi[0] - lo[0], hi[1] - lo[1], hi[2] - lo[2]];
    let axis = if extent[0] >= extent[1] && extent[0] >= extent[2] {
        0
    } else if extent[1] >= extent[2] {
        1
    } else {
        2
    };
    if extent[axis].partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater) {
        // Every centre at one point: nothing to cut along.
        out.push(whole);
        return;
    }
    let mid = items.len() / 2;
    items.select_nth_unstable_by(mid, |a, b| a.centre[axis].total_cmp(&b.centre[axis]));
    let (left, right) = items.split_at_mut(mid);
    if parallel && items_worth_two_cores(mid) {
        let mut right_out = Vec::new();
        rayon::join(
            || split(left, start, per_tile, parallel, out),
            || split(right, start + mid, per_tile, parallel, &mut right_out),
        );
        out.append(&mut right_out);
    } else {
        split(left, start, per_tile, parallel, out);
        split(right, start + mid, per_tile, parallel, out);
    }
}

/// Whether halves of `n` items are worth cutting on two cores at once: below that the
/// hand-over costs more than the cut.
fn items_worth_two_cores(n: usize) -> bool {
    n >= 1 << 14
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

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;

    /// The tiles cut on every core (outside rayon's workers) are those cut on one (inside a
    /// worker): the same triangles, in the same order, tile by tile.
    #[test]
    fn tiles_cut_in_parallel_are_those_cut_on_one_core() {
        // A bumpy grid of 2 x 160 x 160 triangles, shuffled, and a few large ones.
        let n = 160;
        let mut triangles = Vec::new();
        let height = |x: usize, y: usize| ((x * 7 + y * 13) % 5) as f32 * 0.01;
        for y in 0..n {
            for x in 0..n {
                let p = |dx: usize, dy: usize| {
                    Vec3::new((x + dx) as f32, height(x + dx, y + dy), (y + dy) as f32)
                };
                triangles.push(Triangle {
                    vertices: [p(0, 0), p(1, 0), p(0, 1)],
                });
                triangles.push(Triangle {
                    vertices: [p(1, 0), p(1, 1), p(0, 1)],
                });
            }
        }
        for k in 0..3 {
            let z = 10.0 * k as f32;
            triangles.push(Triangle {
                vertices: [
                    Vec3::new(0.0, 0.0, z),
                    Vec3::new(160.0, 0.0, z),
                    Vec3::new(0.0, 40.0, z),
                ],
            });
        }
        let mut rng = crate::random::Rng::new(3, 0);
        for i in (1..triangles.len()).rev() {
            let j = (rng.next_u32() as usize) % (i + 1);
            triangles.swap(i, j);
        }
        let indices = |tiles: Vec<Tile>| -> Vec<Vec<u32>> {
            tiles
                .into_iter()
                .map(|t| {
                    let pending = t.pending.into_inner().unwrap_or_else(|p| p.into_inner());
                    pending.map(|(_, index)| index).unwrap_or_default()
                })
                .collect()
        };
        assert!(rayon::current_thread_index().is_none());
        let parallel = indices(tiles(&triangles, 1000));
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(2)
            .build()
            .expect("a thread pool");
        let serial = indices(pool.install(|| tiles(&triangles, 1000)));
        assert!(parallel.len() > 50, "{} tiles", parallel.len());
        assert_eq!(parallel, serial);
        let all: usize = parallel.iter().map(Vec::len).sum();
        assert_eq!(all, triangles.len());
    }
}
