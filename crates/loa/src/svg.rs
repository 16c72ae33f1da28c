//! Reading keystrokes from SVG.
//!
//! Every `<path>` and `<polyline>` element is one keystroke. Its frame is the required
//! `data-frame` attribute; optional `data-stiffness` and `data-damping` override the defaults,
//! which the root `<svg>` may set with the same attributes (plus `data-fps`). Path data may use
//! the `M L H V C S Q T Z` commands (absolute or relative, one subpath); curves are flattened
//! into [`CURVE_SEGMENTS`] segments each. `transform` attributes are not applied: strokes are
//! taken in the SVG's user coordinates (y pointing down, as on screen).

use glam::DVec2;

use crate::error::LoaError;
use crate::keystroke::{integral_frame, Keystroke, Keystrokes, DEFAULT_DAMPING, DEFAULT_STIFFNESS};
use crate::stroke::Stroke;

/// Number of line segments a Bézier curve segment is flattened into.
pub const CURVE_SEGMENTS: usize = 16;

impl Keystrokes {
    /// Parses keystrokes from SVG; see the [module documentation](crate::svg) for the
    /// accepted elements and attributes.
    pub fn from_svg_str(text: &str) -> Result<Self, LoaError> {
        parse_keystrokes(text)
    }

    /// Parses keystrokes from either layout: SVG when the text starts with `<` (after
    /// whitespace), else JSON ([`Keystrokes::from_json_str`]).
    pub fn parse(text: &str) -> Result<Self, LoaError> {
        if text.trim_start().starts_with('<') {
            Self::from_svg_str(text)
        } else {
            Self::from_json_str(text)
        }
    }
}

/// The deepest element nesting of an XML text, counted on its tags before it is parsed
/// (comments, processing instructions and CDATA are skipped; a `<` inside an attribute
/// value can only over-count, which is safe).
fn nesting_depth(text: &str) -> u64 {
    let bytes = text.as_bytes();
    let (mut depth, mut deepest) = (0u64, 0u64);
    let mut i = 0;
    while let Some(k) = bytes[i..].iter().position(|&b| b == b'<') {
        i += k + 1;
        let rest = &bytes[i..];
        let end = rest.iter().position(|&b| b == b'>').unwrap_or(rest.len());
        match rest.first() {
            Some(b'/') => depth = depth.saturating_sub(1),
            Some(b'!' | b'?') => {}
            Some(_) if end > 0 && rest[end - 1] == b'/' => {}
            Some(_) => {
                depth += 1;
                deepest = deepest.max(depth);
            }
            None => {}
        }
        i += end;
    }
    deepest
}

fn parse_keystrokes(text: &str) -> Result<Keystrokes, LoaError> {
    anim::check_budget(
        "SVG element nesting",
        nesting_depth(text),
        anim::budget::DEFAULT_MAX_NESTING,
        "flatten the groups (<g>) of the keystroke file",
    )?;
    let doc = roxmltree::Document::parse(text).map_err(|e| LoaError::Xml(e.to_string()))?;
    let root = doc.root_element();
    let fps = attr_f64(root, "data-fps").map_err(|m| LoaError::Xml(format!("<svg>: {m}")))?;
    let default_k = attr_f64(root, "data-stiffness")
        .map_err(|m| LoaError::Xml(format!("<svg>: {m}")))?
        .unwrap_or(DEFAULT_STIFFNESS);
    let default_c = attr_f64(root, "data-damping")
        .map_err(|m| LoaError::Xml(format!("<svg>: {m}")))?
        .unwrap_or(DEFAULT_DAMPING);
    let mut keys = Vec::new();
    let elements = doc
        .descendants()
        .filter(|n| n.is_element() && matches!(n.tag_name().name(), "path" | "polyline"));
    for (element, node) in elements.enumerate() {
        let tag = node.tag_name().name().to_string();
        let err = |message: String| LoaError::SvgElement {
            element,
            tag: tag.clone(),
            message,
        };
        let frame = match attr_f64(node, "data-frame").map_err(err)? {
            Some(f) => integral_frame(f).map_err(|e| err(e.to_string()))?,
            None => {
                return Err(err(
                    "missing data-frame attribute: add data-frame=\"<frame number>\"".into(),
                ))
            }
        };
        let points = if tag == "path" {
            parse_path(node.attribute("d").unwrap_or("")).map_err(err)?
        } else {
            parse_points(node.attribute("points").unwrap_or("")).map_err(err)?
        };
        let stroke = Stroke::new(points).map_err(|source| LoaError::Stroke {
            keystroke: keys.len(),
            frame,
            source,
        })?;
        keys.push(Keystroke {
            frame,
            stroke,
            stiffness: attr_f64(node, "data-stiffness")
                .map_err(err)?
                .unwrap_or(default_k),
            damping: attr_f64(node, "data-damping")
                .map_err(err)?
                .unwrap_or(default_c),
        });
    }
    Keystrokes::new(keys, fps)
}

