//! Lobe draws made once for many water points: the part of a lobe sample that depends on the
//! uniform pair and the lobe alone (the half vector of the microfacets, the slope of the
//! waves), for a fixed list of pairs that every point reads alike (the joint fit's control
//! variate matches each pixel's Gaussian to the same grid of lobe directions). Made once per
//! trace or weighting, they spare each point the logarithms, roots and sines of its draws;
//! each sample is the one [`super::WaterModel::reflect`] gives for the pair, to the last bit.

use glam::Vec2;

use crate::optics::{GaussianSlopes, HalfDraw, ReflectionModel, SlopeDraw};

/// The draws of a list of uniform pairs ([`super::WaterModel::lobe_draws`]), with what they
/// were made for: a model that reads draws made for another lobe draws again from the pairs.
#[derive(Clone, Debug)]
pub struct LobeDraws {
    pairs: Vec<Vec2>,
    made: Made,
}

#[derive(Clone, Debug)]
enum Made {
    /// Only the pairs: each point draws from them.
    Pairs,
    /// The microfacets' half vectors at `gloss`.
    Microfacet { gloss: f32, draws: Vec<HalfDraw> },
    /// The slopes of `slopes`.
    Slopes {
        slopes: GaussianSlopes,
        draws: Vec<SlopeDraw>,
    },
}

impl LobeDraws {
    /// The pairs alone.
    pub fn pairs(pairs: &[Vec2]) -> Self {
        LobeDraws {
            pairs: pairs.to_vec(),
            made: Made::Pairs,
        }
    }

    /// The half vectors `model` draws from `pairs`.
    pub fn microfacet(model: &ReflectionModel, pairs: &[Vec2]) -> Self {
        LobeDraws {
            pairs: pairs.to_vec(),
            made: Made::Microfacet {
                gloss: model.gloss,
                draws: pairs.iter().map(|&u| model.draw(u)).collect(),
            },
        }
    }

    /// The slopes `slopes` draws from `pairs`.
    pub fn slopes(slopes: GaussianSlopes, pairs: &[Vec2]) -> Self {
        LobeDraws {
            pairs: pairs.to_vec(),
            made: Made::Slopes {
                slopes,
                draws: pairs.iter().map(|&u| slopes.draw(u)).collect(),
            },
        }
    }

    /// How many pairs.
    pub fn len(&self) -> usize {
        self.pairs.len()
    }

    /// True when there is no pair.
    pub fn is_empty(&self) -> bool {
        self.pairs.is_empty()
    }

    /// The `i`-th pair.
    pub fn pair(&self, i: usize) -> Vec2 {
        self.pairs[i]
    }

    /// The `i`-th half vector, when these are a microfacet lobe's of gloss `gloss`.
    pub fn half(&self, i: usize, gloss: f32) -> Option<&HalfDraw> {
        match &self.made {
            Made::Microfacet { gloss: g, draws } if g.to_bits() == gloss.to_bits() => draws.get(i),
            _ => None,
        }
    }

    /// Every slope, when these are `slopes`'.
    pub fn slopes_of(&self, slopes: &GaussianSlopes) -> Option<&[SlopeDraw]> {
        match &self.made {
            Made::Slopes { slopes: s, draws } if s == slopes => Some(draws),
            _ => None,
        }
    }

    /// The `i`-th slope, when these are `slopes`'.
    pub fn slope(&self, i: usize, slopes: &GaussianSlopes) -> Option<&SlopeDraw> {
        self.slopes_of(slopes)?.get(i)
    }
}

#[cfg(test)]
mod tests {
    use glam::Vec3;

    use super::*;
    use crate::render::WaterPoint;
    use crate::water_model::{ExactSurface, MeanSurface, StatisticalSurface, WaterModel};

    /// Bits of a sample, or of none.
    fn bits(s: Option<crate::optics::LobeSample>) -> Option<[u32; 5]> {
        s.map(|s| {
            [
                s.wi.x.to_bits(),
                s.wi.y.to_bits(),
                s.wi.z.to_bits(),
                s.weight.to_bits(),
                s.pdf.to_bits(),
            ]
        })
    }

