//! Format detection by content (extension only as a tie-breaker) and one-call loading.

use std::path::{Path, PathBuf};

use anim::{Mesh, MeshAnimation, Scene, DEFAULT_FPS};

use crate::{read_file, IoError, Result};

/// A file format toonkit reads or writes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Format {
    /// glTF JSON (`.gltf`).
    Gltf,
    /// Binary glTF (`.glb`).
    Glb,
    /// Wavefront OBJ (a single mesh, or one frame of a sequence).
    Obj,
    /// PC2 point cache.
    Pc2,
    /// MDD point cache.
    Mdd,
    /// BVH motion capture.
    Bvh,
    /// STL (binary or ASCII).
    Stl,
    /// NumPy array.
    Npy,
    /// USD text layer (`.usda`): written by toonkit, never read.
    Usda,
    /// USD binary crate file (`.usdc`): written by toonkit, never read.
    Usdc,
    /// USDZ package (`.usdz`, one `.usdc` layer): written by toonkit, never read.
    Usdz,
    /// Alembic archive (`.abc`, Ogawa): written by toonkit; [`crate::abc::read`] reads it back.
    Abc,
    /// Autodesk FBX (binary or ASCII, 6.x–7.x): read only.
    Fbx,
}

impl Format {
    /// The formats that hold a whole scene of several meshes whose topology may change per
    /// frame (a stylized smear, motion lines), in the order messages list them.
    pub const SCENES: [Format; 5] = [
        Format::Glb,
        Format::Usda,
        Format::Usdc,
        Format::Usdz,
        Format::Abc,
    ];

    /// The formats a deforming mesh (a point cache, a flipbook) is written as by
    /// [`save`](crate::save), in the order messages list them.
    pub const MESH_ANIMATIONS: [Format; 10] = [
        Format::Glb,
        Format::Usda,
        Format::Usdc,
        Format::Usdz,
        Format::Abc,
        Format::Pc2,
        Format::Mdd,
        Format::Obj,
        Format::Stl,
        Format::Npy,
    ];

    /// Whether the format is one of [`Format::SCENES`].
    pub fn holds_scenes(self) -> bool {
        Format::SCENES.contains(&self)
    }

    /// The extensions of `formats` as a message lists them: ".glb, .usda or .abc".
    pub fn list(formats: &[Format]) -> String {
        let dotted: Vec<String> = formats
            .iter()
            .map(|f| format!(".{}", f.extension()))
            .collect();
        match dotted.split_last() {
            None => String::new(),
            Some((last, [])) => last.clone(),
            Some((last, rest)) => format!("{} or {last}", rest.join(", ")),
        }
    }

    /// Whether a file of the format holds one frame only (`.obj`, `.stl`): several frames are
    /// written as a numbered sequence ([`Layout::Sequence`](crate::Layout::Sequence)) or
    /// refused ([`IoError::FramesDoNotFit`](crate::IoError::FramesDoNotFit)).
    pub fn holds_one_frame(self) -> bool {
        matches!(self, Format::Obj | Format::Stl)
    }

    /// The usual lower-case extension of the format, without the dot.
    pub fn extension(self) -> &'static str {
        match self {
            Format::Gltf => "gltf",
            Format::Glb => "glb",
            Format::Obj => "obj",
            Format::Pc2 => "pc2",
            Format::Mdd => "mdd",
            Format::Bvh => "bvh",
            Format::Stl => "stl",
            Format::Npy => "npy",
            Format::Usda => "usda",
            Format::Usdc => "usdc",
            Format::Usdz => "usdz",
            Format::Abc => "abc",
            Format::Fbx => "fbx",
        }
    }

    /// Format from a file extension (for outputs).
    pub fn from_extension(path: &Path) -> Option<Format> {
        let ext = path.extension()?.to_str()?.to_ascii_lowercase();
        Some(match ext.as_str() {
            "gltf" => Format::Gltf,
            "glb" => Format::Glb,
            "obj" => Format::Obj,
            "pc2" => Format::Pc2,
            "mdd" => Format::Mdd,
            "bvh" => Format::Bvh,
            "stl" => Format::Stl,
            "npy" => Format::Npy,
            "usda" => Format::Usda,
            "usdc" => Format::Usdc,
            "usdz" => Format::Usdz,
            "abc" => Format::Abc,
            "fbx" => Format::Fbx,
            _ => return None,
        })
    }
}

