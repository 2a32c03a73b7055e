//! Fitting one streak: plane, footprints, then radiance and edges alternated until they agree.

use std::time::Instant;

use super::edges::{assign, combine, solve_edge, EdgeEstimate};
use super::footprint::{footprints, Footprint};
use super::light_plane::{find_plane, PlaneSearch};
use super::observation::{neighbour, StreakObservation, StreakSide};
use super::radiance::{bright_pixels, fit_radiance, observed_coefficient, RADIANCE_PIXELS};
use super::rect::Rect;
use super::{EdgeSide, EdgeStatus, FitOptions, FittedLight, Skipped};
use crate::photo_in::Photo;
use crate::scene_in::Scene;
use crate::water_model::WaterModel;

/// Seconds spent per stage, summed over streaks.
#[derive(Clone, Copy, Debug, Default)]
pub struct StageTimes {
    /// Finding light planes.
    pub plane: f64,
    /// Tracing footprints.
    pub footprints: f64,
    /// Radiance and edge iterations.
    pub solve: f64,
}

/// At most this many radiance/edge alternations; they usually settle in 5-10 (pixels switching
/// edges can leave a cycle of a millimetre or so, which this cuts short).
const MAX_ITERATIONS: usize = 25;
/// Stop when no edge moved by more than this fraction of the rectangle's size.
const TOLERANCE: f32 = 5e-4;
/// Half the smallest side of a first rectangle, as a share of the light's distance.
const MIN_START_SHARE: f32 = 1e-4;
/// Fewer valid edge pixels than this leave an edge unconstrained.
const MIN_EDGE_PIXELS: usize = 3;
/// An edge is flagged unconstrained when more than this fraction of its pixels sit where the
/// streak is cut by the photo's border or the water's end (a stray pixel touching the border
/// does not count): the pixels left may not reach the light's real edge.
const MAX_TRUNCATED_FRACTION: f32 = 0.1;

/// A streak-edge pixel and its footprint.
struct EdgePixel {
    footprint: usize,
    /// The streak continues past the photo's border or the water's end here: the pixel is
    /// not on the streak's real edge.
    truncated: bool,
    /// Whether it is an edge pixel of each side of the streak (indexed by [`StreakSide`]).
    sides: [bool; 4],
}

