//! How many meta-nodes, and how many of a hierarchy's splits, the far, middle and near views of
//! the came-vd table touch under other layouts of the same hierarchy: meta-nodes of L levels
//! (the stream's 8, or 4), meta-nodes rooted at given depths before those of 8 levels, or of as
//! many levels as keep a unit within S splits (docs/notes/benchmarks-history.md, "What a meta-node costs"), units
//! by depth band (a unit rooted at depth d holds its subtree's splits at depths d + K …
//! d + K + B − 1), or units by error band (the same with each node's deviation step in place of
//! its depth).
//!
//! Bytes are estimated from the stream itself: each split costs its unit's bytes over the
//! unit's splits, and a layout's view reads the splits of the units it touches. The estimate
//! keeps today's cost per split, so it leaves out what smaller units add (contexts starting
//! afresh, index entries, flushes: about 21 bytes a unit, BENCHMARKS.md). Beside it, the
//! needed splits' own bytes: what a view would read if units cost nothing and held only what
//! it needs.
//! Run: cargo run --release --example came_layout_probe -- STREAM [LAYOUT…] (each LAYOUT a
//! comma-separated list of root depths, as 4,8,11; band:K,B,WHOLE; or error:S,K,B,WHOLE,
//! a node's error level being its deviation step over S, in quarter octaves)
use meshcodec::codecs::came::decode_tree;
use meshcodec::codecs::came::refine::{Budget, View, ViewMesh};
use meshcodec_lab::came::vd::{framing, view_camera, VIEWS};
use std::collections::HashSet;

#[derive(Clone, Debug)]
enum Rule {
    Levels(u8),
    /// Units rooted at these depths, then meta-nodes of 8 levels.
    Tiers(Vec<u8>),
    Splits(usize),
    /// Units by depth band: the first holds depths 0 … k + b − 1; a unit rooted at depth
    /// d ≥ b holds its subtree's splits at depths d + k … d + k + b − 1 — or all of them from
    /// d + k down when they number at most `whole`.
    Bands {
        k: u8,
        b: u8,
        whole: usize,
    },
    /// Units by error band: a node's error level is its deviation's step (quarter octaves
    /// below the root's) over `s`; a unit holds the splits whose level lies in a band of `b`
    /// levels, of the region under their deepest ancestor at least `k` levels coarser than
    /// the band's first — or all the splits of a region's subtree when they number at most
    /// `whole`.
    ErrorBands {
        s: u16,
        k: u16,
        b: u16,
        whole: usize,
    },
}

/// Per inner node, the index of the unit that codes its split: its parent's when that unit
/// holds its subtree whole, else `unit_for`'s (which lists whether each unit it makes is whole).
fn assign_units(
    tree: &meshcodec::codecs::came::decoded::DecodedTree,
    mut unit_for: impl FnMut(usize, &mut Vec<bool>) -> u32,
) -> (Vec<u32>, usize) {
    let n = tree.nodes.len();
    let mut unit_of = vec![u32::MAX; n];
    let mut whole_unit: Vec<bool> = Vec::new();
    // Parents come before their children in the decoded order.
    for v in 0..n {
        if tree.nodes[v].children.is_none() {
            continue;
        }
        let parent = tree.nodes[v].parent as usize;
        unit_of[v] = match unit_of.get(parent) {
            Some(&unit) if whole_unit[unit as usize] => unit,
            _ => unit_for(v, &mut whole_unit),
        };
    }
    (unit_of, whole_unit.len())
}

