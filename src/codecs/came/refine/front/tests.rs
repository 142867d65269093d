//! The view-dependent mesh's tests: the full decode and the root at the two ends, views near
//! and far, budgets, picking, loading by thread, inline or by the caller, refused meta-nodes,
//! no cracks and no fold-overs in view, and random views and meta-node orders (proptest).

use super::super::loader::{head_length, Reads};
use super::super::view::Camera;
use super::*;
use crate::codecs::{self, EncodeOptions, Stop};
use crate::container::read_header_and_index;
use crate::hierarchy::came::NodeId;
use crate::mesh::quantize::GridShape;
use crate::mesh::{generate, TriMesh};
use proptest::prelude::*;
use std::collections::HashMap;
use std::sync::OnceLock;

/// A came stream of two spheres, a torus and a loose triangle sharing a vertex.
pub(super) fn stream() -> &'static [u8] {
    static STREAM: OnceLock<Vec<u8>> = OnceLock::new();
    STREAM.get_or_init(|| {
        let mut mesh = generate::icosphere(3);
        mesh.append(&generate::icosphere(2), DVec3::new(2.5, 0.0, 0.0), 0.6);
        mesh.append(
            &generate::torus(1.0, 0.3, 24, 10),
            DVec3::new(0.0, 2.5, 0.0),
            1.0,
        );
        let base = mesh.positions.len() as u32;
        mesh.positions
            .extend([DVec3::new(0.0, 0.0, 1.5), DVec3::new(0.3, 0.0, 1.6)]);
        mesh.faces.push([0, base, base + 1]);
        let options = EncodeOptions {
            quant_bits: 12,
            grid: GridShape::Cubic,
        };
        let canonical = codecs::canonical_for(&mesh, &options).unwrap();
        codecs::by_name("came")
            .unwrap()
            .encode(&canonical)
            .unwrap()
            .bytes
    })
}

/// A mesh's triangles as sorted position triples, rotated to start at their least corner.
fn triangles(mesh: &TriMesh) -> Vec<[[i64; 3]; 3]> {
    let key = |p: DVec3| (p * 1e6).round().to_array().map(|x| x as i64);
    let mut all: Vec<[[i64; 3]; 3]> = mesh
        .faces
        .iter()
        .map(|f| {
            let mut t = f.map(|v| key(mesh.positions[v as usize]));
            let least = (0..3).min_by_key(|&k| t[k]).unwrap();
            t.rotate_left(least);
            t
        })
        .collect();
    all.sort();
    all
}

#[test]
fn refining_everything_gives_the_full_decode_and_coarsening_everything_the_root() {
    let mut vm = ViewMesh::from_stream(stream()).unwrap();
    vm.check_invariants().unwrap();
    assert_eq!(
        vm.fetched().units_loaded,
        1,
        "only the root meta-node at first"
    );
    let done = vm.settle(&View::everything(), Budget::UNLIMITED, 64);
    assert!(done.settled && done.collapses == 0);
    let fetched = vm.fetched();
    assert_eq!(fetched.units_loaded, fetched.units);
    assert_eq!(fetched.bytes_read, stream().len() as u64);
    vm.check_invariants().unwrap();
    let (full, _) = codecs::decode(stream(), Stop::All).unwrap();
    let adapted = vm.mesh();
    assert_eq!(adapted.vertex_count(), full.mesh.vertex_count());
    assert_eq!(triangles(&adapted), triangles(&full.mesh));
    let done = vm.adapt(&View::nothing(), Budget::UNLIMITED);
    assert_eq!(
        (done.splits, done.collapses),
        (0, full.mesh.vertex_count() - 1)
    );
    vm.check_invariants().unwrap();
    assert_eq!((vm.vertex_count(), vm.face_count()), (1, 0));
}

