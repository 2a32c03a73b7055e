//! Numeric option values checked as they are parsed: negative numbers reach these parsers
//! (`allow_negative_numbers`), so `--exposure -1` is told what is wrong with it rather than
//! taken for an unknown option.

/// A finite number greater than zero.
pub fn positive_f32(s: &str) -> Result<f32, String> {
    let v: f32 = s
        .parse()
        .map_err(|_| format!("expected a number, got \"{s}\""))?;
    if v.is_finite() && v > 0.0 {
        Ok(v)
    } else {
        Err(format!("must be a finite number greater than 0, got {s}"))
    }
}

/// A finite number greater than zero, in double precision.
pub fn positive_f64(s: &str) -> Result<f64, String> {
    positive_f32(s).and_then(|_| s.parse::<f64>().map_err(|e| e.to_string()))
}

/// An index of refraction: a finite number above 1.
pub fn ior(s: &str) -> Result<f32, String> {
    let v = positive_f32(s)?;
    if v > 1.0 {
        Ok(v)
    } else {
        Err(format!(
            "must be greater than 1 (water: 1.33), got {s}: light would not reflect off the water"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn positive_values_pass_and_others_are_named() {
        assert_eq!(positive_f32("0.1"), Ok(0.1));
        assert_eq!(positive_f64("683"), Ok(683.0));
        assert_eq!(ior("1.33"), Ok(1.33));
        for bad in ["-1", "0", "nan", "inf", "x"] {
            let e = positive_f32(bad).unwrap_err();
            assert!(e.contains(bad), "{e}");
        }
        assert!(ior("1").unwrap_err().contains("greater than 1"));
    }
}