/// Detects the format of `bytes` by content; `path`'s extension breaks ties (MDD has no
/// magic number; binary STL may start with "solid").
pub fn detect(bytes: &[u8], path: &Path) -> Option<Format> {
    let ext = Format::from_extension(path);
    if bytes.starts_with(b"glTF") {
        return Some(Format::Glb);
    }
    if bytes.starts_with(b"Kaydara FBX Binary") {
        return Some(Format::Fbx);
    }
    if bytes.starts_with(b"POINTCACHE2\0") {
        return Some(Format::Pc2);
    }
    if bytes.starts_with(b"\x93NUMPY") {
        return Some(Format::Npy);
    }
    if bytes.starts_with(b"#usda") {
        return Some(Format::Usda);
    }
    if bytes.starts_with(b"PXR-USDC") {
        return Some(Format::Usdc);
    }
    if crate::abc::is_ogawa(bytes) {
        return Some(Format::Abc);
    }
    if bytes.starts_with(b"PK\x03\x04") && ext == Some(Format::Usdz) {
        return Some(Format::Usdz);
    }
    if bytes.len() >= 84 {
        let n = u32::from_le_bytes([bytes[80], bytes[81], bytes[82], bytes[83]]) as u64;
        if 84 + 50 * n == bytes.len() as u64 && (n > 0 || ext == Some(Format::Stl)) {
            return Some(Format::Stl);
        }
    }
    if bytes.len() >= 8 {
        let f = i32::from_be_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]) as i128;
        let p = i32::from_be_bytes([bytes[4], bytes[5], bytes[6], bytes[7]]) as i128;
        if f > 0 && p > 0 && 8 + f * 4 + f * p * 12 == bytes.len() as i128 {
            return Some(Format::Mdd);
        }
    }
    let head = &bytes[..bytes.len().min(4096)];
    let text = String::from_utf8_lossy(head);
    let t = text.trim_start_matches('\u{feff}').trim_start();
    if t.starts_with('{') {
        return Some(Format::Gltf);
    }
    if t.starts_with("; FBX") || t.starts_with("FBXHeaderExtension") {
        return Some(Format::Fbx);
    }
    if t.starts_with("HIERARCHY") {
        return Some(Format::Bvh);
    }
    if t.starts_with("solid") && text.contains("facet") {
        return Some(Format::Stl);
    }
    if text.lines().any(|l| {
        let l = l.trim_start();
        l.starts_with("v ") || l.starts_with("f ") || l.starts_with("o ") || l.starts_with("mtllib")
    }) {
        return Some(Format::Obj);
    }
    ext
}

/// What a file holds.
#[derive(Debug, Clone)]
pub enum Loaded {
    /// A scene with hierarchy, skins, morphs, clips (glTF, BVH).
    Scene(Box<Scene>),
    /// A point cache (PC2, MDD, OBJ sequence).
    Cache(MeshAnimation),
    /// A static mesh (OBJ, STL).
    Mesh(Mesh),
}

/// Options for [`load`].
#[derive(Debug, Clone)]
pub struct LoadOptions {
    /// Frame rate given to point caches that carry none (PC2 and OBJ sequences).
    pub fps: f32,
    /// Rest mesh for PC2/MDD; default: the same-stem `.obj` beside the cache, else
    /// `rest.obj` in its folder.
    pub rest: Option<PathBuf>,
    /// Scene of a multi-scene glTF file, by name or index (default: the file's default scene).
    pub scene: Option<String>,
}

impl Default for LoadOptions {
    fn default() -> Self {
        LoadOptions {
            fps: DEFAULT_FPS,
            rest: None,
            scene: None,
        }
    }
}

/// Reads any supported animation file, detecting its format by content.
///
/// # Errors
/// One-line errors naming the file: unreadable, unknown format, malformed content.
pub fn load(path: &Path, options: &LoadOptions) -> Result<Loaded> {
    load_with_notes(path, options).map(|(loaded, _)| loaded)
}

/// [`load`], plus one line per thing worth telling the user about the file: glTF extensions
/// accepted and what was done with them, the scene read, FBX units and axes converted.
///
/// # Errors
/// As [`load`].
pub fn load_with_notes(path: &Path, options: &LoadOptions) -> Result<(Loaded, Vec<String>)> {
    let bytes = read_file(path)?;
    let format = detect(&bytes, path).ok_or_else(|| {
        IoError::unsupported(
            "unrecognized file format (expected glTF, GLB, FBX, OBJ, PC2, MDD, BVH or STL)",
        )
        .at(path)
    })?;
    load_as(path, &bytes, format, options).map_err(|e| e.at(path))
}

