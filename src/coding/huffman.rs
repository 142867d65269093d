//! Canonical Huffman codes: built from symbol counts (length-limited), written and read as bit
//! fields. Codes are canonical, so a table is fully described by its code lengths.

use super::{BitSink, BitSource, SyntaxClass};

/// Longest codeword allowed.
pub const MAX_CODE_LENGTH: u8 = 24;
/// Bits of one code length in a written table.
pub const LENGTH_FIELD_BITS: u32 = 5;

/// A canonical prefix code over symbols `0..lengths.len()`; a length of 0 means "no codeword".
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Huffman {
    lengths: Vec<u8>,
    codes: Vec<u32>,
    /// Symbols sorted by (length, symbol): the canonical order.
    sorted: Vec<u16>,
    /// For each length L: first canonical code of that length and index of its first symbol.
    first_code: [u32; MAX_CODE_LENGTH as usize + 1],
    first_index: [u32; MAX_CODE_LENGTH as usize + 1],
    count: [u32; MAX_CODE_LENGTH as usize + 1],
}

impl Huffman {
    /// The canonical code with the given lengths (each ≤ [`MAX_CODE_LENGTH`], Kraft sum ≤ 1).
    pub fn from_lengths(lengths: &[u8]) -> Huffman {
        let mut count = [0u32; MAX_CODE_LENGTH as usize + 1];
        for &l in lengths {
            assert!(l <= MAX_CODE_LENGTH, "code length {l} too long");
            if l > 0 {
                count[l as usize] += 1;
            }
        }
        let mut sorted: Vec<u16> = (0..lengths.len() as u16)
            .filter(|&s| lengths[s as usize] > 0)
            .collect();
        sorted.sort_by_key(|&s| (lengths[s as usize], s));
        let mut first_code = [0u32; MAX_CODE_LENGTH as usize + 1];
        let mut first_index = [0u32; MAX_CODE_LENGTH as usize + 1];
        let (mut code, mut index) = (0u32, 0u32);
        for l in 1..=MAX_CODE_LENGTH as usize {
            code <<= 1;
            first_code[l] = code;
            first_index[l] = index;
            code += count[l];
            index += count[l];
            assert!(code <= 1 << l, "code lengths break the Kraft inequality");
        }
        let mut codes = vec![0u32; lengths.len()];
        for (rank, &s) in sorted.iter().enumerate() {
            let l = lengths[s as usize] as usize;
            codes[s as usize] = first_code[l] + (rank as u32 - first_index[l]);
        }
        Huffman {
            lengths: lengths.to_vec(),
            codes,
            sorted,
            first_code,
            first_index,
            count,
        }
    }

    /// Code lengths of a Huffman code for `counts`, every symbol given a codeword, none longer
    /// than [`MAX_CODE_LENGTH`] (counts are flattened until the longest fits).
    pub fn lengths_for(counts: &[u64]) -> Vec<u8> {
        let mut weights: Vec<u64> = counts.iter().map(|&c| c.max(1)).collect();
        loop {
            let lengths = huffman_lengths(&weights);
            if lengths.iter().all(|&l| l <= MAX_CODE_LENGTH) {
                return lengths;
            }
            let total: u64 = weights.iter().sum();
            let floor = (total >> (MAX_CODE_LENGTH - 4)).max(1);
            weights
                .iter_mut()
                .for_each(|w| *w = (*w).max(floor) + floor);
        }
    }

    /// Writes the table: each symbol's code length in [`LENGTH_FIELD_BITS`] bits.
    pub fn write_lengths(&self, sink: &mut BitSink, class: SyntaxClass) {
        for &l in &self.lengths {
            sink.put(class, LENGTH_FIELD_BITS, l as u32);
        }
    }

    /// Reads a table of `symbols` code lengths as [`Huffman::write_lengths`] writes it; `None`
    /// when the bits run out, a length is too long, or the lengths form no prefix code (no
    /// codeword, or a Kraft sum above 1).
    pub fn read_lengths(source: &mut BitSource, symbols: usize) -> Option<Huffman> {
        let mut lengths = Vec::with_capacity(symbols);
        for _ in 0..symbols {
            let l = source.get(LENGTH_FIELD_BITS)? as u8;
            if l > MAX_CODE_LENGTH {
                return None;
            }
            lengths.push(l);
        }
        let kraft: u64 = lengths
            .iter()
            .filter(|&&l| l > 0)
            .map(|&l| 1u64 << (MAX_CODE_LENGTH - l))
            .sum();
        if kraft == 0 || kraft > 1 << MAX_CODE_LENGTH {
            return None;
        }
        Some(Huffman::from_lengths(&lengths))
    }

    /// Length of the codeword of `symbol` (0 if it has none).
    pub fn length(&self, symbol: usize) -> u8 {
        self.lengths.get(symbol).copied().unwrap_or(0)
    }

    /// Writes the codeword of `symbol`.
    pub fn put(&self, sink: &mut BitSink, class: SyntaxClass, symbol: usize) {
        let l = self.lengths[symbol];
        assert!(l > 0, "symbol {symbol} has no codeword");
        sink.put(class, l as u32, self.codes[symbol]);
    }

