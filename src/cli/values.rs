//! Option values checked as they are parsed: negative numbers reach these parsers
//! (`allow_negative_numbers`), so `--exposure -1` is told what is wrong with it rather than
//! taken for an unknown option. Each error says the accepted range; clap adds the option and
//! the value ("invalid value '-1' for '--exposure <E|auto>': ...") and exits with code 2.

/// A finite number for which `ok` holds; `range` says which in the error (NaN and the
/// infinities are numbers out of every range).
fn number_where(s: &str, range: &str, ok: impl Fn(f64) -> bool) -> Result<f64, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("must be {range}, got \"{s}\""))?;
    if v.is_finite() && ok(v) {
        Ok(v)
    } else {
        Err(format!("must be {range}, got {s}"))
    }
}

/// A finite number greater than zero.
pub fn positive_f32(s: &str) -> Result<f32, String> {
    let v = positive_f64(s)? as f32;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "must be a number greater than 0 that single precision holds, got {s}"
        ))
    }
}

/// A finite number greater than zero, in double precision.
pub fn positive_f64(s: &str) -> Result<f64, String> {
    number_where(s, "a number greater than 0", |v| v > 0.0)
}

/// A finite number of zero or more (a length in metres).
pub fn non_negative_f64(s: &str) -> Result<f64, String> {
    number_where(s, "a number of 0 or more", |v| v >= 0.0)
}

/// A linear colour of zero or more per channel: one value for grey, or R,G,B.
pub fn colour(s: &str) -> Result<[f32; 3], String> {
    let range = "one number of 0 or more, or three as R,G,B";
    let parts: Vec<&str> = s.split(',').collect();
    let values = parts
        .iter()
        .map(|p| number_where(p, range, |v| v >= 0.0 && v <= f32::MAX as f64).map(|v| v as f32))
        .collect::<Result<Vec<f32>, String>>()
        .map_err(|_| format!("must be {range}, got \"{s}\""))?;
    match values[..] {
        [v] => Ok([v; 3]),
        [r, g, b] => Ok([r, g, b]),
        _ => Err(format!("must be {range}, got \"{s}\"")),
    }
}

/// A value in [0, 1] (a fraction of the encoding's maximum).
pub fn unit_interval(s: &str) -> Result<f32, String> {
    number_where(s, "a number from 0 to 1", |v| (0.0..=1.0).contains(&v)).map(|v| v as f32)
}

/// A value in [0, 1): a threshold that some value must exceed.
pub fn unit_threshold(s: &str) -> Result<f32, String> {
    number_where(s, "a number from 0 up to, but not including, 1", |v| {
        (0.0..1.0).contains(&v)
    })
    .map(|v| v as f32)
}

/// A correlation coefficient, in [-1, 1].
pub fn correlation(s: &str) -> Result<f32, String> {
    number_where(s, "a number from -1 to 1", |v| (-1.0..=1.0).contains(&v)).map(|v| v as f32)
}

/// A blur radius (Gaussian sigma) in pixels, in [0, 50].
pub fn blur_sigma(s: &str) -> Result<f32, String> {
    number_where(s, "a number of pixels from 0 to 50", |v| {
        (0.0..=50.0).contains(&v)
    })
    .map(|v| v as f32)
}

/// An index of refraction: a finite number above 1.
pub fn ior(s: &str) -> Result<f32, String> {
    number_where(
        s,
        "greater than 1 (water: 1.33): at 1 or below, light would not reflect off the water",
        |v| v > 1.0,
    )
    .map(|v| v as f32)
}

/// A count: a whole number of 1 or more.
pub fn count(s: &str) -> Result<u32, String> {
    match s.trim().parse::<u32>() {
        Ok(n) if n >= 1 => Ok(n),
        _ => Err(format!(
            "must be a whole number from 1 to {}, got {s}",
            u32::MAX
        )),
    }
}

/// A seed of the random numbers: any whole number from 0 to 2^64 - 1.
pub fn seed(s: &str) -> Result<u64, String> {
    s.trim()
        .parse::<u64>()
        .map_err(|_| format!("must be a whole number from 0 to {}, got {s}", u64::MAX))
}

/// A count as a `usize`.
pub fn count_usize(s: &str) -> Result<usize, String> {
    count(s).map(|n| n as usize)
}

/// `--exposure`: a number, or "auto" for the photo's EXIF.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum ExposureArg {
    /// Linear value per unit of radiance.
    Value(f32),
    /// From the photo's exposure time, f-number and ISO speed.
    Auto,
}

impl ExposureArg {
    /// The value given, and whether it is to be read from the photo instead.
    pub fn value_or_auto(self) -> (f32, bool) {
        match self {
            ExposureArg::Value(v) => (v, false),
            ExposureArg::Auto => (1.0, true),
        }
    }
}

/// Parses `--exposure`.
pub fn exposure(s: &str) -> Result<ExposureArg, String> {
    if s.trim().eq_ignore_ascii_case("auto") {
        return Ok(ExposureArg::Auto);
    }
    number_where(s, "a number greater than 0 or \"auto\"", |v| v > 0.0)
        .map(|v| ExposureArg::Value(v as f32))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn values_in_range_pass_and_others_name_the_range() {
        assert_eq!(positive_f32("0.1"), Ok(0.1));
        assert_eq!(positive_f64("683"), Ok(683.0));
        assert_eq!(ior("1.33"), Ok(1.33));
        assert_eq!(non_negative_f64("0"), Ok(0.0));
        assert_eq!(unit_interval("1"), Ok(1.0));
        assert_eq!(unit_threshold("0"), Ok(0.0));
        assert_eq!(correlation("-1"), Ok(-1.0));
        assert_eq!(blur_sigma("50"), Ok(50.0));
        assert_eq!(count("1"), Ok(1));
        assert_eq!(seed("18446744073709551615"), Ok(u64::MAX));
        assert!(seed("-1").unwrap_err().contains("from 0 to"));
        assert_eq!(exposure("AUTO"), Ok(ExposureArg::Auto));
        assert_eq!(exposure("0.1"), Ok(ExposureArg::Value(0.1)));
        for bad in ["-1", "0", "nan", "inf", "x"] {
            let e = positive_f32(bad).unwrap_err();
            assert!(e.contains(bad), "{e}");
        }
        type Parser = fn(&str) -> Result<f32, String>;
        let cases: [(Parser, &str, &str); 6] = [
            (ior, "1", "greater than 1"),
            (unit_interval, "1.5", "from 0 to 1"),
            (unit_threshold, "1", "not including, 1"),
            (correlation, "-1.1", "from -1 to 1"),
            (blur_sigma, "51", "from 0 to 50"),
            (|s| exposure(s).map(|_| 0.0), "-1", "or \"auto\""),
        ];
        for (parse, bad, range) in cases {
            let e = parse(bad).unwrap_err();
            assert!(e.contains(range) && e.contains(bad), "{e}");
        }
        assert_eq!(colour("0.5"), Ok([0.5; 3]));
        assert_eq!(colour("0.1, 0.2,0.3"), Ok([0.1, 0.2, 0.3]));
        for bad in ["-1", "1,2", "1,2,3,4", "x", "1,,2", "nan,1,1"] {
            let e = colour(bad).unwrap_err();
            assert!(e.contains("R,G,B") && e.contains(bad), "{e}");
        }
        assert!(non_negative_f64("-0.001")
            .unwrap_err()
            .contains("0 or more"));
        for bad in ["0", "-3", "1.5", "4294967296"] {
            assert!(
                count(bad).unwrap_err().contains("whole number from 1"),
                "{bad}"
            );
        }
    }
}
