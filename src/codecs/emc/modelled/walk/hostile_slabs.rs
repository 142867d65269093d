//! Slab streams that lie, fed to the decoder with the lanes' ownership check on (it is on in
//! the crate's tests whatever the build, `lanes::check`): whatever the slab table and the slab
//! streams say, no slab touches another's vertices, so the raw views the slabs share never race.

use super::lanes::{check, Lanes};
use crate::codecs::{self, EncodeOptions, Stop};
use crate::container::read_header_and_index;
use crate::mesh::generate;
use crate::mesh::quantize::GridShape;
use rand::{Rng, SeedableRng};

#[test]
#[should_panic(expected = "touched outside its slab")]
fn the_ownership_check_is_on_in_the_crates_tests() {
    let lanes = Lanes {
        cells: std::ptr::null_mut(),
        depth: std::ptr::null_mut(),
        next_split: std::ptr::null_mut(),
        adjacency: std::ptr::null_mut(),
        leaf: std::ptr::null_mut(),
        centres: std::ptr::null_mut(),
        marks: std::ptr::null(),
        agree: std::ptr::null_mut(),
        representative: std::ptr::null_mut(),
        len: 1,
    };
    check(&lanes, 0, || false);
}

/// `emc` and `emc-ahead` streams of small meshes, every pass of 4 visits or more sliced into
/// `slabs` slabs.
fn slab_streams() -> Vec<Vec<u8>> {
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    let meshes = [generate::messy(5), generate::torus(1.0, 0.4, 24, 12)];
    let mut streams = Vec::new();
    for mesh in &meshes {
        let canonical = codecs::canonical_for(mesh, &options).unwrap();
        for slabs in [2, 3, 4] {
            // `emc`'s and `emc-ahead`'s, whose lookahead passes are sliced too.
            for ahead in [0, 2] {
                let encoded =
                    codecs::emc::modelled::encode_sliced_ahead(&canonical, ahead, slabs, 2)
                        .unwrap();
                streams.push(encoded.bytes);
            }
        }
    }
    streams
}

/// Where each level with a slab table starts (its payload opens with the table's length, 0
/// for a level without one) and where it ends.
fn sliced_levels(bytes: &[u8]) -> Vec<(usize, usize)> {
    let (_, index, start) = read_header_and_index(bytes).unwrap();
    index
        .units
        .iter()
        .map(|unit| {
            let at = start + unit.offset as usize;
            (at, at + unit.length as usize)
        })
        .filter(|&(at, end)| end > at && bytes[at] > 0)
        .collect()
}

#[test]
fn hostile_slab_tables_and_streams_never_touch_another_slabs_vertices() {
    let mut rng = rand_pcg::Pcg64::seed_from_u64(46);
    let (mut decoded, mut refused) = (0, 0);
    let mut decode = |stream: &[u8]| match codecs::decode(stream, Stop::All) {
        Ok(_) => decoded += 1,
        Err(_) => refused += 1,
    };
    for bytes in slab_streams() {
        let levels = sliced_levels(&bytes);
        assert!(!levels.is_empty(), "no sliced level");
        for &(level, end) in &levels {
            // Every byte of the table (and the varints around it) set to values that lie: split
            // counts and slab stream lengths off by one, zero, the largest one byte holds.
            let table_end = (level + 1 + bytes[level] as usize + 4).min(end);
            for at in level..table_end {
                for value in [
                    0,
                    1,
                    2,
                    bytes[at] ^ 1,
                    bytes[at].wrapping_add(1),
                    0x7f,
                    0xff,
                ] {
                    let mut lying = bytes.clone();
                    lying[at] = value;
                    decode(&lying);
                }
            }
            // The slab streams' bytes: the splits and edge codes they decode to change.
            for _ in 0..30 {
                let mut lying = bytes.clone();
                for _ in 0..rng.gen_range(1..4) {
                    let at = rng.gen_range(table_end.min(end - 1)..end);
                    lying[at] = rng.gen();
                }
                decode(&lying);
            }
        }
    }
    // Both kinds happen: lies the decoder refuses, and lies it decodes through every slab.
    assert!(
        decoded > 0 && refused > 0,
        "{decoded} decoded, {refused} refused"
    );
}