/// A client fetching meta-nodes itself (a browser's `Range` requests) from the header, the
/// index and the first unit reaches the front that inline fetching reaches, asking for each
/// unit once and reading only what it asks for.
#[test]
fn fetching_units_externally_reaches_the_inline_front() {
    let bytes = stream();
    assert_eq!(head_length(&bytes[..8]).unwrap(), None);
    let head = head_length(bytes).unwrap().unwrap() as usize;
    assert!(head < bytes.len());
    let view = View::new(&camera(DVec3::new(0.5, 0.8, 3.0)), 1.0).unwrap();
    let mut inline = ViewMesh::from_stream(bytes).unwrap();
    inline.settle(&view, Budget::UNLIMITED, 64);
    let mut external = ViewMesh::open(bytes[..head].to_vec(), Fetch::External).unwrap();
    assert!(
        external.supply(0, &bytes[..1]).is_err(),
        "the first unit is in"
    );
    assert!(external.supply(1 << 20, &[]).is_err(), "no such unit");
    let mut fetched = head as u64;
    let mut asked = std::collections::HashSet::new();
    let mut settled = false;
    for _ in 0..64 {
        let done = external.adapt(&view, Budget::UNLIMITED);
        external.check_invariants().unwrap();
        let wanted = external.wanted();
        if done.settled {
            assert!(wanted.is_empty());
            settled = true;
            break;
        }
        for (unit, range) in wanted {
            assert!(asked.insert(unit), "unit {unit} asked for twice");
            fetched += range.end - range.start;
            let unit_bytes = &bytes[range.start as usize..range.end as usize];
            external.supply(unit, unit_bytes).unwrap();
            assert!(external.supply(unit, unit_bytes).is_err(), "supplied twice");
        }
    }
    assert!(settled && !asked.is_empty());
    assert_eq!(external.fetched().bytes_read, fetched);
    assert_eq!(external.fetched().units_loaded, asked.len() + 1);
    assert_eq!(triangles(&external.mesh()), triangles(&inline.mesh()));
}

/// The meta-nodes a view waits for are asked for in order of the screen error of the nodes
/// waiting for them, largest first.
#[test]
fn meta_nodes_are_asked_for_most_wanted_first() {
    let bytes = stream();
    let head = head_length(bytes).unwrap().unwrap() as usize;
    for eye in [
        DVec3::new(0.5, 0.8, 3.0),
        DVec3::new(-2.0, 1.0, 1.5),
        DVec3::new(2.5, 0.2, 1.0),
    ] {
        let view = View::new(&camera(eye), 0.5).unwrap();
        let mut front = ViewMesh::open(bytes[..head].to_vec(), Fetch::External).unwrap();
        let mut checked = 0;
        for _ in 0..16 {
            let done = front.adapt(&view, Budget::UNLIMITED);
            let wanted = front.wanted();
            let errors: Vec<f64> = wanted
                .iter()
                .map(|&(unit, _)| {
                    // The most wanted of the nodes waiting for it.
                    let waiting = (0..front.nodes.opens.len())
                        .filter(|&v| front.nodes.opens[v] == unit as u32);
                    let errors = waiting.map(|v| {
                        let b = &front.nodes.bounds[v];
                        view.screen_error(b.center, b.radius, b.deviation, front.scale)
                    });
                    errors
                        .reduce(f64::max)
                        .expect("a node waits for each unit asked for")
                })
                .collect();
            assert!(
                errors.windows(2).all(|w| w[0] >= w[1]),
                "asked for out of order: {errors:?}"
            );
            checked += errors.len();
            if done.settled {
                break;
            }
            for (unit, range) in wanted {
                front
                    .supply(unit, &bytes[range.start as usize..range.end as usize])
                    .unwrap();
            }
        }
        assert!(checked > 1, "{checked} units asked for");
    }
}

/// Bytes that are not a unit's (cut short) leave its branch coarse, refused, not a panic.
#[test]
fn a_cut_unit_supplied_is_refused() {
    let bytes = stream();
    let head = head_length(bytes).unwrap().unwrap() as usize;
    let mut external = ViewMesh::open(bytes[..head].to_vec(), Fetch::External).unwrap();
    external.adapt(&View::everything(), Budget::UNLIMITED);
    let wanted = external.wanted();
    let (unit, range) = wanted.first().cloned().expect("the full view wants units");
    let cut = &bytes[range.start as usize..range.end as usize - 1];
    external.supply(unit, cut).unwrap();
    external.adapt(&View::everything(), Budget::UNLIMITED);
    external.check_invariants().unwrap();
    assert_eq!(external.refusals().len(), 1);
    assert!(external.refusals()[0].1.contains("supplied"));
}

pub(super) fn camera(eye: DVec3) -> Camera {
    Camera {
        eye,
        target: DVec3::new(0.5, 0.8, 0.0),
        up: if eye.cross(DVec3::Y).length() < 1e-6 {
            DVec3::X
        } else {
            DVec3::Y
        },
        fov_degrees: 50.0,
        width: 320,
        height: 240,
    }
}

