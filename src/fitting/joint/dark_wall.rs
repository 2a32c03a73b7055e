//! A start that reaches over wall the photo shows dark is cut back to the wall it does not.
//!
//! Out of frame a light has no direct image to place it ([`super::direct_start`]), and the
//! paper's per-streak estimate puts an edge it found no pixel for at the lobes' farthest reach:
//! for a light above the photo's top, often the foot of its wall, which the photo shows, dark.
//! The joint fit refines locally, and from such a start it can settle on a light that reaches
//! down into that dark wall at a hundredth of its radiance while its top climbs tens of metres
//! to keep the reflection (the red light of the harbour's three out of frame over a flat quad:
//! 4.7 x 29 m at radiance 0.03 for a 2.5 x 1 m light of 24). The photo says where the light
//! is not: rows and columns of the start's rectangle that the camera sees, unoccluded and dark,
//! on the wall hold no part of it.
//!
//! The start's rectangle is sampled on a [`GRID`] x [`GRID`] grid of cell centres. A cell is
//! seen dark when its point projects into the photo onto a pixel outside the water, the camera
//! ray to it meets nothing before the light's plane, and that pixel's brightest channel is
//! under [`DARK_SHARE`] of the start's brightest radiance channel (unclipped). Whole rows (or
//! columns) of cells seen dark are peeled off each side whose edge the estimate guessed (an
//! edge placed from streak-edge pixels stands) while any are. A start seen dark over more than
//! [`MOSTLY_DARK`] of its cells is left as it is: it is a stray fragment's more likely than a
//! light's, and there the fit takes its radiance to zero and drops it, where cut back to the
//! photo's edge it could survive as a strip along it.

use crate::fitting::{EdgeSide, EdgeStatus, FittedLight};
use crate::photo_in::Photo;
use crate::scene_in::Scene;

/// Cells per side of the grid the start's rectangle is sampled on.
pub(super) const GRID: usize = 32;

/// A start seen dark over more than this share of its cells is left as it is.
pub(super) const MOSTLY_DARK: f32 = 0.5;

/// A pixel below this share of the start's brightest radiance channel is dark.
pub(super) const DARK_SHARE: f32 = 0.1;

