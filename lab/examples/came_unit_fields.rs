//! What the units a view reads hold: a mesh's `came` stream, then for the far, middle and near
//! views of the came-vd table (1 px, two-sided, guard on) the units the front asks for, and
//! their bits by field against the whole stream's: where a view's bytes go.
//! Run: cargo run --release --example came_unit_fields -- MESH (a shared mesh's name or a file)
use meshcodec::codecs::came::modelled::{encode_with_unit_fields, Came};
use meshcodec::codecs::came::refine::{head_length, Budget, Fetch, View, ViewMesh};
use meshcodec::codecs::{canonical_for, Codec};
use meshcodec::mesh::io;
use meshcodec_lab::came::vd::{framing, view_camera, TOLERANCE_PX, VIEWS};
use std::collections::BTreeMap;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args()
        .nth(1)
        .ok_or("usage: came_unit_fields MESH")?;
    let mesh = io::read_mesh(&io::resolve(&name)?)?;
    let codec = Came;
    let canonical = canonical_for(&mesh, &codec.default_options())?;
    let (encoded, unit_fields) = encode_with_unit_fields(&canonical)?;
    let bytes = encoded.bytes;
    let mut total: BTreeMap<&str, f64> = BTreeMap::new();
    for fields in &unit_fields {
        for (k, v) in fields {
            *total.entry(k).or_default() += v;
        }
    }
    let all_bits: f64 = total.values().sum();
    println!(
        "{name}: {} bytes, {} units, {:.0} bytes of coded fields",
        bytes.len(),
        unit_fields.len(),
        all_bits / 8.0
    );
    let mut full = ViewMesh::from_stream(&bytes)?;
    full.settle(&View::everything(), Budget::UNLIMITED, 256);
    let framed = framing(&full.mesh())?;
    for (view_name, diagonals) in VIEWS {
        let camera = view_camera(view_name, diagonals, framed);
        let view = View::new(&camera, TOLERANCE_PX)?.two_sided(true);
        // The caller fetches: every unit the front asks for is listed.
        let head = head_length(&bytes)?.ok_or("the stream's head is cut")? as usize;
        let mut front = ViewMesh::open(bytes[..head].to_vec(), Fetch::External)?;
        let mut read = vec![0usize];
        for _ in 0..1000 {
            let adapted = front.adapt(&view, Budget::UNLIMITED);
            let wanted = front.wanted();
            if wanted.is_empty() && adapted.settled {
                break;
            }
            for (unit, range) in wanted {
                front.supply(unit, &bytes[range.start as usize..range.end as usize])?;
                read.push(unit);
            }
        }
        let mut fields: BTreeMap<&str, f64> = BTreeMap::new();
        for &unit in &read {
            for (k, v) in &unit_fields[unit] {
                *fields.entry(k).or_default() += v;
            }
        }
        let read_bits: f64 = fields.values().sum();
        let fetched = front.fetched();
        println!(
            "\n{view_name}: {} faces, {} vertices ({:.1}% of the mesh's), {} of {} units, {} bytes read ({:.1}%): {:.0} bytes of coded fields, {:.0} of header, index and unit padding",
            front.face_count(),
            front.vertex_count(),
            100.0 * front.vertex_count() as f64 / canonical.cells.len() as f64,
            read.len(),
            unit_fields.len(),
            fetched.bytes_read,
            100.0 * fetched.bytes_read as f64 / bytes.len() as f64,
            read_bits / 8.0,
            fetched.bytes_read as f64 - read_bits / 8.0
        );
        println!("| field | bytes read | share of read | share of the field stream-wide |");
        println!("|---|---:|---:|---:|");
        for (k, v) in &fields {
            println!(
                "| {k} | {:.0} | {:.1}% | {:.1}% |",
                v / 8.0,
                100.0 * v / read_bits,
                100.0 * v / total[k]
            );
        }
    }
    Ok(())
}
