//! Every mesh in ../shared/meshes loads with the vertex and face counts its MANIFEST.md states.

mod common;

use meshcodec::mesh::io::{data_dirs, read_mesh};
use std::path::PathBuf;

fn shared_dir() -> PathBuf {
    data_dirs()
        .into_iter()
        .find(|d| d.join("MANIFEST.md").is_file())
        .expect("../shared/meshes with its MANIFEST.md beside the checkout")
}

/// (file, vertices, faces) rows of the manifest's table.
fn manifest_rows() -> Vec<(String, usize, usize)> {
    let text = std::fs::read_to_string(shared_dir().join("MANIFEST.md")).unwrap();
    let number = |cell: &str| -> Option<usize> {
        let digits: String = cell
            .split_whitespace()
            .next()?
            .chars()
            .filter(|c| c.is_ascii_digit())
            .collect();
        digits.parse().ok()
    };
    text.lines()
        .filter(|l| l.starts_with('|'))
        .filter_map(|l| {
            let cells: Vec<&str> = l.split('|').map(str::trim).collect();
            let file = cells.get(1)?.to_string();
            let readable = meshcodec::mesh::io::EXTENSIONS
                .iter()
                .any(|e| file.ends_with(&format!(".{e}")));
            if !readable {
                return None;
            }
            Some((file, number(cells.get(3)?)?, number(cells.get(4)?)?))
        })
        .collect()
}

#[test]
fn every_shared_mesh_loads_with_its_manifest_counts() {
    let rows = manifest_rows();
    assert!(rows.len() >= 30, "manifest lists {} meshes", rows.len());
    let dir = shared_dir();
    let mut wrong = Vec::new();
    for (file, vertices, faces) in &rows {
        let mesh = read_mesh(&dir.join(file)).unwrap_or_else(|e| panic!("{file}: {e}"));
        if (mesh.vertex_count(), mesh.face_count()) != (*vertices, *faces) {
            wrong.push(format!(
                "{file}: {} v / {} f, manifest {vertices} / {faces}",
                mesh.vertex_count(),
                mesh.face_count()
            ));
        }
    }
    assert!(wrong.is_empty(), "{}", wrong.join("\n"));
}

#[test]
fn bunny_has_34834_referenced_vertices() {
    let mesh = read_mesh(&shared_dir().join("bunny.ply")).unwrap();
    assert_eq!(mesh.referenced().iter().filter(|&&u| u).count(), 34_834);
}

