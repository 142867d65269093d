#!/usr/bin/env bash
# Writes the seed corpus in fuzz/seeds/: small hand-shaped mesh files for each reader, then
# streams of every codec made from them with the first seven bytes (magic,
# version, codec id, syntax) cut off, as the decode_* targets take them.
# Run from the repository: bash fuzz/make_seeds.sh
set -euo pipefail
cd "$(dirname "$0")/.."
cargo build --release --bin meshcodec
seeds=fuzz/seeds
mkdir -p $seeds/{read_obj,read_ply,read_off,read_stl,read_m,read_gltf}
python3 - "$seeds" <<'EOF'
import math, struct, sys, os
os.chdir(sys.argv[1])
U, V = 8, 5
pts = []
for i in range(U):
    for j in range(V):
        a = 2 * math.pi * i / U; b = 2 * math.pi * j / V
        r = 1 + 0.4 * math.cos(b)
        pts.append((r * math.cos(a), r * math.sin(a), 0.4 * math.sin(b)))
tris, quads = [], []
for i in range(U):
    for j in range(V):
        a = i * V + j; b = ((i + 1) % U) * V + j; c = ((i + 1) % U) * V + (j + 1) % V; d = i * V + (j + 1) % V
        quads.append((a, b, c, d)); tris += [(a, b, c), (a, c, d)]
with open('read_obj/torus.obj', 'w') as f:
    f.write('# torus\nmtllib none.mtl\no torus\n')
    for p in pts: f.write('v %.6f %.6f %.6f\n' % p)
    f.write('vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nvn 0 0 1\ng ring\nusemtl a\ns 1\n')
    for q in quads: f.write('f %d/1/1 %d/2/1 %d/3/1 %d/4/1\n' % tuple(x + 1 for x in q))
with open('read_obj/negative.obj', 'w') as f:
    f.write('v 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nv 0 0 1 1.0\nf 1//1 2//1 4//1\nl 1 2\n')
def ply_header(fmt, extra=''):
    return ('ply\nformat %s 1.0\ncomment seed\nelement vertex %d\nproperty float x\nproperty float y\n'
            'property float z\n%selement face %d\nproperty list uchar int vertex_indices\nend_header\n'
            % (fmt, len(pts), extra, len(tris))).encode()
with open('read_ply/torus-ascii.ply', 'wb') as f:
    f.write(ply_header('ascii', 'property uchar red\n'))
    for p in pts: f.write(b'%f %f %f 200\n' % p)
    for t in tris: f.write(b'3 %d %d %d\n' % t)
with open('read_ply/torus-colours.ply', 'wb') as f:
    f.write(ply_header('ascii', 'property uchar red\nproperty uchar green\nproperty uchar blue\nproperty uchar alpha\n'))
    for k, p in enumerate(pts): f.write(b'%f %f %f %d %d %d 255\n' % (p + (k * 6 % 256, 128 + k % 64, 200 - k)))
    for t in tris: f.write(b'3 %d %d %d\n' % t)
for name, end in (('le', '<'), ('be', '>')):
    with open('read_ply/torus-binary-%s.ply' % name, 'wb') as f:
        f.write(ply_header('binary_little_endian' if end == '<' else 'binary_big_endian'))
        for p in pts: f.write(struct.pack(end + 'fff', *p))
        for t in tris: f.write(struct.pack(end + 'Biii', 3, *t))
with open('read_ply/quad-double.ply', 'wb') as f:
    f.write(b'ply\nformat binary_little_endian 1.0\nelement vertex 4\nproperty double x\nproperty double y\n'
            b'property double z\nelement face 1\nproperty list uint8 uint32 vertex_index\nend_header\n')
    for p in ((0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0)): f.write(struct.pack('<ddd', *p))
    f.write(struct.pack('<BIIII', 4, 0, 1, 2, 3))
with open('read_off/torus.off', 'w') as f:
    f.write('OFF\n# comment\n%d %d 0\n' % (len(pts), len(quads)))
    for p in pts: f.write('%f %f %f\n' % p)
    for q in quads: f.write('4 %d %d %d %d\n' % q)
with open('read_off/colour.off', 'w') as f:
    f.write('COFF\n4 2 5\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n1 1 0 0 0 255 255\n0 1 0 9 9 9 255\n'
            '3 0 1 2 1 0 0\n3 0 2 3\n')
