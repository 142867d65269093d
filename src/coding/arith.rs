//! Adaptive binary arithmetic coding over constriction's range coder (encoding; decoding by a
//! division-free reader of the same streams, `RangeState`).
//!
//! Every symbol is binarized and each binary decision has its own adaptive probability (a
//! context) that encoder and decoder update identically; the context is passed to the coder per
//! symbol. Integers use an adaptive Exp-Golomb binarization: the bit length in unary with one
//! context per position, the bits below the leading one with contexts per position too.
//! Each level is coded separately (`finish` flushes), so a cut stream never decodes garbage.

use super::{BitLedger, SyntaxClass};
use constriction::stream::model::{DecoderModel, EncoderModel, EntropyModel};
use constriction::stream::queue::DefaultRangeEncoder;
use constriction::stream::Encode;
use std::borrow::Borrow;
use std::num::NonZeroU32;

/// Probability precision in bits.
pub const PRECISION: usize = 16;
const ONE: u32 = 1 << PRECISION;
/// Adaptation speeds of the two estimates a context mixes: each symbol moves the fast one
/// 1/2^FAST_RATE of the way, the slow one 1/2^SLOW_RATE.
const FAST_RATE: u32 = 4;
const SLOW_RATE: u32 = 7;

/// An adaptive probability that the next bit is 1: the mean of a fast estimate (follows drifting
/// statistics) and a slow one (precise where they hold still).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct BitContext {
    p1: u32,
    fast: u32,
    slow: u32,
    /// Symbols seen, up to the count where the slow rate settles.
    seen: u32,
}

impl BitContext {
    /// A context that has seen nothing: even odds.
    pub const NEW: BitContext = BitContext {
        p1: ONE / 2,
        fast: ONE / 2,
        slow: ONE / 2,
        seen: 0,
    };
}

impl Default for BitContext {
    fn default() -> Self {
        BitContext::NEW
    }
}

fn adapt(p: u32, bit: bool, rate: u32) -> u32 {
    // p + ((ONE - p) >> rate) for a 1, p - (p >> rate) for a 0, without a branch: the bits a
    // decoder reads are as good as random to a branch predictor.
    let one = (bit as u32).wrapping_neg();
    p + (((ONE - p) >> rate) & one) - ((p >> rate) & !one)
}

impl BitContext {
    /// Adapts to `bit` having been coded (what the coders do after each decision).
    pub fn update(&mut self, bit: bool) {
        // A fresh context learns fast (rates 1/2, 1/4, … as if counting) before settling.
        let warm = self.seen + 1;
        self.seen += (self.seen < SLOW_RATE) as u32;
        self.fast = adapt(self.fast, bit, warm.min(FAST_RATE));
        self.slow = adapt(self.slow, bit, warm.min(SLOW_RATE));
        self.p1 = ((self.fast + self.slow) / 2).clamp(32, ONE - 32);
    }

    /// The context that `copies` of `self`, each adapted apart from the others, hand on: the
    /// mean of the copies that coded anything (their estimates averaged, the most symbols
    /// seen), or `self` if none did. Integer arithmetic only, so that an encoder and a decoder
    /// merge identically.
    pub fn merged<'c>(&self, copies: impl IntoIterator<Item = &'c BitContext>) -> BitContext {
        let (mut fast, mut slow, mut seen, mut used) = (0u64, 0u64, self.seen, 0u64);
        for copy in copies.into_iter().filter(|&copy| copy != self) {
            fast += copy.fast as u64;
            slow += copy.slow as u64;
            seen = seen.max(copy.seen);
            used += 1;
        }
        if used == 0 {
            return *self;
        }
        let (fast, slow) = ((fast / used) as u32, (slow / used) as u32);
        BitContext {
            p1: ((fast + slow) / 2).clamp(32, ONE - 32),
            fast,
            slow,
            seen,
        }
    }

    /// A context that starts from probability `p1` (of 2^16) of a 1, adapting afterwards as if
    /// it had seen `seen` symbols (at most the slow rate's 7): a prior learnt elsewhere.
    pub fn seeded(p1: u32, seen: u32) -> BitContext {
        let p1 = p1.clamp(32, ONE - 32);
        BitContext {
            p1,
            fast: p1,
            slow: p1,
            seen: seen.min(SLOW_RATE),
        }
    }

    /// The slow estimate of the probability of a 1 (of 2^16): what the context has learnt over
    /// its last hundred or so symbols.
    pub fn learnt(&self) -> u32 {
        self.slow
    }

    /// Symbols seen, up to 7 (the slow rate's).
    pub fn seen(&self) -> u32 {
        self.seen
    }

    /// Bits an ideal coder spends on `bit` under this context.
    pub fn cost(&self, bit: bool) -> f64 {
        let p = if bit { self.p1 } else { ONE - self.p1 };
        -(p as f64 / ONE as f64).log2()
    }
}

