//! BVH motion capture (Biovision hierarchy): our own reader and writer.
//!
//! # Reading
//! [`read`] turns a file into an [`anim::Scene`]:
//! * one node per `ROOT`/`JOINT`, in file order, with the `OFFSET` as rest translation and no
//!   rest rotation;
//! * one leaf node per `End Site`, named `<parent>_end` (`_end2`, … when a joint has several),
//!   so that the last bone of each chain gets its real tip (SPEC.md bones: a bone's tip is the
//!   average of its children);
//! * one [`Clip`] named `motion` with LINEAR channels keyed at `t = k × Frame Time`: a
//!   rotation channel for each joint with rotation channels, a translation channel for each
//!   joint with position channels. Rotation channels apply in the listed order, intrinsically
//!   (`Zrotation Xrotation Yrotation` = `Rz · Rx · Ry`), in degrees. Position channels are
//!   *added to* the `OFFSET` (the Biovision convention; for the usual root with
//!   `OFFSET 0 0 0` this equals the "absolute position" reading of other tools);
//! * one [`SkinDef`] listing every `ROOT`/`JOINT` node (End Sites are tips, not joints: the
//!   joint count is the file's) with inverse bind matrices = inverse rest world
//!   matrices, so that [`Scene::skeleton`] and [`anim::sample`] find the joints. No mesh.
//!
//! Units are the file's. A file with `Frames: 0` gives a scene without clip.
//!
//! # Writing
//! [`write()`] and [`write_local`] produce BVH text with `ZXY` rotation channels (see the
//! `write` submodule).

use anim::{Channel, Clip, Interpolation, Node, Property, Scene, SkinDef, Transform};
use glam::{DQuat, DVec3, Mat4, Vec3};

use crate::{IoError, Result};

mod write;
pub use write::{write, write_local, DEFAULT_POSITION_TOLERANCE};

const FORMAT: &str = "BVH";
/// Name of the clip [`read`] creates.
pub const CLIP_NAME: &str = "motion";
/// Suffix of the leaf nodes [`read`] creates for `End Site`s.
pub const END_SITE_SUFFIX: &str = "_end";

fn err_at(line: usize, msg: impl std::fmt::Display) -> IoError {
    IoError::malformed(FORMAT, format!("line {line}: {msg}"))
}

#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Chan {
    Pos(usize),
    Rot(usize),
}

#[derive(Debug)]
struct Joint {
    name: String,
    parent: Option<usize>,
    offset: Option<DVec3>,
    channels: Vec<Chan>,
    end_sites: usize,
    /// An `End Site`: a node for the chain's tip, not a joint.
    end_site: bool,
}

struct Tokens<'a> {
    items: Vec<(&'a str, usize)>,
    pos: usize,
}

impl<'a> Tokens<'a> {
    fn new(text: &'a str) -> Tokens<'a> {
        let items = text
            .lines()
            .enumerate()
            .flat_map(|(l, line)| line.split_ascii_whitespace().map(move |w| (w, l + 1)))
            .collect();
        Tokens { items, pos: 0 }
    }

    fn line(&self) -> usize {
        match self.items.get(self.pos) {
            Some(&(_, l)) => l,
            None => self.items.last().map_or(1, |&(_, l)| l),
        }
    }

    fn err(&self, msg: impl std::fmt::Display) -> IoError {
        err_at(self.line(), msg)
    }

    /// Line of the token consumed last.
    fn prev_line(&self) -> usize {
        self.pos
            .checked_sub(1)
            .and_then(|p| self.items.get(p))
            .map_or(1, |t| t.1)
    }

    fn peek(&self) -> Option<&'a str> {
        self.items.get(self.pos).map(|t| t.0)
    }

