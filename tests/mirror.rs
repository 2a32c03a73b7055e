//! Analytic checks of the renderer: a mirror-flat water plane reflects a light where
//! geometry says, as bright as Fresnel's equations say.

mod common;

use serde_json::json;
use streaklight::render::{render, RenderOptions};
use streaklight::scene_in::{load, LoadOptions};

/// Fresnel reflectance of unpolarised light from air onto a dielectric, from Snell's law and
/// the s and p amplitude coefficients (written independently of the library's form).
fn fresnel(cos_i: f64, n: f64) -> f64 {
    let sin_t = (1.0 - cos_i * cos_i).sqrt() / n;
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (cos_i - n * cos_t) / (cos_i + n * cos_t);
    let rp = (n * cos_i - cos_t) / (n * cos_i + cos_t);
    0.5 * (rs * rs + rp * rp)
}

#[test]
fn flat_water_mirrors_a_light_at_the_rows_geometry_predicts() {
    let dir = common::temp_dir("mirror");
    let mut s = common::paper_setup(Some(json!({"name": "Water"})));
    // A 2 x 1 light with its bottom at y = 2, centred on x = 0, on the wall z = 0.
    let radiance = 10.0;
    s.add_light_facing_z("Light", [0.0, 2.5, 0.0], 2.0, 1.0, [radiance; 3]);
    let path = dir.join("mirror.gltf");
    s.write_gltf(&path);
    let scene = load(
        &path,
        &LoadOptions {
            gloss: Some(1.0e6),
            ..Default::default()
        },
    )
    .unwrap();
    let (w, h) = (200u32, 200u32);
    let image = render(
        &scene,
        &RenderOptions {
            width: w,
            height: h,
            samples_per_pixel: 16,
            exposure: 1.0,
            seed: 3,
            ..Default::default()
        },
    )
    .unwrap();

    // Geometry: the mirror image of a wall point (x, y, 0) in the plane y = 0 is (x, -y, 0);
    // seen from the camera at (0, 0.2, 10) with a 60 degree fov it is at row
    // (1 - ((-y - 0.2) / 10) / tan 30deg) / 2 * h.
    let tan30 = 30f64.to_radians().tan();
    let row_of = |y: f64| (1.0 - ((-y - 0.2) / 10.0) / tan30) / 2.0 * h as f64;
    let (top_row, bottom_row) = (row_of(2.0), row_of(3.0)); // the image is flipped
    let col_of = |x: f64| (1.0 + (x / 10.0) / tan30) / 2.0 * w as f64;
    let (left_col, right_col) = (col_of(-1.0), col_of(1.0));
    assert!(top_row < bottom_row && left_col < right_col);

    let at = |x: u32, y: u32| image.pixels[(y * w + x) as usize][0] as f64;
    let centre_col = w / 2;
    // Every row strictly inside the predicted span is lit, every row well outside is dark.
    for y in 0..h {
        let v = at(centre_col, y);
        let yc = y as f64 + 0.5;
        if yc > top_row + 1.5 && yc < bottom_row - 1.5 {
            // Brightness: the reflection of a mirror is F(theta) L, theta the angle between
            // the view ray and the normal at the water point.
            let view_down = (((yc / h as f64) * 2.0 - 1.0) * tan30).atan(); // below horizon
            let cos_i = view_down.sin();
            let expected = fresnel(cos_i, 1.33) * radiance;
            assert!(
                (v - expected).abs() < 0.03 * expected,
                "row {y}: {v} but Fresnel gives {expected}"
            );
        } else if (yc < top_row - 2.0 || yc > bottom_row + 2.0) && yc > h as f64 / 2.0 + 1.0 {
            assert!(v == 0.0, "row {y} should be dark below the horizon, is {v}");
        }
    }
    // Columns: lit inside the mirror image's span, dark outside.
    let mid_row = ((top_row + bottom_row) / 2.0) as u32;
    for x in 0..w {
        let xc = x as f64 + 0.5;
        let v = at(x, mid_row);
        if xc > left_col + 1.5 && xc < right_col - 1.5 {
            assert!(v > 0.0, "column {x} should be lit");
        } else if xc < left_col - 2.0 || xc > right_col + 2.0 {
            assert!(v == 0.0, "column {x} should be dark, is {v}");
        }
    }
    // The light itself, seen directly above the horizon, at its own rows.
    let direct_row = |y: f64| (1.0 - ((y - 0.2) / 10.0) / tan30) / 2.0 * h as f64;
    let y_mid = ((direct_row(2.0) + direct_row(3.0)) / 2.0) as u32;
    assert!((at(centre_col, y_mid) - radiance).abs() < 1e-4);
}
