//! Diagnostic: at each level of an emc stream with appearance parts, how far each vertex's
//! shown uv lies from its final vertex's uvs (texels of 1024²).
use meshcodec::codecs::{self, canonical_attributed_for, EncodeOptions};
use meshcodec::mesh::attribute_quantization::AttributeBits;
use std::path::Path;

fn main() {
    let name = std::env::args().nth(1).unwrap();
    let path = meshcodec::mesh::io::resolve(&name).expect("mesh");
    let mesh = meshcodec::mesh::io::read_attributed(Path::new(&path)).expect("read");
    let codec = codecs::by_name("emc").unwrap();
    let options = EncodeOptions { quant_bits: 12, ..codec.default_options() };
    let (canonical, appearance) =
        canonical_attributed_for(&mesh, &options, AttributeBits::default()).unwrap();
    let levels = codecs::encode_attributed(codec, &canonical, Some(&appearance)).unwrap();
    let (full, _) = codecs::decode(&levels.bytes, codecs::Stop::All).unwrap();
    let fa = full.attributes.unwrap();
    let fuv = fa.uvs.unwrap();
    // uvs of each final vertex
    let mut at_vertex: Vec<Vec<glam::DVec2>> = vec![Vec::new(); full.mesh.positions.len()];
    for (w, &v) in fa.wedge_vertex.iter().enumerate() {
        at_vertex[v as usize].push(fuv[w]);
    }
    let mut final_face = std::collections::HashMap::new();
    for (f, face) in full.mesh.faces.iter().enumerate() {
        final_face.insert(*face, f);
    }
    let mut decoder = codecs::open(&levels.bytes).unwrap();
    while decoder.advance().unwrap() {
        let level = decoder.mesh().unwrap();
        let a = level.attributes.unwrap();
        let uvs = a.uvs.unwrap();
        let mut errs = Vec::new();
        for (w, &v) in a.wedge_vertex.iter().enumerate() {
            if (w as usize) < level.mesh.positions.len() {
                let best = at_vertex[v as usize].iter().map(|t| (*t - uvs[w]).length() * 1024.0).fold(f64::MAX, f64::min);
                errs.push(best);
            }
        }
        errs.sort_by(f64::total_cmp);
        let n = errs.len();
        let extra = a.wedge_vertex.len() - level.mesh.positions.len();
        // faces whose uv triangle is huge
        let big = a.corners.iter().filter(|c| {
            let t = c.map(|w| uvs[w as usize]);
            ((t[1]-t[0]).length().max((t[2]-t[1]).length()).max((t[0]-t[2]).length())) * 1024.0 > 100.0
        }).count();
        let (mut plain, mut carried, mut np, mut nc, mut bad_c, mut bad_p) = (0.0, 0.0, 0, 0, 0, 0);
        for (f, face) in level.mesh.faces.iter().enumerate() {
            if let Some(&g) = final_face.get(face) {
                for k in 0..3 {
                    let w = a.corners[f][k] as usize;
                    let e = (uvs[w] - fuv[fa.corners[g][k] as usize]).length() * 1024.0;
                    if w >= level.mesh.positions.len() { carried += e; nc += 1; if e > 50.0 { bad_c += 1; if level.mesh.positions.len() == 2924 && f % 50 == 0 { eprintln!("bad carried face {f} {face:?} k {k} shown {:?} true {:?} (true others {:?})", uvs[w] * 4096.0 * 0.25, fuv[fa.corners[g][k] as usize] * 1024.0, [0,1,2].map(|j| fuv[fa.corners[g][j] as usize] * 1024.0)); } } } else { plain += e; np += 1; if e > 50.0 { bad_p += 1; } }
                }
            }
        }
        println!("   faces also final: plain corners {} mean {:.1} ({} > 50), carried {} mean {:.1} ({} > 50)", np, plain / np.max(1) as f64, bad_p, nc, carried / nc.max(1) as f64, bad_c);
        println!("level {:2}: {} vertices, median {:.1} p90 {:.1} max {:.1} texels; {} carried corners; {} of {} faces span >100 texels",
            decoder.levels_decoded(), n, errs[n/2], errs[n*9/10], errs[n-1], extra, big, a.corners.len());
    }
}
