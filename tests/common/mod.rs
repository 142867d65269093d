//! Helpers shared by the integration tests.

/// `bytes` with 1 to `max_flips` single bits flipped at pseudo-random places; `state` is the
/// xorshift generator's state, advanced in place.
pub fn flip_bits(bytes: &[u8], state: &mut u32, max_flips: usize) -> Vec<u8> {
    let mut out = bytes.to_vec();
    let flips = 1 + *state as usize % max_flips;
    for _ in 0..flips {
        *state ^= *state << 13;
        *state ^= *state >> 17;
        *state ^= *state << 5;
        let i = *state as usize % out.len();
        out[i] ^= 1 << (*state >> 29);
    }
    out
}
