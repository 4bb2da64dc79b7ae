#!/usr/bin/env python3
"""Writes the fuzz seed corpus (fuzz/corpus/<target>/seed-*) and the fixed
companion files (fuzz/data/) from scratch: every file is generated here, so
the corpus carries no third-party data. Run from the fuzz/ folder:
    python3 seeds.py
The committed corpus is this output plus inputs the fuzzer found and
`cargo fuzz cmin` kept."""

import base64
import gzip
import json
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))


def put(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    if isinstance(data, str):
        data = data.encode()
    with open(os.path.join(d, "seed-" + name), "wb") as f:
        f.write(data)


def data(name, blob):
    d = os.path.join(HERE, "data")
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(blob)


# ---------------------------------------------------------------- companions
D_RAW = bytes(range(64))  # 4x4x4 u8, 2x4x4 u16, 1x4x4 f32, ...
data("d.raw", D_RAW)
M_OBJ = b"v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 0 1\nf 1 3 2\nf 1 2 4\nf 2 3 4\nf 1 4 3\n"
data("m.obj", M_OBJ)

# ---------------------------------------------------------------- meshes
put("obj", "tetra.obj", M_OBJ)
put("obj", "quads.obj",
    "# comment\nmtllib x.mtl\no cube\nv 0 0 0 1 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0 1\n"
    "vt 0 0\nvn 0 0 1\ng top\nusemtl m\nf 1/1/1 2/1/1 3/1/1 4/1/1\nf -1 -2 -3\n"
    "l 1 2\np 3\n")
TETRA_V = [(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)]
TETRA_F = [(0, 2, 1), (0, 1, 3), (1, 2, 3), (0, 3, 2)]


def ply_header(fmt, extra=""):
    return ("ply\nformat %s 1.0\ncomment seed\nelement vertex 4\nproperty float x\n"
            "property float y\nproperty float z\n%selement face 4\n"
            "property list uchar int vertex_indices\nend_header\n" % (fmt, extra))


put("ply", "ascii.ply", ply_header("ascii") +
    "".join("%g %g %g\n" % v for v in TETRA_V) +
    "".join("3 %d %d %d\n" % f for f in TETRA_F))
for fmt, e in [("binary_little_endian", "<"), ("binary_big_endian", ">")]:
    body = b"".join(struct.pack(e + "3f", *v) for v in TETRA_V)
    body += b"".join(struct.pack(e + "B3i", 3, *f) for f in TETRA_F)
    put("ply", fmt + ".ply", ply_header(fmt).encode() + body)
# Extra vertex properties, a double, a ushort list, an unused element.
head = ("ply\nformat binary_little_endian 1.0\nelement vertex 3\nproperty double x\n"
        "property double y\nproperty double z\nproperty uchar red\n"
        "element face 1\nproperty list uchar ushort vertex_index\n"
        "element edge 1\nproperty int a\nproperty int b\nend_header\n")
body = b"".join(struct.pack("<3dB", *v, 7) for v in TETRA_V[:3])
body += struct.pack("<B3H", 3, 0, 1, 2) + struct.pack("<2i", 0, 1)
put("ply", "extras.ply", head.encode() + body)

put("off", "tetra.off", "OFF\n4 4 6\n" + "".join("%g %g %g\n" % v for v in TETRA_V) +
    "".join("3 %d %d %d\n" % f for f in TETRA_F))
put("off", "coff.off", "COFF # colours\n4 1 0\n0 0 0 255 0 0 255\n1 0 0 0 255 0 255\n"
    "1 1 0 0 0 255 255\n0 1 0 9 9 9 255\n\n4 0 1 2 3 200 10 10\n")
put("off", "nokeyword.off", "3 1 0\n0 0 0\n1 0 0\n0 1 0\n3 0 1 2\n")

# ---------------------------------------------------------------- glTF
pos = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]
buf = b"".join(struct.pack("<3f", *p) for p in pos)  # 0..36
buf += struct.pack("<3H", 0, 1, 2) + b"\0\0"  # 36..44
buf += b"".join(struct.pack("<4H", j, 0, 0, 0) for j in (0, 1, 1))  # 44..68
buf += b"".join(struct.pack("<4f", 1, 0, 0, 0) for _ in pos)  # 68..116
ident = struct.pack("<16f", 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1)
shift = struct.pack("<16f", 1, 0, 0, 0, 0, 1, 0, 0, 0, 0, 1, 0, 0, -1, 0, 1)
buf += ident + shift  # 116..244
buf += struct.pack("<2f", 0, 1)  # 244..252
buf += struct.pack("<4f", 0, 0, 0, 1) + struct.pack("<4f", 0, 0, 0.7071068, 0.7071068)
assert len(buf) == 284
data("d.bin", buf)


