//! Fixed-width bit fields, written most significant bit first, with every field booked in a
//! [`BitLedger`].

use super::{BitLedger, SyntaxClass};
use bitstream_io::{BigEndian, BitRead, BitReader, BitWrite, BitWriter};

/// Writes bit fields and books them.
pub struct BitSink {
    writer: BitWriter<Vec<u8>, BigEndian>,
    ledger: BitLedger,
}

impl Default for BitSink {
    fn default() -> Self {
        BitSink {
            writer: BitWriter::endian(Vec::new(), BigEndian),
            ledger: BitLedger::default(),
        }
    }
}

impl BitSink {
    /// Writes the low `bits` bits of `value` (bits ≤ 32).
    pub fn put(&mut self, class: SyntaxClass, bits: u32, value: u32) {
        if bits == 0 {
            return;
        }
        self.writer
            .write_unsigned_var(bits, value)
            .expect("writing to a Vec cannot fail");
        self.ledger.add(class, bits as u64);
    }

    /// Bits booked so far.
    pub fn ledger(&self) -> BitLedger {
        self.ledger
    }

    /// Pads to a byte boundary and returns the bytes and the ledger (padding is not booked).
    pub fn finish(mut self) -> (Vec<u8>, BitLedger) {
        self.writer
            .byte_align()
            .expect("writing to a Vec cannot fail");
        (self.writer.into_writer(), self.ledger)
    }
}

/// Reads bit fields from a byte slice.
pub struct BitSource<'a> {
    reader: BitReader<&'a [u8], BigEndian>,
}

impl<'a> BitSource<'a> {
    /// Reads from the start of `bytes`.
    pub fn new(bytes: &'a [u8]) -> Self {
        BitSource {
            reader: BitReader::endian(bytes, BigEndian),
        }
    }

    /// Reads a `bits`-bit field (bits ≤ 32); `None` when the bytes run out.
    pub fn get(&mut self, bits: u32) -> Option<u32> {
        if bits == 0 {
            return Some(0);
        }
        self.reader.read_unsigned_var(bits).ok()
    }
}

/// Bits needed to write any index below `n`: ⌈log2 n⌉ (0 for n ≤ 1).
pub fn index_bits(n: u64) -> u32 {
    if n <= 1 {
        0
    } else {
        64 - (n - 1).leading_zeros()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fields_round_trip_and_are_booked() {
        let mut sink = BitSink::default();
        sink.put(SyntaxClass::Geometry, 12, 0xabc);
        sink.put(SyntaxClass::Connectivity, 3, 5);
        sink.put(SyntaxClass::Geometry, 32, u32::MAX);
        let (bytes, ledger) = sink.finish();
        assert_eq!((ledger.geometry, ledger.connectivity), (44, 3));
        assert_eq!(bytes.len(), 6);
        let mut source = BitSource::new(&bytes);
        assert_eq!(source.get(12), Some(0xabc));
        assert_eq!(source.get(3), Some(5));
        assert_eq!(source.get(32), Some(u32::MAX));
        assert_eq!(source.get(8), None);
    }

    #[test]
    fn index_bits_is_ceil_log2() {
        let cases = [
            (0, 0),
            (1, 0),
            (2, 1),
            (3, 2),
            (4, 2),
            (5, 3),
            (34834, 16),
            (65536, 16),
        ];
        for (n, bits) in cases {
            assert_eq!(index_bits(n), bits, "n = {n}");
        }
    }
}