impl EntropyModel<PRECISION> for BitContext {
    type Symbol = bool;
    type Probability = u32;
}

impl EncoderModel<PRECISION> for BitContext {
    fn left_cumulative_and_probability(
        &self,
        symbol: impl Borrow<bool>,
    ) -> Option<(u32, NonZeroU32)> {
        let p0 = ONE - self.p1;
        Some(if *symbol.borrow() {
            (p0, NonZeroU32::new(self.p1)?)
        } else {
            (0, NonZeroU32::new(p0)?)
        })
    }
}

impl DecoderModel<PRECISION> for BitContext {
    fn quantile_function(&self, quantile: u32) -> (bool, u32, NonZeroU32) {
        // Without branches, as in `adapt`.
        let p0 = ONE - self.p1;
        let bit = quantile >= p0;
        let one = (bit as u32).wrapping_neg();
        let probability = (self.p1 & one) | (p0 & !one);
        (
            bit,
            p0 & one,
            NonZeroU32::new(probability).expect("p1 and p0 are clamped away from 0"),
        )
    }
}

/// Precision of a [`Triple`]: enough that every one of its eight values keeps a nonzero share
/// when each bit's probability is clamped to [2^-11, 1 - 2^-11].
const TRIPLE_PRECISION: usize = 24;

/// Three binary decisions coded as one symbol: the interval is split by the first bit's
/// probability, each half by the second's, each quarter by the third's. One range-coder step
/// instead of three, though only a little faster: two divisions are saved but the three splits
/// are a chain of dependent multiplications (`cargo bench --bench arith`: 14.7 ns a symbol,
/// 5.8 ns a single bit). The contexts are read before any of the three is adapted (where two
/// decisions share a context, both see it as it was).
#[derive(Clone, Copy, Debug)]
struct Triple {
    p1: [u32; 3],
}

impl Triple {
    /// Size of the "0" part when an interval of `size` is split by probability `p1` of a 1.
    #[inline]
    fn zero_part(size: u32, p1: u32) -> u32 {
        let zero = ((size as u64 * (ONE - p1) as u64) >> PRECISION) as u32;
        zero.clamp(1, size - 1)
    }

    /// Walks down the splits: `one(k, left, zero)` says whether the k-th bit is 1, given the
    /// current part's start and the size of its "0" sub-part. Returns the three bits, the
    /// chosen part's start and its size.
    #[inline]
    fn descend(&self, mut one: impl FnMut(usize, u32, u32) -> bool) -> (u8, u32, u32) {
        let (mut left, mut size, mut symbol) = (0u32, 1u32 << TRIPLE_PRECISION, 0u8);
        for (k, &p1) in self.p1.iter().enumerate() {
            let zero = Triple::zero_part(size, p1);
            // Without branches: a decoder's bits are as good as random to a branch predictor.
            let bit = one(k, left, zero);
            let mask = (bit as u32).wrapping_neg();
            symbol |= (bit as u8) << k;
            left += zero & mask;
            size = ((size - zero) & mask) | (zero & !mask);
        }
        (symbol, left, size)
    }
}

impl EntropyModel<TRIPLE_PRECISION> for Triple {
    /// The three bits, the first in bit 0.
    type Symbol = u8;
    type Probability = u32;
}

impl EncoderModel<TRIPLE_PRECISION> for Triple {
    fn left_cumulative_and_probability(
        &self,
        symbol: impl Borrow<u8>,
    ) -> Option<(u32, NonZeroU32)> {
        let symbol = *symbol.borrow();
        let (_, left, size) = self.descend(|k, _, _| symbol >> k & 1 == 1);
        Some((left, NonZeroU32::new(size)?))
    }
}

#[cfg(test)]
impl DecoderModel<TRIPLE_PRECISION> for Triple {
    fn quantile_function(&self, quantile: u32) -> (u8, u32, NonZeroU32) {
        let (symbol, left, size) = self.descend(|_, left, zero| quantile - left >= zero);
        (
            symbol,
            left,
            NonZeroU32::new(size).expect("parts are nonzero"),
        )
    }
}