#[test]
fn a_near_view_refines_what_it_sees_and_not_what_is_behind() {
    let mut vm = ViewMesh::from_stream(stream()).unwrap();
    let view = View::new(&camera(DVec3::new(0.5, 0.8, 6.0)), 1.0).unwrap();
    vm.settle(&view, Budget::UNLIMITED, 64);
    vm.check_invariants().unwrap();
    let near = vm.face_count();
    let far = View::new(&camera(DVec3::new(0.5, 0.8, 60.0)), 1.0).unwrap();
    let done = vm.settle(&far, Budget::UNLIMITED, 64);
    vm.check_invariants().unwrap();
    assert!(
        done.collapses > 0 && vm.face_count() < near,
        "{} vs {near}",
        vm.face_count()
    );
}

#[test]
fn back_faces_stay_coarse_unless_the_view_is_two_sided() {
    let view = View::new(&camera(DVec3::new(0.5, 0.8, 4.0)), 0.5).unwrap();
    let mut one = ViewMesh::from_stream(stream()).unwrap();
    one.settle(&view, Budget::UNLIMITED, 64);
    one.check_invariants().unwrap();
    let mut two = ViewMesh::from_stream(stream()).unwrap();
    two.settle(&view.clone().two_sided(true), Budget::UNLIMITED, 64);
    two.check_invariants().unwrap();
    assert!(
        (one.face_count() as f64) < 0.9 * two.face_count() as f64,
        "{} faces one-sided, {} two-sided",
        one.face_count(),
        two.face_count()
    );
    // Nodes the two-sided front splits stay on the one-sided front because they face away.
    let faces_away = |v: u32| {
        let b = &one.nodes.bounds[v as usize];
        view.faces_away(b.center, b.radius, &b.cone)
    };
    let split_in_two: std::collections::HashSet<NodeId> = (0..two.nodes.links.len())
        .filter(|&v| two.nodes.links[v].state == State::Split)
        .map(|v| two.nodes.links[v].id)
        .collect();
    let culled = one
        .front
        .active
        .iter()
        .filter(|&&v| split_in_two.contains(&one.nodes.links[v as usize].id) && faces_away(v))
        .count();
    assert!(culled > 0);
}

#[test]
fn an_operation_budget_spreads_the_work_over_calls_and_ends_where_one_call_does() {
    let view = View::new(&camera(DVec3::new(1.0, 1.0, 5.0)), 0.5).unwrap();
    let mut whole = ViewMesh::from_stream(stream()).unwrap();
    whole.settle(&view, Budget::UNLIMITED, 64);
    let mut stepped = ViewMesh::from_stream(stream()).unwrap();
    let budget = Budget {
        operations: 50,
        faces: None,
    };
    let mut calls = 0;
    loop {
        let done = stepped.adapt(&view, budget);
        stepped.check_invariants().unwrap();
        assert!(
            done.splits + done.collapses <= 50 + 52,
            "forced splits finish"
        );
        calls += 1;
        if done.settled {
            break;
        }
        assert!(calls < 10_000);
    }
    assert!(calls > 2);
    assert_eq!(triangles(&stepped.mesh()), triangles(&whole.mesh()));
}

#[test]
fn a_face_budget_raises_the_tolerance_until_the_front_holds_it() {
    let view = View::new(&camera(DVec3::new(1.0, 1.0, 4.0)), 0.2).unwrap();
    let mut vm = ViewMesh::from_stream(stream()).unwrap();
    vm.settle(&view, Budget::UNLIMITED, 64);
    let free = vm.face_count();
    let target = free / 4;
    let budget = Budget {
        operations: usize::MAX,
        faces: Some(target),
    };
    for _ in 0..40 {
        vm.adapt(&view, budget);
    }
    vm.check_invariants().unwrap();
    assert!(
        vm.face_count() <= target + target / 10,
        "{} faces for {target}",
        vm.face_count()
    );
    assert!(
        vm.face_count() >= target / 2,
        "{} faces for {target}",
        vm.face_count()
    );
    assert!(vm.tolerance_scale() > 1.0);
}