def gltf_doc(buffer):
    views = [(0, 36, 34962), (36, 6, 34963), (44, 24, 34962), (68, 48, 34962),
             (116, 128, None), (244, 8, None), (252, 32, None)]
    bv = []
    for off, n, tgt in views:
        v = {"buffer": 0, "byteOffset": off, "byteLength": n}
        if tgt:
            v["target"] = tgt
        bv.append(v)
    acc = [
        {"bufferView": 0, "componentType": 5126, "count": 3, "type": "VEC3",
         "min": [0, 0, 0], "max": [1, 1, 0]},
        {"bufferView": 1, "componentType": 5123, "count": 3, "type": "SCALAR"},
        {"bufferView": 2, "componentType": 5123, "count": 3, "type": "VEC4"},
        {"bufferView": 3, "componentType": 5126, "count": 3, "type": "VEC4"},
        {"bufferView": 4, "componentType": 5126, "count": 2, "type": "MAT4"},
        {"bufferView": 5, "componentType": 5126, "count": 2, "type": "SCALAR",
         "min": [0], "max": [1]},
        {"bufferView": 6, "componentType": 5126, "count": 2, "type": "VEC4"},
    ]
    return {
        "asset": {"version": "2.0"},
        "scene": 0,
        "scenes": [{"nodes": [0, 1]}],
        "nodes": [{"mesh": 0, "skin": 0}, {"children": [2]},
                  {"translation": [0, 1, 0], "rotation": [0, 0, 0, 1]}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "JOINTS_0": 2,
                                                   "WEIGHTS_0": 3}, "indices": 1}]}],
        "skins": [{"inverseBindMatrices": 4, "joints": [1, 2]}],
        "animations": [{"channels": [{"sampler": 0, "target": {"node": 2, "path": "rotation"}}],
                        "samplers": [{"input": 5, "output": 6, "interpolation": "LINEAR"}]}],
        "buffers": [buffer],
        "bufferViews": bv,
        "accessors": acc,
    }


put("gltf", "file-buffer.gltf", json.dumps(gltf_doc({"uri": "d.bin", "byteLength": 284})))
uri = "data:application/octet-stream;base64," + base64.b64encode(buf).decode()
put("gltf", "data-uri.gltf", json.dumps(gltf_doc({"uri": uri, "byteLength": 284})))


def glb(doc, binary):
    js = json.dumps(doc, separators=(",", ":")).encode()
    js += b" " * (-len(js) % 4)
    binary += b"\0" * (-len(binary) % 4)
    chunks = struct.pack("<I4s", len(js), b"JSON") + js
    chunks += struct.pack("<I4s", len(binary), b"BIN\0") + binary
    return struct.pack("<4sII", b"glTF", 2, 12 + len(chunks)) + chunks


put("glb", "skinned.glb", glb(gltf_doc({"byteLength": 284}), buf))

# ---------------------------------------------------------------- volumes
U8 = bytes((x * 37) & 0xFF for x in range(24))  # a 2x3x4 u8 grid
I16BE = b"".join(struct.pack(">h", x * 100 - 1000) for x in range(24))
F32LE = b"".join(struct.pack("<f", x / 7.0 - 1) for x in range(24))

put("nrrd", "raw.nrrd", b"NRRD0004\n# c\ntype: uchar\ndimension: 3\nsizes: 2 3 4\n"
    b"spacings: 1 2 0.5\nencoding: raw\n\n" + U8)
put("nrrd", "gzip.nrrd", b"NRRD0005\ntype: short\ndimension: 3\nsizes: 2 3 4\nendian: big\n"
    b"space dimension: 3\nspace directions: (1,0,0) (0,-2,0) (0,0,1)\n"
    b"space origin: (1,2,3)\nencoding: gzip\n\n" + gzip.compress(I16BE, mtime=0))
