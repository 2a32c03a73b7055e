//! The warning a report gives about a light the photo does not pin down: one with edges the
//! photo does not constrain, or with a large uncertainty.

use super::{EdgeReport, LightReport};

/// An uncertainty is large above this fraction: an edge's one-sigma uncertainty against the
/// light's size across that edge (its width for the left and right edges, its height for the
/// bottom and top), the radiance's against the light's brightest channel. 5 % is about ten
/// times the joint fit's typical sigma on the samples (BENCHMARKS.md, spread) and the size of
/// the paper's own radiance error (docs/method.md §6).
pub const LARGE_UNCERTAINTY: f64 = 0.05;

/// The warning about `light`: none when every edge is constrained and every uncertainty is
/// small; else one sentence naming the unconstrained edges and the large uncertainties.
pub fn light_warnings(light: &LightReport) -> Option<String> {
    let edges: [(&str, &EdgeReport, f64); 4] = [
        ("left", &light.edges.left, light.width),
        ("right", &light.edges.right, light.width),
        ("bottom", &light.edges.bottom, light.height),
        ("top", &light.edges.top, light.height),
    ];
    let unconstrained: Vec<&str> = edges
        .iter()
        .filter(|(_, e, _)| e.status != "constrained")
        .map(|(name, _, _)| *name)
        .collect();
    let mut large = Vec::new();
    if let Some(u) = &light.uncertainty {
        let sigmas = [u.left, u.right, u.bottom, u.top];
        for ((name, _, size), sigma) in edges.iter().zip(sigmas) {
            if let Some(s) = sigma.filter(|s| *s > LARGE_UNCERTAINTY * size) {
                large.push(format!(
                    "{name} edge +-{s:.3} m ({:.1} % of its {} {size:.3} m)",
                    100.0 * s / size,
                    if matches!(*name, "left" | "right") {
                        "width"
                    } else {
                        "height"
                    }
                ));
            }
        }
        let brightest = light.radiance.iter().cloned().fold(0.0, f64::max);
        let worst = u.radiance.iter().cloned().fold(0.0, f64::max);
        if brightest > 0.0 && worst > LARGE_UNCERTAINTY * brightest {
            // A light the photo shows, but not whole and unclipped in any channel: its
            // radiance comes from its reflections alone, which one photo's waves move by
            // several percent; its own image could give it.
            let advice = if light.radiance_seen == Some(false)
                && light.direct_pixels.is_some_and(|n| n > 0)
            {
                " (only its reflections give it: its image is clipped in every channel or cut \
                 by the frame; a shorter exposure, or a frame that holds the whole lamp, lets \
                 its image give it)"
            } else {
                ""
            };
            large.push(format!(
                "radiance +-{worst:.3} ({:.1} % of {brightest:.3}){advice}",
                100.0 * worst / brightest
            ));
        }
    }
    if unconstrained.is_empty() && large.is_empty() {
        return None;
    }
    let mut parts = Vec::new();
    if !unconstrained.is_empty() {
        parts.push(format!(
            "its {} edge{} {} not constrained by the photo, so the light's {} there {} a guess \
             (the report's edges say why)",
            unconstrained.join(", "),
            if unconstrained.len() > 1 { "s" } else { "" },
            if unconstrained.len() > 1 { "are" } else { "is" },
            match (
                unconstrained.iter().any(|e| matches!(*e, "left" | "right")),
                unconstrained.iter().any(|e| matches!(*e, "bottom" | "top")),
            ) {
                (true, true) => "size",
                (true, false) => "width",
                _ => "height",
            },
            "is"
        ));
    }
    if !large.is_empty() {
        parts.push(format!(
            "large uncertainty (one sigma above {:.0} %): {}",
            100.0 * LARGE_UNCERTAINTY,
            large.join(", ")
        ));
    }
    Some(format!("{}: {}", light.name, parts.join("; ")))
}
