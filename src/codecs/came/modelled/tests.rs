//! `came`'s promises on generated meshes: every decoded cone holds its subtree's face normals,
//! every sphere its subtree's vertices; a meta-node decodes alone once its ancestors are; prefixes
//! decode the levels they hold and the whole stream is exact.

use super::*;
use crate::codecs::{canonical_for, decode, Stop};
use crate::hierarchy::came::NodeId;
use crate::mesh::generate;

fn stream(mesh: &crate::mesh::TriMesh) -> (CanonicalMesh, Vec<u8>) {
    let canonical = canonical_for(mesh, &Came.default_options()).unwrap();
    let bytes = Came.encode(&canonical).unwrap().bytes;
    (canonical, bytes)
}

fn decoder(bytes: &[u8]) -> CameDecoder<'_, ModelledUnits> {
    let reader = StreamReader::open(bytes).unwrap();
    let params = params(reader.header()).unwrap();
    CameDecoder::new(reader, params, ModelledUnits::default()).unwrap()
}

#[test]
fn every_decoded_cone_holds_the_normal_of_every_face_at_its_subtree() {
    let mut mesh = generate::icosphere(3);
    let far = generate::torus(1.0, 0.3, 30, 12);
    mesh.append(&far, glam::DVec3::new(3.0, 0.5, 0.0), 1.0);
    let (canonical, bytes) = stream(&mesh);
    let mut d = decoder(&bytes);
    while d.advance().unwrap() {}
    let tree = d.tree();
    let leaf_at: std::collections::HashMap<[u32; 3], NodeId> = tree
        .nodes
        .iter()
        .filter(|n| n.leaf)
        .map(|n| (n.position.map(|x| x as u32), n.id))
        .collect();
    let cell = glam::DVec3::from_array(canonical.grid.cell);
    let (mut checked, mut with_cone) = (0, 0);
    for face in &canonical.faces {
        let p = face
            .map(|v| glam::DVec3::from_array(canonical.cells[v as usize].map(f64::from)) * cell);
        let normal = (p[1] - p[0]).cross(p[2] - p[0]).normalize();
        for &v in face {
            let leaf = leaf_at[&canonical.cells[v as usize]];
            for len in 0..leaf.len() {
                let a = &tree.nodes[tree.get(leaf.ancestor(len)).unwrap() as usize];
                let cone = a.cone.decoded();
                checked += 1;
                if !cone.is_some() {
                    continue;
                }
                with_cone += 1;
                let axis = glam::DVec3::from_array(cone.axis.map(f64::from));
                let off = normal.cross(axis).length().atan2(normal.dot(axis));
                assert!(off <= cone.half_angle as f64 + 1e-5, "{:?}", a.id);
            }
        }
    }
    assert!(
        with_cone > checked / 4,
        "{with_cone} of {checked} with a cone"
    );
}

#[test]
fn every_sphere_holds_every_vertex_of_its_subtree() {
    let mut mesh = generate::icosphere(4);
    let far = generate::torus(1.0, 0.3, 30, 12);
    mesh.append(&far, glam::DVec3::new(3.0, 0.5, 0.0), 1.0);
    let (_, bytes) = stream(&mesh);
    let mut d = decoder(&bytes);
    while d.advance().unwrap() {}
    let tree = d.tree();
    let mut checked = 0;
    for leaf in tree.nodes.iter().filter(|n| n.leaf) {
        let p = glam::DVec3::from_array(leaf.position);
        for len in 0..leaf.id.len() {
            let a = &tree.nodes[tree.get(leaf.id.ancestor(len)).unwrap() as usize];
            let distance = p.distance(glam::DVec3::from_array(a.position));
            assert!(
                distance <= a.radius,
                "{:?}: {distance} > {}",
                a.id,
                a.radius
            );
            checked += 1;
        }
    }
    assert!(checked > 10 * tree.nodes.len() / 2);
}

#[test]
fn a_meta_node_decodes_alone_once_its_ancestors_are() {
    let (_, bytes) = stream(&generate::icosphere(5));
    let mut full = decoder(&bytes);
    while full.advance().unwrap() {}
    let reader = StreamReader::open(&bytes).unwrap();
    let units = reader.index().units.clone();
    assert!(units.len() > 8, "{} units", units.len());
    let last = units.len() - 1;
    let mut chain = vec![last];
    while let Some(p) = units[*chain.last().unwrap()].parent {
        chain.push(p);
    }
    chain.reverse();
    let mut alone = decoder(&bytes);
    let e = alone.decode_unit(last).unwrap_err();
    assert!(e.to_string().contains("parent unit decoded first"), "{e}");
    for &i in &chain {
        assert!(alone.decode_unit(i).unwrap());
    }
    let corners = |d: &CameDecoder<'_, ModelledUnits>| -> Vec<[NodeId; 3]> {
        d.unit_triangles(last)
            .unwrap()
            .iter()
            .map(|t| t.corners)
            .collect()
    };
    assert!(!corners(&alone).is_empty());
    assert_eq!(corners(&alone), corners(&full));
    assert!(alone.decode_unit(last).is_err());
}

