//! What coding appearance with the levels costs against the appearance unit, and what each
//! level shows: for each mesh, `emc` and `emc-ahead` streams both ways, each level's bytes,
//! uvs and whether the full level is lossless.
use meshcodec::codecs::{self, canonical_attributed_for, EncodeOptions};
use meshcodec::mesh::attribute_quantization::AttributeBits;
use std::path::Path;

fn main() {
    for name in std::env::args().skip(1) {
        let path = meshcodec::mesh::io::resolve(&name).expect("mesh");
        let mesh = meshcodec::mesh::io::read_attributed(Path::new(&path)).expect("read");
        for codec_name in ["emc", "emc-ahead"] {
            let codec = codecs::by_name(codec_name).unwrap();
            let options = EncodeOptions {
                quant_bits: 12,
                ..codec.default_options()
            };
            let (canonical, appearance) =
                canonical_attributed_for(&mesh, &options, AttributeBits::default()).unwrap();
            let plain = codec.encode(&canonical).unwrap();
            let unit = codecs::encode_with_appearance_unit(codec, &canonical, &appearance).unwrap();
            let levels = codecs::encode_attributed(codec, &canonical, Some(&appearance)).unwrap();
            let v = canonical.vertex_count() as f64;
            let bpv = |n: usize| n as f64 * 8.0 / v;
            println!(
                "{name} {codec_name}: geometry {} B ({:.2} bpv); with unit {} B ({:.2} bpv); with levels {} B ({:.2} bpv)",
                plain.bytes.len(),
                bpv(plain.bytes.len()),
                unit.bytes.len(),
                bpv(unit.bytes.len()),
                levels.bytes.len(),
                bpv(levels.bytes.len()),
            );
            let mut decoder = codecs::open(&levels.bytes).unwrap();
            while decoder.advance().unwrap() {
                let level = decoder.mesh().unwrap();
                let a = level.attributes.as_ref();
                println!(
                    "  level {:2}: {:5} vertices {:5} faces, attributes {}",
                    decoder.levels_decoded(),
                    level.mesh.positions.len(),
                    level.mesh.faces.len(),
                    a.map_or("none".to_string(), |a| format!(
                        "{} wedges, uvs {}",
                        a.wedge_vertex.len(),
                        a.uvs.is_some()
                    ))
                );
            }
            let full = decoder.mesh().unwrap();
            let lossless = canonical.check_lossless(&full.mesh).is_ok();
            println!("  full level lossless (geometry): {lossless}");
        }
    }
}