fn attr_f64(node: roxmltree::Node, name: &str) -> Result<Option<f64>, String> {
    match node.attribute(name) {
        None => Ok(None),
        Some(s) => s
            .trim()
            .parse::<f64>()
            .map(Some)
            .map_err(|_| format!("attribute {name}=\"{s}\" is not a number")),
    }
}

/// Splits SVG number lists: `1,2 -3.5e2.5` → `[1, 2, -350, 0.5]`.
fn numbers(s: &str) -> Result<Vec<f64>, String> {
    let mut out = Vec::new();
    let b = s.as_bytes();
    let mut i = 0;
    while i < b.len() {
        let c = b[i];
        if c.is_ascii_whitespace() || c == b',' {
            i += 1;
            continue;
        }
        let start = i;
        if c == b'+' || c == b'-' {
            i += 1;
        }
        let mut dot = false;
        while i < b.len() && (b[i].is_ascii_digit() || (b[i] == b'.' && !dot)) {
            dot |= b[i] == b'.';
            i += 1;
        }
        if i < b.len() && (b[i] == b'e' || b[i] == b'E') {
            let save = i;
            i += 1;
            if i < b.len() && (b[i] == b'+' || b[i] == b'-') {
                i += 1;
            }
            let digits = i;
            while i < b.len() && b[i].is_ascii_digit() {
                i += 1;
            }
            if i == digits {
                i = save;
            }
        }
        let token = &s[start..i];
        match token.parse::<f64>() {
            Ok(v) if v.is_finite() => out.push(v),
            _ => {
                // Twelve characters, not bytes: the text may hold any UTF-8.
                let near: String = s[start..].chars().take(12).collect();
                return Err(format!("cannot read a number at \"{near}\""));
            }
        }
    }
    Ok(out)
}

fn parse_points(s: &str) -> Result<Vec<DVec2>, String> {
    let v = numbers(s)?;
    if v.len() % 2 != 0 {
        return Err("points attribute has an odd number of coordinates".into());
    }
    Ok(v.chunks(2).map(|c| DVec2::new(c[0], c[1])).collect())
}

fn cubic(p0: DVec2, p1: DVec2, p2: DVec2, p3: DVec2, out: &mut Vec<DVec2>) {
    for i in 1..=CURVE_SEGMENTS {
        let t = i as f64 / CURVE_SEGMENTS as f64;
        let u = 1.0 - t;
        out.push(
            p0 * (u * u * u) + p1 * (3.0 * u * u * t) + p2 * (3.0 * u * t * t) + p3 * (t * t * t),
        );
    }
}

fn quadratic(p0: DVec2, p1: DVec2, p2: DVec2, out: &mut Vec<DVec2>) {
    for i in 1..=CURVE_SEGMENTS {
        let t = i as f64 / CURVE_SEGMENTS as f64;
        let u = 1.0 - t;
        out.push(p0 * (u * u) + p1 * (2.0 * u * t) + p2 * (t * t));
    }
}

