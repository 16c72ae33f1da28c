//! The Ogawa container under Alembic: a tree of *groups* (lists of children) and *data*
//! blocks (byte strings), addressed by absolute file offsets.
//!
//! Layout (all integers little-endian):
//! * header, 16 bytes: `Ogawa`, a frozen flag (`0xff` once the file is complete), the format
//!   version `0x00 0x01`, then the `u64` offset of the root group;
//! * group at offset `o`: `u64` child count `n`, then `n` `u64` child references. A reference
//!   with the top bit set is a data block at `reference & !top bit` (`0x8000…0` alone is the
//!   empty data block); otherwise it is a group (`0` is the empty group);
//! * data block at offset `o`: `u64` size, then the bytes.
//!
//! The writer appends blocks bottom-up (children before their group) and writes the root
//! group last, so the file is one pass over a growing buffer.

use crate::{IoError, Result};

/// Magic bytes of an Ogawa file.
pub(crate) const MAGIC: &[u8; 5] = b"Ogawa";
/// Top bit of a child reference: the child is a data block.
const DATA_BIT: u64 = 1 << 63;
/// Size of the file header.
const HEADER: usize = 16;

/// A reference to a written block, as stored in its parent group.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub(crate) struct Ref(u64);

/// An Ogawa file being written.
#[derive(Debug)]
pub(crate) struct Writer {
    out: Vec<u8>,
}

impl Writer {
    /// An empty file (header not yet valid), with room for `capacity` bytes.
    pub(crate) fn with_capacity(capacity: usize) -> Writer {
        let mut out = Vec::with_capacity(capacity + HEADER);
        out.extend_from_slice(MAGIC);
        out.extend_from_slice(&[0x00, 0x00, 0x01]);
        out.extend_from_slice(&0u64.to_le_bytes());
        Writer { out }
    }

    /// Appends a data block made of `parts` (concatenated).
    pub(crate) fn data(&mut self, parts: &[&[u8]]) -> Ref {
        let size: usize = parts.iter().map(|p| p.len()).sum();
        if size == 0 {
            return Ref(DATA_BIT);
        }
        let at = self.out.len() as u64;
        self.out.extend_from_slice(&(size as u64).to_le_bytes());
        for p in parts {
            self.out.extend_from_slice(p);
        }
        Ref(at | DATA_BIT)
    }

    /// Appends a group holding `children`, in order.
    pub(crate) fn group(&mut self, children: &[Ref]) -> Ref {
        let at = self.out.len() as u64;
        self.out
            .extend_from_slice(&(children.len() as u64).to_le_bytes());
        for c in children {
            self.out.extend_from_slice(&c.0.to_le_bytes());
        }
        Ref(at)
    }

    /// Sets the root group, marks the file complete and returns its bytes.
    pub(crate) fn finish(mut self, root: Ref) -> Vec<u8> {
        self.out[8..16].copy_from_slice(&root.0.to_le_bytes());
        self.out[5] = 0xff;
        self.out
    }
}

/// A node read back from an Ogawa file.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub(crate) enum Node {
    /// A group at this offset (`0`: the empty group).
    Group(u64),
    /// A data block at this offset (`None`: the empty block).
    Data(Option<u64>),
}

/// Read access to an Ogawa file held in memory. Every offset and size is checked: a bad
/// file gives an error, never a panic.
#[derive(Debug, Clone, Copy)]
pub(crate) struct Reader<'a> {
    bytes: &'a [u8],
}

impl<'a> Reader<'a> {
    /// Checks the header; returns the reader and the root group.
    pub(crate) fn open(bytes: &'a [u8]) -> Result<(Reader<'a>, Node)> {
        if bytes.len() < HEADER || &bytes[..5] != MAGIC {
            return Err(malformed("not an Ogawa file (no 'Ogawa' header)"));
        }
        if bytes[5] != 0xff {
            return Err(malformed(
                "the file was not closed cleanly while being written",
            ));
        }
        if bytes[6..8] != [0x00, 0x01] {
            return Err(malformed("unsupported Ogawa version"));
        }
        let reader = Reader { bytes };
        let root = reader.u64_at(8)?;
        Ok((reader, Node::Group(root)))
    }

    fn u64_at(&self, at: u64) -> Result<u64> {
        let at = usize::try_from(at).map_err(|_| malformed("offset out of range"))?;
        let end = at.checked_add(8).filter(|&e| e <= self.bytes.len());
        let Some(end) = end else {
            return Err(malformed(format!(
                "offset {at} is past the end of the file"
            )));
        };
        let mut b = [0u8; 8];
        b.copy_from_slice(&self.bytes[at..end]);
        Ok(u64::from_le_bytes(b))
    }

    /// The children of a group.
    pub(crate) fn children(&self, node: Node) -> Result<Vec<Node>> {
        let Node::Group(at) = node else {
            return Err(malformed("expected a group, found data"));
        };
        if at == 0 {
            return Ok(Vec::new());
        }
        let n = self.u64_at(at)?;
        if n > (self.bytes.len() as u64) / 8 {
            return Err(malformed(format!("group at {at} claims {n} children")));
        }
        (0..n)
            .map(|i| {
                let r = self.u64_at(at + 8 + 8 * i)?;
                Ok(if r & DATA_BIT != 0 {
                    let o = r & !DATA_BIT;
                    Node::Data((o != 0).then_some(o))
                } else {
                    Node::Group(r)
                })
            })
            .collect()
    }

    /// The bytes of a data block.
    pub(crate) fn data(&self, node: Node) -> Result<&'a [u8]> {
        let at = match node {
            Node::Data(None) => return Ok(&[]),
            Node::Data(Some(at)) => at,
            Node::Group(_) => return Err(malformed("expected data, found a group")),
        };
        let size = self.u64_at(at)?;
        let start = at as usize + 8;
        let end = usize::try_from(size)
            .ok()
            .and_then(|s| start.checked_add(s))
            .filter(|&e| e <= self.bytes.len())
            .ok_or_else(|| malformed(format!("data block at {at} runs past the end")))?;
        Ok(&self.bytes[start..end])
    }
}

/// An error about a malformed Alembic file.
pub(crate) fn malformed(message: impl Into<String>) -> IoError {
    IoError::malformed("Alembic", message)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn tree_round_trips() {
        let mut w = Writer::with_capacity(0);
        let a = w.data(&[b"ab", b"c"]);
        let e = w.data(&[]);
        let g = w.group(&[a, e]);
        let root = w.group(&[g, a, Ref(0)]);
        let bytes = w.finish(root);
        let (r, root) = Reader::open(&bytes).unwrap();
        let kids = r.children(root).unwrap();
        assert_eq!(kids.len(), 3);
        assert_eq!(r.data(kids[1]).unwrap(), b"abc");
        assert_eq!(r.children(kids[2]).unwrap(), vec![]);
        let inner = r.children(kids[0]).unwrap();
        assert_eq!(r.data(inner[0]).unwrap(), b"abc");
        assert_eq!(r.data(inner[1]).unwrap(), b"");
    }

    #[test]
    fn truncated_files_are_errors() {
        let mut w = Writer::with_capacity(0);
        let a = w.data(&[b"abcdef"]);
        let root = w.group(&[a]);
        let bytes = w.finish(root);
        for len in 0..bytes.len() {
            let cut = &bytes[..len];
            let ok = Reader::open(cut).and_then(|(r, root)| {
                let kids = r.children(root)?;
                kids.iter().try_for_each(|k| r.data(*k).map(|_| ()))
            });
            assert!(ok.is_err(), "truncated at {len}");
        }
    }
}
