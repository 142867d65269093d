//! Bits without meshes: a bit ledger that classes every syntax element as connectivity or
//! geometry, bit-level writers and readers over it (`bits`), adaptive binary arithmetic coding
//! (`arith`), canonical Huffman codes (`huffman`) and LEB128 variable-length integers
//! (`varint`).

pub mod arith;
pub mod bits;
pub mod huffman;
pub mod varint;

pub use bits::{BitSink, BitSource};

/// What a syntax element describes, for the rate split of docs/CONTRACT.md §5.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SyntaxClass {
    /// Which vertices form which faces (and, for progressive codecs, how they split).
    Connectivity,
    /// Where vertices are.
    Geometry,
}

/// Bits spent per syntax class.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct BitLedger {
    /// Bits of connectivity elements.
    pub connectivity: u64,
    /// Bits of geometry elements.
    pub geometry: u64,
}

impl BitLedger {
    /// Books `bits` to `class`.
    pub fn add(&mut self, class: SyntaxClass, bits: u64) {
        match class {
            SyntaxClass::Connectivity => self.connectivity += bits,
            SyntaxClass::Geometry => self.geometry += bits,
        }
    }

    /// All booked bits.
    pub fn total(&self) -> u64 {
        self.connectivity + self.geometry
    }
}
