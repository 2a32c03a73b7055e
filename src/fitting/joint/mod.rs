//! Joint refinement of all lights by render and compare (method §5, last paragraph).
//!
//! The paper fits each streak alone from its edge pixels. Here every water pixel from which
//! a light can be seen counts, and all lights are fitted together: minimise
//!
//! ```text
//! S = sum_p sum_c (I_c(p) - sum_k L_k,c c_k(p; rect_k))^2
//! ```
//!
//! where a clipped pixel only counts when the model is below it (it is a lower bound,
//! method §2). The fitted region is the streaks, dilated, plus every pixel near them whose
//! reflected rays can reach a light's region of interest: a streak's faint ends fall below
//! any segmentation's threshold, and an edge seen only through them would otherwise drift
//! (`region`). Where a light itself is in the photo, the pixels outside the water that see
//! its wall are fitted too: their coefficient is the fraction of their camera rays that land
//! inside the rectangle, and the edges they cross pin it to a fraction of a pixel
//! (`direct`).
//!
//! Each pixel's coefficient is integrated over its footprint as the renderer does it (the
//! forward model is a [`WaterModel`], by default the exact surface the renderer uses):
//! stratified jittered camera rays, each with a stratified set of lobe samples, in two
//! independent halves whose difference measures the estimate's noise. The samples that land
//! on each light's plane inside its region of interest are traced ONCE (`samples`);
//! afterwards `c_k(p; rect)` for any rectangle is a sum over stored samples, so the
//! optimisation traces no ray. Each sample spreads its weight over a small kernel sized by its
//! lobe cell, so that a coefficient changes smoothly with the rectangle's edges (`kernel`).
//! The stored samples are common random numbers across all parameter values, so the cost is
//! a deterministic function of the rectangles, and the coefficients' own noise is removed
//! from it (`cost`).
//!
//! What noise is left is cut by a control variate (`control_variate`): per pixel a
//! Gaussian on the light's plane, matched to the pixel's lobe, whose mass inside a rectangle
//! is known in closed form. Each stored sample carries only its weight less the Gaussian's
//! (so an edge cutting through the samples moves the estimate by far less noise), and the
//! coefficient adds the Gaussian's exact mass back. The expectation is unchanged; on Table 3
//! the noise of a coefficient's derivative by an edge is about a fifth in variance of the
//! plain estimate's, and the fit's errors what 16 times the samples give without it
//! (BENCHMARKS.md).
//!
//! The model is linear in the radiances: given the rectangles they are a nonnegative least
//! squares solve per channel (`cost`). The edges are found by coordinate descent
//! (`descent`) where each 1D step evaluates the cost on a whole grid of edge positions in
//! one pass over the samples near it (`near`; prefix sums over binned samples: `ramps`,
//! `profile`; polynomials where the coefficients are smooth: `pieces`), with
//! that light's radiance re-optimised at every grid point, so a far-off start
//! (the paper's estimate can be metres off) is pulled in by a global 1D search rather than a
//! local step. The grid then shrinks around the best position until it is finer than a
//! millimetre. An edge that no pixel of the streak's edge looks at (outside the photo) is
//! held where the paper method put it.
//!
//! Overlapping streaks (two lights whose reflections merge into one region, the paper's
//! §5.3): where the lamps are in the photo, each lamp's direct image starts a light of its
//! own (`lamp_starts`). Otherwise, when the residual of a fit is structured along the image rows, each light is tried
//! as two (one above the other, or side by side: `split`), and the split is kept when it
//! removes most of that structure. The second light of a split then reads a sample set of
//! its own, drawn independently on the same plane, and the boundary between the two is
//! searched globally before the final descent (`boundary`; the sequence: `optimise`).
//!
//! Independent repeats are averaged (`repeats`); the uncertainties come from the curvature
//! of the cost the fit minimises (`uncertainty`).
//!
//! | file | what |
//! |---|---|
//! | `mod.rs` | [`fit_joint`] |
//! | `options` | what to fit with: samples, sweeps, pixels, splits, a test of the start |
//! | `outcome` | what a fit returns |
//! | `region` | the fitted pixels, each light's region of interest |
//! | `direct` | the pixels that see a light's wall directly, their samples |
//! | `direct_images` | a lamp's image in the photo: the bright pixels that see its wall |
//! | `direct_start` | starts far from a light's direct image moved onto it, fragments merged |
//! | `lamp_starts` | one start per lamp whose reflections share a streak with another's |
//! | `start_estimate` | the paper's estimate that starts a fit, with few samples where lamps pin it |
//! | `samples`, `trace` | the stored plane samples, a coefficient from them; their trace |
//! | `reweight` | a search's samples from one trace, weighted for each fit's lobe |
//! | `proposal` | the lobe that trace is drawn from, the targets it serves |
//! | `near` | the samples a moving edge can change, found by bisection |
//! | `kernel` | each sample's cell and kernel |
//! | `control_variate` | the lobe Gaussian |
//! | `problem` | the fitted pixels with their samples, a fit's state |
//! | `cost` | the cost, the coefficients' noise, the radiances' solve |
//! | `colour` | a clipped or crowded channel's radiance from the light's colour where it is alone |
//! | `ramps` | a coefficient at every grid position of one edge |
//! | `pieces` | a profile's sums as polynomials over runs of its grid |
//! | `profile` | the cost at every grid position of one edge |
//! | `descent` | coordinate descent and its windows |
//! | `optimise` | the start state; descent, split, boundary search, descent; repeats' replay |
//! | `split`, `boundary` | overlapping streaks: the cut, the boundary search |
//! | `significance` | lights the photo cannot tell from nothing, dropped |
//! | `repeats` | the mean of repeated fits and its standard error |
//! | `uncertainty` | uncertainties, facing edges, edge statuses |

