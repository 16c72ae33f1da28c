//! The fixed pieces and printed backs of an earlier library's `pieces/` folder (the names
//! [`LibraryResult::files`](crate::LibraryResult::files) writes: `<part>_<NN>.obj`,
//! `<part>_back.obj`), picked by name from the OBJ files `tkio` read
//! (`tkio::obj::read_folder`).

use std::collections::BTreeMap;

use anim::Mesh;
use glam::Vec3;

/// Fixed pieces per part (vertex positions of each, in file-name order) and printed back
/// surfaces per part.
pub type PiecesFolder = (
    BTreeMap<String, Vec<Vec<Vec3>>>,
    BTreeMap<String, Vec<Vec3>>,
);

/// Whether a file stem of a `pieces/` folder is a piece (`<part>_<NN>`) or a back
/// (`<part>_back`) of one of the parts `names`: the files worth reading.
pub fn is_library_piece(stem: &str, names: &[String]) -> bool {
    names.iter().any(|n| piece_of(stem, n).is_some())
}

/// The fixed pieces and backs of the parts `names` among the `(stem, mesh)` files of a
/// `pieces/` folder (in file-name order).
pub fn library_pieces(names: &[String], files: Vec<(String, Mesh)>) -> PiecesFolder {
    let (mut fixed, mut backs) = (BTreeMap::new(), BTreeMap::new());
    for (stem, mesh) in files {
        for name in names {
            match piece_of(&stem, name) {
                Some(Kind::Piece) => fixed
                    .entry(name.clone())
                    .or_insert_with(Vec::new)
                    .push(mesh.positions.clone()),
                Some(Kind::Back) => {
                    backs.insert(name.clone(), mesh.positions.clone());
                }
                None => {}
            }
        }
    }
    (fixed, backs)
}

enum Kind {
    Piece,
    Back,
}

fn piece_of(stem: &str, name: &str) -> Option<Kind> {
    let rest = stem.strip_prefix(name)?.strip_prefix('_')?;
    if rest == "back" {
        Some(Kind::Back)
    } else if !rest.is_empty() && rest.chars().all(|c| c.is_ascii_digit()) {
        Some(Kind::Piece)
    } else {
        None
    }
}