#[test]
fn picking_hits_the_front_where_the_ray_meets_it() {
    let mut vm = ViewMesh::from_stream(stream()).unwrap();
    vm.settle(&View::everything(), Budget::UNLIMITED, 64);
    // The unit sphere at the origin (icosphere of radius 1): a ray up the z axis, from the
    // side away from the loose triangle.
    let hit = vm.pick(DVec3::new(0.01, 0.02, -5.0), DVec3::Z).unwrap();
    assert!((hit.distance - 4.0).abs() < 0.05, "{hit:?}");
    assert!(vm.pick(DVec3::new(9.0, 9.0, 9.0), DVec3::Z).is_none());
}

/// The torus of [`stream`], close; the spheres below it out of the frustum.
fn torus_view() -> View {
    let torus = Camera {
        eye: DVec3::new(0.0, 2.5, 3.0),
        target: DVec3::new(0.0, 2.5, 0.0),
        fov_degrees: 30.0,
        ..camera(DVec3::Z)
    };
    View::new(&torus, 1.0).unwrap()
}

#[test]
fn a_view_of_one_part_fetches_only_the_meta_nodes_it_needs() {
    let mut vm = ViewMesh::from_stream(stream()).unwrap();
    let view = torus_view();
    let done = vm.settle(&view, Budget::UNLIMITED, 64);
    vm.check_invariants().unwrap();
    let fetched = vm.fetched();
    assert!(done.settled && done.loaded > 0, "{done:?}");
    assert!(fetched.units_loaded < fetched.units, "{fetched:?}");
    assert!(fetched.bytes_read < fetched.stream_bytes, "{fetched:?}");
}

/// A client reads the index only as far as the meta-nodes it fetches. Read a few bytes at a
/// time, the root's front reads less than the whole index, a view of one part reads less
/// than it does from the whole index and adapts alike, and everything refined reads every
/// byte of the stream once.
#[test]
fn the_index_is_read_only_as_far_as_the_meta_nodes_fetched() {
    let (_, index, payload_start) = read_header_and_index(stream()).unwrap();
    let header_bytes = crate::container::Header::read(stream()).unwrap().1 as u64;
    let reads = Reads {
        first: header_bytes + 4,
        index: 4,
    };
    let open = || {
        let source = SeekSource(std::io::Cursor::new(stream().to_vec()));
        ViewMesh::open_reading(source, Fetch::Inline, reads).unwrap()
    };
    assert!(index.len() >= 8, "{} units", index.len());
    let root = open();
    assert!(
        root.fetched().bytes_read < payload_start as u64 + index.units[0].length,
        "{:?}",
        root.fetched()
    );
    let view = torus_view();
    let mut whole = ViewMesh::from_stream(stream()).unwrap();
    whole.settle(&view, Budget::UNLIMITED, 64);
    let mut part = open();
    part.settle(&view, Budget::UNLIMITED, 64);
    part.check_invariants().unwrap();
    assert_eq!(triangles(&part.mesh()), triangles(&whole.mesh()));
    let (read, whole_read) = (part.fetched(), whole.fetched());
    assert_eq!(read.units_loaded, whole_read.units_loaded);
    assert!(
        read.bytes_read < whole_read.bytes_read,
        "{read:?} {whole_read:?}"
    );
    let mut all = open();
    all.settle(&View::everything(), Budget::UNLIMITED, 64);
    all.check_invariants().unwrap();
    assert_eq!(all.fetched().bytes_read, stream().len() as u64);
    let (full, _) = codecs::decode(stream(), Stop::All).unwrap();
    assert_eq!(triangles(&all.mesh()), triangles(&full.mesh));
}

#[test]
fn a_loader_thread_over_a_reader_gives_what_inline_loading_gives() {
    let view = View::new(&camera(DVec3::new(1.0, 1.0, 5.0)), 0.5).unwrap();
    let mut inline = ViewMesh::from_stream(stream()).unwrap();
    inline.settle(&view, Budget::UNLIMITED, 64);
    let reader = SeekSource(std::io::Cursor::new(stream().to_vec()));
    let mut background = ViewMesh::open(reader, Fetch::Background).unwrap();
    let done = background.settle(&view, Budget::UNLIMITED, 64);
    assert!(done.settled, "{done:?}");
    background.check_invariants().unwrap();
    assert_eq!(triangles(&background.mesh()), triangles(&inline.mesh()));
    assert_eq!(background.fetched(), inline.fetched());
}

