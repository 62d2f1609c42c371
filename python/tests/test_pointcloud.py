"""Tests of sdfkit's point-cloud functions (issue 14) on a real OpenCL device (PoCL in CI):
the skeleton of a synthetic worm follows its exact midline, and the compression of a small
animated worm writes a glb whose playback matches the report. Run like test_sdfkit.py."""

import os
import tempfile
import unittest

import numpy as np

import sdfkit


def distance_to_polyline(p, line):
    a, b = line[:-1], line[1:]
    ab = b - a
    u = np.clip(np.einsum("ij,ij->i", p - a, ab) / np.einsum("ij,ij->i", ab, ab), 0.0, 1.0)
    return np.min(np.linalg.norm(p - (a + u[:, None] * ab), axis=1))


class PointcloudSkeleton(unittest.TestCase):
    def test_synthetic_worm_midline_within_one_percent(self):
        points, midline = sdfkit.synthetic_worm(length=150.0, points=2500, seed=3)
        self.assertEqual(points.shape, (2500, 3))
        r = sdfkit.pointcloud_skeleton(points, segments=10, nodes=25, backend="opencl")
        self.assertEqual(r["nodes"].shape, (11, 3))
        self.assertEqual(r["subdivided"]["nodes"].shape, (25, 3))
        self.assertTrue(r["exact"])
        self.assertEqual(r["normals"].shape, (2500, 3))
        self.assertEqual(r["sdf"].shape, (2500,))
        mean = np.mean([distance_to_polyline(p, midline) for p in r["nodes"]])
        self.assertLess(mean, 0.01 * 150.0)
        self.assertTrue(np.all(r["radius"] > 0))
        self.assertEqual(set(r["milliseconds"]), {"neighbours", "normals", "orientation", "surface", "sdf", "shift",
                                                  "clustering", "polyline"})

    def test_bad_input_is_a_value_error(self):
        with self.assertRaises(ValueError):
            sdfkit.pointcloud_skeleton(np.zeros((4, 3)), backend="opencl")
        with self.assertRaises(ValueError):
            sdfkit.pointcloud_skeleton(np.zeros((100, 2)), backend="opencl")
        points, _ = sdfkit.synthetic_worm(points=500)
        with self.assertRaises(ValueError):
            sdfkit.pointcloud_skeleton(points, linkage="complete", backend="opencl")


class PointcloudCompression(unittest.TestCase):
    def test_animated_worm_round_trip(self):
        # A worm whose wave travels: 12 frames of the same particles (same seed, moving phase).
        frames = np.stack([sdfkit.synthetic_worm(points=1200, phase=0.15 * f, noise=0.0, seed=5)[0]
                           for f in range(12)])
        with tempfile.TemporaryDirectory() as d:
            out = os.path.join(d, "w.glb")
            rep = sdfkit.compress_animation(frames, out, bones=8, frame_time=0.05, backend="opencl")
            self.assertEqual(rep["frames"], 12)
            self.assertEqual(rep["compressed_bytes"], os.path.getsize(out))
            self.assertEqual(rep["raw_bytes"], frames.size * 4)
            played = sdfkit.play_skinned_glb(out)
            self.assertEqual(played.shape, frames.shape)
            rmse = np.sqrt(np.mean(np.sum((played - frames) ** 2, axis=2)))
            self.assertAlmostEqual(rmse, rep["rmse"], delta=1e-4 * max(1.0, rep["rmse"]))
            self.assertLess(rep["rmse_percent_of_length"], 2.0)
            with self.assertRaises(ValueError):
                sdfkit.compress_animation(frames, out, bones=2, frame_time=0.05, backend="opencl")


if __name__ == "__main__":
    unittest.main()
