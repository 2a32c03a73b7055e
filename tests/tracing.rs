//! The BVH finds the same closest hits as testing every triangle, whether it holds the
//! triangles in one tile or many, rays along shared edges of a water grid never slip through
//! it, and a tile's BVH is built only when a ray reaches it.

use glam::Vec3;
use streaklight::random::Rng;
use streaklight::tracing::{Tracer, Triangle};

fn random_unit(rng: &mut Rng) -> Vec3 {
    loop {
        let v = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 2.0 - Vec3::ONE;
        let l = v.length_squared();
        if l > 1e-4 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

#[test]
fn closest_hits_agree_with_brute_force() {
    let mut rng = Rng::new(11, 0);
    // 3000 triangles about a metre across and 100 about twenty (over 16 times the median:
    // large, cut into tiles among themselves).
    let tris: Vec<Triangle> = (0..3100)
        .map(|k| {
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0 - 10.0;
            let reach = if k < 3000 { 0.8 } else { 15.0 };
            Triangle {
                vertices: [
                    c + random_unit(&mut rng) * reach,
                    c + random_unit(&mut rng) * reach,
                    c + random_unit(&mut rng) * reach,
                ],
            }
        })
        .collect();
    // One tile, and tiles of 40 triangles.
    for tracer in [Tracer::new(&tris), Tracer::with_tiles_of(&tris, 40)] {
        agrees_with_brute_force(&tracer, &tris, &mut rng);
    }
    // The ordinary triangles make 128 tiles of at most 40; the large ones two or more.
    let (tiles, _) = Tracer::with_tiles_of(&tris, 40).tiles_built();
    assert!((130..=140).contains(&tiles), "{tiles} tiles");
}

fn agrees_with_brute_force(tracer: &Tracer, tris: &[Triangle], rng: &mut Rng) {
    let mut hits = 0;
    for _ in 0..3000 {
        let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 24.0 - 12.0;
        let dir = random_unit(rng);
        let a = tracer.closest_hit(origin, dir, 0.0, f32::INFINITY);
        let b = tracer.closest_hit_brute_force(origin, dir, 0.0, f32::INFINITY);
        match (a, b) {
            (None, None) => {}
            (Some(a), Some(b)) => {
                hits += 1;
                assert_eq!(a.t, b.t, "same distance");
                assert_eq!(a.triangle, b.triangle);
                let s: f32 = a.barycentric.iter().sum();
                assert!((s - 1.0).abs() < 1e-5);
                // The barycentric point is the ray's point.
                let t = tris[a.triangle as usize].vertices;
                let p = t[0] * a.barycentric[0] + t[1] * a.barycentric[1] + t[2] * a.barycentric[2];
                assert!((p - (origin + dir * a.t)).length() < 1e-4);
            }
            (a, b) => panic!("BVH {a:?} but brute force {b:?}"),
        }
        // The occlusion query agrees with the closest hit.
        assert_eq!(
            tracer.occluded(origin, dir, 0.0, f32::INFINITY),
            b.is_some()
        );
    }
    assert!(hits > 300, "the test should exercise many hits, got {hits}");
}

/// A bumpy grid like the water mesh, with vertices on a lattice.
fn grid(n: usize, bumpy: bool) -> (Vec<Triangle>, Vec<Vec3>, Vec<[usize; 2]>) {
    let mut rng = Rng::new(5, 5);
    let mut v = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            let y = if bumpy { rng.next_f32() * 0.05 } else { 0.0 };
            v.push(Vec3::new(i as f32 * 0.25 - 2.0, y, j as f32 * 0.25 - 2.0));
        }
    }
    let w = n + 1;
    let mut tris = Vec::new();
    let mut edges = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let a = j * w + i;
            let (b, c, d) = (a + 1, a + w, a + w + 1);
            tris.push(Triangle {
                vertices: [v[a], v[d], v[b]],
            });
            tris.push(Triangle {
                vertices: [v[a], v[c], v[d]],
            });
            edges.push([a, d]); // the shared diagonal
            if i + 1 < n {
                edges.push([b, d]); // shared with the next cell
            }
            if j + 1 < n {
                edges.push([c, d]);
            }
        }
    }
    (tris, v, edges)
}

#[test]
fn rays_along_shared_edges_never_pass_through_the_grid() {
    for (bumpy, per_tile) in [(false, usize::MAX), (true, usize::MAX), (true, 37)] {
        let (tris, v, edges) = grid(16, bumpy);
        let tracer = Tracer::with_tiles_of(&tris, per_tile);
        let mut rng = Rng::new(7, bumpy as u64);
        let mut rays = 0;
        for e in &edges {
            // Vertices and points along each shared edge, including exact vertex hits.
            for k in 0..=4 {
                let f = k as f32 / 4.0;
                let target = v[e[0]] * (1.0 - f) + v[e[1]] * f;
                // A point on the grid's outer border may be missed by rounding legitimately.
                if target.x.abs() >= 2.0 || target.z.abs() >= 2.0 {
                    continue;
                }
                for _ in 0..4 {
                    // From above at all sorts of angles, some grazing, some axis-aligned. On
                    // the bumpy grid a ray flatter than the bumps could touch a ridge exactly
                    // at its edge and legitimately graze past, so there rays come from higher.
                    let mut from = random_unit(&mut rng);
                    from.y = from.y.abs().max(if bumpy { 0.8 } else { 0.02 });
                    if rng.next_f32() < 0.25 {
                        from = Vec3::Y;
                    }
                    let origin = target + from.normalize() * 3.0;
                    let dir = (target - origin).normalize();
                    rays += 1;
                    let hit = tracer.closest_hit(origin, dir, 0.0, f32::INFINITY);
                    assert!(
                        hit.is_some(),
                        "ray to {target:?} from {origin:?} passed through (bumpy {bumpy})"
                    );
                    assert!(tracer.occluded(origin, dir, 0.0, f32::INFINITY));
                }
            }
        }
        assert!(rays > 10_000);
    }
}