/// Fits the light of one streak, the water as `water_model` has it.
pub fn fit_streak(
    water_model: &dyn WaterModel,
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    obs: &StreakObservation,
    options: &FitOptions,
    times: &mut StageTimes,
) -> Result<FittedLight, Skipped> {
    let (w, h) = (photo.width, photo.height);
    let t = Instant::now();
    let search = find_plane(
        water_model,
        scene,
        &options.model,
        obs.brightest,
        w,
        h,
        options.samples,
        options.seed,
    );
    times.plane += t.elapsed().as_secs_f64();
    let plane =
        match search {
            PlaneSearch::Found(p) => p,
            PlaneSearch::Nothing { rays, water_hits } => {
                let (x, y) = (obs.brightest % w, obs.brightest / w);
                return Err(Skipped::NoPlane {
                    streak: obs.id,
                    message: format!(
                    "streak {} (brightest pixel x {x}, y {y}): none of the {rays} reflected rays \
                     hit anything but {}; add the geometry the light hangs on (a wall, facade \
                     or pole) to the scene",
                    obs.id,
                    if water_hits > 0 { "the water" } else { "the sky" }
                ),
                });
            }
        };

    // Pixels to trace: every streak-edge pixel and the brightest interior ones.
    let mut edge_pixels: Vec<(u32, bool, [bool; 4])> = Vec::new();
    for side in StreakSide::ALL {
        for &p in &obs.edges[side] {
            if p as usize >= photo.clipped.len() || photo.clipped[p as usize] {
                continue;
            }
            let truncated = side.outward_neighbours().iter().any(|&(dx, dy)| {
                neighbour(p, dx, dy, w, h)
                    .is_none_or(|q| !water.get(q as usize).copied().unwrap_or(false))
            });
            let mut sides = [false; 4];
            sides[side] = true;
            edge_pixels.push((p, truncated, sides));
        }
    }
    edge_pixels.sort_unstable_by_key(|e| e.0);
    // A pixel on two sides (a corner) is traced once; it is truncated if either side is.
    edge_pixels.dedup_by(|b, a| {
        if a.0 == b.0 {
            a.1 |= b.1;
            for side in StreakSide::ALL {
                a.2[side] |= b.2[side];
            }
            true
        } else {
            false
        }
    });
    let bright = bright_pixels(obs, photo, water, RADIANCE_PIXELS);
    if bright.is_empty() {
        return Err(Skipped::NoSolution {
            streak: obs.id,
            message: format!(
                "streak {}: no 3 x 3 block of unclipped water pixels inside it (too thin, or \
                 clipped: lower the exposure)",
                obs.id
            ),
        });
    }
    // Edge pixels are fitted by the mean of their 3 x 3 box where it is all usable water: a
    // streak's edge pixels are selected by their own noisy values (above the extraction's
    // threshold, their outward neighbours below it), and the box mixes both, so the selection
    // bias mostly cancels (on Table 1, single pixels put every edge 1-5 cm too far out).
    let usable = |q: u32| water[q as usize] && !photo.clipped[q as usize];
    let box_radius = |p: u32| {
        let inside =
            (-1..=1).all(|dy| (-1..=1).all(|dx| neighbour(p, dx, dy, w, h).is_some_and(usable)));
        u32::from(inside)
    };
    let mut traced: Vec<(u32, u32)> = edge_pixels
        .iter()
        .map(|e| (e.0, box_radius(e.0)))
        .chain(bright.iter().map(|&p| (p, 1)))
        .collect();
    traced.sort_unstable();
    traced.dedup();
    let t = Instant::now();
    let fps = footprints(
        water_model,
        scene,
        &options.model,
        &plane,
        &traced,
        w,
        h,
        options.samples,
        options.seed,
    );
    times.footprints += t.elapsed().as_secs_f64();
    let t = Instant::now();
    let index_of = |p: (u32, u32)| traced.binary_search(&p).ok();
    let edges: Vec<EdgePixel> = edge_pixels
        .iter()
        .filter_map(|&(p, truncated, sides)| {
            index_of((p, box_radius(p))).map(|footprint| EdgePixel {
                footprint,
                truncated,
                sides,
            })
        })
        .collect();
    let bright_fps: Vec<&Footprint> = bright
        .iter()
        .filter_map(|&p| index_of((p, 1)))
        .map(|i| &fps[i])
        .collect();

    let scale = plane.camera_distance();
    let result = solve(photo, obs, &fps, &edges, &bright_fps, scale, true).and_then(|fit| {
        if plausible(&fit) {
            Ok(fit)
        } else {
            // With a model that does not match the photo (a wrong gloss, say) updating L from
            // the current rectangle can run away: a smaller rectangle needs a brighter light,
            // which makes the edges move in further. The paper's way, L from the brightest
            // pixels with the whole plane lit and held, always settles.
            solve(photo, obs, &fps, &edges, &bright_fps, scale, false)
        }
    });
    times.solve += t.elapsed().as_secs_f64();
    let Solution {
        rect,
        radiance,
        status: edge_status,
        ..
    } = result?;
    Ok(FittedLight {
        streak_ids: vec![obs.id],
        plane,
        u_min: rect.u_min,
        u_max: rect.u_max,
        v_min: rect.v_min,
        v_max: rect.v_max,
        radiance,
        edges: edge_status,
    })
}

/// What the alternation settled on.
struct Solution {
    rect: Rect,
    radiance: [f32; 3],
    status: [EdgeStatus; 4],
    /// The paper's estimate: the brightest pixels with the whole plane lit.
    initial_radiance: [f32; 3],
    converged: bool,
}