/// Contexts for an unsigned integer in adaptive Exp-Golomb form.
#[derive(Clone, Debug)]
pub struct UintContext {
    length: [BitContext; 33],
    mantissa: [BitContext; 32],
}

// The fresh contexts are constants, copied where they are made: built field by field, every
// struct of contexts (a codec's hundreds of them) compiled to tens of kilobytes of stores each,
// 1.2 MB of the WebAssembly module.
impl UintContext {
    /// Contexts that have seen nothing.
    pub const NEW: UintContext = UintContext {
        length: [BitContext::NEW; 33],
        mantissa: [BitContext::NEW; 32],
    };
}

impl UintContext {
    /// Its binary contexts: the length's, then the mantissa's.
    pub fn bits_mut(&mut self) -> impl Iterator<Item = &mut BitContext> {
        self.length.iter_mut().chain(self.mantissa.iter_mut())
    }
}

impl Default for UintContext {
    fn default() -> Self {
        UintContext::NEW
    }
}

/// Contexts for a signed integer: zero flag, sign, magnitude − 1.
#[derive(Clone, Debug)]
pub struct IntContext {
    zero: BitContext,
    sign: BitContext,
    magnitude: UintContext,
}

impl IntContext {
    /// Contexts that have seen nothing.
    pub const NEW: IntContext = IntContext {
        zero: BitContext::NEW,
        sign: BitContext::NEW,
        magnitude: UintContext::NEW,
    };
}

impl IntContext {
    /// Its binary contexts: the zero flag's, the sign's, then the magnitude's.
    pub fn bits_mut(&mut self) -> impl Iterator<Item = &mut BitContext> {
        [&mut self.zero, &mut self.sign]
            .into_iter()
            .chain(self.magnitude.bits_mut())
    }
}

impl Default for IntContext {
    fn default() -> Self {
        IntContext::NEW
    }
}

/// Arithmetic encoder of one level, with bits estimated per syntax class and per field.
pub struct ArithEncoder {
    coder: DefaultRangeEncoder,
    estimated: [f64; 2],
    /// Estimated bits per named field.
    pub field_bits: std::collections::BTreeMap<&'static str, f64>,
}

impl Default for ArithEncoder {
    fn default() -> Self {
        ArithEncoder {
            coder: DefaultRangeEncoder::new(),
            estimated: [0.0; 2],
            field_bits: Default::default(),
        }
    }
}

impl ArithEncoder {
    /// Codes one bit under `context` and adapts it; books its cost to `class` and `field`.
    pub fn bit(
        &mut self,
        context: &mut BitContext,
        bit: bool,
        class: SyntaxClass,
        field: &'static str,
    ) {
        let cost = context.cost(bit);
        self.estimated[class as usize] += cost;
        *self.field_bits.entry(field).or_default() += cost;
        self.coder
            .encode_symbol(bit, *context)
            .expect("probabilities are never zero");
        context.update(bit);
    }

    /// Codes three bits at once (one three-bit symbol, docs/FORMAT.md §3.2), `bits[k]` under `contexts[index[k]]`; adapts the
    /// contexts in that order afterwards.
    pub fn bits3(
        &mut self,
        contexts: &mut [BitContext],
        index: [usize; 3],
        bits: [bool; 3],
        class: SyntaxClass,
        field: &'static str,
    ) {
        let triple = Triple {
            p1: index.map(|i| contexts[i].p1),
        };
        let cost: f64 = (0..3).map(|k| contexts[index[k]].cost(bits[k])).sum();
        self.estimated[class as usize] += cost;
        *self.field_bits.entry(field).or_default() += cost;
        let symbol = bits[0] as u8 | (bits[1] as u8) << 1 | (bits[2] as u8) << 2;
        self.coder
            .encode_symbol(symbol, triple)
            .expect("every value has a nonzero probability");
        for k in 0..3 {
            contexts[index[k]].update(bits[k]);
        }
    }