with open('read_stl/torus-binary.stl', 'wb') as f:
    f.write(b'seed'.ljust(80, b' ')); f.write(struct.pack('<I', len(tris)))
    for t in tris:
        f.write(struct.pack('<fff', 0, 0, 1))
        for v in t: f.write(struct.pack('<fff', *pts[v]))
        f.write(b'\0\0')
with open('read_stl/triangle-ascii.stl', 'w') as f:
    f.write('solid seed\n')
    for t in tris[:6]:
        f.write('  facet normal 0 0 1\n    outer loop\n')
        for v in t: f.write('      vertex %f %f %f\n' % pts[v])
        f.write('    endloop\n  endfacet\n')
    f.write('endsolid seed\n')
# glTF: the torus split at its uv seam as glTF stores it (a vertex per (position, uv) pair),
# with normals and two materials; as a .gltf with the buffer embedded and as a .glb.
import base64, json
verts, index = [], {}
def vertex(i, j):
    key = (i, j)
    if key not in index:
        a = 2 * math.pi * i / U; b = 2 * math.pi * j / V
        index[key] = len(verts)
        verts.append((pts[(i % U) * V + j % V], (math.cos(a) * math.cos(b), math.sin(a) * math.cos(b), math.sin(b)), (i / U, j / V)))
    return index[key]
faces = []
for i in range(U):
    for j in range(V):
        a, b, c, d = vertex(i, j), vertex(i + 1, j), vertex(i + 1, j + 1), vertex(i, j + 1)
        faces += [(a, b, c), (a, c, d)]
half = len(faces) // 2
blob = b''.join(struct.pack('<fff', *v[0]) for v in verts)
blob += b''.join(struct.pack('<fff', *v[1]) for v in verts)
blob += b''.join(struct.pack('<ff', *v[2]) for v in verts)
indices = b''.join(struct.pack('<III', *t) for t in faces)
offsets = [0, 12 * len(verts), 24 * len(verts), 32 * len(verts)]
blob += indices
views = [{"buffer": 0, "byteOffset": offsets[k], "byteLength": offsets[k + 1] - offsets[k]} for k in range(3)]
views += [{"buffer": 0, "byteOffset": offsets[3], "byteLength": 12 * half},
          {"buffer": 0, "byteOffset": offsets[3] + 12 * half, "byteLength": 12 * (len(faces) - half)}]
lo = [min(v[0][k] for v in verts) for k in range(3)]; hi = [max(v[0][k] for v in verts) for k in range(3)]
accessors = [{"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3", "min": lo, "max": hi},
             {"bufferView": 1, "componentType": 5126, "count": len(verts), "type": "VEC3"},
             {"bufferView": 2, "componentType": 5126, "count": len(verts), "type": "VEC2"},
             {"bufferView": 3, "componentType": 5125, "count": 3 * half, "type": "SCALAR"},
             {"bufferView": 4, "componentType": 5125, "count": 3 * (len(faces) - half), "type": "SCALAR"}]
attributes = {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}
doc = {"asset": {"version": "2.0"}, "scene": 0, "scenes": [{"nodes": [0]}],
       "nodes": [{"mesh": 0, "translation": [0, 0, 1]}],
       "meshes": [{"primitives": [{"attributes": attributes, "indices": 3, "material": 0},
                                  {"attributes": attributes, "indices": 4, "material": 1}]}],
       "materials": [{"name": "inside"}, {"name": "outside"}],
       "accessors": accessors, "bufferViews": views}
embedded = dict(doc, buffers=[{"byteLength": len(blob), "uri": "data:application/octet-stream;base64," + base64.b64encode(blob).decode()}])
with open('read_gltf/torus.gltf', 'w') as f:
    json.dump(embedded, f)
text = json.dumps(dict(doc, buffers=[{"byteLength": len(blob)}])).encode()
text += b' ' * (-len(text) % 4)
blob += b'\0' * (-len(blob) % 4)
with open('read_gltf/torus.glb', 'wb') as f:
    f.write(struct.pack('<4sII', b'glTF', 2, 12 + 8 + len(text) + 8 + len(blob)))
    f.write(struct.pack('<I4s', len(text), b'JSON') + text)
    f.write(struct.pack('<I4s', len(blob), b'BIN\0') + blob)
with open('read_m/torus.m', 'w') as f:
    f.write('# seed\n')
    for k, p in enumerate(pts): f.write('Vertex %d %f %f %f {normal=(0 0 1)}\n' % ((k + 1,) + p))
    for k, t in enumerate(tris): f.write('Face %d %d %d %d\n' % ((k + 1,) + tuple(x + 1 for x in t)))