/// The stream with the unit laid out last in its payload given `length` bytes in the
/// index (the payload itself unchanged), and that unit.
fn with_last_unit_claiming(length: u64) -> (Vec<u8>, usize) {
    let (header, mut index, start) = read_header_and_index(stream()).unwrap();
    let last = (0..index.len())
        .max_by_key(|&i| index.units[i].offset)
        .unwrap();
    index.units[last].length = length;
    index.payload_bytes = index.units.iter().map(|u| u.length).sum();
    let mut bytes = Vec::new();
    header.write(&mut bytes);
    index.write(&mut bytes);
    bytes.extend_from_slice(&stream()[start..]);
    (bytes, last)
}

/// Everything refined over `bytes`: the front must hold every invariant, and the meta-nodes
/// refused are returned.
fn refine_everything(bytes: &[u8]) -> (ViewMesh, Vec<usize>) {
    let mut vm = ViewMesh::from_stream(bytes).unwrap();
    let done = vm.settle(&View::everything(), Budget::UNLIMITED, 64);
    assert!(done.settled, "{done:?}");
    vm.check_invariants().unwrap();
    let refused = vm.refusals().iter().map(|(u, _)| *u).collect();
    (vm, refused)
}

#[test]
fn a_lying_index_is_refused_unread_for_that_branch_alone() {
    let (full, _) = refine_everything(stream());
    let (bytes, last) = with_last_unit_claiming(1 << 40);
    let (vm, refused) = refine_everything(&bytes);
    assert_eq!(refused, vec![last]);
    assert!(
        vm.refusals()[0].1.contains("past the stream's end"),
        "{:?}",
        vm.refusals()
    );
    let fetched = vm.fetched();
    assert!(fetched.bytes_read < bytes.len() as u64, "{fetched:?}");
    assert!(vm.face_count() < full.face_count() && vm.face_count() > full.face_count() / 2);
}

#[test]
fn a_cut_or_corrupt_meta_node_is_refused_and_the_rest_refines() {
    let (full, _) = refine_everything(stream());
    let reader = crate::container::StreamReader::open(stream()).unwrap();
    let last = (0..reader.index().len())
        .max_by_key(|&i| reader.index().units[i].offset)
        .unwrap();
    let unit = reader.unit(last).unwrap();
    // Cut inside the last unit laid out.
    let cut = &stream()[..unit.start + unit.bytes.len() / 2];
    let (vm, refused) = refine_everything(cut);
    assert_eq!(refused, vec![last]);
    assert!(vm.face_count() < full.face_count());
    // Its bytes garbled instead.
    let mut garbled = stream().to_vec();
    for b in &mut garbled[unit.start..unit.start + unit.bytes.len()] {
        *b = !*b;
    }
    let (vm, refused) = refine_everything(&garbled);
    assert_eq!(refused, vec![last], "{:?}", vm.refusals());
    assert!(vm.face_count() < full.face_count());
}

/// The full mesh's triangles mapped through the front (each leaf corner to the active node
/// on its path), those left with three distinct corners, as sorted corner triples in face
/// order — computed from the whole stream's decode, independently of the front's lists.
fn projection(vm: &ViewMesh, full: &crate::codecs::came::decoded::DecodedTree) -> Vec<[u32; 3]> {
    let mut out: Vec<[u32; 3]> = full
        .triangles
        .iter()
        .map(|t| t.corners.map(|c| vm.active_on(c).unwrap()))
        .filter(|c| c[0] != c[1] && c[1] != c[2] && c[0] != c[2])
        .map(|mut c| {
            let least = (0..3).min_by_key(|&k| c[k]).unwrap();
            c.rotate_left(least);
            c
        })
        .collect();
    out.sort_unstable();
    out
}

/// The present triangles' corners, as [`projection`] gives them.
fn present_corners(vm: &ViewMesh) -> Vec<[u32; 3]> {
    let mut out: Vec<[u32; 3]> = (0..vm.faces.corners.len())
        .filter(|&t| vm.faces.present(t))
        .map(|t| {
            let mut c = vm.faces.corners[t];
            let least = (0..3).min_by_key(|&k| c[k]).unwrap();
            c.rotate_left(least);
            c
        })
        .collect();
    out.sort_unstable();
    out
}

