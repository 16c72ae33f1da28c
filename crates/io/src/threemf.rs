//! 3MF (3D Manufacturing Format core specification 1.3) writer: one package with every
//! printable solid as a named mesh object, millimetres, one base material (display colour)
//! per group of objects, and a build item per object placing it on a build plate.
//!
//! Why an own writer: the `threemf` crate (Fornjot's, 0.7) and its fork `threemf2` write
//! mesh objects and build items, but they bring a second major version of `zip` and
//! `quick-xml` into the tree for what is here ~150 lines of escaped text; the package itself
//! is written with the `zip` crate the workspace already builds (through `openusd`). The
//! model XML is written by hand with every attribute value escaped ([`escape`]).
//!
//! Read back by lib3mf and trimesh in CI (`.ci/meshlab.sh`).

use std::fmt::Write as _;
use std::io::{Cursor, Write};

use anim::Mesh;

use crate::{IoError, Result};

/// The core specification's XML namespace.
const CORE_NS: &str = "http://schemas.microsoft.com/3dmanufacturing/core/2015/02";

/// A base material: a name and its display colour (sRGB with alpha).
#[derive(Debug, Clone, PartialEq)]
pub struct BaseMaterial {
    /// Name shown by slicers.
    pub name: String,
    /// `#RRGGBBAA`.
    pub color: [u8; 4],
}

/// One mesh object and where its build item puts it.
#[derive(Debug, Clone)]
pub struct Object<'a> {
    /// Object name (the piece ID).
    pub name: &'a str,
    /// Closed, outward-oriented triangle mesh in millimetres.
    pub mesh: &'a Mesh,
    /// Index into [`Model::materials`].
    pub material: usize,
    /// Translation of the build item (millimetres).
    pub translation: [f32; 3],
}

/// A 3MF model: materials and objects, each object one build item.
#[derive(Debug, Clone, Default)]
pub struct Model<'a> {
    /// Base materials (one `<basematerials>` group).
    pub materials: Vec<BaseMaterial>,
    /// Objects in build order.
    pub objects: Vec<Object<'a>>,
    /// `<metadata name="Title">`.
    pub title: String,
}

/// Escapes text for an XML attribute value or element text.
fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters are not allowed in XML 1.0.
            c if (c as u32) < 0x20 && !matches!(c, '\t' | '\n' | '\r') => out.push(' '),
            c => out.push(c),
        }
    }
    out
}

/// The model part `3D/3dmodel.model`.
///
/// # Errors
/// [`IoError`] when an object names a missing material or a missing vertex, or has a
/// non-finite coordinate (3MF numbers must be finite).
pub fn model_xml(model: &Model<'_>) -> Result<String> {
    let bad = |what: String| IoError::encode("3MF", what);
    let mut x = String::new();
    // `write!` into a String cannot fail.
    let _ = write!(
        x,
        "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<model unit=\"millimeter\" xml:lang=\"en-US\" xmlns=\"{CORE_NS}\">\n <metadata name=\"Title\">{}</metadata>\n <metadata name=\"Application\">toonkit</metadata>\n <resources>\n",
        escape(&model.title)
    );
    let material_id = 1;
    if !model.materials.is_empty() {
        let _ = writeln!(x, "  <basematerials id=\"{material_id}\">");
        for m in &model.materials {
            let [r, g, b, a] = m.color;
            let _ = writeln!(
                x,
                "   <base name=\"{}\" displaycolor=\"#{r:02X}{g:02X}{b:02X}{a:02X}\"/>",
                escape(&m.name)
            );
        }
        x.push_str("  </basematerials>\n");
    }
    for (i, o) in model.objects.iter().enumerate() {
        let id = i + 2;
        if o.material >= model.materials.len() {
            return Err(bad(format!(
                "object {} uses material {} of {}",
                o.name,
                o.material,
                model.materials.len()
            )));
        }
        let _ = writeln!(
            x,
            "  <object id=\"{id}\" type=\"model\" name=\"{}\" pid=\"{material_id}\" pindex=\"{}\">\n   <mesh>\n    <vertices>",
            escape(o.name),
            o.material
        );
        for p in &o.mesh.positions {
            if !p.is_finite() {
                return Err(bad(format!("object {} has a non-finite vertex", o.name)));
            }
            let _ = writeln!(
                x,
                "     <vertex x=\"{}\" y=\"{}\" z=\"{}\"/>",
                p.x, p.y, p.z
            );
        }
        x.push_str("    </vertices>\n    <triangles>\n");
        let n = o.mesh.positions.len() as u32;
        for t in &o.mesh.triangles {
            if t.iter().any(|&v| v >= n) {
                return Err(bad(format!("object {} indexes a missing vertex", o.name)));
            }
            let _ = writeln!(
                x,
                "     <triangle v1=\"{}\" v2=\"{}\" v3=\"{}\"/>",
                t[0], t[1], t[2]
            );
        }
        x.push_str("    </triangles>\n   </mesh>\n  </object>\n");
    }
    x.push_str(" </resources>\n <build>\n");
    for (i, o) in model.objects.iter().enumerate() {
        let [tx, ty, tz] = o.translation;
        if !(tx.is_finite() && ty.is_finite() && tz.is_finite()) {
            return Err(bad(format!("object {} has a non-finite placement", o.name)));
        }
        let _ = writeln!(
            x,
            "  <item objectid=\"{}\" partnumber=\"{}\" transform=\"1 0 0 0 1 0 0 0 1 {tx} {ty} {tz}\"/>",
            i + 2,
            escape(o.name)
        );
    }
    x.push_str(" </build>\n</model>\n");
    Ok(x)
}