/// [`Rule::ErrorBands`]: per inner node, the index of the unit that codes its split.
fn error_band_partition(
    tree: &meshcodec::codecs::came::decoded::DecodedTree,
    inner_below: &[usize],
    (s, k, b, whole): (u16, u16, u16, usize),
) -> (Vec<u32>, usize) {
    let level = |v: usize| tree.deviation_steps[v] / s;
    let mut unit_at: std::collections::HashMap<(u32, u16), u32> = Default::default();
    assign_units(tree, |v, whole_unit| {
        let l = level(v);
        // The band's first level, and the deepest ancestor k levels coarser than it.
        let first = if l < k + b {
            0
        } else {
            k + b + (l - k - b) / b * b
        };
        // The coarsest band is the root's unit; the others are keyed by their region's root.
        let mut r = if first > 0 {
            tree.nodes[v].parent
        } else {
            u32::MAX
        };
        while r != u32::MAX && level(r as usize) + k > first {
            r = tree.nodes[r as usize].parent;
        }
        let r = if r == u32::MAX { 0 } else { r };
        *unit_at.entry((r, first)).or_insert_with(|| {
            // The region's splits from the band's first level down: a whole unit when few.
            let mut frontier = vec![r];
            let mut total = 0;
            while let Some(x) = frontier.pop() {
                let Some(ch) = tree.nodes[x as usize].children else {
                    continue;
                };
                if level(x as usize) >= first {
                    total += inner_below[x as usize];
                } else {
                    frontier.extend(ch);
                }
                if total > whole {
                    break;
                }
            }
            whole_unit.push(first > 0 && total <= whole);
            whole_unit.len() as u32 - 1
        })
    })
}

/// [`Rule::Bands`]: per inner node, the index of the unit that codes its split.
fn band_partition(
    tree: &meshcodec::codecs::came::decoded::DecodedTree,
    inner_below: &[usize],
    (k, b, whole): (u8, u8, usize),
) -> (Vec<u32>, usize) {
    let mut unit_at: std::collections::HashMap<u32, u32> = Default::default();
    // Inner nodes under `r` at depth `a` or deeper.
    let below = |r: u32, a: u8| -> usize {
        let mut frontier = vec![r];
        let mut total = 0;
        while let Some(v) = frontier.pop() {
            let node = &tree.nodes[v as usize];
            let Some(ch) = node.children else { continue };
            if node.id.len() >= a {
                total += inner_below[v as usize];
            } else {
                frontier.extend(ch);
            }
        }
        total
    };
    assign_units(tree, |v, whole_unit| {
        let d = tree.nodes[v].id.len();
        let (root_depth, first) = if d < k + b {
            (0, 0)
        } else {
            let a = k + b + (d - k - b) / b * b;
            (a - k, a)
        };
        let mut r = v as u32;
        while tree.nodes[r as usize].id.len() > root_depth {
            r = tree.nodes[r as usize].parent;
        }
        *unit_at.entry(r).or_insert_with(|| {
            whole_unit.push(below(r, first) <= whole);
            whole_unit.len() as u32 - 1
        })
    })
}

