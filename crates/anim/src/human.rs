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
    let x: f64 = v.into();
    let a = x.abs();
    let scientific = a != 0.0 && a.is_finite() && !(1e-4..1e7).contains(&a);
    // The shortest text that reads back as `v` in its own type (f32 or f64)…
    let short = if scientific {
        format!("{v:e}")
    } else {
        format!("{v}")
    };
    if !a.is_finite() || significant_digits(&short) <= MAX_DIGITS {
        return short;
    }
    // …unless that spells out more digits than a person reads (an f32 bound widened to f64):
    // then rounded to MAX_DIGITS significant digits.
    if scientific {
        let s = format!("{:.*e}", MAX_DIGITS - 1, x);
        let (mantissa, exponent) = s.split_once('e').unwrap_or((&s, "0"));
        format!("{}e{exponent}", trim_zeros(mantissa))
    } else {
        let decimals = (MAX_DIGITS as i32 - 1 - a.log10().floor() as i32).clamp(0, 12) as usize;
        trim_zeros(&format!("{x:.decimals$}")).to_string()
    }
}

/// Significant digits a person reads at most in a message.
const MAX_DIGITS: usize = 8;

fn significant_digits(s: &str) -> usize {
    let mantissa = s.split(['e', 'E']).next().unwrap_or(s);
    let digits: String = mantissa.chars().filter(char::is_ascii_digit).collect();
    digits.trim_start_matches('0').len()
}

fn trim_zeros(s: &str) -> &str {
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.')
    } else {
        s
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
        assert_eq!(human_number(f64::from(f32::MAX)), "3.4028235e38");
        assert_eq!(human_number(0.1 + 0.2), "0.3");
        assert_eq!(human_number(f64::from(0.1f32)), "0.1");
        assert_eq!(human_number(123.456), "123.456");
        assert_eq!(human_number(f64::INFINITY), "inf");
        assert_eq!(human_number(f64::NAN), "NaN");
        assert_eq!(human_number(0.0), "0");
    }
}