    /// Codes an unsigned integer.
    pub fn uint(
        &mut self,
        context: &mut UintContext,
        value: u64,
        class: SyntaxClass,
        field: &'static str,
    ) {
        let v = value + 1;
        let n = 63 - v.leading_zeros() as usize; // bits below the leading one
        for i in 0..n {
            self.bit(&mut context.length[i.min(32)], true, class, field);
        }
        self.bit(&mut context.length[n.min(32)], false, class, field);
        for i in (0..n).rev() {
            self.bit(
                &mut context.mantissa[i.min(31)],
                (v >> i) & 1 == 1,
                class,
                field,
            );
        }
    }

    /// Codes a signed integer.
    pub fn int(
        &mut self,
        context: &mut IntContext,
        value: i64,
        class: SyntaxClass,
        field: &'static str,
    ) {
        self.bit(&mut context.zero, value == 0, class, field);
        if value != 0 {
            self.bit(&mut context.sign, value < 0, class, field);
            self.uint(
                &mut context.magnitude,
                value.unsigned_abs() - 1,
                class,
                field,
            );
        }
    }

    /// Codes `bits` raw bits of `value` at probability ½.
    pub fn raw(&mut self, value: u64, bits: u32, class: SyntaxClass, field: &'static str) {
        for i in (0..bits).rev() {
            let mut even = BitContext::default();
            self.bit(&mut even, (value >> i) & 1 == 1, class, field);
        }
    }

    /// Flushes; returns the bytes and the ledger (actual bits split in proportion to the
    /// estimates).
    pub fn finish(self) -> (Vec<u8>, BitLedger) {
        let words = self
            .coder
            .into_compressed()
            .expect("writing to a Vec cannot fail");
        let bytes: Vec<u8> = words.iter().flat_map(|w| w.to_le_bytes()).collect();
        let total = bytes.len() as f64 * 8.0;
        let estimated = self.estimated[0] + self.estimated[1];
        let connectivity = if estimated > 0.0 {
            (total * self.estimated[0] / estimated).round() as u64
        } else {
            0
        };
        let ledger = BitLedger {
            connectivity,
            geometry: total as u64 - connectivity.min(total as u64),
        };
        (bytes, ledger)
    }
}

/// The range decoder's state, as constriction's `DefaultRangeDecoder` keeps it (64-bit state,
/// 32-bit words read front to back), so that it reads exactly what constriction's encoder wrote.
///
/// Ours rather than constriction's decoder for one reason, measured: a binary decision needs no
/// division. Constriction finds the symbol from `quantile = (point − lower) / scale`, a 64-bit
/// division on every decision (`came` spent 40% of its decode there); for two symbols,
/// `quantile ≥ p0` is the same test as `point − lower ≥ p0 · scale`, one multiplication.
/// The same holds for [`Triple`]'s three comparisons. Every update below is constriction's, step
/// for step (`RangeDecoder::decode_symbol`), and a test decodes constriction's streams, intact
/// and corrupt, against constriction's decoder.
struct RangeState {
    words: Vec<u32>,
    /// The next word to read.
    next: usize,
    lower: u64,
    range: u64,
    point: u64,
}

impl RangeState {
    fn new(words: Vec<u32>) -> RangeState {
        // The first two words (zeros for missing ones) are the point.
        let point = (0..2).fold(0u64, |point, k| {
            point << 32 | *words.get(k).unwrap_or(&0) as u64
        });
        let next = words.len().min(2);
        RangeState {
            words,
            next,
            lower: 0,
            range: u64::MAX,
            point,
        }
    }

    /// Narrows the range to `[lower + scale·left, + scale·size)`, then renormalizes.
    #[inline(always)]
    fn narrow(&mut self, scale: u64, left: u64, size: u64) {
        self.lower = self.lower.wrapping_add(scale * left);
        self.range = scale * size;
        if self.range < 1 << 32 {
            self.lower <<= 32;
            self.range <<= 32;
            self.point <<= 32;
            if let Some(&word) = self.words.get(self.next) {
                self.point |= word as u64;
                self.next += 1;
            }
        }
    }

    /// One binary decision with probability `p1` (of 2^PRECISION) of a 1; `None` where the
    /// data can't come from an encoder (constriction's `InvalidData`).
    #[inline(always)]
    fn bit(&mut self, p1: u32) -> Option<bool> {
        let scale = self.range >> PRECISION;
        let offset = self.point.wrapping_sub(self.lower);
        if offset >= scale << PRECISION {
            return None;
        }
        let p0 = (ONE - p1) as u64;
        let bit = offset >= scale * p0;
        let (left, size) = if bit { (p0, p1 as u64) } else { (0, p0) };
        self.narrow(scale, left, size);
        Some(bit)
    }