#[test]
fn prefixes_decode_the_levels_they_hold_and_the_whole_stream_is_exact() {
    let (canonical, bytes) = stream(&generate::icosphere(4));
    let (whole, _) = decode(&bytes, Stop::All).unwrap();
    canonical.check_lossless(&whole.mesh).unwrap();
    crate::codecs::came::tests::check_prefixes(&canonical, &bytes);
}

/// A unit decoded before the units that split its region's nodes above its band (what a lying
/// index would ask for) is refused in one line before it changes the tree: here a unit rooted
/// two bands below the first unit, its parent unit skipped.
#[test]
fn a_unit_whose_region_holds_a_node_no_unit_above_it_split_is_refused() {
    use super::super::decoded::{DecodedTree, UnitDecoder};
    let (_, bytes) = stream(&generate::icosphere(5));
    let reader = StreamReader::open(&bytes).unwrap();
    let header = reader.header().clone();
    let params = params(&header).unwrap();
    let first = reader.unit(0).unwrap();
    let units = ModelledUnits::default();
    let mut tree = DecodedTree::new(header.vertices, header.triangles, bytes.len());
    let opened = units
        .decode_unit(&mut tree, &header, &params, 0, first.bytes, first.start)
        .unwrap();
    assert!(!opened.is_empty());
    // The first unit's children are rooted a band down; their own children a band further,
    // and it is those whose regions reach below what the first unit split.
    let Shape::Bands { band, .. } = SHAPE else {
        panic!("came cuts by bands")
    };
    let grandchild = (0..tree.nodes.len() as u32)
        .find(|&v| {
            let node = &tree.nodes[v as usize];
            node.id.len() == 2 * band && !node.leaf
        })
        .expect("an inner node two bands down");
    let nodes = tree.nodes.len();
    let unit = reader.unit(1).unwrap();
    let refused = units
        .decode_unit(
            &mut tree, &header, &params, grandchild, unit.bytes, unit.start,
        )
        .unwrap_err()
        .to_string();
    assert!(
        refused.contains("a unit's region holds a node no unit above it split"),
        "{refused}"
    );
    assert_eq!(tree.nodes.len(), nodes);
}

/// A unit refused once decoded (here by the check a client runs on what it added) leaves the
/// tree as it was (syntax 9): the corner paths it carried on wait again where they waited, at
/// the paths before, and those it began wait nowhere; decoded again, it is kept, and the
/// stream decodes whole with no path left waiting.
#[test]
fn a_refused_unit_puts_back_the_corner_paths_it_carried_on() {
    let (_, bytes) = stream(&generate::icosphere(5));
    let reader = StreamReader::open(&bytes).unwrap();
    let mut d = decoder(&bytes);
    let corners = |d: &CameDecoder<'_, ModelledUnits>| -> Vec<[NodeId; 3]> {
        d.tree().triangles.iter().map(|t| t.corners).collect()
    };
    let mut carried = 0;
    for i in 0..reader.index().units.len() {
        let unit = reader.unit(i).unwrap();
        let before = (corners(&d), d.tree().waiting.clone());
        let refused = d.decode_unit_checked(i, unit.bytes, |added| {
            carried += added.tree.carried().count();
            Err::<(), _>(crate::Error::Unsupported("refused by its check".into()))
        });
        assert!(refused.is_err());
        assert!(
            (corners(&d), d.tree().waiting.clone()) == before,
            "unit {i}"
        );
        d.decode_unit_bytes(i, unit.bytes).unwrap();
    }
    assert!(carried > 100, "{carried} paths carried on");
    assert!(d.tree().waiting.is_empty());
    for t in &d.tree().triangles {
        for c in t.corners {
            assert!(d.tree().nodes[d.tree().get(c).unwrap() as usize].leaf);
        }
    }
}

/// Syntax 9 reads both cuts `came` writes (bands of two levels over regions of four, and of one
/// over regions of three for large meshes); syntax 8 only the first; any other is refused.
#[test]
fn syntax_9_reads_the_large_meshes_bands_and_no_others() {
    let (_, bytes) = stream(&generate::icosphere(2));
    let mut header = StreamReader::open(&bytes).unwrap().header().clone();
    assert_eq!(header.syntax, 9);
    assert_eq!((header.params[8], header.params[0]), (4, 2));
    (header.params[8], header.params[0]) = (3, 1);
    let large = params(&header).unwrap();
    assert_eq!(
        large.shape(),
        Shape::Bands {
            region: 3,
            band: 1,
            whole: 0
        }
    );
    header.syntax = 8;
    let refused = params(&header).unwrap_err().to_string();
    assert!(
        refused.contains("bands of 2 levels over regions of 4"),
        "{refused}"
    );
    header.syntax = 9;
    (header.params[8], header.params[0]) = (5, 1);
    let refused = params(&header).unwrap_err().to_string();
    assert!(
        refused.contains("regions of 4 or bands of 1 level over regions of 3"),
        "{refused}"
    );
}
