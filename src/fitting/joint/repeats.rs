//! Repeated joint fits (method §5, last paragraph): independent fits, each from its own
//! samples, combined into their mean and the standard error of that mean (`--repeats`).

use crate::fitting::rect::Rect;
use crate::fitting::EdgeSide;

/// Per light, the mean rectangle and radiance of several independent fits, and the standard
/// error of each mean (edges in metres, radiance per channel): the fits' sample standard
/// deviation over the square root of their count.
#[allow(clippy::type_complexity)]
pub(super) fn mean_and_spread(
    fits: &[(Vec<Rect>, Vec<[f64; 3]>)],
) -> (Vec<Rect>, Vec<[f64; 3]>, Vec<([f32; 4], [f32; 3])>) {
    let n = fits.len() as f64;
    let lights = fits[0].0.len();
    let mut rects = Vec::with_capacity(lights);
    let mut radiance = Vec::with_capacity(lights);
    let mut spread = Vec::with_capacity(lights);
    let mean_and_error = |values: &[f64]| {
        let mean = values.iter().sum::<f64>() / n;
        let var = values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0);
        (mean, (var / n).sqrt())
    };
    for k in 0..lights {
        let edges = EdgeSide::ALL.map(|side| {
            let values: Vec<f64> = fits.iter().map(|f| f.0[k].edge(side) as f64).collect();
            mean_and_error(&values)
        });
        let channels = [0, 1, 2].map(|c| {
            let values: Vec<f64> = fits.iter().map(|f| f.1[k][c]).collect();
            mean_and_error(&values)
        });
        rects.push(Rect {
            u_min: edges[0].0 as f32,
            u_max: edges[1].0 as f32,
            v_min: edges[2].0 as f32,
            v_max: edges[3].0 as f32,
        });
        radiance.push(channels.map(|c| c.0));
        spread.push((edges.map(|e| e.1 as f32), channels.map(|c| c.1 as f32)));
    }
    (rects, radiance, spread)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn repeats_give_their_mean_and_its_standard_error() {
        let rect = |v: f32| Rect {
            u_min: v,
            u_max: v + 1.0,
            v_min: 2.0 * v,
            v_max: 3.0,
        };
        // Two fits: the standard error of their mean is half their difference.
        let (rects, radiance, spread) = mean_and_spread(&[
            (vec![rect(0.0)], vec![[1.0, 2.0, 3.0]]),
            (vec![rect(0.5)], vec![[3.0, 2.0, 0.0]]),
        ]);
        assert_eq!(rects[0], rect(0.25));
        assert_eq!(radiance[0], [2.0, 2.0, 1.5]);
        assert_eq!(spread[0].0, [0.25, 0.25, 0.5, 0.0]);
        assert_eq!(spread[0].1, [1.0, 0.0, 1.5]);
        // Four: sample standard deviation over 2. Values 1, 2, 3, 6: mean 3, sd sqrt(14/3).
        let fits: Vec<(Vec<Rect>, Vec<[f64; 3]>)> = [1.0, 2.0, 3.0, 6.0]
            .iter()
            .map(|&x| (vec![rect(0.0)], vec![[x, 0.0, 0.0]]))
            .collect();
        let (_, radiance, spread) = mean_and_spread(&fits);
        assert_eq!(radiance[0][0], 3.0);
        let expected = ((14.0f64 / 3.0).sqrt() / 2.0) as f32;
        assert!(
            (spread[0].1[0] - expected).abs() < 1e-6,
            "{:?}",
            spread[0].1
        );
    }
}