    /// Three bits coded as one [`Triple`], by the same comparisons without the division:
    /// `quantile − left ≥ zero` is `point − lower ≥ (left + zero) · scale`.
    #[inline(always)]
    fn triple(&mut self, triple: &Triple) -> Option<u8> {
        let scale = self.range >> TRIPLE_PRECISION;
        let offset = self.point.wrapping_sub(self.lower);
        if offset >= scale << TRIPLE_PRECISION {
            return None;
        }
        let (symbol, left, size) =
            triple.descend(|_, left, zero| offset >= (left + zero) as u64 * scale);
        self.narrow(scale, left as u64, size as u64);
        Some(symbol)
    }
}

/// Arithmetic decoder of one level.
pub struct ArithDecoder {
    coder: RangeState,
}

impl ArithDecoder {
    /// Reads a level's bytes (a multiple of 4; `None` otherwise).
    pub fn new(bytes: &[u8]) -> Option<ArithDecoder> {
        if !bytes.len().is_multiple_of(4) {
            return None;
        }
        let words: Vec<u32> = bytes
            .chunks_exact(4)
            .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
            .collect();
        Some(ArithDecoder {
            coder: RangeState::new(words),
        })
    }

    /// Decodes one bit under `context` and adapts it.
    #[inline]
    pub fn bit(&mut self, context: &mut BitContext) -> Option<bool> {
        let bit = self.coder.bit(context.p1)?;
        context.update(bit);
        Some(bit)
    }

    /// Decodes three bits coded by [`ArithEncoder::bits3`].
    pub fn bits3(&mut self, contexts: &mut [BitContext], index: [usize; 3]) -> Option<[bool; 3]> {
        let triple = Triple {
            p1: index.map(|i| contexts[i].p1),
        };
        let symbol = self.coder.triple(&triple)?;
        let bits = [0, 1, 2].map(|k| symbol >> k & 1 == 1);
        for k in 0..3 {
            contexts[index[k]].update(bits[k]);
        }
        Some(bits)
    }

    /// Decodes an unsigned integer (at most 63 bits).
    pub fn uint(&mut self, context: &mut UintContext) -> Option<u64> {
        let mut n = 0;
        while self.bit(&mut context.length[n.min(32)])? {
            n += 1;
            if n > 62 {
                return None;
            }
        }
        let mut v = 1u64;
        for i in (0..n).rev() {
            v = (v << 1) | self.bit(&mut context.mantissa[i.min(31)])? as u64;
        }
        Some(v - 1)
    }

    /// Decodes a signed integer.
    pub fn int(&mut self, context: &mut IntContext) -> Option<i64> {
        if self.bit(&mut context.zero)? {
            return Some(0);
        }
        let negative = self.bit(&mut context.sign)?;
        let magnitude = self.uint(&mut context.magnitude)?.checked_add(1)? as i64;
        Some(if negative { -magnitude } else { magnitude })
    }