#[test]
fn the_adapted_mesh_is_the_full_mesh_projected_through_the_front_so_it_has_no_crack() {
    let (_, full) = crate::codecs::came::decode_tree(stream()).unwrap();
    let mut vm = ViewMesh::from_stream(stream()).unwrap();
    let eyes = [
        DVec3::new(0.5, 0.8, 6.0),
        DVec3::new(3.0, 0.5, 1.0),
        DVec3::new(0.0, 2.5, 2.0),
        DVec3::new(-4.0, -1.0, -3.0),
    ];
    for (i, eye) in eyes.into_iter().enumerate() {
        let view = View::new(&camera(eye), 0.3 + i as f64).unwrap();
        // Mid-way (meta-nodes still on their way) and settled.
        vm.adapt(&view, Budget::UNLIMITED);
        assert_eq!(present_corners(&vm), projection(&vm, &full));
        vm.settle(&view, Budget::UNLIMITED, 64);
        vm.check_invariants().unwrap();
        assert_eq!(present_corners(&vm), projection(&vm, &full));
    }
}

/// The full mesh's triangles by birth ([`PresentTriangle::birth`], packed), with their
/// corners' positions.
type Counterparts = HashMap<(u64, u32), [DVec3; 3]>;

/// Present faces meeting `view`'s frustum whose normal makes 90° or more with their
/// counterpart's (the full mesh's triangle, `full`), and the present faces that are not the
/// full mesh's own.
fn fold_overs_in_view(vm: &ViewMesh, full: &Counterparts, view: &View) -> (usize, usize) {
    let normal = |p: [DVec3; 3]| (p[1] - p[0]).cross(p[2] - p[0]);
    let (mut folded, mut coarse) = (0, 0);
    for (v, ordinal, t) in vm.present_by_birth() {
        let corners = vm.faces.corners[t as usize];
        let at = corners.map(|c| vm.nodes.bounds[c as usize].center);
        let counterpart = full[&(vm.nodes.links[v as usize].id.packed(), ordinal)];
        if at != counterpart {
            coarse += 1;
        }
        if vm.in_view(view, corners) && normal(at).dot(normal(counterpart)) <= 0.0 {
            folded += 1;
        }
    }
    (folded, coarse)
}

/// The test stream's triangles refined everywhere, by birth, found once.
fn full_positions() -> &'static Counterparts {
    static FULL: OnceLock<Counterparts> = OnceLock::new();
    FULL.get_or_init(|| {
        let (full, _) = refine_everything(stream());
        full.present_triangles()
            .map(|t| ((t.birth.0.packed(), t.birth.1), t.at))
            .collect()
    })
}

#[test]
fn no_face_in_view_turns_against_the_full_meshs_triangle() {
    let full = full_positions();
    let mut vm = ViewMesh::from_stream(stream()).unwrap();
    let mut coarse = 0;
    for (i, eye) in [
        DVec3::new(0.5, 0.8, 6.0),
        DVec3::new(3.0, 0.5, 1.0),
        DVec3::new(0.0, 2.5, 2.0),
        DVec3::new(-4.0, -1.0, -3.0),
        DVec3::new(0.5, 0.8, 30.0),
    ]
    .into_iter()
    .enumerate()
    {
        for tolerance in [0.5, 4.0, 40.0] {
            let view = View::new(&camera(eye), tolerance + i as f64).unwrap();
            let done = vm.settle(&view, Budget::UNLIMITED, 64);
            assert!(done.settled);
            vm.check_invariants().unwrap();
            let (folded, not_full) = fold_overs_in_view(&vm, full, &view);
            assert_eq!(folded, 0, "eye {eye}, tolerance {tolerance}");
            // Every listed face is out of view once settled.
            assert!(vm
                .guard
                .suspects
                .iter()
                .all(|&t| !vm.in_view(&view, vm.faces.corners[t as usize])));
            coarse += not_full;
        }
    }
    // The views left coarse faces to check.
    assert!(coarse > 100, "{coarse}");
}

