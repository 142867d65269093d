//! What the units a view reads hold: a mesh's `came` stream, then for the far, middle and near
//! views of the came-vd table (1 px, two-sided, guard on) the units the front asks for, and
//! their bits by field against the whole stream's: where a view's bytes go. Then the triangles'
//! corner paths in the units read: how many of their steps pass nodes the unit does not split
//! (coded blind, about a bit each), and how many of those lie at nodes split by units the view
//! does not read — the steps a syntax coding paths only as far as their unit knows would take
//! out of the view's bytes.
//! Run: cargo run --release --example came_unit_fields -- MESH (a shared mesh's name or a file;
//! NAME-x4 or NAME-x16 for a shared mesh subdivided once or twice, as the came-vd table's
//! bunny-closed-35k-x16)
use meshcodec::codecs::came::decode_tree;
use meshcodec::codecs::came::knowledge::Status;
use meshcodec::codecs::came::modelled::{encode_with_unit_fields, Came};
use meshcodec::codecs::came::refine::{head_length, Budget, Fetch, View, ViewMesh};
use meshcodec::codecs::{canonical_for, Codec};
use meshcodec::hierarchy::came::NodeId;
use meshcodec::mesh::io;
use meshcodec_lab::came::extras::table_mesh;
use meshcodec_lab::came::vd::{framing, view_camera, TOLERANCE_PX, VIEWS};
use std::collections::{BTreeMap, HashMap, HashSet};

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let name = std::env::args()
        .nth(1)
        .ok_or("usage: came_unit_fields MESH")?;
    // NAME-xN: the mesh subdivided until it has N times its triangles (the came-vd table's
    // bunny-closed-35k-x16).
    let mesh = match name.rsplit_once("-x") {
        Some((base, times)) if times.parse::<u32>().is_ok_and(|t| t.is_power_of_two()) => {
            let subdivisions = times.parse::<u32>()?.trailing_zeros() / 2;
            table_mesh(base, subdivisions)?.1
        }
        _ => io::read_mesh(&io::resolve(&name)?)?,
    };
    let codec = Came;
    let canonical = canonical_for(&mesh, &codec.default_options())?;
    let (encoded, unit_fields) = encode_with_unit_fields(&canonical)?;
    let bytes = encoded.bytes;
    let total = summed(unit_fields.iter().map(|(_, fields)| fields));
    let all_bits: f64 = total.values().sum();
    println!(
        "{name}: {} bytes, {} units, {:.0} bytes of coded fields",
        bytes.len(),
        unit_fields.len(),
        all_bits / 8.0
    );
    let (_, tree) = decode_tree(&bytes)?;
    let every_unit: HashSet<NodeId> = unit_fields.iter().map(|(root, _)| *root).collect();
    // Each unit's parent in the index (the unit it is decoded after), by root.
    let index = meshcodec::container::StreamReader::open(&bytes)?
        .index()
        .clone();
    let parents: HashMap<NodeId, NodeId> = unit_fields
        .iter()
        .zip(&index.units)
        .filter_map(|((root, _), entry)| Some((*root, unit_fields[entry.parent?].0)))
        .collect();
    let whole = path_steps(&tree, &every_unit, &parents);
    println!(
        "corner paths of all {} triangles: {} steps at nodes their unit splits, {} blind ({} of them also a leaf flag)",
        whole.triangles, whole.known, whole.blind, whole.unknown
    );
    println!(
        "  of the blind steps, {} at nodes a descendant of the triangle's unit splits",
        whole.blind_deferrable
    );
    // `came` is lossless: its full decode is the canonical mesh.
    let framed = framing(&canonical.to_mesh())?;
    let head = head_length(&bytes)?.ok_or("the stream's head is cut")? as usize;
    for (view_name, diagonals) in VIEWS {
        let camera = view_camera(view_name, diagonals, framed);
        let view = View::new(&camera, TOLERANCE_PX)?.two_sided(true);
        // The caller fetches: every unit the front asks for is listed.
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
        let fields = summed(read.iter().map(|&unit| &unit_fields[unit].1));
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
        let roots: HashSet<NodeId> = read.iter().map(|&u| unit_fields[u].0).collect();
        let steps = path_steps(&tree, &roots, &parents);
        let right = steps.blind_right as f64 / steps.blind.max(1) as f64;
        println!(
            "corner paths of the {} triangles born in the units read: {} steps at nodes their unit splits, {} blind ({} of them also a leaf flag; {:.1}% to the right child: {:.2} bits a step), {} of the blind ones at nodes split by units not read",
            steps.triangles,
            steps.known,
            steps.blind,
            steps.unknown,
            100.0 * right,
            entropy(right),
            steps.blind_unread
        );
        println!(
            "  of the blind steps at nodes split by units not read, {} on the corners under the birth node; blind steps at nodes a descendant of the triangle's unit splits: {} ({} of them in units not read)",
            steps.blind_unread_under, steps.blind_deferrable, steps.blind_deferrable_unread
        );
    }
    Ok(())
}