/// The whole `.3mf` package (a ZIP archive with the content types, the package
/// relationship to the model, and the model).
///
/// # Errors
/// As [`model_xml`], or when the archive cannot be written.
pub fn encode(model: &Model<'_>) -> Result<Vec<u8>> {
    let xml = model_xml(model)?;
    let zerr = |e: zip::result::ZipError| IoError::encode("3MF", e.to_string());
    let ioerr = |e: std::io::Error| IoError::encode("3MF", e.to_string());
    let mut zip = zip::ZipWriter::new(Cursor::new(Vec::new()));
    // A fixed timestamp: the same model gives the same bytes.
    let opts = zip::write::SimpleFileOptions::default()
        .compression_method(zip::CompressionMethod::Deflated)
        .last_modified_time(zip::DateTime::default());
    let parts: [(&str, &str); 3] = [
        (
            "[Content_Types].xml",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Types xmlns=\"http://schemas.openxmlformats.org/package/2006/content-types\">\n <Default Extension=\"rels\" ContentType=\"application/vnd.openxmlformats-package.relationships+xml\"/>\n <Default Extension=\"model\" ContentType=\"application/vnd.ms-package.3dmanufacturing-3dmodel+xml\"/>\n</Types>\n",
        ),
        (
            "_rels/.rels",
            "<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n<Relationships xmlns=\"http://schemas.openxmlformats.org/package/2006/relationships\">\n <Relationship Target=\"/3D/3dmodel.model\" Id=\"rel0\" Type=\"http://schemas.microsoft.com/3dmanufacturing/2013/01/3dmodel\"/>\n</Relationships>\n",
        ),
        ("3D/3dmodel.model", &xml),
    ];
    for (name, text) in parts {
        zip.start_file(name, opts).map_err(zerr)?;
        zip.write_all(text.as_bytes()).map_err(ioerr)?;
    }
    Ok(zip.finish().map_err(zerr)?.into_inner())
}

#[cfg(test)]
mod tests {
    use super::*;
    use glam::Vec3;

    fn tetrahedron() -> Mesh {
        Mesh::new(
            "t",
            vec![Vec3::ZERO, Vec3::X, Vec3::Y, Vec3::Z],
            vec![[0, 2, 1], [0, 1, 3], [0, 3, 2], [1, 2, 3]],
        )
    }

    #[test]
    fn names_are_escaped_and_every_object_is_built() {
        let t = tetrahedron();
        let model = Model {
            materials: vec![BaseMaterial {
                name: "a<b".into(),
                color: [255, 0, 16, 255],
            }],
            objects: vec![
                Object {
                    name: "x\"&y",
                    mesh: &t,
                    material: 0,
                    translation: [1.0, 2.0, 0.0],
                },
                Object {
                    name: "z",
                    mesh: &t,
                    material: 0,
                    translation: [0.0; 3],
                },
            ],
            title: "lib".into(),
        };
        let xml = model_xml(&model).unwrap();
        assert!(xml.contains("name=\"x&quot;&amp;y\""));
        assert!(xml.contains("name=\"a&lt;b\" displaycolor=\"#FF0010FF\""));
        assert_eq!(xml.matches("<item ").count(), 2);
        assert_eq!(xml.matches("<vertex ").count(), 8);
        assert!(xml.contains("transform=\"1 0 0 0 1 0 0 0 1 1 2 0\""));
        let bytes = encode(&model).unwrap();
        assert_eq!(&bytes[..2], b"PK");
        assert_eq!(bytes, encode(&model).unwrap(), "deterministic");
    }

    #[test]
    fn refuses_missing_materials_vertices_and_nan() {
        let t = tetrahedron();
        let mut bad = t.clone();
        bad.triangles.push([0, 1, 9]);
        let mut nan = t.clone();
        nan.positions[0].x = f32::NAN;
        for (mesh, material) in [(&t, 1), (&bad, 0), (&nan, 0)] {
            let model = Model {
                materials: vec![BaseMaterial {
                    name: "m".into(),
                    color: [0; 4],
                }],
                objects: vec![Object {
                    name: "o",
                    mesh,
                    material,
                    translation: [0.0; 3],
                }],
                title: String::new(),
            };
            assert!(model_xml(&model).is_err());
        }
    }
}
