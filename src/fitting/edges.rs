//! method §5 step 9 (paper §4.3.2): one edge of the rectangle from the streak's edge pixels.
//!
//! A streak-edge pixel shows the coefficient `coef = I(p) / L`. Moving one edge of the
//! rectangle (the other three held) changes `c(p; rect)` monotonically, so the edge position
//! where `c(p; rect) = coef` is found by walking the pixel's footprint samples sorted along that
//! axis. The edge is a weighted mean of the pixels' solutions (the paper's eq. 11 takes the
//! plain mean; see [`combine`]).

use glam::Vec2;

use super::footprint::Footprint;
use super::rect::Rect;
use super::EdgeSide;

/// One pixel's solution for one edge.
#[derive(Clone, Copy, Debug)]
pub struct EdgeEstimate {
    /// Edge position in plane coordinates.
    pub position: f32,
    /// Inverse-variance weight (see [`solve_edge`]).
    pub weight: f32,
}

/// Which light edge the pixel's footprint constrains: the edge beyond which its lobe's centre
/// lands, measured in units of the rectangle's half sizes (so a long light does not claim every
/// pixel for its short sides). The paper maps streak sides to light sides once and for all
/// ([`EdgeSide::streak_side`], which the first rectangle still uses); with waves a streak's top pixel can look past a light's side edge, so this decides per
/// pixel. A dim pixel centred inside the rectangle goes to the nearest edge: it says that
/// edge is too far out (an initial rectangle that is too large must be able to shrink). `None`
/// for a footprint with no sample on the plane.
pub fn assign(fp: &Footprint, rect: &Rect) -> Option<EdgeSide> {
    let c = fp.centroid()?;
    let centre = rect.center();
    let half = Vec2::new(rect.width(), rect.height()).max(Vec2::splat(1e-6)) * 0.5;
    let d = (c - centre) / half;
    Some(if d.x.abs() >= d.y.abs() {
        if d.x < 0.0 {
            EdgeSide::Left
        } else {
            EdgeSide::Right
        }
    } else if d.y < 0.0 {
        EdgeSide::Bottom
    } else {
        EdgeSide::Top
    })
}

/// Solves `c(p; rect with edge side moved to x) = coef` for x; `min_band` is the narrowest
/// half-width over which the slope there is measured (a share of the light's distance, for
/// a rectangle too small to give one).
///
/// Samples outside the three held edges never count; of the rest, those on the inner side of
/// x do. Walking them from the far (inner) side, the cumulative weight crosses `coef` between
/// two samples, and x is interpolated between their coordinates. Returns `None` when `coef` is
/// not positive or exceeds what the pixel can see with the edge pushed out to infinity.
///
/// The weight is `slope^2 / coef`, with `slope = |dc/dx|` at the solution: the photo's Monte
/// Carlo and quantisation noise and the footprint's own noise all have a variance roughly
/// proportional to `c`, so `coef / slope^2` is the variance of x up to a common factor.
pub fn solve_edge(
    fp: &Footprint,
    rect: &Rect,
    side: EdgeSide,
    coef: f32,
    min_band: f32,
) -> Option<EdgeEstimate> {
    if coef.is_nan() || coef <= 0.0 {
        return None;
    }
    // q grows towards the inside of the rectangle for this edge, so "inside" is q >= x'.
    let (sign, along_u) = match side {
        EdgeSide::Left => (1.0f32, true),
        EdgeSide::Right => (-1.0, true),
        EdgeSide::Bottom => (1.0, false),
        EdgeSide::Top => (-1.0, false),
    };
    let held = rect.with_edge(
        side,
        if sign > 0.0 {
            f32::NEG_INFINITY
        } else {
            f32::INFINITY
        },
    );
    let mut relevant: Vec<(f32, f32)> = fp
        .points
        .iter()
        .zip(&fp.weights)
        .filter(|(p, _)| held.contains(**p))
        .map(|(p, &w)| (sign * if along_u { p.x } else { p.y }, w))
        .collect();
    relevant.sort_by(|a, b| b.0.total_cmp(&a.0));
    let n = fp.samples.max(1) as f32;
    let target = coef * n;
    let mut cum = 0.0f32;
    let mut prev_q = relevant.first()?.0;
    let mut solution = None;
    for &(q, w) in &relevant {
        if cum + w >= target {
            let t = if w > 0.0 { (target - cum) / w } else { 1.0 };
            solution = Some(prev_q + (q - prev_q) * t);
            break;
        }
        cum += w;
        prev_q = q;
    }
    let x = solution?;
    // Slope from the samples within delta of the solution: the weight per unit length there.
    let size = if along_u { rect.width() } else { rect.height() };
    let delta = (0.05 * size).max(min_band);
    let band: f32 = relevant
        .iter()
        .filter(|(q, _)| (q - x).abs() <= delta)
        .map(|(_, w)| w)
        .sum();
    let slope = band / n / (2.0 * delta);
    Some(EdgeEstimate {
        position: sign * x,
        weight: slope * slope / coef,
    })
}

/// Combines the pixels' solutions for one edge: solutions further than four (weighted) median
/// absolute deviations from the weighted median are dropped (a pixel assigned to the wrong
/// edge, or lit by something else), the rest averaged with their weights. `None` when nothing
/// is left.
pub fn combine(estimates: &[EdgeEstimate]) -> Option<f32> {
    let usable: Vec<EdgeEstimate> = estimates
        .iter()
        .copied()
        .filter(|e| e.position.is_finite() && e.weight.is_finite() && e.weight > 0.0)
        .collect();
    let median = weighted_median(usable.iter().map(|e| (e.position, e.weight)))?;
    let mad = weighted_median(
        usable
            .iter()
            .map(|e| ((e.position - median).abs(), e.weight)),
    )?;
    // All but a few solutions equal (a MAD of 0): keep those within rounding of the median.
    let limit = 4.0 * mad.max(f32::EPSILON * median.abs());
    let (sum, wsum) = usable
        .iter()
        .filter(|e| (e.position - median).abs() <= limit)
        .fold((0f64, 0f64), |(s, ws), e| {
            (
                s + e.position as f64 * e.weight as f64,
                ws + e.weight as f64,
            )
        });
    (wsum > 0.0).then(|| (sum / wsum) as f32)
}

fn weighted_median(items: impl Iterator<Item = (f32, f32)>) -> Option<f32> {
    let mut v: Vec<(f32, f32)> = items.collect();
    if v.is_empty() {
        return None;
    }
    v.sort_by(|a, b| a.0.total_cmp(&b.0));
    let total: f32 = v.iter().map(|x| x.1).sum();
    let mut acc = 0.0;
    for &(x, w) in &v {
        acc += w;
        if acc >= 0.5 * total {
            return Some(x);
        }
    }
    v.last().map(|x| x.0)
}
