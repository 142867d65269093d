//! The container's round trips, lookups by byte range, and refusals of foreign, oversized,
//! lying or overlong streams.

use super::header::{
    FLAG_DERIVED_NORMALS, FLAG_GEOMETRIC_NORMALS, FLAG_IN_LEVELS, FLAG_NORMALS, FLAG_UVS,
};
use super::*;
use crate::limits;
use crate::mesh::Grid;

fn header() -> Header {
    Header {
        codec_id: 7,
        syntax: 1,
        params: vec![1, 2, 3],
        grid: Grid {
            origin: [0.5, -1.0, 2.0],
            cell: [0.25, 0.25, 0.125],
            bits: 12,
        },
        vertices: 1000,
        triangles: 2000,
        appearance: None,
    }
}

fn two_levels() -> (Vec<u8>, Vec<LevelRecord>) {
    let mut writer = StreamWriter::new(&header());
    writer.push_level(&[9; 5], LevelCost::default());
    writer.push_level(&[8; 300], LevelCost::default());
    writer.finish()
}

/// A stream with `header()` and the given index over `payload`.
fn with_index(index: &Index, payload: &[u8]) -> Vec<u8> {
    let mut bytes = Vec::new();
    header().write(&mut bytes);
    index.write(&mut bytes);
    bytes.extend_from_slice(payload);
    bytes
}

#[test]
fn header_and_levels_round_trip_and_every_prefix_reads_cleanly() {
    let (bytes, records) = two_levels();
    let mut reader = StreamReader::open(&bytes).unwrap();
    assert!(reader.require_layered().is_ok());
    assert_eq!(reader.header(), &header());
    assert_eq!(reader.next_level().unwrap().bytes, &[9; 5]);
    assert_eq!(reader.next_level().unwrap().bytes.len(), 300);
    assert!(reader.next_level().is_none());
    assert_eq!(records.last().map(|r| r.end_byte), Some(bytes.len()));
    for cut in 0..bytes.len() {
        match StreamReader::open(&bytes[..cut]) {
            Err(Error::Truncated(_)) => {}
            Err(e) => panic!("cut {cut}: {e}"),
            Ok(mut r) => {
                let mut complete = 0;
                while r.next_level().is_some() {
                    complete += 1;
                }
                let expected = records.iter().filter(|r| r.end_byte <= cut).count();
                assert_eq!(complete, expected, "cut {cut}");
                assert!(r.truncated());
            }
        }
    }
}

#[test]
fn any_unit_is_found_from_the_header_and_index_alone() {
    let (bytes, records) = two_levels();
    let (_, index, payload_start) = read_header_and_index(&bytes).unwrap();
    let unit = index.units[1];
    let start = payload_start + unit.offset as usize;
    assert_eq!(start, records[0].end_byte);
    assert_eq!(&bytes[start..start + unit.length as usize], &[8; 300]);
    assert_eq!(unit.parent, Some(0));
}

#[test]
fn foreign_and_oversized_headers_are_refused() {
    assert!(matches!(
        Header::read(b"PK\x03\x04 zip file"),
        Err(Error::Malformed { .. })
    ));
    let mut big = header();
    big.vertices = 1 << 31;
    let mut bytes = Vec::new();
    big.write(&mut bytes);
    assert!(matches!(Header::read(&bytes), Err(Error::Limit(_))));
}

#[test]
fn normal_modes_are_declared_only_with_normals_inside_the_levels() {
    let spec = AppearanceSpec {
        normal_bits: Some(10),
        in_levels: true,
        derived_normals: true,
        ..AppearanceSpec::default()
    };
    let mut bytes = Vec::new();
    spec.write(&mut bytes);
    assert_eq!(AppearanceSpec::read(&bytes, &mut 0).unwrap(), spec);
    // Either normal mode without normals, or without the levels carrying them, or both
    // modes at once: refused.
    let both = FLAG_NORMALS | FLAG_IN_LEVELS | FLAG_GEOMETRIC_NORMALS;
    for flags in [FLAG_UVS | FLAG_IN_LEVELS, FLAG_NORMALS, both] {
        let mut bad = bytes.clone();
        bad[0] = flags | FLAG_DERIVED_NORMALS;
        let err = AppearanceSpec::read(&bad, &mut 0).unwrap_err();
        assert!(err.to_string().contains("appearance flags"), "{err}");
    }
}