    fn next(&mut self, what: &str) -> Result<&'a str> {
        let t = self
            .peek()
            .ok_or_else(|| self.err(format!("file ends where {what} was expected")))?;
        self.pos += 1;
        Ok(t)
    }

    fn expect(&mut self, word: &str) -> Result<()> {
        let t = self.next(&format!("'{word}'"))?;
        if t != word {
            self.pos -= 1;
            return Err(self.err(format!("expected '{word}', found '{t}'")));
        }
        Ok(())
    }

    fn number(&mut self, what: &str) -> Result<f64> {
        let t = self.next(what)?;
        match t.parse::<f64>() {
            Ok(v) if v.is_finite() => Ok(v),
            Ok(_) => {
                self.pos -= 1;
                Err(self.err(format!("{what} '{t}' is NaN or infinite")))
            }
            Err(_) => {
                self.pos -= 1;
                Err(self.err(format!("{what} '{t}' is not a number")))
            }
        }
    }

    /// The rest of the current token's line, joined by single spaces (names with spaces).
    fn rest_of_line(&mut self, what: &str) -> Result<String> {
        let line = self.line();
        let first = self.next(what)?;
        let mut name = first.to_string();
        while let Some(&(w, l)) = self.items.get(self.pos) {
            if l != line || w == "{" {
                break;
            }
            name.push(' ');
            name.push_str(w);
            self.pos += 1;
        }
        Ok(name)
    }

    /// A `Key:` value where the colon may be attached or separate (`Frames: 10`,
    /// `Frames:10`).
    fn keyed(&mut self, key: &str) -> Result<&'a str> {
        let t = self.next(&format!("'{key}'"))?;
        if let Some(rest) = t.strip_prefix(key) {
            if !rest.is_empty() {
                return Ok(rest);
            }
            return self.next(&format!("the value of '{key}'"));
        }
        self.pos -= 1;
        Err(self.err(format!("expected '{key}', found '{t}'")))
    }
}