/// Over a grid of 128 x 128 cells with a wall of two large triangles behind it, rays from a
/// camera above one corner of the grid build the tiles around that corner and the wall's,
/// not the rest, and find what testing every triangle finds.
#[test]
fn tiles_out_of_reach_are_not_built() {
    let (mut tris, _, _) = grid(128, true);
    // The grid spans -2..30 in x and z; the wall stands at z = -2.5, 40 m wide and 10 m tall.
    let wall = [
        Vec3::new(-20.0, -1.0, -2.5),
        Vec3::new(20.0, -1.0, -2.5),
        Vec3::new(20.0, 9.0, -2.5),
        Vec3::new(-20.0, 9.0, -2.5),
    ];
    tris.push(Triangle {
        vertices: [wall[0], wall[1], wall[2]],
    });
    tris.push(Triangle {
        vertices: [wall[0], wall[2], wall[3]],
    });
    let tracer = Tracer::with_tiles_of(&tris, 512);
    let (tiles, built) = tracer.tiles_built();
    // 32,768 grid triangles in tiles of 512 at most, and the wall's tile.
    assert_eq!((tiles, built), (65, 0));
    let mut rng = Rng::new(3, 1);
    let camera = Vec3::new(-1.0, 1.0, -1.0);
    for _ in 0..2000 {
        // Down onto the grid's corner within 2 m of the camera, or up towards the wall.
        let target = if rng.next_f32() < 0.5 {
            Vec3::new(rng.next_f32() * 2.0 - 2.0, 0.0, rng.next_f32() * 2.0 - 2.0)
        } else {
            Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 6.0, -2.5)
        };
        let dir = (target - camera).normalize();
        let a = tracer.closest_hit(camera, dir, 0.0, f32::INFINITY);
        let b = tracer.closest_hit_brute_force(camera, dir, 0.0, f32::INFINITY);
        assert_eq!(a.map(|h| (h.t, h.triangle)), b.map(|h| (h.t, h.triangle)));
        assert!(a.is_some(), "every ray ends on the grid or the wall");
    }
    let wall_hits = (0..200)
        .filter(|k| {
            let dir = (Vec3::new(*k as f32 * 0.02 - 2.0, 4.0, -2.5) - camera).normalize();
            let hit = tracer.closest_hit(camera, dir, 0.0, f32::INFINITY);
            hit.is_some_and(|h| h.triangle as usize >= tris.len() - 2)
        })
        .count();
    assert_eq!(wall_hits, 200);
    // The brute force built every tile: count on a fresh tracer.
    let fresh = Tracer::with_tiles_of(&tris, 512);
    for _ in 0..2000 {
        let target = if rng.next_f32() < 0.5 {
            Vec3::new(rng.next_f32() * 2.0 - 2.0, 0.0, rng.next_f32() * 2.0 - 2.0)
        } else {
            Vec3::new(rng.next_f32() * 8.0 - 4.0, rng.next_f32() * 6.0, -2.5)
        };
        fresh.closest_hit(camera, (target - camera).normalize(), 0.0, f32::INFINITY);
    }
    let (_, built) = fresh.tiles_built();
    // The corner's 2 x 2 m is 1/256 of the grid's area; with the tiles next to it that a ray
    // crosses low and the wall's, a handful are built.
    assert!((2..=8).contains(&built), "{built} of 65 tiles built");
}

/// A ray leaving a large triangle from just above it never hits it: the reflected rays of a
/// game scene's water (one quad kilometres wide) start a fraction of a millimetre above it.
/// Single precision puts the computed distance of such a miss within about 1e-7 of the
/// triangle's size of zero, on either side; a hit closer than that error bound is no hit.
#[test]
fn rays_leaving_a_large_quad_do_not_hit_it() {
    for half in [50.0f32, 500.0, 5000.0, 50000.0] {
        let quad = [
            Vec3::new(-half, 0.0, -half),
            Vec3::new(half, 0.0, -half),
            Vec3::new(half, 0.0, half),
            Vec3::new(-half, 0.0, half),
        ];
        let tracer = Tracer::new(&[
            Triangle {
                vertices: [quad[0], quad[1], quad[2]],
            },
            Triangle {
                vertices: [quad[0], quad[2], quad[3]],
            },
        ]);
        let mut rng = Rng::new(5, 0);
        let mut false_hits = 0;
        let count = 20_000;
        for _ in 0..count {
            let origin = Vec3::new(rng.next_f32() * 40.0 - 20.0, 1e-4, rng.next_f32() * -40.0);
            let mut dir = random_unit(&mut rng);
            dir.y = dir.y.abs().max(1e-3);
            let dir = dir.normalize();
            if tracer
                .closest_hit(origin, dir, 0.0, f32::INFINITY)
                .is_some()
            {
                false_hits += 1;
            }
        }
        eprintln!("quad of half-size {half} m: {false_hits} of {count} rays leaving it hit it");
        assert_eq!(false_hits, 0, "half-size {half} m");
    }
}