EOF
# No oriented manifold: two tetrahedra sharing a vertex (a bow-tie), one face turned over, and
# a fin on an edge; pm cuts it to a manifold (docs/FORMAT.md §6.2).
cat > $seeds/read_obj/bowtie-fin.obj <<'OBJ'
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
v -1 0 0
v 0 -1 0
v 0 0 -1
v 1 1 1
f 1 3 2
f 1 2 4
f 1 4 3
f 2 4 3
f 1 6 5
f 1 5 7
f 1 7 6
f 5 6 7
f 2 3 8
OBJ
# The torus with a fin on the edge of its first face and its second face turned over: cut, and
# refined over several levels.
awk '/^v /{n++} /^f /{f++; if (f == 2) {printf "f"; for (i = NF; i > 1; i--) printf " %s", $i; print ""; next}} {print} END {print "v 0 0 3"; print "f 1 2", n + 1}' \
  $seeds/read_obj/torus.obj | sed 's|/[0-9/]*||g' > $seeds/read_obj/torus-fin.obj
stream=$(mktemp)
for codec in raw emc emc-ahead emc-paper pm pm-reordered came came-paper; do
  dir=$seeds/decode_${codec//-/_}
  mkdir -p "$dir"
  for mesh in $seeds/read_obj/torus.obj $seeds/read_off/colour.off $seeds/read_obj/bowtie-fin.obj $seeds/read_obj/torus-fin.obj; do
    name=$(basename "$mesh"); name=${name%.*}
    target/release/meshcodec encode --codec "$codec" --quant 10 --drop-attributes "$mesh" "$stream" >/dev/null 2>&1
    tail -c +8 "$stream" > "$dir/$name.body"
  done
done
# A torus fine enough for several meta-nodes (1,200 vertices), so that `came`'s corner paths
# wait at the nodes where their meta-node stops for the one that splits them (syntax 9).
fine=$(mktemp --suffix=.obj)
python3 - "$fine" <<'EOF'
import math, sys
U, V = 60, 20
with open(sys.argv[1], 'w') as f:
    for i in range(U):
        for j in range(V):
            a = 2 * math.pi * i / U; b = 2 * math.pi * j / V
            r = 1 + 0.4 * math.cos(b) + 0.05 * math.sin(5 * a)
            f.write('v %.6f %.6f %.6f\n' % (r * math.cos(a), r * math.sin(a), 0.4 * math.sin(b)))
    for i in range(U):
        for j in range(V):
            q = [i * V + j, ((i + 1) % U) * V + j, ((i + 1) % U) * V + (j + 1) % V, i * V + (j + 1) % V]
            f.write('f %d %d %d\nf %d %d %d\n' % (q[0] + 1, q[1] + 1, q[2] + 1, q[0] + 1, q[2] + 1, q[3] + 1))
EOF
for codec in came came-paper; do
  target/release/meshcodec encode --codec "$codec" --quant 10 "$fine" "$stream" >/dev/null 2>&1
  tail -c +8 "$stream" > "$seeds/decode_${codec//-/_}/torus-fine.body"
done
rm -f "$fine"
# emc streams with slabs, every pass of 4 visits or more sliced into 3 slabs (as `emc` writes
# meshes of 65,536 vertices or more, in small).
cargo build --release --example emc_slabs
for mesh in $seeds/read_obj/torus.obj $seeds/read_obj/torus-fin.obj; do
  name=$(basename "$mesh"); name=${name%.*}
  target/release/examples/emc_slabs "$mesh" --write "$stream" 3 2
  tail -c +8 "$stream" > "$seeds/decode_emc/$name-slabs.body"
  target/release/examples/emc_slabs "$mesh" --write "$stream" 3 2 2
  tail -c +8 "$stream" > "$seeds/decode_emc_ahead/$name-slabs.body"
done
# Streams whose levels carry their appearance in parts (emc, emc-ahead; docs/FORMAT.md §10),
# with the magic and version cut off: decode_level_parts's input. spot at 6 bits has levels that
# code their representatives, sketch them and settle.
mkdir -p $seeds/decode_level_parts
for codec in emc emc-ahead; do
  for mesh in $seeds/read_obj/torus.obj $seeds/read_gltf/torus.glb $seeds/read_ply/torus-colours.ply; do
    name=$(basename "$mesh"); name=${name%.*}-${mesh##*.}
    target/release/meshcodec encode --codec "$codec" --quant 10 --uv-bits 8 --normal-bits 6 "$mesh" "$stream" >/dev/null 2>&1
    tail -c +6 "$stream" > "$seeds/decode_level_parts/$codec-$name.body"
  done
  if [ -f ../shared/meshes/spot.obj ]; then
    target/release/meshcodec encode --codec "$codec" --quant 6 --uv-bits 6 ../shared/meshes/spot.obj "$stream" >/dev/null 2>&1
    tail -c +6 "$stream" > "$seeds/decode_level_parts/$codec-spot-q6.body"
  fi
done

# Streams with appearance (every codec that carries it, on the seeds with uvs, normals,
# materials or colours), with the magic and version cut off: decode_appearance's input.
mkdir -p $seeds/decode_appearance
for codec in raw emc pm came; do
  for mesh in $seeds/read_obj/torus.obj $seeds/read_gltf/torus.glb $seeds/read_ply/torus-colours.ply; do
    name=$(basename "$mesh"); name=${name%.*}-${mesh##*.}
    if target/release/meshcodec encode --codec "$codec" --quant 10 --uv-bits 8 --normal-bits 6 "$mesh" "$stream" >/dev/null 2>&1; then
      tail -c +6 "$stream" > "$seeds/decode_appearance/$codec-$name.body"
    fi
  done
done
# Appearance in pm's splits on a mesh pm cuts to a manifold (a fin and a quad turned over), with
# the magic and version cut off: decode_pm_wedges's input.
mkdir -p $seeds/decode_pm_wedges
for codec in pm pm-reordered; do
  for rule in fit keep; do
    target/release/meshcodec encode --codec "$codec" --quant 10 --uv-bits 8 --normal-bits 6 \
      --attributes "$rule" $seeds/read_obj/torus-fin.obj "$stream" >/dev/null 2>&1
    tail -c +6 "$stream" > "$seeds/decode_pm_wedges/$codec-torus-fin-$rule.body"
  done
done
# Normals in the splits on the torus (a manifold with uvs and normals): predicted from the
# geometry of their vertex's faces (appearance flag 64), and derived from it (flag 32).
for derive in "" --derive-normals; do
  target/release/meshcodec encode --codec pm-reordered --quant 10 --uv-bits 8 --normal-bits 6 \
    --attributes keep $derive $seeds/read_obj/torus.obj "$stream" >/dev/null 2>&1
  tail -c +6 "$stream" > "$seeds/decode_pm_wedges/pm-reordered-torus-keep${derive:+-derived}.body"
done
# One meta-node alone takes the CAME codecs' streams too.
for codec in came came_paper; do
  mkdir -p $seeds/decode_${codec}_unit
  cp $seeds/decode_$codec/*.body $seeds/decode_${codec}_unit/
done
# View-dependent refinement over came streams with normal cones: 16 bytes of views (eyes on
# three sides of the torus, tolerances, budgets), then the stream's body.
mkdir -p $seeds/adapt_came
for body in $seeds/decode_came/*.body; do
  { printf '\xa0\x80\x80\x41\x80\xa0\x90\x22\x60\x80\x70\x83\x80\x80\x40\x10'; cat "$body"; } \
    > "$seeds/adapt_came/$(basename "$body")"
done
rm -f "$stream"

# glTF scenes for pack_gltf: the torus as .gltf and .glb, and packed (so unpack reads streams
# and the extension), embedded and with a fallback of every face.
mkdir -p $seeds/pack_gltf
cp $seeds/read_gltf/torus.gltf $seeds/read_gltf/torus.glb $seeds/pack_gltf/
target/release/meshcodec pack --quant 8 $seeds/read_gltf/torus.glb $seeds/pack_gltf/torus-packed.glb >/dev/null 2>&1
target/release/meshcodec pack --quant 8 --no-fallback $seeds/read_obj/torus.obj $seeds/pack_gltf/torus-obj-packed.glb >/dev/null 2>&1
# The torus compressed by gltfpack (EXT_meshopt_compression), when experiments/gltf's tools are
# installed (bash experiments/gltf.sh installs them).
if [ -x experiments/gltf/node_modules/.bin/gltfpack ]; then
  experiments/gltf/node_modules/.bin/gltfpack -i $seeds/read_gltf/torus.glb -o $seeds/pack_gltf/torus-gltfpack.glb -cc >/dev/null
fi
