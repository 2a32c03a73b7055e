//! A light's colour from the pixels that show it alone and unclipped, for the channels the
//! photo clips and the channels other lights crowd.
//!
//! The radiances are least-squares solves per channel in which a clipped channel is only a
//! lower bound (`cost`). Where a light clips one channel of the photo and not another (an
//! orange lamp of radiance (24, 12, 3) at exposure 0.1 clips red and green on its direct
//! image, not blue), the clipped channel is told only by the pixels that stay under the clip,
//! and those are a biased choice: on water the scene does not hold, the expected image is a
//! mean over glints, and the photo's brightest glints, the ones that clip, are the ones left
//! out (the harbour pair over another wave field: red 7 % low, green 6 %); with the exact
//! model the one-sided cost meets the coefficients' noise and pushes the channel up (4.5 %).
//!
//! A pixel lit by one light alone has that light's colour in every channel, however bright:
//! the water's Fresnel reflectance and the coverage of a pixel do not depend on the channel.
//! So a clipped channel's radiance is the light's radiance in its best-told channel (the one
//! its pixels clip least, of the largest radiance among those) times the ratio of the two
//! channels summed over the pixels where that light makes all but [`OTHERS_SHARE`] of the
//! model and no channel is clipped. Leaving the clipped pixels out selects by brightness,
//! not by colour, so the ratio is not biased by it.

use super::problem::{Problem, State};

/// The largest share of a pixel's model other lights may make for the pixel to tell a
/// light's colour.
const OTHERS_SHARE: f64 = 0.05;

/// Fewest unclipped pixels a light's colour is read from.
const MIN_PIXELS: usize = 16;

/// Sets the radiance of every channel a light's pixels clip more often than its best-told
/// channel, and of every channel other lights crowd ([`crowded`]), from the best-told channel
/// and the light's colour in the pixels it lights alone, unclipped (module doc). Lights with
/// no such channel, or too few such pixels, are left as they are.
pub(super) fn colour_from_own_pixels(problem: &Problem, st: &mut State) {
    for k in 0..st.rects.len() {
        let radiance = st.radiance[k];
        // Per channel: how many of the pixels this light lights are clipped in it.
        let mut lit = 0usize;
        let mut clipped = [0usize; 3];
        // Per channel: the light's own part of the photo over its unclipped pixels.
        let mut sums = [0f64; 3];
        // Per channel, over every pixel it lights: its own model and the other lights'.
        let (mut own_total, mut rest_total) = ([0f64; 3], [0f64; 3]);
        let mut clean = 0usize;
        for i in 0..problem.n() {
            let c = st.coef[k][i] as f64;
            if c <= 0.0 {
                continue;
            }
            let own = radiance.map(|l| l * c);
            let (rest, _) = problem.others(st, k, i);
            for ch in 0..3 {
                own_total[ch] += own[ch];
                rest_total[ch] += rest[ch];
            }
            if (0..3).any(|ch| rest[ch] > OTHERS_SHARE * (own[ch] + rest[ch])) {
                continue;
            }
            lit += 1;
            let cl = problem.clipped_channels[i];
            for ch in 0..3 {
                clipped[ch] += cl[ch] as usize;
            }
            if !cl.contains(&true) {
                clean += 1;
                for ch in 0..3 {
                    sums[ch] += problem.obs[i][ch] as f64 - rest[ch];
                }
            }
        }
        let share = [0, 1, 2].map(|ch| {
            let total = own_total[ch] + rest_total[ch];
            if total > 0.0 {
                rest_total[ch] / total
            } else {
                0.0
            }
        });
        // A light with no channel clipped more than another and none crowded is left as it
        // is by the loop below.
        if lit == 0 || clean < MIN_PIXELS {
            continue;
        }
        let Some(best) = (0..3)
            .filter(|&ch| sums[ch] > 0.0 && radiance[ch] > 0.0)
            .min_by(|&a, &b| {
                clipped[a]
                    .cmp(&clipped[b])
                    .then(radiance[b].total_cmp(&radiance[a]))
            })
        else {
            continue;
        };
        for ch in 0..3 {
            if clipped[ch] > clipped[best] || crowded(share, ch, best) {
                st.radiance[k][ch] = radiance[best] * (sums[ch] / sums[best]).max(0.0);
            }
        }
    }
}

/// Whether other lights crowd channel `ch` of a light compared with its channel `best`:
/// their share of the model over the pixels it lights is above [`OTHERS_SHARE`] in `ch` and
/// more than twice their share in `best`. Lights of one colour share every channel alike, so
/// a white light under another keeps its least-squares radiance.
fn crowded(share: [f64; 3], ch: usize, best: usize) -> bool {
    share[ch] > OTHERS_SHARE && share[ch] > 2.0 * share[best]
}