/// Parses a BVH file into a scene (see the module docs).
///
/// # Errors
/// [`IoError::Malformed`] naming the line: missing `HIERARCHY`/`MOTION`/braces, a `CHANNELS`
/// count that does not match the listed channels, a joint without `OFFSET`, a non-number, a
/// NaN or infinite value, a non-positive frame time, or a motion section whose value count is
/// not `Frames ×` the number of channels.
pub fn read(bytes: &[u8]) -> Result<Scene> {
    let text = String::from_utf8_lossy(bytes);
    let mut tk = Tokens::new(&text);
    tk.expect("HIERARCHY")?;
    let mut joints: Vec<Joint> = Vec::new();
    let mut stack: Vec<usize> = Vec::new();
    loop {
        let t = tk.next("ROOT, JOINT, End Site, OFFSET, CHANNELS, '}' or MOTION")?;
        let at = tk.prev_line();
        match t {
            "ROOT" | "JOINT" => {
                if (t == "ROOT") != stack.is_empty() {
                    tk.pos -= 1;
                    let msg = if t == "ROOT" {
                        "ROOT inside a joint"
                    } else {
                        "JOINT outside a ROOT"
                    };
                    return Err(tk.err(msg));
                }
                let name = tk.rest_of_line("a joint name")?;
                tk.expect("{")?;
                joints.push(Joint {
                    name,
                    parent: stack.last().copied(),
                    offset: None,
                    channels: Vec::new(),
                    end_sites: 0,
                    end_site: false,
                });
                stack.push(joints.len() - 1);
            }
            "End" => {
                tk.expect("Site")?;
                let Some(&parent) = stack.last() else {
                    return Err(err_at(at, "End Site outside a joint"));
                };
                tk.expect("{")?;
                tk.expect("OFFSET")?;
                let offset = read_vec3(&mut tk)?;
                tk.expect("}")?;
                let p = &mut joints[parent];
                p.end_sites += 1;
                let name = match p.end_sites {
                    1 => format!("{}{END_SITE_SUFFIX}", p.name),
                    k => format!("{}{END_SITE_SUFFIX}{k}", p.name),
                };
                joints.push(Joint {
                    name,
                    parent: Some(parent),
                    offset: Some(offset),
                    channels: Vec::new(),
                    end_sites: 0,
                    end_site: true,
                });
            }
            "OFFSET" => {
                let Some(&j) = stack.last() else {
                    return Err(err_at(at, "OFFSET outside a joint"));
                };
                joints[j].offset = Some(read_vec3(&mut tk)?);
            }
            "CHANNELS" => {
                let Some(&j) = stack.last() else {
                    return Err(err_at(at, "CHANNELS outside a joint"));
                };
                let n = tk.next("a channel count")?;
                let n: usize = n
                    .parse()
                    .map_err(|_| tk.err(format!("bad channel count '{n}'")))?;
                let mut chans = Vec::with_capacity(n.min(6));
                for k in 0..n {
                    let c = tk.peek().and_then(channel_kind).ok_or_else(|| {
                        err_at(at, format!("CHANNELS {n} lists only {k} channel names"))
                    })?;
                    tk.pos += 1;
                    chans.push(c);
                }
                joints[j].channels = chans;
            }
            "}" => {
                let Some(j) = stack.pop() else {
                    return Err(err_at(at, "unmatched '}'"));
                };
                if joints[j].offset.is_none() {
                    return Err(err_at(
                        at,
                        format!("joint '{}' has no OFFSET", joints[j].name),
                    ));
                }
            }
            "MOTION" if stack.is_empty() => break,
            "MOTION" => {
                return Err(err_at(
                    at,
                    "MOTION before all joints are closed (missing '}')",
                ))
            }
            other => {
                tk.pos -= 1;
                return Err(tk.err(format!("unexpected '{other}'")));
            }
        }
    }
    if joints.is_empty() {
        return Err(tk.err("the hierarchy has no ROOT"));
    }
    let frames_text = tk.keyed("Frames:")?;
    let frames: usize = frames_text
        .parse()
        .map_err(|_| tk.err(format!("bad frame count '{frames_text}'")))?;
    tk.expect("Frame")?;
    let dt_text = tk.keyed("Time:")?;
    let frame_time = match dt_text.parse::<f64>() {
        Ok(v) if v.is_finite() && v >= MIN_FRAME_TIME => v,
        Ok(v) if v.is_finite() && v > 0.0 => {
            return Err(tk.err(format!(
                "frame time {dt_text} s is below {MIN_FRAME_TIME} s (10,000 frames per second): \
                 its frames would collapse into one when sampled; write the capture's real \
                 frame time (e.g. 0.0083333 for 120 fps)"
            )))
        }
        _ => return Err(tk.err(format!("frame time '{dt_text}' must be a positive number"))),
    };
    let per_frame: usize = joints.iter().map(|j| j.channels.len()).sum();
    let available = tk.items.len() - tk.pos;
    match frames.checked_mul(per_frame) {
        Some(need) if need == available => {}
        Some(need) if need > available => {
            return Err(IoError::malformed(
                FORMAT,
                format!(
                    "line {}: MOTION has {available} values, but {frames} frames × \
                     {per_frame} channels need {need}",
                    tk.items.last().map_or(1, |t| t.1)
                ),
            ))
        }
        Some(need) => {
            tk.pos += need;
            return Err(tk.err(format!(
                "MOTION has more values than {frames} frames × {per_frame} channels"
            )));
        }
        None => return Err(tk.err(format!("frame count {frames} is too large"))),
    }
    let last_time = (frames.saturating_sub(1) as f64 * frame_time) as f32;
    if !last_time.is_finite() {
        return Err(tk.err("Frames × Frame Time is too large"));
    }
    let mut values = Vec::with_capacity(available);
    for _ in 0..available {
        values.push(tk.number("motion value")?);
    }
    build_scene(&joints, frames, frame_time, &values)
}

/// The shortest `Frame Time` read (seconds): faster than any motion-capture system records,
/// and far enough above f32's resolution that every frame keeps its own key time.
pub const MIN_FRAME_TIME: f64 = 1e-4;

fn read_vec3(tk: &mut Tokens<'_>) -> Result<DVec3> {
    Ok(DVec3::new(
        tk.number("offset")?,
        tk.number("offset")?,
        tk.number("offset")?,
    ))
}