fn load_as(
    path: &Path,
    bytes: &[u8],
    format: Format,
    options: &LoadOptions,
) -> Result<(Loaded, Vec<String>)> {
    let scene = |(s, notes): (Scene, Vec<String>)| (Loaded::Scene(Box::new(s)), notes);
    let plain = |l: Loaded| (l, Vec::new());
    match format {
        Format::Glb | Format::Gltf => {
            crate::gltf::read::read_full(bytes, path.parent(), options.scene.as_deref()).map(scene)
        }
        #[cfg(feature = "fbx")]
        Format::Fbx => crate::fbx::read(bytes).map(scene),
        #[cfg(not(feature = "fbx"))]
        Format::Fbx => Err(IoError::unsupported(
            "FBX support was not compiled in (feature \"fbx\")",
        )),
        Format::Bvh => crate::bvh::read(bytes).map(|s| plain(Loaded::Scene(Box::new(s)))),
        #[cfg(feature = "obj")]
        Format::Obj => {
            let seq = crate::obj::sequence_paths(path).unwrap_or_default();
            if seq.len() > 1 {
                crate::obj::read_sequence(&seq, options.fps).map(|c| plain(Loaded::Cache(c)))
            } else {
                crate::obj::read(bytes).map(|m| plain(Loaded::Mesh(m)))
            }
        }
        #[cfg(feature = "stl")]
        Format::Stl => crate::stl::read(bytes).map(|m| plain(Loaded::Mesh(m))),
        Format::Pc2 | Format::Mdd => {
            let rest = rest_mesh(path, options)?;
            if format == Format::Pc2 {
                crate::pc2::read(bytes, rest, options.fps).map(|c| plain(Loaded::Cache(c)))
            } else {
                crate::mdd::read(bytes, rest, options.fps).map(|c| plain(Loaded::Cache(c)))
            }
        }
        Format::Npy => Err(IoError::unsupported("a .npy array is not an animation")),
        Format::Usda | Format::Usdc | Format::Usdz => Err(IoError::unsupported(
            "USD input is not supported (toonkit only writes .usda/.usdc/.usdz; export glTF/GLB instead)",
        )),
        Format::Abc => Err(IoError::unsupported(
            "Alembic input is not supported (toonkit only writes .abc; export glTF/GLB instead)",
        )),
        #[allow(unreachable_patterns)]
        _ => Err(IoError::unsupported(format!(
            "{format:?} support was not compiled in"
        ))),
    }
}

#[cfg(feature = "obj")]
fn rest_mesh(path: &Path, options: &LoadOptions) -> Result<Mesh> {
    let candidates: Vec<PathBuf> = match &options.rest {
        Some(r) => vec![r.clone()],
        None => vec![path.with_extension("obj"), path.with_file_name("rest.obj")],
    };
    for c in &candidates {
        if c.is_file() {
            let bytes = read_file(c)?;
            return crate::obj::read(&bytes).map_err(|e| e.at(c));
        }
    }
    Err(IoError::unsupported(format!(
        "a point cache needs its rest mesh: none of {} exists (give one with --rest FILE.obj)",
        candidates
            .iter()
            .map(|c| c.display().to_string())
            .collect::<Vec<_>>()
            .join(", ")
    )))
}

#[cfg(not(feature = "obj"))]
fn rest_mesh(_: &Path, _: &LoadOptions) -> Result<Mesh> {
    Err(IoError::unsupported(
        "point caches need the \"obj\" feature for their rest mesh",
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Messages list the formats in the words users type (every scene format once, the
    /// extension that names it), so the CLI's refusals take their lists from here.
    #[test]
    fn format_lists_read_as_messages_and_name_formats_by_their_extension() {
        assert_eq!(
            Format::list(&Format::SCENES),
            ".glb, .usda, .usdc, .usdz or .abc"
        );
        assert_eq!(Format::list(&[Format::Obj]), ".obj");
        assert_eq!(Format::list(&[]), "");
        for f in Format::SCENES {
            let path = PathBuf::from(format!("out.{}", f.extension()));
            assert_eq!(Format::from_extension(&path), Some(f));
            assert!(f.holds_scenes());
        }
        assert!(!Format::Obj.holds_scenes());
        assert_eq!(
            Format::list(&Format::MESH_ANIMATIONS),
            ".glb, .usda, .usdc, .usdz, .abc, .pc2, .mdd, .obj, .stl or .npy"
        );
    }
}