/// `light` with the sides of its rectangle that the photo shows as dark wall cut off (module
/// doc).
pub(super) fn trimmed_to_unseen_wall(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    light: &FittedLight,
) -> FittedLight {
    let rect = light.rect();
    let brightest = light.radiance.iter().copied().fold(0.0f32, f32::max);
    if rect.is_empty() || brightest.is_nan() || brightest <= 0.0 {
        return light.clone();
    }
    let (w, h) = (photo.width, photo.height);
    let origin = scene.camera.position;
    let cell = |i: usize, j: usize| -> bool {
        let u = rect.u_min + (i as f32 + 0.5) / GRID as f32 * rect.width();
        let v = rect.v_min + (j as f32 + 0.5) / GRID as f32 * rect.height();
        let p = light.plane.point_at(u, v);
        let Some((x, y)) = scene.camera.project(p, w, h) else {
            return false;
        };
        if !(x >= 0.0 && y >= 0.0 && x < w as f32 && y < h as f32) {
            return false;
        }
        let pixel = photo.index(x as u32, y as u32);
        if water[pixel] || photo.clipped[pixel] {
            return false;
        }
        let to = p - origin;
        let distance = to.length();
        if distance.is_nan() || distance <= 0.0 {
            return false;
        }
        let dir = to / distance;
        // What the camera sees there: the light's plane, not anything in front of it (a
        // thousandth of the distance either side: a face's triangles lie within a
        // ten-thousandth of its plane).
        let seen = scene
            .tracer
            .closest_hit(origin, dir, 0.0, distance * 1.001)
            .is_some_and(|hit| {
                hit.t > distance * 0.999 && light.plane.contains_triangle(scene, hit.triangle)
            });
        seen && photo.radiance[pixel].into_iter().fold(0.0f32, f32::max) < DARK_SHARE * brightest
    };
    let dark: Vec<Vec<bool>> = (0..GRID)
        .map(|i| (0..GRID).map(|j| cell(i, j)).collect())
        .collect();
    // A start seen dark over most of it is no light's misplaced guess but a stray one's:
    // left as it is, the fit takes its radiance to zero and drops it.
    let dark_cells = dark.iter().flatten().filter(|&&d| d).count();
    if dark_cells as f32 > MOSTLY_DARK * (GRID * GRID) as f32 {
        return light.clone();
    }
    // Only the edges the paper's estimate guessed: one it placed from streak-edge pixels
    // stands.
    let guessed = |side: EdgeSide| matches!(light.edges[side], EdgeStatus::Unconstrained { .. });
    // The kept cells: columns i0..i1, rows j0..j1.
    let (mut i0, mut i1, mut j0, mut j1) = (0, GRID, 0, GRID);
    let row_dark = |j: usize, i0: usize, i1: usize| (i0..i1).all(|i| dark[i][j]);
    let column_dark = |i: usize, j0: usize, j1: usize| (j0..j1).all(|j| dark[i][j]);
    loop {
        let before = (i0, i1, j0, j1);
        while guessed(EdgeSide::Bottom) && j0 < j1 && row_dark(j0, i0, i1) {
            j0 += 1;
        }
        while guessed(EdgeSide::Top) && j1 > j0 && row_dark(j1 - 1, i0, i1) {
            j1 -= 1;
        }
        while guessed(EdgeSide::Left) && i0 < i1 && column_dark(i0, j0, j1) {
            i0 += 1;
        }
        while guessed(EdgeSide::Right) && i1 > i0 && column_dark(i1 - 1, j0, j1) {
            i1 -= 1;
        }
        if (i0, i1, j0, j1) == before || i0 >= i1 || j0 >= j1 {
            break;
        }
    }
    if i0 >= i1 || j0 >= j1 {
        return light.clone();
    }
    // Cell boundary k of `lo..hi`, its ends exactly.
    let at = |k: usize, lo: f32, hi: f32| match k {
        0 => lo,
        GRID => hi,
        _ => lo + k as f32 / GRID as f32 * (hi - lo),
    };
    FittedLight {
        u_min: at(i0, rect.u_min, rect.u_max),
        u_max: at(i1, rect.u_min, rect.u_max),
        v_min: at(j0, rect.v_min, rect.v_max),
        v_max: at(j1, rect.v_min, rect.v_max),
        ..light.clone()
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::fitting::joint::direct_start::tests::table1;
    use crate::fitting::joint::fixture::start_light;
    use crate::fitting::rect::Rect;

    /// Table 1's light (3 m x 3 m, radiance 20, in frame on a black wall 10 m away) started
    /// 2 m too low, its bottom edge a guess: the rows the photo shows as black wall are cut
    /// off, and the bottom comes back to within half a grid cell (5 m / 64: the kept row's
    /// centre sees the light, the cut one's below it does not) and a pixel of the truth's,
    /// every other edge as it was. The same start with its bottom edge fitted from pixels,
    /// or a start mostly on the black wall below the light, is left as it is.
    #[test]
    fn a_guessed_edge_over_dark_wall_is_cut_back() {
        let (scene, photo, water, plane, truth) = table1();
        let low = Rect {
            v_min: truth.v_min - 2.0,
            ..truth
        };
        let start = |rect: Rect, bottom_guessed: bool| {
            let mut light = start_light(&plane, rect, 0);
            light.radiance = [20.0; 3];
            if bottom_guessed {
                light.edges[EdgeSide::Bottom] = EdgeStatus::Unconstrained {
                    reason: "no edge pixel".into(),
                    pixels: 0,
                    unseen: false,
                };
            }
            light
        };
        let got = trimmed_to_unseen_wall(scene, photo, water, &start(low, true)).rect();
        let cell = low.height() / GRID as f32;
        let footprint = 10.0 * 2.0 * (30f32.to_radians()).tan() / photo.height as f32;
        assert!(
            (got.v_min - truth.v_min).abs() < 0.5 * cell + footprint,
            "bottom {} against {} (a cell is {cell} m)",
            got.v_min,
            truth.v_min
        );
        assert_eq!(
            (got.u_min, got.u_max, got.v_max),
            (low.u_min, low.u_max, low.v_max)
        );

        let fitted = trimmed_to_unseen_wall(scene, photo, water, &start(low, false));
        assert_eq!(fitted.rect(), low);

        // Three quarters of it on the black wall below the light, a quarter on the light.
        let below = Rect {
            v_min: truth.v_min - 1.8,
            v_max: truth.v_min + 0.6,
            ..truth
        };
        let dark = trimmed_to_unseen_wall(scene, photo, water, &start(below, true));
        assert_eq!(dark.rect(), below);
    }
}
