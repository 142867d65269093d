//! Probe: how many faces in view a per-triangle orientation bound would prove, coded beside each
//! triangle against the proxy triangle its own and its ancestors' meta-nodes place.
//! Run: cargo run --release --example came_cert_probe -- STREAM [DEPTHS…]
use glam::DVec3;
use meshcodec::codecs::came::decode_tree;
use meshcodec::codecs::came::refine::{Budget, Camera, View, ViewMesh};
use meshcodec::hierarchy::came::NodeId;
use meshcodec_lab::came::vd::{framing, towards, FOV_DEGREES, HEIGHT, VIEWS, WIDTH};
use std::collections::HashMap;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let path = std::env::args().nth(1).ok_or("usage")?;
    let bytes = std::fs::read(&path)?;
    let (_, tree) = decode_tree(&bytes)?;
    let n = tree.nodes.len();
    let mut full = ViewMesh::from_stream(&bytes)?;
    full.settle(&View::everything(), Budget::UNLIMITED, 256);
    // World position of every node: its representative leaf's.
    let mut world = vec![DVec3::ZERO; n];
    for v in 0..n {
        let mut r = v;
        while let Some([t, _]) = tree.nodes[r].children {
            r = t as usize;
        }
        world[v] = full.position_of(tree.nodes[r].id).ok_or("no leaf")?;
    }
    // Partitions: the stream's (split_unit), and tiers.
    let mut layouts: Vec<(String, Vec<NodeId>)> = vec![(
        "stream".into(),
        tree.nodes
            .iter()
            .map(|x| x.split_unit.unwrap_or(NodeId::ROOT))
            .collect(),
    )];
    for depths in std::env::args().skip(2) {
        let tiers: Vec<u8> = depths
            .split(',')
            .map(str::parse)
            .collect::<Result<_, _>>()?;
        // Unit root of an inner node: its ancestor at the deepest tier depth at or above it,
        // then every 8 levels past the last tier.
        let last = *tiers.last().unwrap();
        let roots = tree
            .nodes
            .iter()
            .map(|x| {
                let d = x.id.len();
                let r = if d >= last {
                    last + (d - last) / 8 * 8
                } else {
                    tiers.iter().rev().copied().find(|&t| t <= d).unwrap_or(0)
                };
                x.id.ancestor(r)
            })
            .collect();
        layouts.push((depths, roots));
    }
    let (centre, diagonal, spot) = framing(&full.mesh())?;
    let normal = |p: [DVec3; 3]| (p[1] - p[0]).cross(p[2] - p[0]);
    let angle = |a: DVec3, b: DVec3| {
        let c = a.dot(b) / (a.length() * b.length());
        if c.is_finite() {
            c.clamp(-1.0, 1.0).acos().to_degrees()
        } else {
            180.0
        }
    };
    // The proxy of a triangle under a layout: on each leaf path, the deepest node whose position
    // the birth node's unit and its ancestors give.
    let proxy = |roots: &Vec<NodeId>, leaves: [NodeId; 3]| -> [u32; 3] {
        let pairs = [(0, 1), (1, 2), (2, 0)];
        let (a, _) = *pairs
            .iter()
            .max_by_key(|&&(a, b)| leaves[a].common_len(leaves[b]))
            .unwrap();
        let birth = leaves[a].ancestor(leaves[a].common_len(leaves[(a + 1) % 3]));
        let bu = roots[tree.lookup[&birth.packed()] as usize];
        leaves.map(|leaf| {
            let mut v = 0u32;
            loop {
                let node = &tree.nodes[v as usize];
                let Some(ch) = node.children else { break };
                if !roots[v as usize].is_ancestor_of(bu) {
                    break;
                }
                let bit = leaf.bit(node.id.len());
                v = ch[bit as usize];
            }
            v
        })
    };
    for (lname, roots) in &layouts {
        // Bound per triangle: angle(proxy, counterpart), for the bits.
        let mut hist = [0usize; 18];
        let mut exact = 0usize;
        for t in &tree.triangles {
            let pr = proxy(roots, t.corners);
            let cp = t.corners.map(|l| world[tree.lookup[&l.packed()] as usize]);
            if pr
                .iter()
                .zip(t.corners)
                .all(|(&p, l)| tree.nodes[p as usize].id == l)
            {
                exact += 1;
                continue;
            }
            let b = angle(normal(pr.map(|p| world[p as usize])), normal(cp));
            let code = if b >= 90.0 {
                16
            } else {
                (b / (90.0 / 16.0)).ceil() as usize
            };
            hist[code.min(16)] += 1;
        }
        for eps in [11.25f64, 5.625] {
            let mut cells: HashMap<(i64, i64), usize> = HashMap::new();
            let mut m = 0usize;
            for t in &tree.triangles {
                let pr = proxy(roots, t.corners);
                if pr
                    .iter()
                    .zip(t.corners)
                    .all(|(&p, l)| tree.nodes[p as usize].id == l)
                {
                    continue;
                }
                let cp = t.corners.map(|l| world[tree.lookup[&l.packed()] as usize]);
                let np = normal(pr.map(|p| world[p as usize])).normalize_or_zero();
                let nc = normal(cp).normalize_or_zero();
                // Tangent frame of the proxy's normal; residual as azimuthal-equidistant coordinates.
                let (u, w) = if np == DVec3::ZERO {
                    (DVec3::X, DVec3::Y)
                } else {
                    np.any_orthonormal_pair()
                };
                let th = np.dot(nc).clamp(-1.0, 1.0).acos().to_degrees();
                let dir = DVec3::new(nc.dot(u), nc.dot(w), 0.0).normalize_or_zero();
                let key = (
                    (th * dir.x / eps).round() as i64,
                    (th * dir.y / eps).round() as i64,
                );
                *cells.entry(key).or_default() += 1;
                m += 1;
            }
            let h: f64 = cells
                .values()
                .map(|&c| {
                    let p = c as f64 / m as f64;
                    -(c as f64) * p.log2()
                })
                .sum();
            println!(
                "  residual at {eps}°: {} cells, {:.2} bits each coded, {:.3} bits a triangle",
                cells.len(),
                h / m.max(1) as f64,
                h / tree.triangles.len() as f64
            );
        }
        let coded: usize = hist.iter().sum();
        let entropy: f64 = hist
            .iter()
            .filter(|&&c| c > 0)
            .map(|&c| {
                let p = c as f64 / coded as f64;
                -(c as f64) * p.log2()
            })
            .sum();
        println!(
            "{path} layout {lname}: {} triangles, {exact} proxies exact, {coded} coded, {:.2} bits each, {:.3} bits a triangle; codes {:?}",
            tree.triangles.len(),
            entropy / coded.max(1) as f64,
            entropy / tree.triangles.len() as f64,
            hist
        );
    }
    let _ = HashMap::<u8, u8>::new();
    for (name, diagonals) in VIEWS {
        let (eye, target) = if name == "near" {
            (spot + towards() * diagonals * diagonal, spot)
        } else {
            (centre + towards() * diagonals * diagonal, centre)
        };
        let camera = Camera {
            eye,
            target,
            up: DVec3::Y,
            fov_degrees: FOV_DEGREES,
            width: WIDTH,
            height: HEIGHT,
        };
        for guard in [false, true] {
            let view = View::new(&camera, 1.0)?
                .two_sided(true)
                .keep_orientation(guard);
            let mut front = ViewMesh::from_stream(&bytes)?;
            front.settle(&view, Budget::UNLIMITED, 256);
            let mut shown = 0;
            let mut folded = 0;
            let mut truth = [0usize; 3];
            let mut proved = vec![0usize; layouts.len()];
            let mut proved_q = vec![0usize; layouts.len()];
            for (leaves, at) in front.present_triangles() {
                if !view.shows_triangle(at) {
                    continue;
                }
                shown += 1;
                let nf = normal(at);
                let cp = leaves.map(|l| world[tree.lookup[&l.packed()] as usize]);
                let t_angle = angle(nf, normal(cp));
                for (k, e) in [0.0, 8.0, 16.0].iter().enumerate() {
                    truth[k] += (t_angle + e < 90.0) as usize;
                }
                if nf.dot(normal(cp)) <= 0.0 {
                    folded += 1;
                }
                for (k, (_, roots)) in layouts.iter().enumerate() {
                    let pr = proxy(roots, leaves);
                    let np = normal(pr.map(|p| world[p as usize]));
                    let b = angle(np, normal(cp));
                    let bq = if b >= 90.0 {
                        90.0
                    } else {
                        (b / (90.0 / 16.0)).ceil() * (90.0 / 16.0)
                    };
                    let a = angle(nf, np);
                    proved[k] += (a + b < 90.0) as usize;
                    proved_q[k] += (a + bq < 90.0) as usize;
                }
            }
            println!(
                "{name} guard {guard}: {} faces, {shown} shown, {folded} fold; within 90/82/74: {:?}; proved exact/quantized per layout: {:?}",
                front.face_count(), truth,
                proved.iter().zip(&proved_q).collect::<Vec<_>>()
            );
        }
    }
    Ok(())
}
