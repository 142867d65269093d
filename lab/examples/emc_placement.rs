//! Where `emc`'s intermediate levels show their vertices, and what it does to their error: each
//! level of each mesh at 12 bits (cubic grid) as the decoder shows it (every vertex where its
//! neighbours predict it inside its cell, `codecs::emc::modelled::placement`) and with every
//! vertex at its cell's centre, as the paper shows it; RMS and Hausdorff relative to the
//! bounding box's diagonal, both ways, 10 samples a triangle (as `experiment`).
//! Run: cargo run --release --example emc_placement -- [mesh…]

use meshcodec::codecs::{self, EncodeOptions, LevelMesh};
use meshcodec::mesh::io::{read_mesh, resolve};
use meshcodec::mesh::quantize::GridShape;
use meshcodec::mesh::Grid;
use meshcodec::metrics::{Reference, SampleBudget, DEFAULT_SEED};

/// `level` with every vertex moved to the centre of its cell at `level` (whole levels of a
/// cubic grid: each axis has taken `level` bits).
fn at_cell_centres(shown: &LevelMesh, grid: &Grid, level: u8) -> LevelMesh {
    let shift = grid.bits - level;
    let last = (1u32 << level) - 1;
    let mut centred = shown.clone();
    for p in &mut centred.mesh.positions {
        let cell = [0, 1, 2].map(|a| {
            let size = grid.cell[a] * (1u64 << shift) as f64;
            (((p[a] - grid.origin[a]) / size).floor().max(0.0) as u32).min(last)
        });
        *p = grid.coarse_centre(cell, [shift; 3]);
    }
    centred
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let mut meshes: Vec<String> = std::env::args().skip(1).collect();
    if meshes.is_empty() {
        meshes = vec!["bunny".into(), "armadillo-43k".into()];
    }
    let options = EncodeOptions {
        quant_bits: 12,
        grid: GridShape::Cubic,
    };
    for name in meshes {
        let mesh = read_mesh(&resolve(&name)?)?;
        let canonical = codecs::canonical_for(&mesh, &options)?;
        let encoded = codecs::by_name("emc")?.encode(&canonical)?;
        let reference = Reference::new(&mesh, SampleBudget::default(), DEFAULT_SEED);
        let mut decoder = codecs::open(&encoded.bytes)?;
        let grid = decoder.header().grid;
        let levels = decoder.levels();
        println!("{name} (12 bits, {} vertices)", canonical.vertex_count());
        println!("| level | bits/vertex | RMS at centres | RMS shown | ratio | Hausdorff at centres | Hausdorff shown |");
        println!("|---:|---:|---:|---:|---:|---:|---:|");
        for record in &encoded.levels {
            if !decoder.advance()? {
                break;
            }
            let level = decoder.levels_decoded();
            if level == levels {
                break; // exact: shown at the decoded cells' centres
            }
            let shown = decoder.mesh()?;
            let centred = at_cell_centres(&shown, &grid, level as u8);
            let (Some(s), Some(c)) = (reference.compare(&shown), reference.compare(&centred))
            else {
                continue;
            };
            println!(
                "| {level} | {:.3} | {:.3e} | {:.3e} | {:.2} | {:.3e} | {:.3e} |",
                record.end_byte as f64 * 8.0 / canonical.vertex_count() as f64,
                c.rms,
                s.rms,
                c.rms / s.rms,
                c.hausdorff,
                s.hausdorff
            );
        }
        println!();
    }
    Ok(())
}
