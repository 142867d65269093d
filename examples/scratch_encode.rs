use meshcodec::codecs::{self, EncodeOptions};
use meshcodec::mesh::quantize::GridShape;
use std::time::Instant;
fn main() -> Result<(), Box<dyn std::error::Error>> {
    let subs: u32 = std::env::args().nth(1).and_then(|s| s.parse().ok()).unwrap_or(2);
    let (_, mesh) = meshcodec::came_extras::table_mesh("bunny-closed-35k", subs)?;
    let options = EncodeOptions { quant_bits: 12, grid: GridShape::Cubic };
    let canonical = codecs::canonical_for(&mesh, &options)?;
    let codec = codecs::by_name("emc")?;
    for _ in 0..3 {
        let t = Instant::now();
        let e = codec.encode(&canonical)?;
        eprintln!("encode {:.3} s {} bytes", t.elapsed().as_secs_f64(), e.bytes.len());
    }
    Ok(())
}
