//! EMC's syntax elements and their fixed codes.

use crate::coding::huffman::{get_gamma, put_gamma, Huffman};
use crate::coding::{BitSink, BitSource, SyntaxClass};
use std::sync::OnceLock;

pub use super::super::state::EdgeCode;

/// Code lengths of STAY, MOVE, DUPLICATE. See the module docs of `emc` for the measurement
/// behind the choice.
pub const EDGE_CODE_LENGTHS: [u8; 3] = [1, 2, 2];

/// Longest split distance any stream can need: 3 × 30 levels − 1.
pub const MAX_DISTANCE: usize = 89;

/// Code lengths of the split-distance alphabet: symbol 0 = "no further split", symbol d =
/// the next split comes d steps later. Derived from measurements (see `emc` module docs and
/// `cargo run --release --example emc_split_distance_table`).
pub const SPLIT_DISTANCE_CODE_LENGTHS: [u8; MAX_DISTANCE + 1] =
    include!("split_distance_lengths.in");

fn edge_code() -> &'static Huffman {
    static CODE: OnceLock<Huffman> = OnceLock::new();
    CODE.get_or_init(|| Huffman::from_lengths(&EDGE_CODE_LENGTHS))
}

fn distance_code() -> &'static Huffman {
    static CODE: OnceLock<Huffman> = OnceLock::new();
    CODE.get_or_init(|| Huffman::from_lengths(&SPLIT_DISTANCE_CODE_LENGTHS))
}

/// Writes an edge code.
pub fn put_edge(sink: &mut BitSink, code: EdgeCode) {
    edge_code().put(sink, SyntaxClass::Connectivity, code as usize);
}

/// Reads an edge code.
pub fn get_edge(source: &mut BitSource) -> Option<EdgeCode> {
    edge_code()
        .get(source)
        .map(|s| [EdgeCode::Stay, EdgeCode::Move, EdgeCode::Duplicate][s])
}

/// Bits of an edge code.
pub fn edge_bits(code: EdgeCode) -> u64 {
    EDGE_CODE_LENGTHS[code as usize] as u64
}

/// Writes the distance from `step` to `next` (a later step, or `None` for no further split).
pub fn put_distance(sink: &mut BitSink, step: usize, next: Option<usize>) -> u64 {
    let symbol = next.map_or(0, |n| n - step);
    distance_code().put(sink, SyntaxClass::Geometry, symbol);
    distance_code().length(symbol) as u64
}

/// Reads a split distance; `Some(None)` is "no further split".
pub fn get_distance(source: &mut BitSource) -> Option<Option<usize>> {
    distance_code().get(source).map(|s| (s > 0).then_some(s))
}

/// Writes an ascending list of positions: its length, then the gaps, in Elias-gamma codes.
pub fn put_list(sink: &mut BitSink, list: &[u32]) {
    put_gamma(sink, SyntaxClass::Connectivity, list.len() as u64 + 1);
    let mut previous = 0u64;
    for (i, &x) in list.iter().enumerate() {
        let gap = if i == 0 {
            x as u64
        } else {
            x as u64 - previous - 1
        };
        put_gamma(sink, SyntaxClass::Connectivity, gap + 1);
        previous = x as u64;
    }
}

/// Reads a list written by [`put_list`]; every entry must be below `bound`.
pub fn get_list(source: &mut BitSource, bound: usize) -> Option<Vec<u32>> {
    let len = get_gamma(source)? - 1;
    if len as usize > bound {
        return None;
    }
    let mut list = Vec::with_capacity(len as usize);
    let mut next = 0u64;
    for _ in 0..len {
        let x = next + get_gamma(source)? - 1;
        if x as usize >= bound {
            return None;
        }
        list.push(x as u32);
        next = x + 1;
    }
    Some(list)
}