/// Alternates radiance and edges from an initial rectangle until they agree. `scale` is the
/// light's distance from the camera ([`super::LightPlane::camera_distance`]), which the
/// smallest lengths are shares of.
#[allow(clippy::too_many_arguments)]
fn solve(
    photo: &Photo,
    obs: &StreakObservation,
    fps: &[Footprint],
    edges: &[EdgePixel],
    bright: &[&Footprint],
    scale: f32,
    update_radiance: bool,
) -> Result<Solution, Skipped> {
    let no_solution = |what: &str| Skipped::NoSolution {
        streak: obs.id,
        message: format!("streak {}: {what}", obs.id),
    };
    let mut rect = initial_rect(fps, edges, scale)
        .ok_or_else(|| no_solution("no edge pixel's reflected rays reach the light's plane"))?;
    let initial_radiance = fit_radiance(photo, bright, None).ok_or_else(|| {
        no_solution("the brightest pixels' reflected rays miss the light's plane")
    })?;
    let mut radiance = initial_radiance;
    let far = far_extent(fps);
    let mut last_fitted = [true; 4];
    let mut converged = false;
    let mut status: [EdgeStatus; 4] =
        std::array::from_fn(|_| EdgeStatus::Constrained { pixels: 0 });
    for _ in 0..MAX_ITERATIONS {
        let before = rect;
        // Who constrains what is decided once per pass, against the rectangle the pass
        // starts from.
        let mut assigned: [Vec<&EdgePixel>; 4] = Default::default();
        // Edges with enough valid pixels to fit, even when flagged unconstrained.
        let mut fitted = [false; 4];
        for e in edges {
            if let Some(side) = assign(&fps[e.footprint], &rect) {
                assigned[side].push(e);
            }
        }
        for side in EdgeSide::ALL {
            let pixels = &assigned[side];
            let truncated = pixels.iter().filter(|e| e.truncated).count();
            let valid = pixels.len() - truncated;
            status[side] = if valid < MIN_EDGE_PIXELS {
                EdgeStatus::Unconstrained {
                    reason: format!(
                        "only {valid} streak-edge pixels constrain the light's {} edge",
                        side.name()
                    ),
                    pixels: valid,
                    unseen: valid == 0,
                }
            } else if truncated as f32 > MAX_TRUNCATED_FRACTION * pixels.len() as f32 {
                EdgeStatus::Unconstrained {
                    reason: format!(
                        "the streak is cut by the photo's border or the water's end on the side \
                         of the light's {} edge ({truncated} of {} pixels); fitted from the other \
                         {valid}, which may not show the real edge",
                        side.name(),
                        pixels.len()
                    ),
                    pixels: valid,
                    unseen: false,
                }
            } else {
                EdgeStatus::Constrained { pixels: valid }
            };
            fitted[side] = valid >= MIN_EDGE_PIXELS;
        }
        // An edge no valid pixel constrains is placed as far as any traced pixel can see, so
        // that it does not cut the other pixels' lobes short. `rect` keeps the last estimate,
        // against which pixels are assigned, so that such an edge can still collect pixels.
        let modelled = |rect: &Rect, fitted: &[bool; 4]| {
            EdgeSide::ALL.iter().fold(*rect, |r, &s| {
                if fitted[s] {
                    r
                } else {
                    r.with_edge(s, far.edge(s))
                }
            })
        };
        for side in EdgeSide::ALL {
            if !fitted[side] {
                continue;
            }
            let model = modelled(&rect, &fitted);
            let estimates: Vec<EdgeEstimate> = assigned[side]
                .iter()
                // Pixels where the streak is cut are not on its edge: solving them as edge
                // pixels pulls the edge in (tried: light1 of Table 3 came out 0.6 m short).
                .filter(|e| !e.truncated)
                .filter_map(|e| {
                    let fp = &fps[e.footprint];
                    let coef = observed_coefficient(fp.observed(photo), radiance)?;
                    solve_edge(fp, &model, side, coef, MIN_START_SHARE * scale)
                })
                .collect();
            if let Some(x) = combine(&estimates) {
                let candidate = rect.with_edge(side, x);
                if candidate.width() > 0.0 && candidate.height() > 0.0 {
                    rect = candidate;
                }
            }
        }
        if update_radiance {
            if let Some(l) = fit_radiance(photo, bright, Some(&modelled(&rect, &fitted))) {
                radiance = l;
            }
        }
        last_fitted = fitted;
        let size = rect.width().max(rect.height());
        let moved = EdgeSide::ALL
            .iter()
            .map(|&s| (rect.edge(s) - before.edge(s)).abs())
            .fold(0.0f32, f32::max);
        if moved <= TOLERANCE * size {
            converged = true;
            break;
        }
    }
    let model = EdgeSide::ALL.iter().fold(rect, |r, &s| {
        if last_fitted[s] {
            r
        } else {
            r.with_edge(s, far.edge(s))
        }
    });
    Ok(Solution {
        rect: model,
        radiance,
        status,
        initial_radiance,
        converged,
    })
}

