//! Parsers of numeric arguments, so that a bad number is refused with what to give instead, before
//! anything runs. Numeric arguments also take negative numbers as values (`--dt -1`), so that the
//! answer is about the number, not about an unknown option.

/// A frame count: a whole number from 1.
pub fn frames(s: &str) -> Result<u32, String> {
    match s.trim().parse::<i64>() {
        Ok(n) if n >= 1 && n <= i64::from(u32::MAX) => Ok(n as u32),
        Ok(0) => Err("0 frames runs nothing; give at least 1".into()),
        Ok(n) if n < 0 => Err(format!(
            "{n} is below 0; give a whole number of frames from 1"
        )),
        Ok(n) => Err(format!(
            "{n} is more than the {} frames a run may have",
            u32::MAX
        )),
        Err(_) => Err(format!(
            "{s:?} is not a whole number of frames; give one such as 300"
        )),
    }
}

/// Bits of a depth format the renderer offers: 16 or 32.
pub fn depth_bits(s: &str) -> Result<u32, String> {
    match s.trim() {
        "16" => Ok(16),
        "32" => Ok(32),
        _ => Err(format!(
            "{s:?} is not a depth the shadow map offers; give 16 or 32"
        )),
    }
}

/// A number that must be finite as a 32-bit float (parsed wide, so that `1e39` is named as it was
/// written rather than as "inf").
fn finite(s: &str) -> Result<f32, String> {
    let v: f64 = s
        .trim()
        .parse()
        .map_err(|_| format!("{s:?} is not a number"))?;
    if !v.is_finite() {
        return Err(format!("{s} is not a finite number"));
    }
    if v.abs() > f64::from(f32::MAX) {
        return Err(format!(
            "{s} is beyond the largest number snowprint computes with (3.4e38)"
        ));
    }
    Ok(v as f32)
}

/// Seconds per frame: finite and above 0.
pub fn seconds(s: &str) -> Result<f32, String> {
    let v = finite(s)
        .map_err(|e| format!("{e}; give a finite number of seconds above 0, such as 0.0166"))?;
    if v > 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "{s} is not above 0; give a finite number of seconds above 0, such as 0.0166"
        ))
    }
}

/// A moment of the demo's clip: finite seconds, 0 or more.
pub fn moment(s: &str) -> Result<f32, String> {
    let v = finite(s).map_err(|e| format!("{e}; give seconds from 0, such as 2.5"))?;
    if v >= 0.0 {
        Ok(v)
    } else {
        Err(format!(
            "{s} is before the start; give seconds from 0, such as 2.5"
        ))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_are_named_as_written() {
        assert_eq!(seconds("0.5"), Ok(0.5));
        assert!(seconds("1e39").unwrap_err().starts_with("1e39 is beyond"));
        assert!(seconds("-1").unwrap_err().starts_with("-1 is not above 0"));
        assert!(seconds("nan").unwrap_err().contains("not a finite number"));
        assert_eq!(frames("3"), Ok(3));
        assert!(frames("0").unwrap_err().contains("at least 1"));
        assert!(frames("-2").unwrap_err().contains("below 0"));
        assert!(moment("-1").unwrap_err().contains("before the start"));
        assert_eq!((depth_bits("16"), depth_bits("32")), (Ok(16), Ok(32)));
        assert!(depth_bits("24").unwrap_err().contains("give 16 or 32"));
    }
}
