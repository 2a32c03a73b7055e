//! Benchmark: the statistical water's lobe (Gaussian slopes with Smith's masking, the slope
//! search's lobe on the harbour samples) per water point, as the joint fit's weighting reads
//! it: each water point's grid of 64 drawn slopes sampled, and each point's stored samples'
//! `f cos` valued (128 directions a point), once with everything a point's samples share
//! made for every sample (`sample_drawn`, `eval_cos`) and once made for the point
//! (`view`, then `sample_in`, `eval_cos_in`). Both give the same bits; the bench checks that.
//! Run with `cargo bench --bench lobe`.

use std::hint::black_box;
use std::time::Instant;

use glam::{Vec2, Vec3};
use streaklight::optics::{GaussianSlopes, ReflectionModel, Shadowing};

/// Water points: views 3 to 18 degrees above the water, as the harbour's camera sees it.
const POINTS: usize = 20_000;
/// Directions valued per point.
const VALUED: usize = 128;

fn main() {
    let slopes = GaussianSlopes {
        variance: [3e-3, 2.5e-3],
    };
    let model = ReflectionModel::new(20000.0, 1.33).with_shadowing(Shadowing::Smith);
    let (n, t) = (Vec3::Y, Vec3::NEG_Z);
    let views: Vec<Vec3> = (0..POINTS)
        .map(|i| {
            let e = (3.0 + 15.0 * (i as f32 / POINTS as f32)).to_radians();
            Vec3::new(0.05 * ((i % 7) as f32 - 3.0) / 3.0, e.sin(), e.cos()).normalize()
        })
        .collect();
    let draws: Vec<_> = (0..64)
        .map(|i| {
            slopes.draw(Vec2::new(
                ((i % 8) as f32 + 0.5) / 8.0,
                ((i / 8) as f32 + 0.5) / 8.0,
            ))
        })
        .collect();
    // Directions to value: the lobe's own samples, cycled.
    let wis: Vec<Vec3> = views
        .iter()
        .flat_map(|&wo| {
            draws
                .iter()
                .filter_map(move |d| slopes.sample_drawn(&model, n, t, wo, d))
        })
        .map(|s| s.wi)
        .take(100_000)
        .collect();
    let wi = |k: usize, j: usize| wis[(k * VALUED + j) % wis.len()];
    let per = |seconds: f64, count: usize| seconds * 1e9 / count as f64;
    for run in 0..3 {
        let t0 = Instant::now();
        let mut each = 0f32;
        for &wo in &views {
            for d in &draws {
                if let Some(s) = slopes.sample_drawn(&model, n, t, wo, d) {
                    each += s.weight;
                }
            }
        }
        let sample_each = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        let mut shared = 0f32;
        for &wo in &views {
            if let Some(view) = slopes.view(&model, n, t, wo) {
                for d in &draws {
                    if let Some(s) = slopes.sample_in(&model, &view, d) {
                        shared += s.weight;
                    }
                }
            }
        }
        let sample_shared = t0.elapsed().as_secs_f64();
        assert_eq!(each.to_bits(), shared.to_bits());
        let t0 = Instant::now();
        let mut each = 0f32;
        for (k, &wo) in views.iter().enumerate() {
            for j in 0..VALUED {
                each += slopes.eval_cos(&model, n, t, wo, black_box(wi(k, j)));
            }
        }
        let value_each = t0.elapsed().as_secs_f64();
        let t0 = Instant::now();
        let mut shared = 0f32;
        for (k, &wo) in views.iter().enumerate() {
            let view = slopes.view(&model, n, t, wo);
            for j in 0..VALUED {
                let wi = black_box(wi(k, j));
                shared += view.map_or(0.0, |v| slopes.eval_cos_in(&model, &v, wi));
            }
        }
        let value_shared = t0.elapsed().as_secs_f64();
        assert_eq!(each.to_bits(), shared.to_bits());
        let (drawn, valued) = (POINTS * draws.len(), POINTS * VALUED);
        println!(
            "run {run}: a sample {:.1} ns each, {:.1} ns from its point's view; a value {:.1} ns \
             each, {:.1} ns from its point's view",
            per(sample_each, drawn),
            per(sample_shared, drawn),
            per(value_each, valued),
            per(value_shared, valued),
        );
    }
}
