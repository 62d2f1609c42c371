#!/usr/bin/env python3
"""Writes the fuzz harnesses' seed corpora (fuzz/corpus/<harness>/) from the test data.

The meshes are small files of CGAL's data set (the tarball the tests extract: Debian package
libcgal-demo), kept as they are (OFF, PLY) and converted to the other formats, with the
variants each reader has code for: polygons, comments, colours, quality, every PLY encoding and
list/index type, glTF data URIs, external buffers, sparse accessors, strips, fans, node
transforms and a .glb. Run it again after changing it; the output is deterministic.
Usage: fuzz/make_corpus.py [CGAL data.tar.gz]
"""
import base64
import json
import os
import shutil
import struct
import sys
import tarfile

TARBALL = sys.argv[1] if len(sys.argv) > 1 else "/usr/share/doc/libcgal-dev/data.tar.gz"
OUT = os.path.join(os.path.dirname(os.path.abspath(__file__)), "corpus")
OFF_NAMES = ["cube.off", "cube_poly.off", "cube_quad.off", "icosahedron.off",
             "mesh_with_colors.off", "degtri_sliding.off", "in.off", "P.off"]
PLY_NAMES = ["colored_tetra.ply"]


def parse_off(text):
    rows = [l.split("#", 1)[0].split() for l in text.splitlines()]
    rows = [r for r in rows if r]
    assert rows[0][0].endswith("OFF")
    head = rows[0][1:] if len(rows[0]) > 1 else rows[1]
    first = 1 if len(rows[0]) > 1 else 2
    nv, nf = int(head[0]), int(head[1])
    verts = [tuple(float(w) for w in r[:3]) for r in rows[first:first + nv]]
    faces = []
    for r in rows[first + nv:first + nv + nf]:
        n = int(r[0])
        faces.append([int(w) for w in r[1:1 + n]])
    return verts, faces


def write(harness, name, data):
    d = os.path.join(OUT, harness)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def obj_text(verts, faces, variant):
    lines = ["# from CGAL's data set"]
    lines += ["v %g %g %g" % v for v in verts]
    if variant == 1:
        lines += ["vt 0 0", "vn 0 0 1", "g group", "usemtl m", "s 1"]
    for f in faces:
        if variant == 1:
            lines.append("f " + " ".join("%d/1/1" % (i + 1) for i in f))
        elif variant == 2:
            lines.append("f " + " ".join("%d" % (i - len(verts)) for i in f))  # negative
        else:
            lines.append("f " + " ".join("%d" % (i + 1) for i in f))
    return "\n".join(lines) + "\n"


def ply(verts, faces, encoding, list_type="uchar", index_type="int", quality=False):
    head = ["ply", "format %s 1.0" % encoding, "comment from CGAL's data set",
            "element vertex %d" % len(verts), "property float x", "property float y",
            "property float z"]
    if quality:
        head.append("property float quality")
    head += ["element face %d" % len(faces),
             "property list %s %s vertex_indices" % (list_type, index_type), "end_header"]
    codes = {"uchar": "B", "ushort": "H", "int": "i", "uint": "I", "short": "h"}
    if encoding == "ascii":
        body = ""
        for v in verts:
            body += "%g %g %g%s\n" % (v + ((" 0.5",) if quality else ("",)))
        for f in faces:
            body += "%d %s\n" % (len(f), " ".join(str(i) for i in f))
        return ("\n".join(head) + "\n" + body).encode()
    e = "<" if encoding == "binary_little_endian" else ">"
    body = b""
    for v in verts:
        body += struct.pack(e + "3f", *v) + (struct.pack(e + "f", 0.5) if quality else b"")
    for f in faces:
        body += struct.pack(e + codes[list_type], len(f))
        body += struct.pack(e + codes[index_type] * len(f), *f)
    return ("\n".join(head) + "\n").encode() + body


def triangles(faces):
    out = []
    for f in faces:
        for k in range(1, len(f) - 1):
            out += [f[0], f[k], f[k + 1]]
    return out


