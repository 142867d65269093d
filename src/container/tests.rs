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

#[test]
fn lying_indexes_are_refused() {
    let entry = |offset, length, parent| UnitEntry {
        offset,
        length,
        parent,
    };
    let past = Index {
        units: vec![entry(0, 4, None), entry(4, 10, Some(0))],
        payload_bytes: 8,
        appearance: None,
    };
    let e = StreamReader::open(&with_index(&past, &[0; 8])).unwrap_err();
    assert!(e.to_string().contains("runs past"), "{e}");
    let overlapping = Index {
        units: vec![entry(0, 6, None), entry(4, 2, Some(0))],
        payload_bytes: 8,
        appearance: None,
    };
    let e = StreamReader::open(&with_index(&overlapping, &[0; 8])).unwrap_err();
    assert!(e.to_string().contains("overlap"), "{e}");
    let gap = Index {
        units: vec![entry(0, 2, None), entry(4, 2, Some(0))],
        payload_bytes: 8,
        appearance: None,
    };
    let e = StreamReader::open(&with_index(&gap, &[0; 8])).unwrap_err();
    assert!(e.to_string().contains("cover 4 of the 8"), "{e}");
    // A count of units the bytes cannot hold is refused before any entry is read.
    let mut huge = Vec::new();
    header().write(&mut huge);
    varint::put(&mut huge, limits::MAX_UNITS);
    varint::put(&mut huge, 8);
    assert!(matches!(
        StreamReader::open(&huge),
        Err(Error::Truncated(_))
    ));
    // Units out of order are a valid index, but not the levels of a layered codec.
    let swapped = Index {
        units: vec![entry(4, 4, None), entry(0, 4, Some(0))],
        payload_bytes: 8,
        appearance: None,
    };
    let bytes = with_index(&swapped, &[0; 8]);
    assert!(StreamReader::open(&bytes).is_ok());
    assert!(StreamReader::open(&bytes)
        .unwrap()
        .require_layered()
        .is_err());
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
