//! Caps on the options that set how much work a run does: a value above its cap would run for
//! hours or fail to allocate, so it is refused before any work, with the option, its value and
//! its cap named.

use streaklight::limits::check_cap;

/// `fit --samples` (default 512, or 32-128 where the estimate starts a joint fit): lobe
/// samples per traced pixel of the paper's estimate.
pub const SAMPLES: u64 = 65_536;
/// `fit --joint-samples` (default 72): the joint fit's time grows in proportion.
pub const JOINT_SAMPLES: u64 = 8_192;
/// `fit --repeats`: the joint fit's time is multiplied by it.
pub const REPEATS: u64 = 64;
/// `render --spp`, `samples --spp`: camera rays per pixel.
pub const SPP: u64 = 65_536;
/// `render --width`, `--height`: pixels on a side (as the photos streaklight reads).
pub const SIDE: u64 = streaklight::photo_in::MAX_SIDE as u64 / 2;
/// `render`: camera rays in all (width x height x spp), some hours at the slowest.
pub const RAYS: u64 = 1 << 36;

/// Refuses `fit`'s options above their caps.
pub fn fit(args: &super::fit::Args) -> streaklight::Result<()> {
    if let Some(n) = args.samples {
        check_cap(
            "--samples",
            n.into(),
            SAMPLES,
            "the fit's time grows with it",
        )?;
    }
    if let Some(n) = args.joint_samples {
        check_cap(
            "--joint-samples",
            n.into(),
            JOINT_SAMPLES,
            "the joint fit's time grows with it",
        )?;
    }
    check_cap(
        "--repeats",
        args.repeats.into(),
        REPEATS,
        "each repeat is one more joint fit",
    )
}

/// Refuses an image size and rays per pixel above their caps.
pub fn render(width: u32, height: u32, spp: u32) -> streaklight::Result<()> {
    check_cap("--width", width.into(), SIDE, "pixels on a side")?;
    check_cap("--height", height.into(), SIDE, "pixels on a side")?;
    check_cap("--spp", spp.into(), SPP, "the render's time grows with it")?;
    let rays = u64::from(width) * u64::from(height) * u64::from(spp);
    if rays > RAYS {
        return Err(streaklight::Error::Usage(format!(
            "--width {width} x --height {height} x --spp {spp} is {rays} camera rays, above the \
             cap of {RAYS} (hours of rendering); lower one of them"
        )));
    }
    Ok(())
}