/// Per inner node: the index of the unit that codes its split.
fn partition(
    tree: &meshcodec::codecs::came::decoded::DecodedTree,
    inner_below: &[usize],
    height: &[u8],
    rule: Rule,
) -> (Vec<u32>, usize) {
    let n = tree.nodes.len();
    let mut unit_of = vec![u32::MAX; n];
    let mut roots = std::collections::VecDeque::from([0u32]);
    let mut units = 0usize;
    while let Some(root) = roots.pop_front() {
        let unit = units as u32;
        units += 1;
        let top = tree.nodes[root as usize].id.len() as usize;
        // Levels this unit holds.
        let levels = match rule {
            Rule::Levels(l) => {
                if height[root as usize] <= l + l / 2 {
                    u8::MAX
                } else {
                    l
                }
            }
            Rule::Tiers(ref tiers) => match tiers.iter().position(|&t| t as usize > top) {
                Some(i) => tiers[i] - top as u8,
                None if height[root as usize] <= 12 => u8::MAX,
                None => 8,
            },
            Rule::Bands { .. } | Rule::ErrorBands { .. } => unreachable!("band_partition"),
            Rule::Splits(s) => {
                if inner_below[root as usize] <= s + s / 2 {
                    u8::MAX
                } else {
                    // Splits per depth below the root, then the most levels within s.
                    let mut per_depth: Vec<usize> = Vec::new();
                    let mut frontier = vec![root];
                    while !frontier.is_empty() && per_depth.iter().sum::<usize>() <= s {
                        per_depth.push(frontier.len());
                        frontier = frontier
                            .iter()
                            .flat_map(|&v| tree.nodes[v as usize].children.unwrap())
                            .filter(|&c| tree.nodes[c as usize].children.is_some())
                            .collect();
                    }
                    let mut total = 0;
                    let mut l = 0u8;
                    for count in per_depth {
                        if total + count > s && l > 0 {
                            break;
                        }
                        total += count;
                        l += 1;
                    }
                    l
                }
            }
        };
        let mut stack = vec![root];
        while let Some(v) = stack.pop() {
            unit_of[v as usize] = unit;
            for c in tree.nodes[v as usize].children.unwrap() {
                if tree.nodes[c as usize].children.is_none() {
                    continue;
                }
                let depth = tree.nodes[c as usize].id.len() as usize;
                if levels == u8::MAX || depth < top + levels as usize {
                    stack.push(c);
                } else {
                    roots.push_back(c);
                }
            }
        }
    }
    (unit_of, units)
}

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args()
        .nth(1)
        .ok_or("usage: came_layout_probe STREAM")?;
    let bytes = std::fs::read(&path)?;
    let (_, tree) = decode_tree(&bytes)?;
    let n = tree.nodes.len();
    // Children follow their parents in the decoded order: sizes bottom-up in reverse.
    let mut inner_below = vec![0usize; n];
    let mut height = vec![0u8; n];
    for v in (0..n).rev() {
        if let Some([t, u]) = tree.nodes[v].children {
            inner_below[v] = 1 + inner_below[t as usize] + inner_below[u as usize];
            height[v] = 1 + height[t as usize].max(height[u as usize]);
        }
    }
    let splits = inner_below[0];
    // What each split costs in the stream: its unit's bytes over the unit's splits. Units are
    // decoded in stream order, so the order in which their roots first create nodes is the
    // stream's.
    let reader = meshcodec::container::StreamReader::open(&bytes)?;
    let lengths: Vec<u64> = reader.index().units.iter().map(|u| u.length).collect();
    let mut stream_unit: std::collections::HashMap<u64, usize> = Default::default();
    for node in &tree.nodes {
        let next = stream_unit.len();
        stream_unit
            .entry(node.created_unit.packed())
            .or_insert(next);
    }
    let mut per_unit = vec![0usize; lengths.len()];
    let unit_today: Vec<usize> = tree
        .nodes
        .iter()
        .map(|node| {
            node.split_unit
                .map_or(usize::MAX, |u| stream_unit[&u.packed()])
        })
        .collect();
    for &u in &unit_today {
        if u != usize::MAX {
            per_unit[u] += 1;
        }
    }
    let cost: Vec<f64> = unit_today
        .iter()
        .map(|&u| {
            if u == usize::MAX {
                0.0
            } else {
                lengths[u] as f64 / per_unit[u] as f64
            }
        })
        .collect();
    println!(
        "  units {} in the index, {} met in the tree; payload {} bytes",
        lengths.len(),
        stream_unit.len(),
        lengths.iter().sum::<u64>()
    );
    println!(
        "{path}: {} bytes, {splits} splits, height {}",
        bytes.len(),
        height[0]
    );
    let mut full = ViewMesh::from_stream(&bytes)?;
    full.settle(&View::everything(), Budget::UNLIMITED, 256);
    let framed = framing(&full.mesh())?;
    let mut rules = vec![
        Rule::Levels(8),
        Rule::Levels(4),
        Rule::Tiers(vec![4, 8, 11]),
        Rule::Tiers(vec![4, 8, 10, 12, 14]),
        Rule::Splits(64),
    ];
    for depths in std::env::args().skip(2) {
        if let Some(band) = depths.strip_prefix("error:") {
            let v: Vec<usize> = band.split(',').map(str::parse).collect::<Result<_, _>>()?;
            let [s, k, b, whole] = v[..] else {
                return Err("error:S,K,B,WHOLE".into());
            };
            rules.push(Rule::ErrorBands {
                s: s as u16,
                k: k as u16,
                b: b as u16,
                whole,
            });
            continue;
        }
        if let Some(band) = depths.strip_prefix("band:") {
            let v: Vec<usize> = band.split(',').map(str::parse).collect::<Result<_, _>>()?;
            let [k, b, whole] = v[..] else {
                return Err("band:K,B,WHOLE".into());
            };
            rules.push(Rule::Bands {
                k: k as u8,
                b: b as u8,
                whole,
            });
            continue;
        }
        let depths: Vec<u8> = depths
            .split(',')
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        rules.push(Rule::Tiers(depths));
    }
    let partitions: Vec<_> = rules
        .iter()
        .map(|r| match *r {
            Rule::Bands { k, b, whole } => band_partition(&tree, &inner_below, (k, b, whole)),
            Rule::ErrorBands { s, k, b, whole } => {
                error_band_partition(&tree, &inner_below, (s, k, b, whole))
            }
            _ => partition(&tree, &inner_below, &height, r.clone()),
        })
        .collect();
    for (rule, (_, units)) in rules.iter().zip(&partitions) {
        println!(
            "  {rule:?}: {units} units, {:.1} splits a unit",
            splits as f64 / *units as f64
        );
    }
    for (name, diagonals) in VIEWS {
        let camera = view_camera(name, diagonals, framed);
        for guard in [true, false] {
            let view = View::new(&camera, 1.0)?
                .two_sided(true)
                .keep_orientation(guard);
            let mut front = ViewMesh::from_stream(&bytes)?;
            front.settle(&view, Budget::UNLIMITED, 256);
            let mut split: HashSet<u64> = HashSet::new();
            for id in front.active_nodes() {
                let mut a = id;
                while let Some(p) = a.parent() {
                    if !split.insert(p.packed()) {
                        break;
                    }
                    a = p;
                }
            }
            let fetched = front.fetched();
            let needed_bytes: f64 = split.iter().map(|p| cost[tree.lookup[p] as usize]).sum();
            println!(
                "  the needed splits alone: {needed_bytes:.0} bytes ({:.1}%)",
                100.0 * needed_bytes / bytes.len() as f64
            );
            println!(
                "{name} guard {guard}: {} faces, {} splits needed ({:.1}%), read today {:.1}% ({} units)",
                front.face_count(),
                split.len(),
                100.0 * split.len() as f64 / splits as f64,
                100.0 * fetched.bytes_read as f64 / fetched.stream_bytes as f64,
                fetched.units_loaded
            );
            for (rule, (unit_of, _)) in rules.iter().zip(&partitions) {
                let touched: HashSet<u32> = split
                    .iter()
                    .map(|p| unit_of[tree.lookup[p] as usize])
                    .collect();
                let held: usize = (0..n)
                    .filter(|&v| tree.nodes[v].children.is_some())
                    .filter(|&v| touched.contains(&unit_of[v]))
                    .count();
                let held_bytes: f64 = (0..n)
                    .filter(|&v| tree.nodes[v].children.is_some())
                    .filter(|&v| touched.contains(&unit_of[v]))
                    .map(|v| cost[v])
                    .sum();
                println!(
                    "    {rule:?}: {} units, {held} splits ({:.1}%), {:.0} bytes ({:.1}% of the stream)",
                    touched.len(),
                    100.0 * held as f64 / splits as f64,
                    held_bytes,
                    100.0 * held_bytes / bytes.len() as f64
                );
            }
        }
    }
    Ok(())
}