use std::time::Instant;

use crate::fitting::light_plane::LightPlane;
use crate::fitting::rect::Rect;
use crate::fitting::{FittedLight, StreakObservation};
use crate::optics::ReflectionModel;
use crate::photo_in::Photo;
use crate::scene_in::Scene;
use crate::water_model::{ExactSurface, WaterModel};
use crate::{Error, Result};

mod boundary;
mod clipped;
mod colour;
mod control_variate;
mod cost;
mod dark_wall;
mod descent;
mod direct;
mod direct_images;
pub(crate) mod direct_start;
#[cfg(test)]
mod fixture;
mod glitter;
mod image_bound;
mod kernel;
mod lamp_starts;
mod near;
mod optimise;
mod options;
mod outcome;
mod pieces;
mod problem;
mod profile;
mod proposal;
mod ramps;
mod region;
mod repeats;
mod reweight;
mod samples;
mod significance;
mod split;
mod stacked;
mod start_estimate;
mod store;
mod trace;
mod uncertainty;

pub use options::{
    JointOptions, ModelledPixel, PixelShare, StartGate, DEFAULT_JOINT_SAMPLES, LARGE_PHOTO_PIXELS,
    MAX_JOINT_SAMPLES, THIN_MIN_WATER_PIXELS,
};
pub use outcome::JointOutcome;
pub use proposal::{Lobe, ProposalCache, Reweight, TARGET_OVER_PROPOSAL};
pub use samples::effective_samples;
pub use split::{Split, SplitWay};
pub use uncertainty::{edge_statuses, Uncertainty, VarianceParts};

use direct_start::enclosing_image;
pub use lamp_starts::place_starts;
use optimise::{optimise, start_state};
use problem::{Problem, State};
use region::{fit_pixels, region_of_interest, RegionAsk};
use repeats::mean_and_spread;
use samples::sample_extent;
pub use start_estimate::{start_estimate, PlacedStart, StartEstimate};
use uncertainty::uncertainties;

/// Refines `start` (typically the paper's per-streak estimate) by fitting all lights together
/// to every water pixel of their streaks and surroundings (see the module doc).
///
/// `streaks` must hold the streaks named by the lights' `streak_ids` (their pixels, dilated,
/// are the fitted region). The lights' planes are kept; edges and radiances are refitted.
/// The water is the scene's water mesh ([`ExactSurface`]; [`fit_joint_with`] takes another
/// model).
pub fn fit_joint(
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    start: &[FittedLight],
    options: &JointOptions,
) -> Result<JointOutcome> {
    fit_joint_with(&ExactSurface, scene, photo, water, streaks, start, options)
}