proptest! {
    #![proptest_config(ProptestConfig::with_cases(48))]
    #[test]
    fn random_view_sequences_keep_every_invariant(
        views in proptest::collection::vec(
            (-8.0f64..8.0, -8.0f64..8.0, -8.0f64..8.0, 0.1f64..8.0, 1usize..400),
            1..8,
        )
    ) {
        let mut vm = ViewMesh::from_stream(stream()).unwrap();
        for (x, y, z, tolerance, operations) in views {
            let eye = DVec3::new(x, y, z);
            if eye.distance(DVec3::new(0.5, 0.8, 0.0)) < 0.5 {
                continue;
            }
            let view = View::new(&camera(eye), tolerance).unwrap();
            let budget = Budget { operations, faces: None };
            vm.adapt(&view, budget);
            prop_assert_eq!(vm.check_invariants(), Ok(()));
            if operations % 3 == 0 {
                vm.wait_for_units();
                prop_assert_eq!(vm.check_invariants(), Ok(()));
            }
            if operations % 5 == 0 {
                // Settled means settled: another adaptation to the view changes nothing.
                let done = vm.settle(&view, Budget::UNLIMITED, 64);
                prop_assert!(done.settled);
                prop_assert_eq!(fold_overs_in_view(&vm, full_positions(), &view).0, 0);
                let again = vm.adapt(&view, Budget { operations: usize::MAX - 1, faces: None });
                prop_assert_eq!((again.splits, again.collapses), (0, 0));
            }
        }
    }
}

/// Eyes around the test stream, near to far, for the guard's comparisons with and without it.
const GUARD_EYES: [DVec3; 4] = [
    DVec3::new(0.5, 0.8, 6.0),
    DVec3::new(3.0, 0.5, 1.0),
    DVec3::new(-4.0, -1.0, -3.0),
    DVec3::new(0.5, 0.8, 30.0),
];

#[test]
fn the_guard_reads_what_decides_a_face_rather_than_splitting_it() {
    // A face not certain from the meta-nodes at hand waits for those that hold its
    // counterpart's corners; splitting it instead chases the counterpart down the hierarchy,
    // face after face (on the million-triangle mesh's far view, 13× the unguarded front's
    // faces; BENCHMARKS.md).
    let full = full_positions();
    let mut counts = Vec::new();
    for eye in GUARD_EYES {
        for tolerance in [0.5, 2.0, 8.0] {
            let faces = |guard: bool| {
                let view = View::new(&camera(eye), tolerance)
                    .unwrap()
                    .keep_orientation(guard);
                let mut vm = ViewMesh::from_stream(stream()).unwrap();
                assert!(vm.settle(&view, Budget::UNLIMITED, 64).settled);
                vm.check_invariants().unwrap();
                if guard {
                    assert_eq!(fold_overs_in_view(&vm, full, &view).0, 0);
                }
                vm.face_count()
            };
            counts.push((faces(true), faces(false)));
        }
    }
    // A front of a few dozen faces may need a dozen more for a face that truly folds over.
    let (guarded, unguarded) = counts.iter().fold((0, 0), |(g, u), &(a, b)| (g + a, u + b));
    assert!(guarded * 10 <= unguarded * 11, "{counts:?}");
    assert!(
        counts.iter().all(|&(g, u)| u < 100 || g * 4 <= u * 5),
        "{counts:?}"
    );
}

#[test]
fn with_triangle_normals_the_guard_reads_nothing_the_view_does_not() {
    // Each triangle's own normal decides every face standing for it from the meta-node that
    // creates it: the guard splits what folds over and never fetches meta-nodes to prove a face
    // (before syntax 4 it fetched them down to the leaves: dragon-50k's far view read 98.5% of
    // its stream against 68.1% unguarded).
    let full = full_positions();
    let (mut guarded_bytes, mut unguarded_bytes) = (0, 0);
    for eye in GUARD_EYES {
        for tolerance in [0.5, 2.0, 8.0] {
            let read = |guard: bool| {
                let view = View::new(&camera(eye), tolerance)
                    .unwrap()
                    .two_sided(true)
                    .keep_orientation(guard);
                let mut vm = ViewMesh::from_stream(stream()).unwrap();
                let adapted = vm.settle(&view, Budget::UNLIMITED, 64);
                assert!(adapted.settled && adapted.unsure == 0, "{adapted:?}");
                vm.check_invariants().unwrap();
                if guard {
                    assert_eq!(fold_overs_in_view(&vm, full, &view).0, 0);
                }
                vm.fetched().bytes_read
            };
            let (g, u) = (read(true), read(false));
            guarded_bytes += g;
            unguarded_bytes += u;
        }
    }
    assert!(
        guarded_bytes * 100 <= unguarded_bytes * 102,
        "{guarded_bytes} bytes read guarded, {unguarded_bytes} unguarded"
    );
}