/// False for a fit that ran away: a rectangle squeezed to almost nothing, or a radiance many
/// times the whole-plane estimate (which is a lower bound: the whole plane lit is the most a
/// pixel can see).
fn plausible(fit: &Solution) -> bool {
    let peak = |l: [f32; 3]| l.iter().copied().fold(0.0f32, f32::max);
    let size = fit.rect.width().min(fit.rect.height());
    fit.converged
        && size > 1e-3 * fit.rect.width().max(fit.rect.height())
        && peak(fit.radiance) < 5.0 * peak(fit.initial_radiance)
}

/// A first rectangle, larger than the light: each edge at a far percentile of where the edge
/// pixels of the streak side showing it have their lobes centred, with the paper's mapping of
/// streak sides to light edges ([`EdgeSide::streak_side`]: the reflection's flip puts the
/// light's bottom edge on the streak's top side). Edge pixels are dim, so their lobes are
/// centred outside the light: the first pass sees every real edge pixel outside the rectangle,
/// where the per-pixel assignment needs it.
fn initial_rect(fps: &[Footprint], edges: &[EdgePixel], scale: f32) -> Option<Rect> {
    let pct = |mut xs: Vec<f32>, q: f32| -> Option<f32> {
        if xs.is_empty() {
            return None;
        }
        xs.sort_by(f32::total_cmp);
        Some(xs[((xs.len() - 1) as f32 * q).round() as usize])
    };
    let all: Vec<glam::Vec2> = edges
        .iter()
        .filter_map(|e| fps[e.footprint].centroid())
        .collect();
    // From the side's pixels, or from every edge pixel (a nearer percentile) when the side
    // has none.
    let edge = |side: EdgeSide| -> Option<f32> {
        let along = |c: glam::Vec2| if side.along_u() { c.x } else { c.y };
        let (q_side, q_all) = if side.is_min() {
            (0.1, 0.03)
        } else {
            (0.9, 0.97)
        };
        let shown: Vec<f32> = edges
            .iter()
            .filter(|e| e.sides[side.streak_side()])
            .filter_map(|e| fps[e.footprint].centroid())
            .map(along)
            .collect();
        pct(shown, q_side).or_else(|| pct(all.iter().copied().map(along).collect(), q_all))
    };
    let mut r = Rect {
        u_min: edge(EdgeSide::Left)?,
        u_max: edge(EdgeSide::Right)?,
        v_min: edge(EdgeSide::Bottom)?,
        v_max: edge(EdgeSide::Top)?,
    };
    if r.u_min > r.u_max {
        (r.u_min, r.u_max) = (r.u_max, r.u_min);
    }
    if r.v_min > r.v_max {
        (r.v_min, r.v_max) = (r.v_max, r.v_min);
    }
    // A streak of one column still needs a rectangle with area to start from: a millimetre
    // at ten metres.
    let min_size = MIN_START_SHARE * scale;
    if r.width() < min_size {
        let c = r.center().x;
        (r.u_min, r.u_max) = (c - min_size, c + min_size);
    }
    if r.height() < min_size {
        let c = r.center().y;
        (r.v_min, r.v_max) = (c - min_size, c + min_size);
    }
    Some(r)
}

/// The box of every sample landing point: as far as the traced pixels can see.
fn far_extent(fps: &[Footprint]) -> Rect {
    let mut r = Rect {
        u_min: f32::INFINITY,
        u_max: f32::NEG_INFINITY,
        v_min: f32::INFINITY,
        v_max: f32::NEG_INFINITY,
    };
    for p in fps.iter().flat_map(|f| &f.points) {
        r.u_min = r.u_min.min(p.x);
        r.u_max = r.u_max.max(p.x);
        r.v_min = r.v_min.min(p.y);
        r.v_max = r.v_max.max(p.y);
    }
    r
}