def gltf(verts, faces, variant):
    """(json dict, bin bytes) for one mesh; variants exercise the reader's paths."""
    pos = b"".join(struct.pack("<3f", *v) for v in verts)
    idx_list = triangles(faces)
    idx = struct.pack("<%dH" % len(idx_list), *idx_list)
    pad = b"\0" * ((4 - len(idx) % 4) % 4)
    binary = pos + idx + pad
    lo = [min(v[k] for v in verts) for k in range(3)]
    hi = [max(v[k] for v in verts) for k in range(3)]
    doc = {
        "asset": {"version": "2.0", "generator": "fuzz/make_corpus.py"},
        "buffers": [{"byteLength": len(binary)}],
        "bufferViews": [{"buffer": 0, "byteOffset": 0, "byteLength": len(pos), "target": 34962},
                        {"buffer": 0, "byteOffset": len(pos), "byteLength": len(idx), "target": 34963}],
        "accessors": [{"bufferView": 0, "componentType": 5126, "count": len(verts), "type": "VEC3",
                       "min": lo, "max": hi},
                      {"bufferView": 1, "componentType": 5123, "count": len(idx_list), "type": "SCALAR"}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 4}]}],
        "nodes": [{"mesh": 0}],
        "scenes": [{"nodes": [0]}],
        "scene": 0,
    }
    if variant == 1:  # node hierarchy with transforms, a mirrored instance, a strip
        doc["nodes"] = [{"children": [1, 2], "translation": [1, 2, 3]},
                        {"mesh": 0, "rotation": [0, 0.7071068, 0, 0.7071068]},
                        {"mesh": 1, "scale": [-1, 1, 1]}]
        doc["meshes"].append({"primitives": [{"attributes": {"POSITION": 0}, "indices": 1, "mode": 5}]})
    if variant == 2:  # sparse accessor on top of the positions, a fan without indices
        sparse_idx = struct.pack("<2H", 0, 1)
        sparse_val = struct.pack("<6f", 0, 0, 0, 1, 1, 1)
        off = len(binary)
        binary += sparse_idx + sparse_val
        doc["bufferViews"] += [{"buffer": 0, "byteOffset": off, "byteLength": 4},
                               {"buffer": 0, "byteOffset": off + 4, "byteLength": 24}]
        doc["accessors"][0]["sparse"] = {"count": 2, "indices": {"bufferView": 2, "componentType": 5123},
                                         "values": {"bufferView": 3}}
        doc["meshes"][0]["primitives"].append({"attributes": {"POSITION": 0}, "mode": 6})
        doc["buffers"][0]["byteLength"] = len(binary)
    if variant == 3:  # a texture image as a data URI, a material, a LINES primitive
        png = base64.b64decode("iVBORw0KGgoAAAANSUhEUgAAAAEAAAABCAYAAAAfFcSJAAAADUlEQVR42mP8z8BQDwAEhQGAhKmMIQAAAABJRU5ErkJggg==")
        doc["images"] = [{"uri": "data:image/png;base64," + base64.b64encode(png).decode()}]
        doc["textures"] = [{"source": 0}]
        doc["materials"] = [{"pbrMetallicRoughness": {"baseColorTexture": {"index": 0}}}]
        doc["meshes"][0]["primitives"][0]["material"] = 0
        doc["meshes"][0]["primitives"].append({"attributes": {"POSITION": 0}, "indices": 1, "mode": 1})
    return doc, binary


def main():
    if os.path.isdir(OUT):
        shutil.rmtree(OUT)
    meshes = {}
    with tarfile.open(TARBALL) as tar:
        for name in OFF_NAMES + PLY_NAMES:
            data = tar.extractfile("data/meshes/" + name).read()
            if name.endswith(".off"):
                write("off", name, data)
                meshes[name[:-4]] = parse_off(data.decode())
            else:
                write("ply_ascii", name, data)
    for stem, (verts, faces) in sorted(meshes.items()):
        for variant in range(3):
            write("obj", "%s-%d.obj" % (stem, variant), obj_text(verts, faces, variant))
        write("ply_ascii", stem + ".ply", ply(verts, faces, "ascii", quality=stem == "cube"))
        for enc, lt, it in [("binary_little_endian", "uchar", "int"),
                            ("binary_big_endian", "ushort", "uint"),
                            ("binary_little_endian", "int", "short")]:
            write("ply_binary", "%s-%s-%s-%s.ply" % (stem, enc.split("_")[1], lt, it),
                  ply(verts, faces, enc, lt, it, quality=stem == "icosahedron"))
        if len(verts) < 3 or max(max(f) for f in faces) >= 65536:
            continue
        for variant in range(4):
            doc, binary = gltf(verts, faces, variant)
            with_uri = json.loads(json.dumps(doc))
            with_uri["buffers"][0]["uri"] = "data:application/octet-stream;base64," + \
                base64.b64encode(binary).decode()
            write("gltf", "%s-%d.gltf" % (stem, variant), json.dumps(with_uri, indent=1))
            if variant == 0:  # an external buffer (not found where the harness loads it)
                ext = json.loads(json.dumps(doc))
                ext["buffers"][0]["uri"] = stem + ".bin"
                write("gltf", "%s-external.gltf" % stem, json.dumps(ext))
            chunk = json.dumps(doc).encode()
            chunk += b" " * ((4 - len(chunk) % 4) % 4)
            total = 12 + 8 + len(chunk) + 8 + len(binary)
            glb = struct.pack("<4sII", b"glTF", 2, total)
            glb += struct.pack("<II", len(chunk), 0x4E4F534A) + chunk
            glb += struct.pack("<II", len(binary), 0x004E4942) + binary
            write("gltf", "%s-%d.glb" % (stem, variant), glb)
    # Manifests: comments, blank lines, CRLF, '@' nesting, the manifest naming itself.
    write("manifest", "simple.list", "# meshes\n\na.off\n  b.ply  \n")
    write("manifest", "self.list", "inputs.list\n@inputs.list\n")
    write("manifest", "crlf.list", "x.obj\r\n# c\r\n\t@inputs.list\r\n")
    write("manifest", "dir.list", ".\n")
    n = sum(len(files) for _, _, files in os.walk(OUT))
    print("wrote %d seeds under %s" % (n, OUT))


if __name__ == "__main__":
    main()