put("nrrd", "ascii.nrrd", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 3 4\nencoding: ascii\n"
    "line skip: 1\nbyte skip: 0\n\nskipped line\n" + " ".join("%g" % (x / 3) for x in range(24)))
put("nhdr", "detached.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 4\n"
    "encoding: raw\ndata file: d.raw\n")
put("nhdr", "skip.nhdr", "NRRD0004\ntype: ushort\ndimension: 3\nsizes: 2 3 4\nendian: little\n"
    "encoding: raw\nbyte skip: 16\ndata file: ./d.raw\n")
put("nhdr", "tail.nhdr", "NRRD0004\ntype: float\ndimension: 3\nsizes: 2 2 2\nendian: big\n"
    "encoding: raw\nbyte skip: -1\ndata file: d.raw\n")
put("nhdr", "list.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 4 4 2\nencoding: raw\n"
    "byte skip: 48\ndata file: LIST 2\nd.raw\nd.raw\n")
put("nhdr", "pattern.nhdr", "NRRD0004\ntype: uchar\ndimension: 3\nsizes: 8 8 1\n"
    "encoding: raw\ndata file: d%d.raw 1 1 1 2\n")
put("mhd", "detached.mhd", "ObjectType = Image\nNDims = 3\nDimSize = 4 4 4\n"
    "ElementType = MET_UCHAR\nElementSpacing = 1 1 2\nOffset = 0 0 0\n"
    "ElementDataFile = d.raw\n")
put("mhd", "header.mhd", "NDims = 3\nDimSize = 2 3 4\nElementType = MET_SHORT\n"
    "BinaryDataByteOrderMSB = True\nHeaderSize = -1\nTransformMatrix = 1 0 0 0 -1 0 0 0 1\n"
    "ElementDataFile = d.raw\n")
put("mhd", "list.mhd", "NDims = 3\nDimSize = 4 4 2\nElementType = MET_UCHAR\nHeaderSize = 48\n"
    "ElementDataFile = LIST 2D\nd.raw\nd.raw\n")
put("mha", "local.mha", b"ObjectType = Image\nNDims = 3\nDimSize = 2 3 4\n"
    b"ElementType = MET_UCHAR\nElementDataFile = LOCAL\n" + U8)
put("mha", "zlib.mha", b"NDims = 3\nDimSize = 2 3 4\nElementType = MET_SHORT\nBinaryData = True\n"
    b"BinaryDataByteOrderMSB = True\nCompressedData = True\nAnatomicalOrientation = RAI\n"
    b"ElementSpacing = 0.5 0.5 2\nElementDataFile = LOCAL\n" + zlib.compress(I16BE))
put("vtk", "ascii.vtk", "# vtk DataFile Version 3.0\nseed\nASCII\nDATASET STRUCTURED_POINTS\n"
    "DIMENSIONS 2 3 4\nSPACING 1 2 3\nORIGIN -1 0 1\nPOINT_DATA 24\nSCALARS s float 1\n"
    "LOOKUP_TABLE default\n" + " ".join("%g" % (x / 5) for x in range(24)) + "\n")
put("vtk", "binary.vtk", b"# vtk DataFile Version 2.0\nseed\nBINARY\nDATASET STRUCTURED_POINTS\n"
    b"DIMENSIONS 2 3 4\nASPECT_RATIO 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 24\nSCALARS s short\n"
    b"LOOKUP_TABLE default\n" + I16BE)
put("vtk", "uchar.vtk", b"# vtk DataFile Version 2.0\nseed\nBINARY\nDATASET STRUCTURED_POINTS\n"
    b"DIMENSIONS 2 3 4\nSPACING 1 1 1\nORIGIN 0 0 0\nPOINT_DATA 24\nSCALARS s unsigned_char 1\n"
    b"LOOKUP_TABLE default\n" + U8)


def vti(attrs, array, appended=None):
    f = ('<?xml version="1.0"?>\n<VTKFile type="ImageData" version="1.0" %s>\n'
         '<ImageData WholeExtent="1 2 0 2 0 3" Origin="0 0 0" Spacing="0.5 1 1" '
         'Direction="1 0 0 0 1 0 0 0 -1">\n<Piece Extent="1 2 0 2 0 3">\n'
         '<PointData Scalars="s">\n%s\n</PointData>\n</Piece>\n</ImageData>\n'
         % (attrs, array)).encode()
    if appended:
        enc, blob = appended
        f += b'<AppendedData encoding="%s">\n  _' % enc.encode() + blob + b"\n</AppendedData>\n"
    return f + b"</VTKFile>\n"