#[test]
fn unknown_versions_are_refused() {
    let (mut bytes, _) = two_levels();
    bytes[4] = 1;
    let e = StreamReader::open(&bytes).unwrap_err();
    assert!(e.to_string().contains("format version 1"), "{e}");
    // Earlier versions told codec syntaxes apart by their parameters' length: refused, with
    // what to do.
    for version in 2..FORMAT_VERSION {
        // Version 6's index named each unit's offset and parent.
        bytes[4] = version;
        let e = StreamReader::open(&bytes).unwrap_err().to_string();
        assert!(
            e.contains(&format!("format version {version}")) && e.contains("re-encode"),
            "{e}"
        );
    }
}

/// Without appearance, the header ends in a zero flags byte; with it, the flags open the
/// appearance block; a header cut before that byte is truncated.
#[test]
fn the_appearance_flags_close_the_header() {
    let mut bytes = Vec::new();
    header().write(&mut bytes);
    assert_eq!(bytes.last(), Some(&0));
    assert_eq!(Header::read(&bytes).unwrap(), (header(), bytes.len()));
    let cut = Header::read(&bytes[..bytes.len() - 1]).unwrap_err();
    assert!(matches!(cut, Error::Truncated(_)), "{cut}");
    assert_eq!(bytes[6], 1, "the syntax byte follows the codec id");
}

/// A stream with `header()`, an index of `units` entries (length, children) in `entry_bytes`
/// bytes (their own length when `None`) over `payload_bytes`, then the payload's bytes.
fn with_entries(units: &[(u64, u64)], entry_bytes: Option<u64>, payload_bytes: u64) -> Vec<u8> {
    let mut entries = Vec::new();
    for &(length, children) in units {
        varint::put(&mut entries, length);
        varint::put(&mut entries, children);
    }
    let mut bytes = Vec::new();
    header().write(&mut bytes);
    varint::put(&mut bytes, units.len() as u64);
    varint::put(&mut bytes, entry_bytes.unwrap_or(entries.len() as u64));
    varint::put(&mut bytes, payload_bytes);
    bytes.extend_from_slice(&entries);
    bytes.extend(std::iter::repeat_n(0, payload_bytes as usize));
    bytes
}

#[test]
fn lying_indexes_are_refused() {
    let refusal = |bytes: Vec<u8>| StreamReader::open(&bytes).unwrap_err().to_string();
    let e = refusal(with_entries(&[(4, 1), (10, 0)], None, 8));
    assert!(e.contains("runs past"), "{e}");
    let e = refusal(with_entries(&[(2, 1), (2, 0)], None, 8));
    assert!(e.contains("cover 4 of the 8"), "{e}");
    // More children than units follow.
    let e = refusal(with_entries(&[(4, 2), (4, 0)], None, 8));
    assert!(e.contains("unit 0 has 2 children"), "{e}");
    // Index bytes that end inside an entry, or after the entries end.
    let e = refusal(with_entries(&[(200, 1), (200, 0)], Some(5), 400));
    assert!(e.contains("runs past the index's end"), "{e}");
    let long = with_entries(&[(200, 1), (200, 0)], Some(7), 400);
    let e = refusal(long.clone());
    assert!(e.contains("it says at"), "{e}");
    // Read by parts, the same once the last entry is in, before the index's said end.
    let (_, mut pos) = Header::read(&long).unwrap();
    let mut partial = PartialIndex::start(&long, &mut pos).unwrap();
    let e = partial.read_on(&long[..pos + 6]).unwrap_err().to_string();
    assert!(e.contains("it says at"), "{e}");
    // A count of units its index bytes cannot hold is refused before any entry is read, and
    // so is a count of index bytes the stream does not hold.
    let mut huge = Vec::new();
    header().write(&mut huge);
    varint::put(&mut huge, limits::MAX_UNITS);
    varint::put(&mut huge, 8);
    varint::put(&mut huge, 8);
    assert!(refusal(huge.clone()).contains("units in 8 bytes"));
    huge.truncate(huge.len() - 2);
    varint::put(&mut huge, limits::MAX_UNITS * 2);
    varint::put(&mut huge, 8);
    assert!(matches!(
        StreamReader::open(&huge),
        Err(Error::Truncated(_))
    ));
    // Two units that both need no other are a valid index, but not the levels of a layered
    // codec.
    let bytes = with_entries(&[(4, 0), (4, 0)], None, 8);
    let reader = StreamReader::open(&bytes).unwrap();
    assert_eq!(reader.index().units[1].parent, None);
    assert!(reader.require_layered().is_err());
}