    /// Bits of a direction and its weight.
    fn pair_bits((wi, weight): (Vec3, f32)) -> [u32; 4] {
        [
            wi.x.to_bits(),
            wi.y.to_bits(),
            wi.z.to_bits(),
            weight.to_bits(),
        ]
    }

    /// Both models, at water points seen from 2 to 60 degrees above the water under tilted
    /// shading normals: a sample from draws made once is the sample drawn from its pair, to
    /// the last bit, one at a time or all of a point's at once; draws made for another lobe
    /// (another gloss, other variances) are drawn again from the pairs, to the same samples.
    #[test]
    fn a_sample_from_draws_made_once_is_the_sample_drawn_from_its_pair() {
        let pairs: Vec<Vec2> = (0..400)
            .map(|i| {
                Vec2::new(
                    ((i % 20) as f32 + 0.37) / 20.0,
                    ((i / 20) as f32 + 0.61) / 20.0,
                )
            })
            .collect();
        let surface = MeanSurface::new(Vec3::new(0.0, -2.0, -10.0), Vec3::Y, Vec3::NEG_Z, Vec3::Y);
        let statistical = StatisticalSurface {
            surface,
            waves: [3e-3, 1.5e-3],
        };
        let other_waves = StatisticalSurface {
            waves: [2e-3, 1.5e-3],
            ..statistical
        };
        let model = ReflectionModel::new(800.0, 1.33);
        let other_gloss = ReflectionModel::new(600.0, 1.33);
        let models: [(&dyn WaterModel, &dyn WaterModel); 2] =
            [(&ExactSurface, &ExactSurface), (&statistical, &other_waves)];
        let mut compared = 0;
        for (water_model, other) in models {
            for (k, elevation) in [2.0f32, 8.0, 25.0, 60.0].into_iter().enumerate() {
                let e = elevation.to_radians();
                let tilt = Vec3::new(0.03 * k as f32, 1.0, -0.02).normalize();
                let point = WaterPoint {
                    start: Vec3::new(0.0, -2.0, -5.0),
                    wo: Vec3::new(0.1, e.sin(), e.cos()).normalize(),
                    normal: tilt,
                    face: Vec3::Y,
                    clear: 0.0,
                };
                let own = water_model.lobe_draws(&model, &pairs);
                let foreign_gloss = water_model.lobe_draws(&other_gloss, &pairs);
                let foreign_model = other.lobe_draws(&model, &pairs);
                for (i, &u) in pairs.iter().enumerate() {
                    let want = bits(water_model.reflect(&point, &model, u));
                    assert_eq!(
                        bits(water_model.reflect_drawn(&point, &model, &own, i)),
                        want
                    );
                    assert_eq!(
                        bits(water_model.reflect_drawn(&point, &model, &foreign_gloss, i)),
                        want
                    );
                    assert_eq!(
                        bits(water_model.reflect_drawn(&point, &model, &foreign_model, i)),
                        want
                    );
                    compared += want.is_some() as usize;
                }
                // All of a point's samples at once: the same, in order, the rejected left out.
                let want: Vec<[u32; 4]> = pairs
                    .iter()
                    .filter_map(|&u| water_model.reflect(&point, &model, u))
                    .map(|s| pair_bits((s.wi, s.weight)))
                    .collect();
                let mut all = vec![(Vec3::ZERO, 0.0); 3];
                for draws in [&own, &foreign_gloss, &foreign_model] {
                    water_model.reflect_all_drawn(&point, &model, draws, &mut all);
                    assert_eq!(all.iter().copied().map(pair_bits).collect::<Vec<_>>(), want);
                }
            }
            // Seen from below the surface: nothing.
            let below = WaterPoint {
                start: Vec3::new(0.0, -2.0, -5.0),
                wo: Vec3::new(0.1, -0.2, 1.0).normalize(),
                normal: Vec3::Y,
                face: Vec3::Y,
                clear: 0.0,
            };
            let mut all = vec![(Vec3::ZERO, 0.0); 3];
            water_model.reflect_all_drawn(
                &below,
                &model,
                &water_model.lobe_draws(&model, &pairs),
                &mut all,
            );
            assert!(all.is_empty(), "{all:?}");
        }
        // Most pairs reflect something (the rest leave below the surface at grazing views).
        assert!(compared > 2000, "{compared} samples compared");
    }
}
