"""Tests of the sdfkit Python module on a real OpenCL device (PoCL in CI).

Run by CTest (one entry per TestCase class) with PYTHONPATH set to the built module, or by hand:
    PYTHONPATH=build/python /usr/bin/python3 -m unittest -v test_sdfkit      (in python/tests)
A missing OpenCL device fails the tests unless SDFKIT_ALLOW_NO_DEVICE=1 (CTest unsets it).
"""

import math
import os
import re
import struct
import tempfile
import threading
import unittest

import numpy as np

import sdfkit


# --- meshes built here from numpy arrays -------------------------------------------------------

def icosphere(radius, level):
    """(V,3) float64 vertices on a sphere and (F,3) int64 CCW-outward faces: an icosahedron
    subdivided `level` times, new vertices pushed onto the sphere."""
    t = (1.0 + 5.0 ** 0.5) / 2.0
    v = [(-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
         (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1)]
    f = [(0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
         (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
         (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1)]
    verts = [np.array(p, dtype=np.float64) / np.linalg.norm(p) for p in v]
    for _ in range(level):
        midpoint = {}

        def mid(a, b):
            key = (min(a, b), max(a, b))
            if key not in midpoint:
                m = verts[a] + verts[b]
                verts.append(m / np.linalg.norm(m))
                midpoint[key] = len(verts) - 1
            return midpoint[key]

        nf = []
        for a, b, c in f:
            ab, bc, ca = mid(a, b), mid(b, c), mid(c, a)
            nf += [(a, ab, ca), (b, bc, ab), (c, ca, bc), (ab, bc, ca)]
        f = nf
    return np.array(verts) * radius, np.array(f, dtype=np.int64)


def capsule(radius, half_length, segments=64, cap_rings=12, side_rings=24):
    """A capsule along z: a cylinder of `radius` from -half_length to +half_length closed by two
    hemispheres. Returns (V,3) float64 vertices, (F,3) int64 CCW-outward faces."""
    profile = []  # (z, rho) from the top pole to the bottom pole
    for k in range(cap_rings + 1):
        a = 0.5 * math.pi * k / cap_rings
        profile.append((half_length + radius * math.cos(a), radius * math.sin(a)))
    for k in range(1, side_rings):
        profile.append((half_length - 2.0 * half_length * k / side_rings, radius))
    for k in range(cap_rings, -1, -1):
        a = 0.5 * math.pi * k / cap_rings
        profile.append((-half_length - radius * math.cos(a), radius * math.sin(a)))
    rings = profile[1:-1]
    angles = 2.0 * math.pi * np.arange(segments) / segments
    verts = [(0.0, 0.0, profile[0][0])]
    for z, rho in rings:
        verts += [(rho * math.cos(a), rho * math.sin(a), z) for a in angles]
    verts.append((0.0, 0.0, profile[-1][0]))
    bottom = len(verts) - 1

    def ring(k, j):
        return 1 + k * segments + j % segments

    faces = [(0, ring(0, j), ring(0, j + 1)) for j in range(segments)]
    for k in range(len(rings) - 1):
        for j in range(segments):
            faces.append((ring(k, j), ring(k + 1, j), ring(k + 1, j + 1)))
            faces.append((ring(k, j), ring(k + 1, j + 1), ring(k, j + 1)))
    last = len(rings) - 1
    faces += [(ring(last, j), bottom, ring(last, j + 1)) for j in range(segments)]
    return np.array(verts), np.array(faces, dtype=np.int64)


def signed_volume(vertices, faces):
    a, b, c = (vertices[faces[:, i]] for i in range(3))
    return float(np.einsum("ij,ij->i", a, np.cross(b, c)).sum() / 6.0)


def write_off(path, vertices, faces):
    with open(path, "w") as out:
        out.write("OFF\n%d %d 0\n" % (len(vertices), len(faces)))
        for p in vertices:
            out.write("%.9g %.9g %.9g\n" % tuple(p))
        for f in faces:
            out.write("3 %d %d %d\n" % tuple(f))


def read_ply(path):
    """Minimal binary little-endian PLY reader: {element: {property: array}}; list properties
    (face indices) as an (n, count) array of a fixed count."""
    types = {"char": "b", "uchar": "B", "short": "h", "ushort": "H", "int": "i", "uint": "I",
             "float": "f", "double": "d", "int8": "b", "uint8": "B", "int32": "i", "uint32": "I",
             "float32": "f", "float64": "d"}
    with open(path, "rb") as f:
        data = f.read()
    end = data.index(b"end_header\n") + len(b"end_header\n")
    header = data[:end].decode("ascii").splitlines()
    assert header[0] == "ply" and header[1] == "format binary_little_endian 1.0", header[:2]
    elements = []
    for line in header:
        w = line.split()
        if w[0] == "element":
            elements.append((w[1], int(w[2]), []))
        elif w[0] == "property":
            elements[-1][2].append(w[1:])
    pos, out = end, {}
    for name, count, props in elements:
        columns = {p[-1]: [] for p in props}
        for _ in range(count):
            for p in props:
                if p[0] == "list":
                    (n,) = struct.unpack_from("<" + types[p[1]], data, pos)
                    pos += struct.calcsize(types[p[1]])
                    fmt = "<%d%s" % (n, types[p[2]])
                    columns[p[-1]].append(struct.unpack_from(fmt, data, pos))
                    pos += struct.calcsize(fmt)
                else:
                    fmt = "<" + types[p[0]]
                    columns[p[-1]].append(struct.unpack_from(fmt, data, pos)[0])
                    pos += struct.calcsize(fmt)
        out[name] = {k: np.array(v) for k, v in columns.items()}
    assert pos == len(data), "trailing bytes in %s" % path
    return out


# --- the estimator in closed form ---------------------------------------------------------------

def cone_thetas(rays, cone_degrees):
    """Ray angles to the cone axis: cos th_i = 1 - (1 - cos(cone/2)) (i + 1/2) / N."""
    i = np.arange(rays, dtype=np.float64)
    half = math.radians(cone_degrees) / 2.0
    return np.arccos(1.0 - (1.0 - math.cos(half)) * (i + 0.5) / rays)


def gather(lengths, thetas):
    """Median sorted[k//2], population sigma, keep |d - median| <= sigma, 1/theta-weighted mean."""
    order = np.argsort(lengths, kind="stable")
    d, w = lengths[order], 1.0 / thetas[order]
    median = d[len(d) // 2]
    sigma = math.sqrt(np.mean((d - d.mean()) ** 2))
    keep = np.abs(d - median) <= sigma
    return float(np.sum(w[keep] * d[keep]) / np.sum(w[keep]))


def sphere_sdf(radius, rays, cone_degrees):
    """Every ray from a point of a sphere leaves it again (the CGAL rule accepts all) after the
    chord 2 R cos(theta)."""
    th = cone_thetas(rays, cone_degrees)
    return gather(2.0 * radius * np.cos(th), th)


def cylinder_sdf_range(radius, rays, cone_degrees):
    """(min, max) of the estimator at a point of an infinite cylinder's wall over every rotation
    of the ray set about the normal (either handedness): the backend's tangent frame fixes one.
    A ray at angle theta from the inward normal n and azimuth phi from the circumference
    direction has components c_n = cos th, c_t = sin th cos phi in the cross-section; it
    crosses the circle after 2 r c_n / (c_n^2 + c_t^2)."""
    th = cone_thetas(rays, cone_degrees)
    golden = math.pi * (3.0 - math.sqrt(5.0))
    values = []
    for sign in (1.0, -1.0):
        for phi0 in np.linspace(0.0, 2.0 * math.pi, 720, endpoint=False):
            phi = sign * golden * np.arange(rays) + phi0
            cn, ct = np.cos(th), np.sin(th) * np.cos(phi)
            values.append(gather(2.0 * radius * cn / (cn * cn + ct * ct), th))
    return min(values), max(values)


# --- shared device session -----------------------------------------------------------------------

_session = None


def opencl_session(test):
    """One OpenCL session for the whole file (PoCL builds the kernels once)."""
    global _session
    if _session is None:
        try:
            _session = sdfkit.Session("opencl")
        except sdfkit.DeviceError as e:
            if os.environ.get("SDFKIT_ALLOW_NO_DEVICE") == "1":
                test.skipTest("no OpenCL device (SDFKIT_ALLOW_NO_DEVICE=1): %s" % e)
            raise
    return _session


class AnalyticTest(unittest.TestCase):
    """Values against the estimator's closed form on shapes built from numpy arrays."""

    def test_meshes_are_closed_and_outward(self):
        for v, f in (icosphere(1.0, 3), capsule(0.5, 2.5)):
            self.assertGreater(signed_volume(v, f), 0.0)
            edges = np.sort(np.concatenate([f[:, [0, 1]], f[:, [1, 2]], f[:, [2, 0]]]), axis=1)
            _, counts = np.unique(edges, axis=0, return_counts=True)
            self.assertTrue(np.all(counts == 2), "every edge has two faces")

    def test_sphere_matches_closed_form(self):
        s = opencl_session(self)
        radius = 1.7
        v, f = icosphere(radius, 3)
        s.set_mesh(v, f)
        for rays, cone in ((30, 120.0), (12, 90.0)):
            values = s.compute(rays=rays, cone=cone, false_hits="cgal")
            expected = sphere_sdf(radius, rays, cone)
            self.assertEqual(values.dtype, np.float32)
            self.assertEqual(values.shape, (len(v),))
            self.assertTrue(np.all(s.last_kept_rays > 0))
            # Facets lie inside the sphere (sagitta ~0.5% of R at this level): chords come out a
            # little shorter (measured on PoCL: median -0.25%, worst vertex -1.2%).
            self.assertAlmostEqual(float(np.median(values)) / expected, 1.0, delta=0.005)
            self.assertLess(float(np.max(np.abs(values / expected - 1.0))), 0.02)
        self.assertIn("total", s.last_timings)

    def test_sphere_per_face(self):
        s = opencl_session(self)
        v, f = icosphere(1.0, 3)
        s.set_mesh(v, f)
        values = s.compute(per="face", rays=30, false_hits="cgal")
        self.assertEqual(values.shape, (len(f),))
        # Face centroids sit slightly inside the sphere, with face normals exactly radial.
        self.assertAlmostEqual(float(np.median(values)) / sphere_sdf(1.0, 30, 120.0), 1.0, delta=0.01)

    def test_capsule_wall_within_closed_form_band(self):
        s = opencl_session(self)
        radius, half = 0.5, 2.5
        v, f = capsule(radius, half)
        s.set_mesh(v, f)
        rays = 24
        values = s.compute(rays=rays, false_hits="cgal")
        lo, hi = cylinder_sdf_range(radius, rays, 120.0)
        # Points near the middle: every ray leaves through the wall (axial travel <= 2r tan 60).
        middle = np.abs(v[:, 2]) < half - 2.0 * radius * math.tan(math.radians(60.0)) - 0.1
        self.assertGreater(int(middle.sum()), 100)
        mid = values[middle]
        self.assertGreater(float(mid.min()), lo * 0.99, (lo, hi))
        self.assertLess(float(mid.max()), hi * 1.01, (lo, hi))


class SessionTest(unittest.TestCase):
    """A session keeps its device and geometry between calls."""

    def test_update_positions_scales_values(self):
        s = opencl_session(self)
        # 29 segments: no two facets exactly 90 degrees apart, where the paper's rule would sit
        # exactly on its threshold and float rounding of the moved mesh could flip a ray.
        v, f = capsule(0.5, 1.5, segments=29, cap_rings=8, side_rings=12)
        moved = v * 2.5 + np.array([3.0, -1.0, 0.5])
        for per, rule in (("vertex", "cgal"), ("face", "paper")):
            s.set_mesh(v, f)
            base = s.compute(per=per, rays=16, false_hits=rule)
            s.update_positions(moved)
            self.assertIn("total", s.last_timings)
            scaled = s.compute(per=per, rays=16, false_hits=rule)
            ratio = scaled / base
            # Same rays, same hits: equal up to float rounding of the moved geometry.
            self.assertAlmostEqual(float(np.median(ratio)), 2.5, delta=2.5e-4)
            self.assertGreater(float(np.mean(np.abs(ratio - 2.5) < 2.5e-3)), 0.99)
            # Moving the vertices is the same as uploading the moved mesh.
            s.set_mesh(moved, f)
            np.testing.assert_array_equal(s.compute(per=per, rays=16, false_hits=rule), scaled)
            self.assertEqual(s.vertex_count, len(v))
            self.assertEqual(s.face_count, len(f))

    def test_new_mesh_replaces_old(self):
        s = opencl_session(self)
        small_v, small_f = icosphere(0.5, 2)
        s.set_mesh(small_v, small_f)
        small = s.compute(rays=16, false_hits="cgal")
        big_v, big_f = icosphere(2.0, 3)
        s.set_mesh(big_v, big_f)
        big = s.compute(rays=16, false_hits="cgal")
        self.assertEqual(len(small), len(small_v))
        self.assertEqual(len(big), len(big_v))
        self.assertAlmostEqual(float(np.median(big) / np.median(small)), 4.0, delta=0.08)
        self.assertIn("opencl", s.name)
        self.assertTrue(s.device)

    def test_accepts_convertible_arrays(self):
        s = opencl_session(self)
        v, f = icosphere(1.0, 1)
        s.set_mesh(v.astype(np.float32), f.astype(np.uint32))
        reference = s.compute(rays=8)
        s.set_mesh(v.tolist(), f.astype(np.float64))  # lists, float faces holding whole numbers
        np.testing.assert_array_equal(s.compute(rays=8), reference)
        s.set_mesh(np.asfortranarray(v), f.astype(np.int16))
        np.testing.assert_array_equal(s.compute(rays=8), reference)
        # Integer vertices are accepted too (a cube of whole-number corners).
        cube_v = np.array([[x, y, z] for x in (0, 2) for y in (0, 2) for z in (0, 2)])
        cube_f = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                           [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
        self.assertGreater(signed_volume(cube_v.astype(float), cube_f), 0.0)
        s.set_mesh(cube_v.astype(np.float32), cube_f)
        reference = s.compute(per="face", rays=30, false_hits="cgal")
        s.set_mesh(cube_v, cube_f)
        np.testing.assert_array_equal(s.compute(per="face", rays=30, false_hits="cgal"), reference)
        self.assertTrue(np.all((reference > 1.5) & (reference < 2.5)), reference)

    def test_threads_share_a_session(self):
        s = opencl_session(self)
        v, f = icosphere(1.0, 2)
        s.set_mesh(v, f)
        reference = s.compute(rays=16)
        results = [None] * 4

        def work(i):
            results[i] = s.compute(rays=16)

        threads = [threading.Thread(target=work, args=(i,)) for i in range(len(results))]
        for t in threads:
            t.start()
        for t in threads:
            t.join()
        for r in results:
            np.testing.assert_array_equal(r, reference)


class FileTest(unittest.TestCase):
    """compute_file and load: files in, files and reports out."""

    def setUp(self):
        self.tmp = tempfile.TemporaryDirectory(prefix="sdfkit-python-")
        self.v, self.f = capsule(0.5, 1.0, segments=24, cap_rings=6, side_rings=8)
        self.off = os.path.join(self.tmp.name, "capsule.off")
        write_off(self.off, self.v, self.f)

    def tearDown(self):
        self.tmp.cleanup()

    def test_load(self):
        asset = sdfkit.load(self.off)
        self.assertEqual(asset.format, "off")
        self.assertEqual(asset.path, self.off)
        np.testing.assert_allclose(asset.vertices, self.v, rtol=1e-6, atol=1e-7)
        np.testing.assert_array_equal(asset.faces, self.f)
        np.testing.assert_array_equal(asset.input_to_welded, np.arange(len(self.v)))
        self.assertEqual(asset.vertices.dtype, np.float32)
        self.assertEqual(asset.faces.dtype, np.uint32)
        self.assertFalse(asset.vertices.flags.writeable)
        self.assertIn("capsule.off", repr(asset))

    def test_load_welds_seams(self):
        # Split every face's corners apart, as a file with per-face normals would.
        split_v = self.v[self.f.reshape(-1)]
        split_f = np.arange(len(split_v)).reshape(-1, 3)
        path = os.path.join(self.tmp.name, "split.off")
        write_off(path, split_v, split_f)
        asset = sdfkit.load(path)
        self.assertEqual(len(asset.input_vertices), len(split_v))
        self.assertEqual(len(asset.vertices), len(self.v))
        np.testing.assert_array_equal(asset.vertices[asset.input_to_welded], asset.input_vertices)
        np.testing.assert_array_equal(asset.input_to_welded[asset.input_faces], asset.faces)

    def test_compute_file_round_trip(self):
        s = opencl_session(self)
        options = dict(rays=12, false_hits="cgal")
        s.set_mesh(self.v, self.f)
        per_vertex = s.compute(**options)
        per_face = s.compute(per="face", **options)

        txt = os.path.join(self.tmp.name, "out.txt")
        report = sdfkit.compute_file(self.off, txt, backend="opencl", **options)
        self.assertTrue(report["ok"])
        self.assertIsNone(report["error"])
        self.assertEqual(report["input"], self.off)
        self.assertEqual(report["output"], txt)
        self.assertEqual(report["backend"], s.name)
        self.assertEqual(report["counts"]["points"], len(self.v))
        self.assertEqual(report["counts"]["input_faces"], len(self.f))
        self.assertEqual(report["counts"]["filled_points"], 0)
        self.assertGreater(report["total_ms"], 0.0)
        from_txt = np.loadtxt(txt, dtype=np.float32)
        # The file's coordinates are the arrays' printed to 9 digits: the same float32 mesh.
        np.testing.assert_allclose(from_txt, per_vertex, rtol=1e-5)
        self.assertAlmostEqual(report["summary"]["median"], float(np.median(per_vertex)), places=5)

        ply = os.path.join(self.tmp.name, "out.ply")
        report = sdfkit.compute_file(self.off, ply, per="face", session=s, color=False, **options)
        self.assertEqual(report["counts"]["points"], len(self.f))
        content = read_ply(ply)
        np.testing.assert_allclose(content["face"]["quality"], per_face, rtol=1e-5)
        self.assertNotIn("red", content["face"])
        np.testing.assert_allclose(np.stack([content["vertex"][c] for c in "xyz"], axis=1), self.v,
                                   rtol=1e-6, atol=1e-7)
        np.testing.assert_array_equal(np.array(content["face"]["vertex_indices"]), self.f)
        # compute_file gave the session the file's mesh (the same float32 mesh): the session
        # computes on it, not on a mesh it no longer holds.
        self.assertEqual(s.vertex_count, len(self.v))
        np.testing.assert_allclose(s.compute(per="face", **options), per_face, rtol=1e-5)

    def test_asset_write_back(self):
        s = opencl_session(self)
        asset = sdfkit.load(self.off)
        s.set_mesh(asset)
        values = s.compute(rays=8)
        out = os.path.join(self.tmp.name, "written.ply")
        asset.write(out, values, normalize=True)
        content = read_ply(out)
        q = content["vertex"]["quality"]
        self.assertAlmostEqual(float(q.min()), 0.0, places=6)
        self.assertAlmostEqual(float(q.max()), 1.0, places=6)
        self.assertIn("red", content["vertex"])
        glb = os.path.join(self.tmp.name, "written.glb")
        asset.write(glb, values)
        back = sdfkit.load(glb)
        np.testing.assert_allclose(back.vertices, asset.vertices)
        with self.assertRaisesRegex(sdfkit.InputError, "glTF"):
            asset.write(glb, s.compute(per="face", rays=8), per="face")

    def test_builtin_shape(self):
        asset = sdfkit.load("builtin:sphere")
        self.assertGreater(len(asset.faces), 100)
        report = sdfkit.compute_file("builtin:sphere", None, backend="opencl", rays=8, smooth=1)
        self.assertEqual(report["output"], "")
        self.assertIn("smooth", report["time_ms"])


class ErrorTest(unittest.TestCase):
    """Engine errors arrive as sdfkit.InputError / DeviceError with the engine's message."""

    def test_missing_file(self):
        path = "/nonexistent/dir/missing_mesh.off"
        for call in (lambda: sdfkit.load(path), lambda: sdfkit.compute_file(path, "/tmp/never.ply")):
            with self.assertRaises(sdfkit.InputError) as caught:
                call()
            self.assertIn(path, str(caught.exception))
            self.assertIsInstance(caught.exception, ValueError)
            self.assertIsInstance(caught.exception, sdfkit.Error)
        self.assertFalse(os.path.exists("/tmp/never.ply"))

    def test_malformed_file(self):
        with tempfile.TemporaryDirectory() as tmp:
            path = os.path.join(tmp, "broken.off")
            with open(path, "w") as out:
                out.write("OFF\n3 1 0\n0 0 0\n1 0 0\n")  # truncated
            with self.assertRaisesRegex(sdfkit.InputError, re.escape(path)):
                sdfkit.load(path)
            with self.assertRaisesRegex(sdfkit.InputError, "unknown extension"):
                sdfkit.load(os.path.join(tmp, "mesh.xyz"))

    def test_untrusted_assets(self):
        """A glTF's buffer outside its directory is refused unless allow_external_paths; the
        limits refuse big assets (SECURITY.md)."""
        with tempfile.TemporaryDirectory() as tmp:
            xyz = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1)
            idx = struct.pack("<12H", 0, 2, 1, 0, 1, 3, 0, 3, 2, 1, 2, 3)
            with open(os.path.join(tmp, "secret.bin"), "wb") as out:
                out.write(xyz + idx)
            os.mkdir(os.path.join(tmp, "assets"))
            path = os.path.join(tmp, "assets", "evil.gltf")
            with open(path, "w") as out:
                out.write('{"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],'
                          '"nodes":[{"mesh":0}],"meshes":[{"primitives":[{"attributes":'
                          '{"POSITION":0},"indices":1}]}],"accessors":[{"bufferView":0,'
                          '"componentType":5126,"count":4,"type":"VEC3"},{"bufferView":1,'
                          '"componentType":5123,"count":12,"type":"SCALAR"}],"bufferViews":'
                          '[{"buffer":0,"byteLength":48},{"buffer":0,"byteOffset":48,'
                          '"byteLength":24}],"buffers":[{"byteLength":72,"uri":"../secret.bin"}]}')
            with self.assertRaisesRegex(sdfkit.InputError, re.escape("external reference '../secret.bin'")):
                sdfkit.load(path)
            asset = sdfkit.load(path, allow_external_paths=True)
            self.assertEqual(len(asset.faces), 4)
            self.assertEqual(len(sdfkit.load(path, allow_external_paths=True, max_triangles=4).faces), 4)
            with self.assertRaisesRegex(sdfkit.InputError, "more than the limit of 3 triangles"):
                sdfkit.load(path, allow_external_paths=True, max_triangles=3)
            with self.assertRaisesRegex(sdfkit.InputError, "more than the limit of 100"):
                sdfkit.load(path, allow_external_paths=True, max_file_size=100)
            with self.assertRaisesRegex(sdfkit.InputError, re.escape("'../secret.bin'")):
                sdfkit.compute_file(path, os.path.join(tmp, "out.ply"))
            self.assertFalse(os.path.exists(os.path.join(tmp, "out.ply")))

    def test_device_errors(self):
        with self.assertRaises(sdfkit.DeviceError) as caught:
            sdfkit.Session("opencl", device="no-such-device-anywhere")
        self.assertIsInstance(caught.exception, RuntimeError)
        self.assertIsInstance(caught.exception, sdfkit.Error)
        self.assertNotIsInstance(caught.exception, ValueError)
        self.assertIn("no-such-device-anywhere", str(caught.exception))
        with self.assertRaisesRegex(sdfkit.InputError, "unknown backend 'metal'"):
            sdfkit.Session("metal")

    def test_bad_arrays(self):
        s = opencl_session(self)
        v, f = icosphere(1.0, 1)
        cases = [
            ((v[:, :2], f), r"vertices must have shape \(V, 3\), got \(42, 2\)"),
            ((v, f[:, :2]), r"faces must have shape \(F, 3\)"),
            ((v.reshape(-1), f), r"vertices must have shape \(V, 3\), got \(126,\)"),
            ((np.where(np.arange(len(v))[:, None] == 5, np.nan, v), f), "vertex 5 has a non-finite"),
            ((v, np.where(f == 7, 1000, f)), "out of range"),
            ((v, np.where(f == 7, -1, f)), "negative vertex index"),
            ((v, f + 0.5), "not a whole number"),
            ((v, f[:0]), "no triangles"),
        ]
        for args, message in cases:
            with self.subTest(message=message):
                with self.assertRaisesRegex(sdfkit.InputError, message):
                    s.set_mesh(*args)
        with self.assertRaisesRegex(TypeError, "vertices must be an array of numbers"):
            s.set_mesh(np.full((3, 3), "a"), f)
        s.set_mesh(v, f)
        with self.assertRaisesRegex(sdfkit.InputError, "got 41 vertices, the mesh has 42"):
            s.update_positions(v[:-1])
        with self.assertRaisesRegex(sdfkit.InputError, "non-finite"):
            s.update_positions(v * np.inf)
        with self.assertRaisesRegex(sdfkit.InputError, 'per must be "vertex" or "face"'):
            s.compute(per="edge")
        with self.assertRaisesRegex(sdfkit.InputError, 'false_hits must be "paper" or "cgal"'):
            s.compute(false_hits="both")
        with self.assertRaises(sdfkit.InputError):
            s.compute(rays=0)
        with self.assertRaises(sdfkit.InputError):
            s.compute(cone=0.0)
        with self.assertRaises(TypeError):
            s.compute("vertex")  # options are keyword-only
        with self.assertRaises(TypeError):
            sdfkit.compute_file("builtin:sphere", None, no_such_option=1)
        with self.assertRaisesRegex(sdfkit.InputError, "either session or backend"):
            sdfkit.compute_file("builtin:sphere", None, session=s, backend="opencl")


class RoadTest(unittest.TestCase):
    """The engine's road: the backend contract and the automatic choice, as the CLI has them."""

    def test_an_option_the_backend_would_ignore_is_refused(self):
        with self.assertRaisesRegex(sdfkit.InputError, "--views is an option of the vulkan backend"):
            sdfkit.Session("opencl", views=64)
        with self.assertRaisesRegex(sdfkit.InputError, "both backends"):
            sdfkit.Session("auto", views=64, memory_cap=1 << 20)
        with self.assertRaisesRegex(sdfkit.InputError, "--rays is an option of the opencl backend"):
            sdfkit.compute_file("builtin:sphere", None, backend="vulkan", rays=4)

    def test_rays_on_a_vulkan_session_are_refused(self):
        if not any(d["backend"] == "vulkan" and d["usable"] for d in sdfkit.devices()):
            self.skipTest("no Vulkan device")
        s = sdfkit.Session("vulkan", views=16, resolution=64)
        v, f = icosphere(1.0, 2)
        s.set_mesh(v, f)
        with self.assertRaisesRegex(sdfkit.InputError, "--rays is an option of the opencl backend"):
            s.compute(rays=4)
        self.assertEqual(s.compute().shape, (len(v),))

    def test_auto_prefers_opencl_to_a_cpu_rasterizer(self):
        devices = sdfkit.devices()
        if any(d["gpu"] and d["usable"] for d in devices):
            self.skipTest("a GPU is present: the rule picks it")
        s = sdfkit.Session()
        self.assertEqual(s.name, "opencl")
        if any(d["backend"] == "vulkan" and d["usable"] for d in devices):
            self.assertIn("CPU rasterizer", s.choice)
        report = sdfkit.compute_file("builtin:sphere", None, rays=6)
        self.assertEqual(report["backend"], "opencl")
        self.assertEqual(report["options"]["sdf"]["rays"], 6)


class UtilityTest(unittest.TestCase):
    """smooth, compare, devices, version."""

    @unittest.skipUnless(hasattr(sdfkit, "diffuse"), "built without Vulkan")
    def test_diffuse(self):
        v, f = capsule(0.5, 1.0)
        constant = np.full(len(v), 3.25)
        np.testing.assert_allclose(sdfkit.diffuse(v, f, constant, radius=4.0, atlas_size=512), constant, rtol=1e-4)
        noisy = 1.0 + 0.2 * np.random.default_rng(7).standard_normal(len(v))
        diffused = sdfkit.diffuse(v, f, noisy, sigma=0.1, atlas_size=512)
        self.assertEqual(diffused.dtype, np.float32)
        self.assertLess(float(np.std(diffused)), 0.5 * float(np.std(noisy)))
        # steps: two blurs of sigma / sqrt(2) are not one blur of sigma (the kernel is carried on
        # between them), and both smooth; more than 256 is refused.
        one = sdfkit.diffuse(v, f, noisy, sigma=0.1, steps=1, atlas_size=512)
        two = sdfkit.diffuse(v, f, noisy, sigma=0.1, steps=2, atlas_size=512)
        self.assertGreater(float(np.max(np.abs(one - two))), 1e-4)
        self.assertLess(float(np.std(two)), 0.5 * float(np.std(noisy)))
        with self.assertRaisesRegex(sdfkit.InputError, "steps"):
            sdfkit.diffuse(v, f, noisy, sigma=0.1, steps=257, atlas_size=512)
        # stretch and conserve are honoured: each changes the result; conserve keeps the mean over
        # the capsule's lumped vertex areas (its integral), which the blur's own read-back drifts from.
        for kw in ({"stretch": False}, {"conserve": False}):
            other = sdfkit.diffuse(v, f, noisy, sigma=0.1, atlas_size=512, **kw)
            self.assertGreater(float(np.max(np.abs(other - diffused))), 1e-5, kw)
        area = np.zeros(len(v))
        tri = np.asarray(v, dtype=np.float64)[np.asarray(f)]
        a = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
        for k in range(3):
            np.add.at(area, np.asarray(f)[:, k], a / 3.0)
        kept = sdfkit.diffuse(v, f, noisy, sigma=0.1, atlas_size=512)
        drift = sdfkit.diffuse(v, f, noisy, sigma=0.1, atlas_size=512, conserve=False)
        self.assertAlmostEqual(float(area @ kept), float(area @ noisy), delta=1e-4 * float(area @ noisy))
        self.assertGreater(abs(float(area @ drift) - float(area @ noisy)), abs(float(area @ kept) - float(area @ noisy)))
        with self.assertRaisesRegex(sdfkit.InputError, "stretch"):
            sdfkit.diffuse(v, f, noisy, radius=2.0, stretch=False, atlas_size=512)
        with self.assertRaisesRegex(sdfkit.InputError, "exactly one"):
            sdfkit.diffuse(v, f, noisy)
        with self.assertRaisesRegex(sdfkit.InputError, "one value per vertex"):
            sdfkit.diffuse(v, f, noisy[:-1], radius=2.0)

    def test_smooth(self):
        v, f = icosphere(1.0, 2)
        constant = np.full(len(v), 3.25)
        np.testing.assert_allclose(sdfkit.smooth(v, f, constant, rings=2), constant, rtol=1e-6)
        noisy = 1.0 + 0.2 * np.random.default_rng(7).standard_normal(len(v))
        smoothed = sdfkit.smooth(v, f, noisy, rings=2)
        self.assertEqual(smoothed.dtype, np.float32)
        self.assertLess(float(np.std(smoothed)), 0.5 * float(np.std(noisy)))
        self.assertAlmostEqual(float(np.mean(smoothed)), float(np.mean(noisy)), delta=0.02)
        per_face = sdfkit.smooth(v, f, np.full(len(f), 2.0), per="face", rings=1)
        np.testing.assert_allclose(per_face, 2.0, rtol=1e-6)
        with self.assertRaisesRegex(sdfkit.InputError, "values for"):
            sdfkit.smooth(v, f, constant[:-1])
        with self.assertRaises(sdfkit.InputError):
            sdfkit.smooth(v, f, constant, rings=0)

    def test_compare(self):
        a = np.linspace(1.0, 2.0, 50)
        same = sdfkit.compare(a, a)
        self.assertEqual(same["points"], 50)
        self.assertAlmostEqual(same["pearson"], 1.0, places=6)
        self.assertEqual(same["median_relative"], 0.0)
        double = sdfkit.compare(2.0 * a, a)
        self.assertAlmostEqual(double["median_signed_relative"], 1.0, places=6)
        self.assertAlmostEqual(double["max_relative"], 1.0, places=6)
        with self.assertRaisesRegex(sdfkit.InputError, "a has 50 values, b has 49"):
            sdfkit.compare(a, a[1:])

    def test_devices(self):
        opencl_session(self)  # skips here too when no device is allowed
        listing = sdfkit.devices()
        self.assertTrue(listing)
        self.assertEqual(set(listing[0]), {"backend", "description", "usable", "reason", "gpu"})
        self.assertTrue(any(d["backend"] == "opencl" and d["usable"] for d in listing), listing)
        self.assertIn("opencl", sdfkit.backends())

    def test_version(self):
        self.assertRegex(sdfkit.__version__, r"^\d+\.\d+\.\d+$")


if __name__ == "__main__":
    unittest.main()
