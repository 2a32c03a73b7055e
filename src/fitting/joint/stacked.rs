//! Lights stacked in one column that the reflections alone cannot tell from one light.
//!
//! Under a statistical water model a streak is the light's angular height convolved with the
//! spread of the waves' slopes along the view, and at harbour range the spread is many times
//! the height (method §10): the reflections give a light's flux per unit width, not where on
//! its column that flux sits. One realisation's waves, though, break a streak into fragments
//! whose rows hold more or less light than the expectation, and a fit can then explain a
//! bright fragment far down the streak with a second light of the same colour above the
//! first on the same wall: the sign out of frame over a flat quad ends with a 10.8 x 15.9 m
//! light 8 m above it (image at 44 sigma, the real red light of three out of frame at 34, so
//! no significance separates them).
//!
//! Two such lights are one light for the photo when all of these hold, and the weaker (the
//! smaller image significance) is dropped:
//! - they lie on the same face, and their spans across the column overlap by at least
//!   [`MIN_COLUMN_OVERLAP`] of the narrower;
//! - their colours (radiance over its channel sum) agree within [`SAME_COLOUR`] in every
//!   channel: fragments of one light carry its colour, different lamps rarely agree as well;
//! - the weaker has no direct pixel: where a light is seen, its image places it, and two
//!   lamps in one column are told apart.
//!
//! Only the statistical fit asks for this ([`super::JointOptions::stacked_as_one`]): under the
//! exact model a fragment's glints map to their own rows of the wall, and two stacked lamps of
//! one colour (the stacked samples) are two lights.

use super::problem::{Problem, State};
use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::fitting::FittedLight;

/// The part of the narrower light's width the two spans across the column must share.
pub(super) const MIN_COLUMN_OVERLAP: f32 = 0.5;

/// The largest difference in any channel of two colours (each radiance over its channel
/// sum) that counts as one colour. Fragments of the harbour sign fitted as two lights differ
/// by 0.001; the harbour samples' lamps of different colours by 0.2 and more.
pub(super) const SAME_COLOUR: f64 = 0.02;

/// One fitted light as the rule reads it.
pub(super) struct Column<'a> {
    /// The face it lies on, whose frame `rect` is in.
    pub plane: &'a LightPlane,
    pub rect: Rect,
    pub radiance: [f64; 3],
    /// Its image significance ([`super::significance::image_significance`]).
    pub image: f64,
    /// Whether a direct pixel sees it.
    pub seen: bool,
    /// The streaks it started from (for the warning).
    pub streaks: &'a [usize],
}

/// The lights of `st` to drop as the weaker of a stacked pair (module doc), ascending, with
/// why; `skip` are lights already dropped for another reason (never paired), `start` the
/// lights the fit started from (their planes).
pub(super) fn stacked(
    problem: &Problem,
    st: &State,
    start: &[FittedLight],
    skip: &[usize],
) -> Vec<(usize, String)> {
    let image = super::significance::image_significance(problem, st);
    let lights: Vec<Column> = (0..st.rects.len())
        .map(|k| {
            let origin = &start[problem.set_origin[st.set_of[k]]];
            Column {
                plane: &origin.plane,
                rect: st.rects[k],
                radiance: st.radiance[k],
                image: image[k],
                seen: problem.direct_pixels_inside(st.set_of[k], &st.rects[k]) > 0,
                streaks: &origin.streak_ids,
            }
        })
        .collect();
    weaker_of_stacked(&lights, skip)
}

/// [`stacked`] over lights as the rule reads them.
pub(super) fn weaker_of_stacked(lights: &[Column], skip: &[usize]) -> Vec<(usize, String)> {
    let mut drop: Vec<(usize, String)> = Vec::new();
    for a in 0..lights.len() {
        for b in a + 1..lights.len() {
            let dropped = |k: usize| skip.contains(&k) || drop.iter().any(|d| d.0 == k);
            if dropped(a) || dropped(b) {
                continue;
            }
            let (la, lb) = (&lights[a], &lights[b]);
            if !la.plane.same_face(lb.plane) {
                continue;
            }
            let shift = la.plane.coords(lb.plane.point).x;
            let (ra, rb) = (la.rect, lb.rect);
            let overlap = ra.u_max.min(rb.u_max + shift) - ra.u_min.max(rb.u_min + shift);
            let narrower = ra.width().min(rb.width());
            if !(narrower > 0.0 && overlap >= MIN_COLUMN_OVERLAP * narrower) {
                continue;
            }
            let Some(difference) = colour_difference(la.radiance, lb.radiance) else {
                continue;
            };
            if difference > SAME_COLOUR {
                continue;
            }
            let (weak, strong) = if la.image < lb.image { (a, b) } else { (b, a) };
            if lights[weak].seen {
                continue;
            }
            drop.push((
                weak,
                format!(
                    "it lay in one column with the light of streak(s) {:?} on the same face, \
                     of the same colour (within {difference:.3}), and with the waves' slopes \
                     spread as wide as they are, the reflections cannot tell two such lights \
                     from one",
                    lights[strong].streaks
                ),
            ));
        }
    }
    drop.sort_by_key(|d| d.0);
    drop
}

