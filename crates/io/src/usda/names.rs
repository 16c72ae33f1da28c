//! USD prim names: identifiers `[A-Za-z_][A-Za-z0-9_]*`, unique among siblings.

use std::collections::BTreeSet;

/// Name given to an empty (or all-invalid) name.
const FALLBACK_NAME: &str = "mesh";

/// Turns any string into a valid USD prim name `[A-Za-z_][A-Za-z0-9_]*`.
///
/// Every character outside `[A-Za-z0-9_]` (spaces, dots, dashes, non-ASCII letters) becomes
/// `_`; a leading digit gets a `_` prefix; an empty name becomes `mesh`.
///
/// # Examples
/// ```
/// assert_eq!(tkio::usda::sanitize_name("Robot.001"), "Robot_001");
/// assert_eq!(tkio::usda::sanitize_name("2nd arm"), "_2nd_arm");
/// assert_eq!(tkio::usda::sanitize_name(""), "mesh");
/// ```
pub fn sanitize_name(name: &str) -> String {
    if name.is_empty() {
        return FALLBACK_NAME.to_string();
    }
    let mut out = String::with_capacity(name.len() + 1);
    if name.starts_with(|c: char| c.is_ascii_digit()) {
        out.push('_');
    }
    out.extend(name.chars().map(|c| {
        if c.is_ascii_alphanumeric() || c == '_' {
            c
        } else {
            '_'
        }
    }));
    out
}

/// Hands out sanitized names that are unique among one prim's children: a repeated name gets
/// the first free suffix `_1`, `_2`, ….
#[derive(Debug, Clone, Default)]
pub struct UniqueNames {
    used: BTreeSet<String>,
}

impl UniqueNames {
    /// No name used yet.
    pub fn new() -> UniqueNames {
        UniqueNames::default()
    }

    /// A valid name for `name`, different from every name returned before.
    pub fn claim(&mut self, name: &str) -> String {
        let base = sanitize_name(name);
        let mut candidate = base.clone();
        let mut k = 1usize;
        while self.used.contains(&candidate) {
            candidate = format!("{base}_{k}");
            k += 1;
        }
        self.used.insert(candidate.clone());
        candidate
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn is_identifier(s: &str) -> bool {
        let mut c = s.chars();
        c.next()
            .is_some_and(|f| f.is_ascii_alphabetic() || f == '_')
            && c.all(|c| c.is_ascii_alphanumeric() || c == '_')
    }

    #[test]
    fn sanitized_names_are_identifiers() {
        for n in [
            "",
            "a",
            "9",
            "Robot.001",
            "é",
            "a b-c",
            "__x",
            "Head|Neck",
            "0_1",
        ] {
            let s = sanitize_name(n);
            assert!(is_identifier(&s), "{n:?} → {s:?}");
        }
        assert_eq!(sanitize_name("ok_Name1"), "ok_Name1");
    }

    #[test]
    fn repeated_names_get_suffixes() {
        let mut u = UniqueNames::new();
        let got: Vec<String> = ["a", "a", "a.", "a_1", "a"]
            .iter()
            .map(|n| u.claim(n))
            .collect();
        assert_eq!(got, ["a", "a_1", "a_", "a_1_1", "a_2"]);
    }
}