fn channel_kind(word: &str) -> Option<Chan> {
    let axis = match word.as_bytes().first()? {
        b'X' | b'x' => 0,
        b'Y' | b'y' => 1,
        b'Z' | b'z' => 2,
        _ => return None,
    };
    match &word[1..] {
        "position" => Some(Chan::Pos(axis)),
        "rotation" => Some(Chan::Rot(axis)),
        _ => None,
    }
}

fn build_scene(joints: &[Joint], frames: usize, dt: f64, values: &[f64]) -> Result<Scene> {
    let n = joints.len();
    let mut nodes: Vec<Node> = joints
        .iter()
        .map(|j| Node {
            name: j.name.clone(),
            parent: j.parent,
            transform: Transform::from_translation(j.offset.unwrap_or_default().as_vec3()),
            ..Node::default()
        })
        .collect();
    for (k, j) in joints.iter().enumerate() {
        if let Some(p) = j.parent {
            nodes[p].children.push(k);
        }
    }
    // Rest world matrices: pure translations (parents come first).
    let mut rest_world = vec![Vec3::ZERO; n];
    for k in 0..n {
        let o = nodes[k].transform.translation;
        rest_world[k] = joints[k].parent.map_or(o, |p| rest_world[p] + o);
    }
    let skin = SkinDef {
        name: "bvh".into(),
        joints: (0..n).filter(|&k| !joints[k].end_site).collect(),
        inverse_bind: (0..n)
            .filter(|&k| !joints[k].end_site)
            .map(|k| Mat4::from_translation(-rest_world[k]))
            .collect(),
        skeleton: None,
    };
    let mut clips = Vec::new();
    let per_frame = values.len().checked_div(frames).unwrap_or(0);
    // No channel (or no frame) means no clip; this also keeps a huge `Frames:` with no
    // channels from allocating key times.
    if per_frame > 0 {
        let times: Vec<f32> = (0..frames).map(|k| (k as f64 * dt) as f32).collect();
        let mut channels = Vec::new();
        let mut first = 0;
        for (k, j) in joints.iter().enumerate() {
            let c = j.channels.len();
            let has_rot = j.channels.iter().any(|c| matches!(c, Chan::Rot(_)));
            let has_pos = j.channels.iter().any(|c| matches!(c, Chan::Pos(_)));
            let mut rot = Vec::with_capacity(if has_rot { 4 * frames } else { 0 });
            let mut pos = Vec::with_capacity(if has_pos { 3 * frames } else { 0 });
            let mut prev = DQuat::IDENTITY;
            for f in 0..frames {
                let row = &values[f * per_frame + first..f * per_frame + first + c];
                let mut q = DQuat::IDENTITY;
                let mut t = j.offset.unwrap_or_default();
                for (ch, &v) in j.channels.iter().zip(row) {
                    match *ch {
                        Chan::Pos(a) => t[a] += v,
                        Chan::Rot(a) => q *= DQuat::from_axis_angle(DVec3::AXES[a], v.to_radians()),
                    }
                }
                if q.dot(prev) < 0.0 {
                    q = -q;
                }
                prev = q;
                rot.extend(q.normalize().as_quat().to_array());
                pos.extend(t.as_vec3().to_array());
            }
            if has_rot {
                channels.push(linear(k, Property::Rotation, &times, rot));
            }
            if has_pos {
                channels.push(linear(k, Property::Translation, &times, pos));
            }
            first += c;
        }
        clips.push(Clip {
            name: CLIP_NAME.into(),
            channels,
        });
    }
    let scene = Scene {
        nodes,
        skins: vec![skin],
        clips,
        ..Scene::default()
    };
    scene.validate()?;
    Ok(scene)
}

fn linear(node: usize, property: Property, times: &[f32], values: Vec<f32>) -> Channel {
    Channel {
        node,
        property,
        interpolation: Interpolation::Linear,
        times: times.to_vec(),
        values,
    }
}

#[cfg(test)]
mod tests;