/// Flattens one subpath of SVG path data into points.
pub(crate) fn parse_path(d: &str) -> Result<Vec<DVec2>, String> {
    // Split into (command, arguments) groups.
    let mut groups: Vec<(char, Vec<f64>)> = Vec::new();
    let mut start: Option<(char, usize)> = None;
    for (i, c) in d.char_indices() {
        if c.is_ascii_alphabetic() && c != 'e' && c != 'E' {
            if let Some((cmd, s)) = start {
                groups.push((cmd, numbers(&d[s..i])?));
            }
            start = Some((c, i + c.len_utf8()));
        } else if start.is_none() && !(c.is_whitespace() || c == ',') {
            return Err("path data must start with a command (M)".into());
        }
    }
    if let Some((cmd, s)) = start {
        groups.push((cmd, numbers(&d[s..])?));
    }
    let mut out: Vec<DVec2> = Vec::new();
    let mut cur = DVec2::ZERO;
    let mut first = DVec2::ZERO;
    let mut last_ctrl: Option<(char, DVec2)> = None;
    for (g, (cmd, args)) in groups.iter().enumerate() {
        let rel = cmd.is_ascii_lowercase();
        let upper = cmd.to_ascii_uppercase();
        let arity = match upper {
            'M' | 'L' | 'T' => 2,
            'H' | 'V' => 1,
            'C' => 6,
            'S' | 'Q' => 4,
            'Z' => 0,
            other => {
                return Err(format!(
                    "unsupported path command '{other}'; use M/L/H/V/C/S/Q/T/Z (convert arcs to curves)"
                ))
            }
        };
        if upper == 'M' && g > 0 {
            return Err("more than one subpath; draw one keystroke per <path>".into());
        }
        if g == 0 && upper != 'M' {
            return Err("path data must start with M".into());
        }
        if arity == 0 {
            if !args.is_empty() {
                return Err("Z takes no arguments".into());
            }
            out.push(first);
            cur = first;
            continue;
        }
        if args.is_empty() || args.len() % arity != 0 {
            return Err(format!(
                "command '{cmd}' needs a multiple of {arity} numbers, got {}",
                args.len()
            ));
        }
        for (k, a) in args.chunks(arity).enumerate() {
            let base = if rel { cur } else { DVec2::ZERO };
            let pt = |i: usize| base + DVec2::new(a[i], a[i + 1]);
            let mut ctrl = None;
            match upper {
                'M' => {
                    cur = pt(0);
                    if k == 0 {
                        first = cur;
                    }
                    out.push(cur);
                }
                'L' => {
                    cur = pt(0);
                    out.push(cur);
                }
                'H' => {
                    cur = DVec2::new(if rel { cur.x + a[0] } else { a[0] }, cur.y);
                    out.push(cur);
                }
                'V' => {
                    cur = DVec2::new(cur.x, if rel { cur.y + a[0] } else { a[0] });
                    out.push(cur);
                }
                'C' => {
                    let (c1, c2, e) = (pt(0), pt(2), pt(4));
                    cubic(cur, c1, c2, e, &mut out);
                    ctrl = Some(('C', c2));
                    cur = e;
                }
                'S' => {
                    let c1 = match last_ctrl {
                        Some(('C', c)) => 2.0 * cur - c,
                        _ => cur,
                    };
                    let (c2, e) = (pt(0), pt(2));
                    cubic(cur, c1, c2, e, &mut out);
                    ctrl = Some(('C', c2));
                    cur = e;
                }
                'Q' => {
                    let (c, e) = (pt(0), pt(2));
                    quadratic(cur, c, e, &mut out);
                    ctrl = Some(('Q', c));
                    cur = e;
                }
                'T' => {
                    let c = match last_ctrl {
                        Some(('Q', c)) => 2.0 * cur - c,
                        _ => cur,
                    };
                    let e = pt(0);
                    quadratic(cur, c, e, &mut out);
                    ctrl = Some(('Q', c));
                    cur = e;
                }
                _ => unreachable!("arity table covers every accepted command"),
            }
            last_ctrl = ctrl;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn path_commands_flatten() {
        let p = parse_path("M0,0 L10 0 h5 v-5 Q20,-5 20,0 c0,5 5,5 5,0").unwrap();
        assert_eq!(p[0], DVec2::ZERO);
        assert_eq!(p[1], DVec2::new(10.0, 0.0));
        assert_eq!(p[2], DVec2::new(15.0, 0.0));
        assert_eq!(p[3], DVec2::new(15.0, -5.0));
        assert_eq!(p[3 + CURVE_SEGMENTS], DVec2::new(20.0, 0.0));
        assert_eq!(*p.last().unwrap(), DVec2::new(25.0, 0.0));
        assert_eq!(p.len(), 4 + 2 * CURVE_SEGMENTS);
    }

    #[test]
    fn compact_numbers_and_errors() {
        assert_eq!(numbers("1-2.5.5e1").unwrap(), vec![1.0, -2.5, 5.0]);
        assert!(parse_path("M0 0 A 1 1 0 0 1 2 2")
            .unwrap_err()
            .contains("arcs"));
        assert!(parse_path("M0 0 L1 1 M2 2 L3 3").is_err());
        assert!(parse_path("L1 1").is_err());
        assert!(parse_path("M0 0 L1").is_err());
    }
}