/// Steps of corner paths (docs/FORMAT.md §8.2, pass 2) of the triangles born in the units
/// rooted at `read`.
#[derive(Default)]
struct PathSteps {
    triangles: usize,
    /// At nodes the triangle's unit (or an ancestor) splits: "towards" bits.
    known: usize,
    /// At nodes it does not: plain bits.
    blind: usize,
    /// Of those, at nodes it does not know the creation of either (a leaf flag too).
    unknown: usize,
    /// Blind steps at nodes split by a unit not in `read`.
    blind_unread: usize,
    /// Of those, on the two corners under the birth node (n1 and n2).
    blind_unread_under: usize,
    /// Blind steps at nodes split by a unit descending from the triangle's (which could code
    /// them, knowing the triangle), and of those at nodes split by units not in `read`.
    blind_deferrable: usize,
    blind_deferrable_unread: usize,
    /// Blind steps to the right child (their plain context codes about the entropy of this
    /// share a step).
    blind_right: usize,
}

fn path_steps(
    tree: &meshcodec::codecs::came::decoded::DecodedTree,
    read: &HashSet<NodeId>,
    parents: &HashMap<NodeId, NodeId>,
) -> PathSteps {
    let mut steps = PathSteps::default();
    for t in &tree.triangles {
        let c = t.corners;
        // Two corners part at the birth node.
        let pairs = [(0, 1), (1, 2), (0, 2)];
        let Some(birth) = pairs
            .iter()
            .map(|&(i, j)| c[i].ancestor(c[i].common_len(c[j])))
            .find(|b| b.len() == t.birth_depth)
        else {
            continue;
        };
        let Some(unit) = tree
            .get(birth)
            .and_then(|s| tree.nodes[s as usize].split_unit)
        else {
            continue;
        };
        if !read.contains(&unit) {
            continue;
        }
        steps.triangles += 1;
        for corner in c {
            for depth in corner.common_len(birth) + 1..corner.len() {
                let Some(x) = tree.get(corner.ancestor(depth)) else {
                    continue;
                };
                match tree.status_of(x, unit) {
                    Status::Inner => steps.known += 1,
                    status => {
                        steps.blind += 1;
                        steps.blind_right += corner.bit(depth) as usize;
                        steps.unknown += (status == Status::Unknown) as usize;
                        let split = tree.nodes[x as usize].split_unit;
                        let unread = split.is_some_and(|u| !read.contains(&u));
                        steps.blind_unread += unread as usize;
                        if corner.common_len(birth) == birth.len() {
                            steps.blind_unread_under += unread as usize;
                        }
                        if split.is_some_and(|u| descends(parents, u, unit)) {
                            steps.blind_deferrable += 1;
                            steps.blind_deferrable_unread += unread as usize;
                        }
                    }
                }
            }
        }
    }
    steps
}

/// Whether the unit rooted at `u` is `ancestor`'s or one of its descendants' in the index
/// (`parents`: each unit's parent, by root).
fn descends(parents: &HashMap<NodeId, NodeId>, mut u: NodeId, ancestor: NodeId) -> bool {
    loop {
        if u == ancestor {
            return true;
        }
        match parents.get(&u) {
            Some(&parent) => u = parent,
            None => return false,
        }
    }
}

/// The entropy of a bit that is 1 with probability `p`, in bits.
fn entropy(p: f64) -> f64 {
    if p <= 0.0 || p >= 1.0 {
        return 0.0;
    }
    -(p * p.log2() + (1.0 - p) * (1.0 - p).log2())
}

/// Bits by field, summed over `units`.
fn summed<'a>(
    units: impl Iterator<Item = &'a BTreeMap<&'static str, f64>>,
) -> BTreeMap<&'static str, f64> {
    let mut total = BTreeMap::new();
    for fields in units {
        for (&k, v) in fields {
            *total.entry(k).or_default() += v;
        }
    }
    total
}