    /// Reads one symbol; `None` when the bits run out or form no codeword.
    pub fn get(&self, source: &mut BitSource) -> Option<usize> {
        let mut code = 0u32;
        for l in 1..=MAX_CODE_LENGTH as usize {
            code = (code << 1) | source.get(1)?;
            let offset = code.wrapping_sub(self.first_code[l]);
            if code >= self.first_code[l] && offset < self.count[l] {
                return Some(self.sorted[(self.first_index[l] + offset) as usize] as usize);
            }
        }
        None
    }
}

/// Plain Huffman code lengths by repeatedly merging the two lightest trees.
fn huffman_lengths(weights: &[u64]) -> Vec<u8> {
    use std::cmp::Reverse;
    use std::collections::BinaryHeap;
    let n = weights.len();
    if n == 1 {
        return vec![1];
    }
    // Nodes 0..n are leaves; parents are appended.
    let mut parent = vec![usize::MAX; n];
    let mut heap: BinaryHeap<Reverse<(u64, usize)>> = weights
        .iter()
        .enumerate()
        .map(|(i, &w)| Reverse((w, i)))
        .collect();
    while heap.len() > 1 {
        let Reverse((wa, a)) = heap.pop().expect("two nodes");
        let Reverse((wb, b)) = heap.pop().expect("two nodes");
        let p = parent.len();
        parent.push(usize::MAX);
        parent[a] = p;
        parent[b] = p;
        heap.push(Reverse((wa + wb, p)));
    }
    (0..n)
        .map(|leaf| {
            let (mut depth, mut node) = (0u8, leaf);
            while parent[node] != usize::MAX {
                node = parent[node];
                depth = depth.saturating_add(1);
            }
            depth
        })
        .collect()
}

/// Elias-gamma code of `value` ≥ 1: ⌊log2 v⌋ zeros, then v in binary. Returns bits written.
pub fn put_gamma(sink: &mut BitSink, class: SyntaxClass, value: u64) {
    assert!((1..1 << 32).contains(&value));
    let bits = 64 - value.leading_zeros();
    sink.put(class, bits - 1, 0);
    sink.put(class, bits, value as u32);
}

/// Reads an Elias-gamma value; `None` when the bits run out or the value exceeds 32 bits.
pub fn get_gamma(source: &mut BitSource) -> Option<u64> {
    let mut zeros = 0;
    while source.get(1)? == 0 {
        zeros += 1;
        if zeros > 31 {
            return None;
        }
    }
    let rest = source.get(zeros)? as u64;
    Some((1 << zeros) | rest)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn codes_round_trip_and_follow_the_counts() {
        let counts = [500u64, 120, 120, 40, 3, 0, 1, 70_000];
        let lengths = Huffman::lengths_for(&counts);
        assert!(lengths[7] < lengths[0] && lengths[0] < lengths[4]);
        let code = Huffman::from_lengths(&lengths);
        let mut sink = BitSink::default();
        let message = [7usize, 0, 5, 4, 7, 1, 2, 3, 6, 7];
        for &s in &message {
            code.put(&mut sink, SyntaxClass::Geometry, s);
        }
        for v in [1u64, 2, 3, 1000, u32::MAX as u64] {
            put_gamma(&mut sink, SyntaxClass::Connectivity, v);
        }
        let (bytes, _) = sink.finish();
        let mut source = BitSource::new(&bytes);
        for &s in &message {
            assert_eq!(code.get(&mut source), Some(s));
        }
        for v in [1u64, 2, 3, 1000, u32::MAX as u64] {
            assert_eq!(get_gamma(&mut source), Some(v));
        }
    }

    #[test]
    fn long_tails_are_limited() {
        let counts: Vec<u64> = (0..60).map(|i| 1u64 << (i % 40)).collect();
        assert!(Huffman::lengths_for(&counts)
            .iter()
            .all(|&l| (1..=MAX_CODE_LENGTH).contains(&l)));
    }

    #[test]
    fn tables_round_trip_and_broken_ones_are_refused() {
        let code = Huffman::from_lengths(&Huffman::lengths_for(&[9, 1, 4, 0, 30]));
        let mut sink = BitSink::default();
        code.write_lengths(&mut sink, SyntaxClass::Connectivity);
        let (bytes, _) = sink.finish();
        assert_eq!(
            Huffman::read_lengths(&mut BitSource::new(&bytes), 5),
            Some(code)
        );
        // Three codewords of one bit break the Kraft inequality; none at all is no code.
        let mut sink = BitSink::default();
        for l in [1, 1, 1, 0, 0] {
            sink.put(SyntaxClass::Connectivity, LENGTH_FIELD_BITS, l);
        }
        let (bytes, _) = sink.finish();
        assert_eq!(Huffman::read_lengths(&mut BitSource::new(&bytes), 5), None);
        assert_eq!(Huffman::read_lengths(&mut BitSource::new(&[0; 4]), 5), None);
        assert_eq!(Huffman::read_lengths(&mut BitSource::new(&[8]), 5), None);
    }
}
