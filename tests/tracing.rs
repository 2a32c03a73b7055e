//! The BVH finds the same closest hits as testing every triangle, and rays along shared
//! edges of a water grid never slip through it.

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
    let tris: Vec<Triangle> = (0..3000)
        .map(|_| {
            let c = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 20.0 - 10.0;
            Triangle {
                vertices: [
                    c + random_unit(&mut rng) * 0.8,
                    c + random_unit(&mut rng) * 0.8,
                    c + random_unit(&mut rng) * 0.8,
                ],
            }
        })
        .collect();
    let tracer = Tracer::new(&tris);
    let mut hits = 0;
    for _ in 0..3000 {
        let origin = Vec3::new(rng.next_f32(), rng.next_f32(), rng.next_f32()) * 24.0 - 12.0;
        let dir = random_unit(&mut rng);
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
    for bumpy in [false, true] {
        let (tris, v, edges) = grid(16, bumpy);
        let tracer = Tracer::new(&tris);
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
