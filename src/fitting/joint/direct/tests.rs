use glam::{Vec2, Vec3};

use super::*;
use crate::fitting::joint::kernel::kernel_coverage;
use crate::photo_in::Photo;
use crate::samples::PHOTO_SIZE;

/// The samples' scene (camera at (0, 0.2, 10) looking down -z, the wall at z = 0 facing it),
/// its water mask, and the wall as a light plane, found by the camera ray through `pixel`.
fn wall() -> (&'static Scene, &'static [bool], LightPlane) {
    let (scene, _, water, plane) = table1_wall();
    (scene, water, plane)
}

/// [`wall`] with Table 1's photo (one 3 m x 3 m light on that wall, in frame).
pub(in crate::fitting::joint) fn table1_wall(
) -> (&'static Scene, &'static Photo, &'static [bool], LightPlane) {
    let crate::samples::Fixture {
        scene,
        photo,
        water,
        ..
    } = crate::samples::fixture("table1.png");
    assert_eq!((photo.width, photo.height), (PHOTO_SIZE, PHOTO_SIZE));
    let origin = scene.camera.position;
    let dir = scene.camera.direction(300.5, 100.5, PHOTO_SIZE, PHOTO_SIZE);
    let hit = scene
        .tracer
        .closest_hit(origin, dir, 0.0, f32::INFINITY)
        .expect("the wall");
    let s = scene.sources[hit.triangle as usize];
    let mut normal = scene.face_normal(hit.triangle);
    if normal.dot(dir) > 0.0 {
        normal = -normal;
    }
    let plane = LightPlane::with_frame(
        (s.node as usize, s.mesh as usize, s.primitive as usize),
        origin + dir * hit.t,
        normal,
        Vec3::X,
        1.0,
    )
    .expect("a plane");
    (scene, photo, water, plane)
}

/// Where the corner (`x`, `y`) of the image lands on the plane.
fn corner(scene: &Scene, plane: &LightPlane, x: f32, y: f32) -> Vec2 {
    let dir = scene.camera.direction(x, y, PHOTO_SIZE, PHOTO_SIZE);
    plane
        .hit(scene.camera.position, dir)
        .expect("on the wall")
        .1
}

/// The direct coefficient of pixel (`x`, `y`) for `rect`, as the fit computes it (each
/// sample's box share inside the rectangle, summed, over the strata).
fn coefficient(scene: &Scene, plane: &LightPlane, rect: &Rect, x: u32, y: u32) -> f64 {
    let roi = rect.grow(0.5);
    let hits = direct_hits(scene, &[plane], &[roi], x, y, PHOTO_SIZE, PHOTO_SIZE, 1.0);
    assert_eq!(
        hits.len(),
        DIRECT_RAYS as usize,
        "every stratum sees the wall"
    );
    let c: f32 = hits
        .iter()
        .map(|&(k, q, h, w, half, _)| {
            assert_eq!((k, half), (0, 0.0));
            w * kernel_coverage(q.x, h.x, rect.u_min, rect.u_max)
                * kernel_coverage(q.y, h.y, rect.v_min, rect.v_max)
        })
        .sum();
    c as f64 / DIRECT_RAYS as f64
}