/// Every shared mesh round-trips losslessly through every lossless codec at 12 and 24 bits (pm:
/// 12 and 16, its default), on both grids for EMC; through a lossy one (came-paper) with every
/// vertex and face, at 12 bits. pm takes every one, cutting those that are no oriented
/// manifold to one, and no crack opens at any of their levels. Each mesh and codec is a job of
/// its own, the jobs spread over the cores: most encoders keep to one, and on two cores the
/// test took 257 s one job after another, 199 s so.
#[test]
fn every_shared_mesh_round_trips_losslessly() {
    use meshcodec::codecs::{self, EncodeOptions, Stop};
    use meshcodec::mesh::quantize::GridShape;
    use rayon::prelude::*;
    let dir = shared_dir();
    let meshes: Vec<_> = manifest_rows()
        .into_iter()
        .map(|(file, _, _)| {
            let mesh = read_mesh(&dir.join(&file)).unwrap();
            (file, mesh)
        })
        .collect();
    let registry = codecs::registry();
    let jobs: Vec<_> = meshes
        .iter()
        .flat_map(|mesh| registry.iter().map(move |codec| (mesh, codec)))
        .collect();
    // Per job: the failures, and the runs pm cut to a manifold.
    let (failures, cut): (Vec<Vec<String>>, Vec<Vec<String>>) = jobs
        .into_par_iter()
        .map(|((file, mesh), codec)| {
            let (mut failures, mut cut) = (Vec::new(), Vec::new());
            let pm = codec.name().starts_with("pm");
            let all_bits: &[u8] = match (pm, codec.lossless()) {
                (true, _) => &[12, 16],
                (false, true) => &[12, 24],
                (false, false) => &[12],
            };
            for &bits in all_bits {
                for grid in [GridShape::Cubic, GridShape::PerAxis] {
                    if grid == GridShape::PerAxis && !codec.name().starts_with("emc") {
                        continue;
                    }
                    let options = EncodeOptions {
                        quant_bits: bits,
                        grid,
                    };
                    let canonical = codecs::canonical_for(mesh, &options).unwrap();
                    let encoded = match codec.encode(&canonical) {
                        Ok(e) => e,
                        Err(e) => panic!("{} {file} {bits} bits: {e}", codec.name()),
                    };
                    if pm {
                        let t = meshcodec::mesh::topology::analyze(&canonical.to_mesh());
                        if !t.is_oriented_manifold() {
                            let copies = common::walk_without_cracks(&encoded.bytes, false);
                            cut.push(format!(
                                "{} {file} {bits} bits ({copies} copies)",
                                codec.name()
                            ));
                        }
                    }
                    let (decoded, _) = codecs::decode(&encoded.bytes, Stop::All).unwrap();
                    if !codec.lossless() {
                        // Lossy by design: every vertex and face comes back, moved.
                        let got = (decoded.mesh.vertex_count(), decoded.mesh.face_count());
                        let want = (canonical.vertex_count(), canonical.face_count());
                        if got != want {
                            failures.push(format!(
                                "{} {file}: decodes {got:?} vertices and faces, not {want:?}",
                                codec.name()
                            ));
                        }
                        continue;
                    }
                    if let Err(e) = canonical.check_lossless(&decoded.mesh) {
                        failures.push(format!("{} {file} {bits} bits {grid:?}: {e}", codec.name()));
                    }
                }
            }
            (failures, cut)
        })
        .unzip();
    let (failures, cut) = (failures.concat(), cut.concat());
    assert!(failures.is_empty(), "{}", failures.join("\n"));
    eprintln!("cut to a manifold by pm: {}", cut.join(", "));
    // The meshes MANIFEST.md says are not manifolds are among them.
    for name in ["cow.obj", "teapot.obj", "dragon-res3.ply", "porsche.ply"] {
        assert!(cut.iter().any(|r| r.contains(name)), "{name} was not cut");
    }
}

/// Every shared OBJ and PLY reads with its appearance — the same geometry as without it, wedges
/// that validate, as many attributes as `appearance_of` counts in the file — and each writer
/// that can hold what it carries writes a file that reads back to the same wedges.
#[test]
fn every_shared_obj_and_ply_keeps_its_appearance_through_both_writers() {
    use meshcodec::mesh::io::{
        appearance_of, read_attributed, read_attributed_bytes, write_attributed_bytes,
    };
    let dir = shared_dir();
    let mut report = Vec::new();
    for (file, _, _) in manifest_rows() {
        let ext = file.rsplit('.').next().unwrap_or("").to_string();
        if ext != "obj" && ext != "ply" {
            continue;
        }
        let path = dir.join(&file);
        let m = read_attributed(&path).unwrap_or_else(|e| panic!("{file}: {e}"));
        assert!(
            m.mesh == read_mesh(&path).unwrap(),
            "{file}: geometry differs"
        );
        let a = &m.attributes;
        a.validate(&m.mesh).unwrap();
        let bytes = std::fs::read(&path).unwrap();
        let counted = appearance_of(&bytes, &ext, m.mesh.positions.len(), m.mesh.faces.len());
        assert_eq!(a.normals.is_some(), counted.normals > 0, "{file}: normals");
        assert_eq!(a.uvs.is_some(), counted.uvs > 0, "{file}: uvs");
        assert_eq!(a.colours.is_some(), counted.colours > 0, "{file}: colours");
        assert_eq!(
            a.materials.is_some(),
            counted.materials > 0,
            "{file}: materials"
        );
        let mut written = Vec::new();
        for out in ["obj", "ply"] {
            let Ok(bytes) = write_attributed_bytes(&m, out) else {
                continue;
            };
            let back = read_attributed_bytes(&bytes, out).unwrap();
            assert_eq!(
                back.attributes.wedge_count(),
                a.wedge_count(),
                "{file} through {out}"
            );
            written.push(out);
        }
        if !a.is_empty() {
            report.push(format!(
                "{file}: {} wedges, written as {written:?}",
                a.wedge_count()
            ));
        }
    }
    assert!(report.len() >= 4, "{report:?}");
}
