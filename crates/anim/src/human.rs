//! Numbers in messages, written for people: `2.5`, `24`, `1e9`, `3.4e38` — never the 39
//! digits of `f32::MAX` spelled out.

/// A number as people write it: plain for ordinary magnitudes, scientific (`1e9`,
/// `3.4028235e38`, `1e-7`) for very large or very small ones; `NaN`, `inf` as such.
/// Takes `f32` or `f64` and writes the shortest digits of that type (`f32::MAX` is
/// `3.4028235e38`).
pub fn human_number<T>(v: T) -> String
where
    T: Into<f64> + std::fmt::Display + std::fmt::LowerExp + Copy,
{
    let a = v.into().abs();
    if a != 0.0 && a.is_finite() && !(1e-4..1e7).contains(&a) {
        format!("{v:e}")
    } else {
        format!("{v}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn large_and_small_numbers_are_short() {
        assert_eq!(human_number(2.5), "2.5");
        assert_eq!(human_number(100000.0), "100000");
        assert_eq!(human_number(1e9), "1e9");
        assert_eq!(human_number(-1e-7), "-1e-7");
        assert_eq!(human_number(f32::MAX), "3.4028235e38");
        assert_eq!(human_number(f64::NAN), "NaN");
        assert_eq!(human_number(0.0), "0");
    }
}