#[test]
fn a_direct_pixel_sees_the_fraction_of_its_footprint_inside_the_light() {
    // The camera looks straight at the wall, so a pixel's footprint there is a square and the
    // fraction inside a rectangle is its overlap, by hand: a left edge 30 % into the pixel
    // leaves 70 % of it lit; with the top edge 40 % of the way up from the pixel's bottom,
    // 0.7 x 0.4 = 28 %.
    let (scene, _, plane) = wall();
    let (x, y) = (150u32, 100u32);
    let top_left = corner(scene, &plane, x as f32, y as f32);
    let bottom_right = corner(scene, &plane, x as f32 + 1.0, y as f32 + 1.0);
    let side = bottom_right.x - top_left.x;
    // u grows to the right, v upwards: the image's rows grow downwards.
    assert!(side > 0.0 && (top_left.y - bottom_right.y - side).abs() < 1e-3 * side);
    let left = top_left.x + 0.3 * side;
    let straddling_left = Rect {
        u_min: left,
        u_max: left + 1.0,
        v_min: bottom_right.y - 1.0,
        v_max: top_left.y + 1.0,
    };
    let corner_rect = Rect {
        v_max: bottom_right.y + 0.4 * side,
        ..straddling_left
    };
    for (rect, exact) in [(straddling_left, 0.7), (corner_rect, 0.28)] {
        let c = coefficient(scene, &plane, &rect, x, y);
        assert!((c - exact).abs() < 1e-3, "{c} against {exact}");
    }
    // The share follows the edge linearly across the pixel, and is 0 and 1 beyond it.
    for step in -4..=14 {
        let f = step as f32 / 10.0;
        let rect = Rect {
            u_min: top_left.x + f * side,
            ..straddling_left
        };
        let c = coefficient(scene, &plane, &rect, x, y);
        let exact = (1.0 - f as f64).clamp(0.0, 1.0);
        assert!((c - exact).abs() < 1e-3, "edge at {f}: {c} against {exact}");
    }
    // A plane behind the wall is hidden by it: its rays' first hit is the wall, not its face.
    let behind = LightPlane {
        point: plane.point - plane.normal,
        ..plane.clone()
    };
    let roi = straddling_left.grow(5.0);
    let hits = direct_hits(scene, &[&behind], &[roi], x, y, PHOTO_SIZE, PHOTO_SIZE, 1.0);
    assert!(hits.is_empty(), "{} rays through the wall", hits.len());
}

#[test]
fn direct_pixels_are_the_wall_around_a_light_in_frame_and_none_out_of_it() {
    let (scene, water, plane) = wall();
    // Table 1's light, 3 x 3 m from (-4, 2) on the wall, in plane coordinates (the scene
    // frame is the world's less `scene.origin`).
    let at = |x: f64, y: f64| plane.coords((glam::DVec3::new(x, y, 0.0) - scene.origin).as_vec3());
    let (lo, hi) = (at(-4.0, 2.0), at(-1.0, 5.0));
    let rect = Rect {
        u_min: lo.x,
        u_max: hi.x,
        v_min: lo.y,
        v_max: hi.y,
    };
    // Grown by 0.9 m: inside the photo, whose top row sees the wall at y = 5.97 m.
    let roi = rect.grow(0.9);
    let pixels = direct_pixels(
        scene,
        &[&plane],
        &[roi],
        PHOTO_SIZE,
        PHOTO_SIZE,
        water,
        PixelShare::Checkerboard,
    );
    // 4.8 x 4.8 m at 10 m, 600 pixels over 2 tan(30 deg) 10 m: about 250 pixels a side, half of
    // them on the checkerboard.
    let metres_per_pixel = 20.0 * (30f32).to_radians().tan() / PHOTO_SIZE as f32;
    let expected = (roi.width() / metres_per_pixel) * (roi.height() / metres_per_pixel) / 2.0;
    assert!(
        (pixels.len() as f32 - expected).abs() < 0.03 * expected,
        "{} pixels, {expected} expected",
        pixels.len()
    );
    assert!(pixels.iter().all(|&p| !water[p as usize]));
    assert!(pixels
        .iter()
        .all(|&p| (p % PHOTO_SIZE + p / PHOTO_SIZE).is_multiple_of(2)));
    // The same light moved above the top of the photo (the wall is seen up to y = 5.97 m).
    let above = Rect {
        v_min: at(0.0, 7.0).y,
        v_max: at(0.0, 10.0).y,
        ..rect
    };
    let none = direct_pixels(
        scene,
        &[&plane],
        &[above],
        PHOTO_SIZE,
        PHOTO_SIZE,
        water,
        PixelShare::Checkerboard,
    );
    assert!(none.is_empty(), "{} pixels", none.len());
}
