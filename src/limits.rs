//! Limits on what a run reads and allocates, each raisable by an environment variable: a
//! hostile or corrupt input (a FIFO, `/dev/zero`, a tiny PNG that decompresses to a huge
//! picture, an option of billions of samples) is refused with a message saying which limit it
//! met and how to raise it, instead of hanging or running out of memory.

/// Environment variable: the most megabytes (MiB) read from one input file.
pub const MAX_INPUT_MB_VAR: &str = "STREAKLIGHT_MAX_INPUT_MB";
/// Default of [`MAX_INPUT_MB_VAR`]: 2048 MiB, above any scene, buffer or photo met in practice.
pub const DEFAULT_MAX_INPUT_MB: u64 = 2048;
/// Environment variable: the most memory (MiB) a run's estimate may come to before any work.
pub const MAX_MEMORY_MB_VAR: &str = "STREAKLIGHT_MAX_MEMORY_MB";
/// Default of [`MAX_MEMORY_MB_VAR`]: 4096 MiB.
pub const DEFAULT_MAX_MEMORY_MB: u64 = 4096;
/// Bytes of memory a fit takes per photo pixel, measured on the samples and an 11000 x 11000
/// photo (about 6 GB): the photo in several forms (display, linear, clipped, masks, superpixel
/// labels, debug canvases) dominates.
pub const FIT_BYTES_PER_PIXEL: u64 = 50;

/// The limit of `var` in MiB (its default when unset), as bytes.
fn megabytes(var: &str, default: u64) -> crate::Result<u64> {
    let mb = match std::env::var(var) {
        Err(_) => default,
        Ok(text) => text
            .trim()
            .parse::<u64>()
            .ok()
            .filter(|&v| v > 0)
            .ok_or_else(|| {
                crate::Error::Usage(format!(
                    "the environment variable {var} must be a whole number of megabytes > 0, \
                     not \"{}\"",
                    crate::names::escaped(&text)
                ))
            })?,
    };
    Ok(mb.saturating_mul(1 << 20))
}

/// The most bytes read from one input file ([`MAX_INPUT_MB_VAR`]).
pub fn max_input_bytes() -> crate::Result<u64> {
    megabytes(MAX_INPUT_MB_VAR, DEFAULT_MAX_INPUT_MB)
}

/// Refuses, before any work, a run whose memory estimate `bytes` is above the limit
/// ([`MAX_MEMORY_MB_VAR`]): the message completes "`what` would need ...".
pub fn check_memory(bytes: u64, what: &str) -> crate::Result<(), String> {
    let limit = megabytes(MAX_MEMORY_MB_VAR, DEFAULT_MAX_MEMORY_MB).map_err(|e| e.to_string())?;
    if bytes > limit {
        let mib = |b: u64| b as f64 / f64::from(1u32 << 20);
        return Err(format!(
            "{what} would need about {:.1} MiB of memory, above the limit of {:.0} MiB; set the \
             environment variable {MAX_MEMORY_MB_VAR} to raise it",
            mib(bytes),
            mib(limit)
        ));
    }
    Ok(())
}

/// Refuses `value` of the option `name` above `cap` (a value whose run would not finish in
/// reasonable time or memory).
pub fn check_cap(name: &str, value: u64, cap: u64, why: &str) -> crate::Result<()> {
    if value > cap {
        return Err(crate::Error::Usage(format!(
            "{name} {value} is above its cap of {cap} ({why})"
        )));
    }
    Ok(())
}