/// [`fit_joint`] with the water as `water_model` has it: the fitted region's probe rays, the
/// stored samples and the control variates ask it where each camera ray meets the water and
/// how its lobe leaves.
pub fn fit_joint_with(
    water_model: &dyn WaterModel,
    scene: &Scene,
    photo: &Photo,
    water: &[bool],
    streaks: &[StreakObservation],
    start: &[FittedLight],
    options: &JointOptions,
) -> Result<JointOutcome> {
    super::check_sizes(photo, water)?;
    let n_all = photo.width as usize * photo.height as usize;
    if options.samples == 0 {
        return Err(Error::Usage(
            "the joint fit needs at least one sample per pixel".into(),
        ));
    }
    if options.samples > MAX_JOINT_SAMPLES {
        return Err(Error::Usage(format!(
            "the joint fit takes at most {MAX_JOINT_SAMPLES} samples per pixel, not {}",
            options.samples
        )));
    }
    if options.repeats == 0 {
        return Err(Error::Usage(
            "the joint fit needs at least one repeat".into(),
        ));
    }
    if start.is_empty() {
        return Ok(JointOutcome::empty(options.pixels));
    }
    // The footprints' stage counts from here: placing the starts traces the lamps' images.
    let t0 = Instant::now();
    // Starts far from the lights' direct images are moved onto them, one light per lamp
    // (`place_starts`).
    let moved;
    let start = if options.direct_view && !options.starts_placed {
        moved = place_starts(scene, photo, water, streaks, start, options.progress);
        &moved[..]
    } else {
        start
    };
    let used: Vec<&StreakObservation> = streaks
        .iter()
        .filter(|s| start.iter().any(|l| l.streak_ids.contains(&s.id)))
        .collect();
    if let Some(s) = used
        .iter()
        .find(|s| s.pixels.iter().any(|&p| p as usize >= n_all))
    {
        return Err(Error::Usage(format!(
            "streak {} holds a pixel outside the {} x {} photo",
            s.id, photo.width, photo.height
        )));
    }
    let planes: Vec<&LightPlane> = start.iter().map(|l| &l.plane).collect();
    // A light on a lamp's whole direct image searches close around it where asked
    // (`region_of_interest`, `JointOptions::close_regions`); where every light is on one, a
    // fit that may thin its pixels does (`JointOptions::share_for`).
    let may_thin = options.share_for(true) != options.pixels;
    // A glitter-weighted fit reads them too (`weights_at_start` below).
    let given = (options.start_images.len() == start.len()).then_some(options.start_images);
    let images: Vec<Option<(Rect, f32)>> = start
        .iter()
        .enumerate()
        .map(|(k, light)| {
            (options.direct_view && (options.close_regions || may_thin || options.glitter_weights))
                .then(|| {
                    given.map_or_else(|| enclosing_image(scene, photo, water, light), |g| g[k])
                })
                .flatten()
        })
        .collect();
    let roi: Vec<Rect> = start
        .iter()
        .zip(&images)
        .map(|(light, &image)| region_of_interest(light, image.filter(|_| options.close_regions)))
        .collect();

    let probe_model = ReflectionModel {
        gloss: options.region_gloss.unwrap_or(options.model.gloss),
        ..options.model
    };
    let ask = RegionAsk {
        water_model: options.region_water.unwrap_or(water_model),
        model: &probe_model,
        planes: &planes,
        roi: &roi,
        streaks: &used,
        margin: options.margin,
        shares: (
            options.pixels,
            options.share_for(images.iter().all(Option::is_some)),
        ),
        direct_view: options.direct_view,
    };
    let (pixels, first_direct, share) = fit_pixels(
        scene,
        photo,
        water,
        &ask,
        options.reweight.map(|rw| &rw.cache.region),
    );
    let trace = |planes: &[&LightPlane], roi: &[Rect], repeat: u32, draw: u32| {
        let fit = proposal::FitSamples {
            water_model,
            scene,
            pixels: &pixels,
            size: (photo.width, photo.height),
            first_direct,
        };
        fit.samples(options, planes, roi, repeat, draw)
    };
    let problem_for = |repeat: u32| {
        let (stored, per_pixel_samples) = trace(&planes, &roi, repeat, 0);
        Problem {
            width: photo.width,
            pixel_ids: pixels.clone(),
            obs: pixels.iter().map(|&p| photo.radiance[p as usize]).collect(),
            clipped: pixels.iter().map(|&p| photo.clipped[p as usize]).collect(),
            clipped_channels: pixels
                .iter()
                .map(|&p| photo.clipped_channels(p as usize))
                .collect(),
            planes: stored,
            set_origin: (0..planes.len()).collect(),
            inv_samples: 1.0 / per_pixel_samples as f32,
            first_direct,
            encoding: (photo.rounding, photo.exposure),
            edges_by_image: options.edges_by_image,
        }
    };
    // Rows weighted from the start by a fit before over the same pixels (`row_scales`).
    let given_scales = options
        .row_scales
        .filter(|s| s.len() == pixels.len() && options.repeats == 1);
    // Glitter weights measured at the start rather than after an unweighted descent, where
    // the start is already within a fraction of a footprint of the optimum: every light
    // resumed where a search fit put it, or on its lamp's whole direct image (`glitter`).
    let resumed = options.resume.len() == start.len() && options.resume.iter().all(Option::is_some);
    let weights_at_start = options.glitter_weights
        && given_scales.is_none()
        && options.repeats == 1
        && (resumed || images.iter().all(Option::is_some));
    // The rows' scales in force, which a sample set traced later takes too.
    let scales_in_force: std::cell::OnceCell<Vec<f32>> = std::cell::OnceCell::new();
    // Seconds spent tracing the split lights' own sample sets (footprints, not optimisation).
    let fresh_seconds = std::cell::Cell::new(0.0);
    // The `draw`-th extra sample set of repeat `repeat`, on start light `origin`'s plane,
    // independent of every other set.
    let fresh_set = |repeat: u32, origin: usize, draw: u32| {
        let t = Instant::now();
        let (mut stored, _) = trace(&[planes[origin]], &[roi[origin]], repeat, draw);
        fresh_seconds.set(fresh_seconds.get() + t.elapsed().as_secs_f64());
        // One plane in, one set out, weighted as the others.
        let mut set = stored.swap_remove(0);
        if let Some(s) = scales_in_force.get() {
            glitter::scale_set(&mut set, s);
        }
        set
    };
    let stage = options
        .reweight
        .and_then(|rw| rw.kept_trace_stage(&pixels, &planes, &roi))
        .unwrap_or_else(|| {
            format!(
                "joint fit: tracing the footprints of {} pixels, {} samples each",
                pixels.len(),
                effective_samples(options.samples)
            )
        });
    options.progress.stage(&stage);
    let mut problem = problem_for(0);
    if let Some(s) = given_scales {
        glitter::scale_rows(&mut problem, s);
        let _ = scales_in_force.set(s.to_vec());
    }
    let mut footprint_seconds = t0.elapsed().as_secs_f64();
    let mut extents: Vec<Option<Rect>> = problem.planes.iter().map(sample_extent).collect();
    if let Some(gate) = options.start_gate {
        let mut st = start_state(&problem, start, &extents, options.held, options.resume);
        problem.solve_radiance(&mut st);
        let modelled = problem.water_image(&st, given_scales);
        if !(gate.0)(&modelled) {
            return Ok(JointOutcome {
                pixels: pixels.len(),
                timings: vec![("footprints".into(), footprint_seconds)],
                modelled,
                stopped_at_start: true,
                ..JointOutcome::empty(share)
            });
        }
    }
    let held = if options.held.len() == start.len() {
        options.held.iter().filter(|r| r.is_some()).count()
    } else {
        0
    };
    options.progress.stage(&if held == start.len() {
        format!(
            "joint fit: {held} light(s) held where their lamps' images pin them, radiances solved"
        )
    } else if held > 0 {
        format!(
            "joint fit: descent of {} light(s), {} sweeps ({held} more held where their \
             lamps' images pin them)",
            start.len() - held,
            options.sweeps
        )
    } else {
        format!(
            "joint fit: descent of {} light(s), {} sweeps",
            start.len(),
            options.sweeps
        )
    });
    if weights_at_start {
        let mut st = start_state(&problem, start, &extents, options.held, options.resume);
        problem.solve_radiance(&mut st);
        if let Some(s) = glitter::weigh(water_model, scene, &mut problem, &st, photo.height) {
            let _ = scales_in_force.set(s);
        }
    }
    let t1 = Instant::now();
    let (first, replay, splits) = optimise(
        &mut problem,
        start,
        &mut extents,
        options.sweeps,
        options.split,
        options.known_splits,
        options.end_at_split,
        &|origin, draw| fresh_set(0, origin, draw),
        options.progress,
        options.held,
        options.resume,
    );
    let mut optimise_seconds = t1.elapsed().as_secs_f64();
    if options.end_at_split && !splits.is_empty() {
        return Ok(JointOutcome {
            pixels: pixels.len(),
            timings: vec![
                ("footprints".into(), footprint_seconds),
                ("optimise".into(), optimise_seconds),
            ],
            splits,
            ended_at_split: true,
            ..JointOutcome::empty(share)
        });
    }
    let mut repeats = vec![(first.rects.clone(), first.radiance.clone())];
    for repeat in 1..options.repeats {
        options.progress.stage(&format!(
            "joint fit: repeat {} of {} (independent samples)",
            repeat + 1,
            options.repeats
        ));
        let t = Instant::now();
        let mut again = problem_for(repeat);
        footprint_seconds += t.elapsed().as_secs_f64();
        let t = Instant::now();
        let mut extents: Vec<Option<Rect>> = again.planes.iter().map(sample_extent).collect();
        let extra_origins = &problem.set_origin[start.len()..];
        let st = again.replay(
            &replay,
            extra_origins,
            &mut extents,
            options.sweeps,
            &|origin, draw| fresh_set(repeat, origin, draw),
        );
        repeats.push((st.rects, st.radiance));
        optimise_seconds += t.elapsed().as_secs_f64();
    }
    footprint_seconds += fresh_seconds.get();
    optimise_seconds -= fresh_seconds.get();
    let t2 = Instant::now();
    let (mut st, spread) = if repeats.len() == 1 {
        // One fit: the curvature alone (see `uncertainties`). With the control variate it
        // covers the errors (8 seeds through the pipeline: Table 3 0.5-1.3 sigma rms, largest
        // 2.1; the stacked sample 0.3-1.2, largest 1.8); adding the spread of two refits, one
        // from each half of the samples, would cost 0.7 s of Table 3's fit and only widen the
        // sigmas further (docs/decisions.md, "A control variate for the joint fit's coefficients").
        (first, None)
    } else {
        let (rects, radiance, spread) = mean_and_spread(&repeats);
        let st = problem.state(
            first.set_of.clone(),
            first.pinned.clone(),
            rects,
            radiance.clone(),
        );
        // The mean's radiances, not the ones the first fit's samples would give its edges.
        (State { radiance, ..st }, Some(spread))
    };
    let mut spread = spread;
    // Weighted by the glitter's noise where asked (`glitter`) and not weighted from the
    // start: the first fit's residual gives the noise model, and the fit is descended again
    // over the weighted rows.
    let mut scales: Option<Vec<f32>> = scales_in_force.get().cloned();
    if options.glitter_weights && !weights_at_start && scales.is_none() && repeats.len() == 1 {
        if let Some(s) = glitter::weigh(water_model, scene, &mut problem, &st, photo.height) {
            st = problem.state(
                st.set_of.clone(),
                st.pinned.clone(),
                st.rects.clone(),
                st.radiance.clone(),
            );
            problem.solve_radiance(&mut st);
            // Every light lies at the unweighted fit's optimum, within a fraction of a
            // footprint of the weighted one where its image pins it.
            let near = vec![true; st.rects.len()];
            problem.descend_near(&mut st, &extents, options.sweeps, &near);
            scales = Some(s);
        }
    }
    let mut uncertainty = finish(&problem, &mut st, &extents, spread.as_deref());
    // Lights the photo cannot tell from nothing (`significance`), or, where asked, from a
    // light of their colour in their column (`stacked`), are dropped, the others fitted
    // again without them.
    let mut dropped = significance::insignificant(&problem, &st, &uncertainty);
    if options.stacked_as_one {
        let skip: Vec<usize> = dropped.iter().map(|d| d.0).collect();
        dropped.extend(stacked::stacked(&problem, &st, start, &skip));
        dropped.sort_by_key(|d| d.0);
    }
    let mut warnings = Vec::new();
    if !dropped.is_empty() {
        for (k, why) in dropped.iter().rev() {
            let (r, l) = (st.rects[*k], st.radiance[*k]);
            let origin = &start[problem.set_origin[st.set_of[*k]]];
            warnings.push(format!(
                "a light of streak(s) {:?} ({:.2} x {:.2} m, radiance {:.3}, {:.3}, {:.3}) \
                 was dropped: {why}",
                origin.streak_ids,
                r.width(),
                r.height(),
                l[0],
                l[1],
                l[2]
            ));
            significance::remove(&mut st, *k);
            if let Some(s) = spread.as_mut() {
                s.remove(*k);
            }
        }
        warnings.reverse();
        options.progress.stage(&format!(
            "joint fit: descent of {} light(s) after dropping {} the photo cannot tell from \
             nothing or from another light",
            st.rects.len(),
            dropped.len()
        ));
        problem.solve_radiance(&mut st);
        problem.descend(&mut st, &extents, options.sweeps);
        uncertainty = finish(&problem, &mut st, &extents, spread.as_deref());
    }
    let cost = problem.cost(&st);
    let variance = problem.residual_variance(&st);
    optimise_seconds += t2.elapsed().as_secs_f64();
    let modelled = problem.water_image(&st, scales.as_deref());
    let seen_whole = outcome::seen_whole(&problem, &st, &uncertainty, start.len());
    for (k, u) in uncertainty.iter_mut().enumerate() {
        u.direct_pixels = problem.direct_pixels_inside(st.set_of[k], &st.rects[k]);
        u.radiance_seen = problem.sees_radiance(st.set_of[k], &st.rects[k], st.radiance[k]);
    }
    let lights = outcome::fitted_lights(&problem, &st, start);
    Ok(JointOutcome {
        lights,
        uncertainty,
        pixels: pixels.len(),
        share,
        residual_variance: variance,
        cost,
        timings: vec![
            ("footprints".into(), footprint_seconds),
            ("optimise".into(), optimise_seconds),
        ],
        modelled,
        warnings,
        splits,
        row_scales: scales,
        stopped_at_start: false,
        ended_at_split: false,
        seen_whole,
    })
}

/// The last steps of a fit: the channels a light clips, or other lights crowd, from its colour
/// in the pixels it lights alone (`colour`), then the uncertainties, the repeats' `spread` (one per light, where there
/// are several repeats) added to the curvature's.
fn finish(
    problem: &Problem,
    st: &mut State,
    extents: &[Option<Rect>],
    spread: Option<&[([f32; 4], [f32; 3])]>,
) -> Vec<Uncertainty> {
    let colours = colour::colour_from_own_pixels(problem, st);
    let mut uncertainty = uncertainties(problem, st, extents, &colours);
    for (u, (edges, radiance)) in uncertainty.iter_mut().zip(spread.into_iter().flatten()) {
        let spread = [
            edges[0],
            edges[1],
            edges[2],
            edges[3],
            radiance[0],
            radiance[1],
            radiance[2],
        ];
        u.add_other(spread.map(|sd| (sd as f64).powi(2)));
    }
    uncertainty
}