    /// Decodes `bits` raw bits.
    pub fn raw(&mut self, bits: u32) -> Option<u64> {
        let mut v = 0u64;
        for _ in 0..bits {
            let mut even = BitContext::default();
            v = (v << 1) | self.bit(&mut even)? as u64;
        }
        Some(v)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn integers_round_trip_and_skewed_bits_cost_little() {
        let mut enc = ArithEncoder::default();
        let (mut u, mut i, mut b) = (
            UintContext::default(),
            IntContext::default(),
            BitContext::default(),
        );
        let values = [0u64, 1, 2, 3, 100, 65535, 1 << 40];
        for &v in &values {
            enc.uint(&mut u, v, SyntaxClass::Geometry, "u");
            enc.int(&mut i, -(v as i64), SyntaxClass::Geometry, "i");
        }
        for k in 0..10_000 {
            enc.bit(&mut b, k % 50 == 0, SyntaxClass::Connectivity, "b");
        }
        enc.raw(0xabcde, 20, SyntaxClass::Geometry, "r");
        let (bytes, ledger) = enc.finish();
        assert!(
            ledger.connectivity < 2_500,
            "skewed bits: {}",
            ledger.connectivity
        );
        let mut dec = ArithDecoder::new(&bytes).unwrap();
        let (mut u, mut i, mut b) = (
            UintContext::default(),
            IntContext::default(),
            BitContext::default(),
        );
        for &v in &values {
            assert_eq!(dec.uint(&mut u), Some(v));
            assert_eq!(dec.int(&mut i), Some(-(v as i64)));
        }
        for k in 0..10_000 {
            assert_eq!(dec.bit(&mut b), Some(k % 50 == 0));
        }
        assert_eq!(dec.raw(20), Some(0xabcde));
    }

    /// Bits and three-bit symbols under drifting probabilities, read by constriction's decoder
    /// and by ours from the same words: intact streams and streams with words changed, cut short
    /// or made of noise; both must decode the same symbols and fail at the same place.
    #[test]
    fn the_division_free_decoder_reads_what_constrictions_decoder_reads() {
        use constriction::stream::queue::DefaultRangeDecoder;
        use constriction::stream::Decode;
        let mut x = 0x9e37_79b9_7f4a_7c15_u64;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 7;
            x ^= x << 17;
            x
        };
        // The model of draw k, the same on both sides: a probability or a triple.
        let model = |k: u64| -> (u32, Triple) {
            let p = |j: u64| (32 + (k.wrapping_mul(2_654_435_761 + j) % (ONE as u64 - 64))) as u32;
            (
                p(0),
                Triple {
                    p1: [p(1), p(2), p(3)],
                },
            )
        };
        for round in 0..40 {
            let mut encoder = DefaultRangeEncoder::new();
            let draws = 1 + next() % 3000;
            for k in 0..draws {
                let (p1, triple) = model(k);
                if k % 5 == 4 {
                    encoder.encode_symbol((next() % 8) as u8, triple).unwrap();
                } else {
                    let context = BitContext {
                        p1,
                        ..Default::default()
                    };
                    encoder.encode_symbol(next() % 3 == 0, context).unwrap();
                }
            }
            let mut words = encoder.into_compressed().unwrap();
            match round % 4 {
                1 => {
                    let at = (next() as usize) % words.len().max(1);
                    if let Some(w) = words.get_mut(at) {
                        *w ^= 1 << (next() % 32);
                    }
                }
                2 => words.truncate((next() as usize) % (words.len() + 1)),
                3 => words.iter_mut().for_each(|w| *w = next() as u32),
                _ => {}
            }
            let mut theirs = DefaultRangeDecoder::from_compressed(words.clone()).unwrap();
            let mut ours = RangeState::new(words);
            for k in 0..draws + 50 {
                let (p1, triple) = model(k);
                if k % 5 == 4 {
                    let expected = theirs.decode_symbol(triple).ok();
                    assert_eq!(ours.triple(&triple), expected, "round {round}, draw {k}");
                } else {
                    let context = BitContext {
                        p1,
                        ..Default::default()
                    };
                    let expected = theirs.decode_symbol(context).ok();
                    assert_eq!(ours.bit(p1), expected, "round {round}, draw {k}");
                }
            }
        }
    }

    #[test]
    fn three_bits_as_one_symbol_round_trip_and_cost_what_three_bits_would() {
        // Skewed and even bits, two of the three sharing a context now and then.
        let mut x = 0x2545_f491_u32;
        let mut next = move || {
            x ^= x << 13;
            x ^= x >> 17;
            x ^= x << 5;
            x
        };
        let draws: Vec<([usize; 3], [bool; 3])> = (0..20_000)
            .map(|_| {
                let r = next();
                let index = [(r % 4) as usize, ((r >> 2) % 4) as usize, 4];
                let bits = [r >> 8 & 15 == 0, r >> 12 & 1 == 1, r >> 13 & 63 != 0];
                (index, bits)
            })
            .collect();
        let mut contexts = [BitContext::default(); 5];
        let mut enc = ArithEncoder::default();
        for &(index, bits) in &draws {
            enc.bits3(&mut contexts, index, bits, SyntaxClass::Geometry, "t");
        }
        let estimated = enc.estimated[SyntaxClass::Geometry as usize];
        let (bytes, _) = enc.finish();
        let actual = bytes.len() as f64 * 8.0;
        assert!(
            actual < estimated * 1.01 + 64.0,
            "{actual} bits coded, {estimated} estimated"
        );
        let mut dec = ArithDecoder::new(&bytes).unwrap();
        let mut contexts = [BitContext::default(); 5];
        for &(index, bits) in &draws {
            assert_eq!(dec.bits3(&mut contexts, index), Some(bits));
        }
    }
}