def b64(b):
    return base64.b64encode(b).decode()


blocks = [zlib.compress(F32LE[i:i + 40]) for i in range(0, 96, 40)]
zhead = struct.pack("<3I", len(blocks), 40, 96 % 40) + b"".join(
    struct.pack("<I", len(b)) for b in blocks)
zbody = b"".join(blocks)
put("vti", "ascii.vti", vti("", '<DataArray type="Float32" Name="s" format="ascii">%s</DataArray>'
                        % " ".join("%g" % (x / 7 - 1) for x in range(24))))
put("vti", "base64.vti", vti('header_type="UInt32" byte_order="LittleEndian"',
                         '<DataArray type="Float32" Name="s" format="binary">%s</DataArray>'
                         % b64(struct.pack("<I", 96) + F32LE)))
put("vti", "zlib.vti", vti('compressor="vtkZLibDataCompressor"',
                       '<DataArray type="Float32" Name="s" format="binary">%s%s</DataArray>'
                       % (b64(zhead), b64(zbody))))
put("vti", "appended.vti", vti('header_type="UInt64"',
                           '<DataArray type="Float32" Name="s" format="appended" offset="0"/>',
                           ("raw", struct.pack("<Q", 96) + F32LE)))
put("vti", "appended-zlib.vti", vti('compressor="vtkZLibDataCompressor"',
                                '<DataArray type="Float32" Name="s" format="appended" '
                                'offset="0"/>', ("base64", (b64(zhead) + b64(zbody)).encode())))


def slc(compressed):
    head = b"11111\n2 3 4 8\n1.0 1.0 2.0\n0 0 0 %d\n2 1 X" % compressed + bytes(6)
    for z in range(4):
        plane = U8[6 * z:6 * z + 6]
        if compressed:
            # A literal run of 4, a repeat run of 2, the end.
            s = bytes([0x84]) + plane[:4] + bytes([0x02, plane[4], 0])
        else:
            s = plane
        head += b"%d X" % len(s) + s
    return head


put("slc", "rle.slc", slc(1))
put("slc", "plain.slc", slc(0))


def raw(dims, scalar, big, header, body):
    h = struct.pack("<3H", *(d - 1 for d in dims)) + bytes([scalar | (8 if big else 0), header])
    return h + bytes(header) + body


put("raw", "u8", raw((2, 3, 4), 0, False, 0, U8))
put("raw", "i16be-header", raw((2, 3, 4), 3, True, 5, I16BE))
put("raw", "f32", raw((2, 3, 4), 6, False, 0, F32LE))
put("raw", "f64", raw((1, 1, 3), 7, False, 0, struct.pack("<3d", 1, -2, 3.5)))

# ---------------------------------------------------------------- scenes
put("scene", "mesh.toml", """[input]
mesh = "m.obj"
weld = true

[[camera]]
orbit = 3
elevation = 20
up = [0.0, 0.0, 1.0]

[[camera]]
eye = [0, 1, 4]
fov = 35
ortho = true

[effects]
shading = {}
curvature_colors = { scale = 2.0 }
ao = { level = "lut", radius = 0.05 }
contours = { width = 2 }
suggestive_contours = { threshold = 0.05, fade = 0.2 }
feature_edges = { crease = 30, caps = "adjacency" }

[output]
dir = "out"
size = [64, 48]
formats = ["png", "svg"]
""")
put("scene", "sdf.toml", """[input]
sdf = "gyroid"
resolution = 24

[[camera]]
direction = [1.0, 0.8, 1.3]

[effects]
curvature_colors = {}
curvature_strokes = { spacing = 0.05, sampling = "auto", color = [0.1, 0.1, 0.2], width = 0.01 }

[output]
size = [32, 32]
""")
put("scene", "volume.toml", """[input]
volume = "d.raw"
iso = 30
inside = "above"

[frames]
start = 0
end = 4
step = 2
fps = 30

[effects]
contours = {}
""")
put("scene", "generate.toml", """[input]
generate = "torus"
resolution = 400

[effects]
feature_edges = { crease = 40 }
""")
