//! One piece of a replacement library: its surface and its printable solid.

use anim::Mesh;

/// One printable piece.
#[derive(Debug, Clone, PartialEq)]
pub struct Piece {
    /// Identifier `<part>_<NN>` (the file stem of `pieces/<id>.stl`); the ID embossed on
    /// the back is [`piece_label`](crate::piece_label)`(part, index)`.
    pub id: String,
    /// Index of the part.
    pub part: usize,
    /// Index of the piece in its part's library (fixed pieces first).
    pub index: usize,
    /// The piece's surface in model units, with the part's topology and UVs.
    pub surface: Mesh,
    /// The printable solid in millimetres (with the part's plug shells, if any); `None` when
    /// the job was asked for surfaces alone ([`LibraryJobOptions::print`](crate::LibraryJobOptions::print)).
    pub solid: Option<Mesh>,
}
