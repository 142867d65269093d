//! Property tests over generated meshes: the canonical mesh, the readers and writers, and the
//! `raw` codec's losslessness and prefix behaviour.

use meshcodec::codecs::{self, Stop};
use meshcodec::mesh::canonical::CanonicalMesh;
use meshcodec::mesh::generate;
use meshcodec::mesh::io::{read_mesh_bytes, write_obj, write_ply};
use meshcodec::mesh::quantize::{Grid, GridShape};
use proptest::prelude::*;

fn cases() -> u32 {
    std::env::var("PROPTEST_CASES")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(256)
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(cases()))]

    #[test]
    fn canonical_mesh_obeys_its_rules(seed in any::<u64>(), bits in 1u8..=24, per_axis in any::<bool>()) {
        let mesh = generate::messy(seed);
        let shape = if per_axis { GridShape::PerAxis } else { GridShape::Cubic };
        let grid = Grid::fit(&mesh, bits, shape).unwrap();
        let canon = CanonicalMesh::new(&mesh, grid).unwrap();
        let mut cells = canon.cells.clone();
        cells.sort_unstable();
        cells.dedup();
        prop_assert_eq!(cells.len(), canon.cells.len(), "cells repeat");
        let mut faces: Vec<_> = canon.faces.iter().map(|f| meshcodec::mesh::canonical::rotate_to_smallest(*f)).collect();
        faces.sort_unstable();
        faces.dedup();
        prop_assert_eq!(faces.len(), canon.faces.len(), "faces repeat");
        for f in &canon.faces {
            prop_assert!(f[0] != f[1] && f[1] != f[2] && f[0] != f[2]);
        }
        // Canonicalizing the canonical mesh keeps its faces (isolated points aside).
        if !canon.faces.is_empty() {
            let again = CanonicalMesh::new(&canon.to_mesh(), grid).unwrap();
            let in_cells = |m: &CanonicalMesh| {
                let mut f: Vec<[[u32; 3]; 3]> = m.faces.iter().map(|f| {
                    let c = f.map(|v| m.cells[v as usize]);
                    let k = (0..3).min_by_key(|&k| c[k]).unwrap();
                    [c[k], c[(k + 1) % 3], c[(k + 2) % 3]]
                }).collect();
                f.sort_unstable();
                f
            };
            prop_assert_eq!(in_cells(&again), in_cells(&canon));
        }
        prop_assert_eq!(canon.check_lossless(&canon.to_mesh()), Ok(()));
    }

    #[test]
    fn raw_round_trips_losslessly(seed in any::<u64>(), bits in 1u8..=30) {
        let mesh = generate::messy(seed);
        let codec = codecs::by_name("raw").unwrap();
        let options = codecs::EncodeOptions { quant_bits: bits, grid: GridShape::Cubic };
        let Ok(canonical) = codecs::canonical_for(&mesh, &options) else {
            // At very coarse grids every face may collapse: that is an error, not a panic.
            return Ok(());
        };
        let encoded = codec.encode(&canonical).unwrap();
        let again = codec.encode(&canonical).unwrap();
        prop_assert_eq!(&encoded.bytes, &again.bytes, "encoding is deterministic");
        let (decoded, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
        prop_assert_eq!(canonical.check_lossless(&decoded.mesh), Ok(()));
    }

    #[test]
    fn every_cut_of_a_stream_decodes_or_errors(seed in any::<u64>(), cut_at in any::<prop::sample::Index>()) {
        let mesh = generate::messy(seed);
        let codec = codecs::by_name("raw").unwrap();
        let options = codec.default_options();
        let canonical = codecs::canonical_for(&mesh, &options).unwrap();
        let bytes = codec.encode(&canonical).unwrap().bytes;
        let cut = cut_at.index(bytes.len());
        if let Ok((level, n)) = codecs::decode(&bytes[..cut], Stop::All) {
            prop_assert_eq!(n, 0);
            prop_assert!(level.mesh.faces.is_empty());
        }
    }

    #[test]
    fn writers_and_readers_agree(seed in any::<u64>()) {
        let mesh = generate::messy(seed);
        let grid = Grid::fit(&mesh, 30, GridShape::Cubic).unwrap();
        let expected = CanonicalMesh::new(&mesh, grid).unwrap().normal_form();
        for format in ["ply", "obj"] {
            let mut bytes = Vec::new();
            if format == "ply" { write_ply(&mesh, &mut bytes).unwrap() } else { write_obj(&mesh, &mut bytes).unwrap() }
            let back = read_mesh_bytes(&bytes, format).unwrap();
            let got = CanonicalMesh::new(&back, grid).unwrap().normal_form();
            prop_assert!(got == expected, "{} changed the mesh", format);
        }
    }
}