/// Children counts give each unit's parent breadth first; an index read by parts gives the
/// same entries as the whole, the payload's offset from its first bytes.
#[test]
fn children_counts_give_parents_breadth_first_and_read_by_parts() {
    // 0 → 1, 2; 1 → 3; 2 → 4, 5; then a unit that needs none.
    let units = [(3, 2), (1, 1), (2, 2), (1, 0), (1, 0), (1, 0), (2, 0)];
    let bytes = with_entries(&units, None, 11);
    let reader = StreamReader::open(&bytes).unwrap();
    let parents: Vec<Option<usize>> = reader.index().units.iter().map(|u| u.parent).collect();
    assert_eq!(
        parents,
        [None, Some(0), Some(0), Some(1), Some(2), Some(2), None]
    );
    let offsets: Vec<u64> = reader.index().units.iter().map(|u| u.offset).collect();
    assert_eq!(offsets, [0, 3, 4, 6, 7, 8, 9]);
    // Written back, the same bytes.
    assert_eq!(with_index(reader.index(), &[0; 11]), bytes);
    let (_, mut pos) = Header::read(&bytes).unwrap();
    let mut partial = PartialIndex::start(&bytes, &mut pos).unwrap();
    assert_eq!(partial.payload_start, reader.payload_start());
    for cut in pos..=partial.payload_start {
        partial.read_on(&bytes[..cut]).unwrap();
        assert_eq!(
            partial.index.units[..],
            reader.index().units[..partial.index.len()]
        );
    }
    assert_eq!(partial.finish().unwrap(), *reader.index());
}

#[test]
fn bytes_after_the_payload_are_refused() {
    let (mut bytes, _) = two_levels();
    bytes.push(0);
    let e = StreamReader::open(&bytes).unwrap_err();
    assert!(e.to_string().contains("after the last unit"), "{e}");
}

#[test]
fn levels_read_from_an_input_stream_match() {
    let (bytes, _) = two_levels();
    let mut source = ReadLevels::open(&bytes[..]).unwrap();
    assert_eq!(
        source.next_owned_level().unwrap().unwrap().bytes,
        vec![9; 5]
    );
    assert_eq!(source.next_owned_level().unwrap().unwrap().bytes.len(), 300);
    assert!(source.next_owned_level().unwrap().is_none());
}

/// A finished stream reopened takes the appearance unit after its last unit: the header says
/// what it carries, the index where the unit lies, the full level ends with it, and the levels'
/// costs are those first recorded; a stream that already carries appearance is refused.
#[test]
fn a_reopened_stream_takes_the_appearance_unit_before_it_finishes() {
    let (bytes, records) = two_levels();
    let mut writer = StreamWriter::reopen(bytes, &records).unwrap();
    let spec = AppearanceSpec {
        colours: true,
        ..AppearanceSpec::default()
    };
    writer.set_appearance(spec.clone(), vec![7; 11]);
    let (with, levels) = writer.finish();
    let reader = StreamReader::open(&with).unwrap();
    assert_eq!(reader.header().appearance.as_ref(), Some(&spec));
    assert_eq!(reader.appearance_unit().unwrap().0, &[7; 11][..]);
    assert_eq!(reader.unit(1).unwrap().bytes, &[8; 300][..]);
    assert_eq!(levels.last().unwrap().end_byte, with.len());
    assert_eq!(levels[0].end_byte - reader.payload_start(), 5);
    for (a, b) in levels.iter().zip(&records) {
        assert_eq!(
            (
                a.connectivity_bits,
                a.geometry_bits,
                a.vertices,
                a.triangles
            ),
            (
                b.connectivity_bits,
                b.geometry_bits,
                b.vertices,
                b.triangles
            )
        );
    }
    let refused = StreamWriter::reopen(with, &levels).err().unwrap();
    assert!(
        refused.to_string().contains("already carries appearance"),
        "{refused}"
    );
}
