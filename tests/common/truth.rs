//! A fitted light against the sample light it stands for.

use streaklight::report::LightReport;
use streaklight::samples::SampleLight;

/// How a radiance channel's error is measured.
#[derive(Clone, Copy)]
pub enum RadianceBar {
    /// As a fraction of the truth's own value in that channel.
    OfChannel(f64),
    /// As a fraction of the truth's largest channel.
    OfPeak(f64),
}

/// The fitted light of `lights` whose centre is nearest `truth`'s.
pub fn nearest<'a>(lights: &'a [LightReport], truth: &SampleLight) -> &'a LightReport {
    let c = truth.center();
    let dist = |l: &LightReport| {
        let x = l.corner_left_bottom[0] + l.width / 2.0 - c.x;
        let y = l.corner_left_bottom[1] + l.height / 2.0 - c.y;
        x * x + y * y
    };
    lights
        .iter()
        .min_by(|a, b| dist(a).total_cmp(&dist(b)))
        .expect("a light")
}

/// Asserts every edge of `light` within `edge_bar` of `truth`'s size along its axis, and every
/// radiance channel within `radiance_bar`; prints the errors (`label` names the case).
pub fn assert_light_within(
    label: &str,
    light: &LightReport,
    truth: &SampleLight,
    edge_bar: f64,
    radiance_bar: RadianceBar,
) {
    let edges = truth.edge_errors(light.corner_left_bottom, light.width, light.height);
    eprintln!(
        "{label} {}: edges {edges:?} radiance {:?}",
        truth.name, light.radiance
    );
    assert!(
        edges.iter().all(|e| e.abs() < edge_bar),
        "{label} {}: edges {edges:?}",
        truth.name
    );
    let peak = truth.radiance.iter().cloned().fold(0.0, f64::max);
    for ch in 0..3 {
        let want = truth.radiance[ch];
        let bar = match radiance_bar {
            RadianceBar::OfChannel(f) => f * want,
            RadianceBar::OfPeak(f) => f * peak,
        };
        assert!(
            (light.radiance[ch] - want).abs() < bar,
            "{label} {} channel {ch}: {} against {want}",
            truth.name,
            light.radiance[ch]
        );
    }
}

/// Asserts every error of `light` the report gives a sigma for (its constrained edges and
/// every radiance channel) within `bound` of those sigmas.
pub fn assert_within_sigmas(light: &LightReport, truth: &SampleLight, bound: f64) {
    let u = light
        .uncertainty
        .as_ref()
        .unwrap_or_else(|| panic!("{}: no uncertainties", truth.name));
    let edges = truth.edge_errors(light.corner_left_bottom, light.width, light.height);
    let sizes = [truth.width, truth.width, truth.height, truth.height];
    for (k, sd) in [u.left, u.right, u.bottom, u.top].iter().enumerate() {
        if let Some(sd) = sd {
            let metres = edges[k] * sizes[k];
            eprintln!("{} edge {k}: {metres:.4} m, sigma {sd:.4} m", truth.name);
            assert!(
                metres.abs() < bound * sd,
                "{} edge {k}: {metres} m against sigma {sd}",
                truth.name
            );
        }
    }
    for ch in 0..3 {
        let e = light.radiance[ch] - truth.radiance[ch];
        eprintln!(
            "{} channel {ch}: {e:.4}, sigma {:.4}",
            truth.name, u.radiance[ch]
        );
        assert!(
            e.abs() < bound * u.radiance[ch],
            "{} channel {ch}: {e} against sigma {}",
            truth.name,
            u.radiance[ch]
        );
    }
}
