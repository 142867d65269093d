//! The range coder's floor under the modelled EMC decoder: decoding 100,000 adaptive binary
//! decisions, and 100,000 three-bit symbols ([`ArithDecoder::bits3`], a leaf's refinement of a
//! level), each under contexts picked from 256, for bits as good as random and for bits that
//! are nearly always 0; and the bits through constriction's own decoder, the anchor.
//! Run: cargo bench --bench arith

use constriction::stream::queue::DefaultRangeDecoder;
use constriction::stream::Decode;
use criterion::{criterion_group, criterion_main, BenchmarkId, Criterion, Throughput};
use meshcodec::coding::arith::{ArithDecoder, ArithEncoder, BitContext};
use meshcodec::coding::SyntaxClass;

const SYMBOLS: usize = 100_000;
const CONTEXTS: usize = 256;

/// Context indices and bits from a fixed xorshift sequence; a bit is 1 with probability
/// `ones_in_64` / 64.
fn decisions(ones_in_64: u64) -> Vec<(usize, bool)> {
    let mut state = 0x9e37_79b9_7f4a_7c15u64;
    (0..3 * SYMBOLS)
        .map(|_| {
            state ^= state << 13;
            state ^= state >> 7;
            state ^= state << 17;
            (
                (state % CONTEXTS as u64) as usize,
                (state >> 40) % 64 < ones_in_64,
            )
        })
        .collect()
}

fn coder(c: &mut Criterion) {
    let mut group = c.benchmark_group("arith");
    group.throughput(Throughput::Elements(SYMBOLS as u64));
    for (name, ones_in_64) in [("random", 32), ("skewed", 2)] {
        let decisions = decisions(ones_in_64);
        let mut encoder = ArithEncoder::default();
        let mut contexts = vec![BitContext::default(); CONTEXTS];
        for &(i, bit) in &decisions[..SYMBOLS] {
            encoder.bit(&mut contexts[i], bit, SyntaxClass::Geometry, "bit");
        }
        let (bits, _) = encoder.finish();
        group.bench_function(BenchmarkId::new("decode bit", name), |b| {
            b.iter(|| {
                let mut decoder = ArithDecoder::new(&bits).unwrap();
                let mut contexts = vec![BitContext::default(); CONTEXTS];
                let mut ones = 0;
                for &(i, _) in &decisions[..SYMBOLS] {
                    ones += decoder.bit(&mut contexts[i]).unwrap() as usize;
                }
                ones
            })
        });
        // The anchor: the same words through constriction's own range decoder, whose division
        // per decision `ArithDecoder` does without.
        group.bench_function(
            BenchmarkId::new("decode bit, constriction's decoder", name),
            |b| {
                b.iter(|| {
                    let words: Vec<u32> = bits
                        .chunks_exact(4)
                        .map(|c| u32::from_le_bytes([c[0], c[1], c[2], c[3]]))
                        .collect();
                    let mut decoder = DefaultRangeDecoder::from_compressed(words).unwrap();
                    let mut contexts = vec![BitContext::default(); CONTEXTS];
                    let mut ones = 0;
                    for &(i, _) in &decisions[..SYMBOLS] {
                        let bit = decoder.decode_symbol(contexts[i]).unwrap();
                        contexts[i].update(bit);
                        ones += bit as usize;
                    }
                    ones
                })
            },
        );
        let mut encoder = ArithEncoder::default();
        let mut contexts = vec![BitContext::default(); CONTEXTS];
        for triple in decisions.chunks(3) {
            let index = [triple[0].0, triple[1].0, triple[2].0];
            let bits = [triple[0].1, triple[1].1, triple[2].1];
            encoder.bits3(&mut contexts, index, bits, SyntaxClass::Geometry, "half");
        }
        let (triples, _) = encoder.finish();
        group.bench_function(BenchmarkId::new("decode bits3", name), |b| {
            b.iter(|| {
                let mut decoder = ArithDecoder::new(&triples).unwrap();
                let mut contexts = vec![BitContext::default(); CONTEXTS];
                let mut ones = 0;
                for triple in decisions.chunks(3) {
                    let index = [triple[0].0, triple[1].0, triple[2].0];
                    ones += decoder.bits3(&mut contexts, index).unwrap()[0] as usize;
                }
                ones
            })
        });
    }
    group.finish();
}

criterion_group!(benches, coder);
criterion_main!(benches);