/// The largest difference in any channel between the colours of two radiances (each over its
/// channel sum); `None` when either is black.
fn colour_difference(a: [f64; 3], b: [f64; 3]) -> Option<f64> {
    let (sa, sb) = (a.iter().sum::<f64>(), b.iter().sum::<f64>());
    if !(sa > 0.0 && sb > 0.0) {
        return None;
    }
    Some(
        (0..3)
            .map(|c| (a[c] / sa - b[c] / sb).abs())
            .fold(0.0, f64::max),
    )
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    /// The wall z = 0 facing +z, its frame's origin at `origin` on it; `node` tells faces
    /// apart.
    fn wall(node: usize, origin: Vec3) -> LightPlane {
        LightPlane::with_frame((node, 0, 0), origin, Vec3::Z, Vec3::X, 1.0).expect("a plane")
    }

    use crate::fitting::joint::fixture::rect;

    fn column<'a>(plane: &'a LightPlane, rect: Rect, radiance: [f64; 3], image: f64) -> Column<'a> {
        Column {
            plane,
            rect,
            radiance,
            image,
            seen: false,
            streaks: &[],
        }
    }

    fn dropped(lights: &[Column]) -> Vec<usize> {
        weaker_of_stacked(lights, &[]).iter().map(|d| d.0).collect()
    }

    /// The harbour sign out of frame over a flat quad: the sign 6 m wide at 0-3 m, and a
    /// fragment's light of its colour, 11 m wide, 2-17 m up: the fragment's light goes,
    /// whichever comes first.
    #[test]
    fn a_fragments_light_above_a_light_of_its_colour_goes() {
        let plane = wall(0, Vec3::ZERO);
        let sign = || {
            column(
                &plane,
                rect(-1.0, 5.1, -0.4, 3.1),
                [5.12, 4.61, 3.59],
                224.0,
            )
        };
        let fragment = || column(&plane, rect(-6.5, 4.4, 1.5, 17.4), [4.33, 3.90, 3.04], 43.9);
        assert_eq!(dropped(&[sign(), fragment()]), vec![1]);
        let got = weaker_of_stacked(&[fragment(), sign()], &[]);
        assert_eq!(got.iter().map(|d| d.0).collect::<Vec<_>>(), vec![0]);
        assert!(got[0].1.contains("one column"), "{}", got[0].1);
    }

    /// Each condition alone keeps both: another colour (red's share 0.03 higher), columns side by
    /// side (sharing under half the narrower), another face, a weaker light its direct image
    /// shows; the same column measured from a frame origin elsewhere on the face is one.
    #[test]
    fn stacked_lights_stay_apart_unless_every_condition_holds() {
        let plane = wall(0, Vec3::ZERO);
        let warm = [5.0, 4.5, 3.5];
        let lower = || column(&plane, rect(0.0, 2.0, 0.0, 1.0), warm, 100.0);
        // Red's share 5/13 raised by 0.03, green and blue as they were.
        let share = 5.0 / 13.0 + 0.03;
        let redder = [8.0 * share / (1.0 - share), 4.5, 3.5];
        assert!(dropped(&[
            lower(),
            column(&plane, rect(0.0, 2.0, 3.0, 4.0), redder, 50.0)
        ])
        .is_empty());
        assert!(dropped(&[
            lower(),
            column(&plane, rect(1.1, 3.1, 3.0, 4.0), warm, 50.0)
        ])
        .is_empty());
        assert_eq!(
            dropped(&[
                lower(),
                column(&plane, rect(0.9, 2.9, 3.0, 4.0), warm, 50.0)
            ]),
            vec![1]
        );
        let other = wall(1, Vec3::ZERO);
        assert!(dropped(&[
            lower(),
            column(&other, rect(0.0, 2.0, 3.0, 4.0), warm, 50.0)
        ])
        .is_empty());
        let mut seen = column(&plane, rect(0.0, 2.0, 3.0, 4.0), warm, 50.0);
        seen.seen = true;
        assert!(dropped(&[lower(), seen]).is_empty());
        let shifted = wall(0, Vec3::new(10.0, 0.0, 0.0));
        assert_eq!(
            dropped(&[
                lower(),
                column(&shifted, rect(-10.0, -8.0, 3.0, 4.0), warm, 50.0)
            ]),
            vec![1]
        );
        assert!(dropped(&[
            lower(),
            column(&shifted, rect(0.0, 2.0, 3.0, 4.0), warm, 50.0)
        ])
        .is_empty());
    }

    /// Three of one colour in one column: the two weaker go, the strongest stays; a light
    /// already dropped is never paired.
    #[test]
    fn of_three_in_one_column_the_strongest_stays() {
        let plane = wall(0, Vec3::ZERO);
        let c = |v: f32, image: f64| column(&plane, rect(0.0, 2.0, v, v + 1.0), [1.0; 3], image);
        assert_eq!(
            dropped(&[c(0.0, 10.0), c(2.0, 30.0), c(4.0, 20.0)]),
            vec![0, 2]
        );
        let lights = [c(0.0, 10.0), c(2.0, 30.0)];
        assert!(weaker_of_stacked(&lights, &[1]).is_empty());
    }

    #[test]
    fn colours_compare_by_their_share_of_each_channel() {
        // One colour at two brightnesses.
        assert_eq!(
            colour_difference([5.0, 4.5, 3.5], [10.0, 9.0, 7.0]),
            Some(0.0)
        );
        // Orange against blue: most in blue, 0.667 against 0.077.
        let d = colour_difference([1.0, 0.5, 0.125], [0.15, 0.35, 1.0]).unwrap_or(0.0);
        assert!((d - (1.0 / 1.5 - 0.125 / 1.625)).abs() < 1e-12, "{d}");
        assert_eq!(colour_difference([0.0; 3], [1.0; 3]), None);
    }
}
