"""The Python module `impactdeck` against the CLI and closed forms (run by ctest with Debian's
python3 and PYTHONPATH=build/python):  test_python.py IMPACTDECK_EXE SOURCE_DIR"""
import json
import math
import os
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import impactdeck

EXE, SRC = sys.argv[1], sys.argv[2]
del sys.argv[1:3]


def cli(*args, cwd=None):
    p = subprocess.run([EXE, *args], capture_output=True, text=True, cwd=cwd)
    return p.returncode, p.stdout, p.stderr


def without_times(doc):
    """Drops wall times (they differ between two runs) and nothing else."""
    if isinstance(doc, dict):
        return {k: without_times(v) for k, v in doc.items() if k != "stage_times_s"}
    if isinstance(doc, list):
        return [without_times(v) for v in doc]
    return doc


class Contract(unittest.TestCase):
    def test_run_returns_the_document_of_run_json(self):
        scene = os.path.join(SRC, "samples", "two_spheres.toml")
        with tempfile.TemporaryDirectory() as out:
            rc, stdout, _ = cli("run", scene, "--out", out, "--json")
            self.assertEqual(rc, 0)
            from_cli = json.loads(stdout)
            from_py = impactdeck.run(scene, out=out)
        self.assertIsInstance(from_py, dict)
        self.assertEqual(without_times(from_py), without_times(from_cli))
        self.assertEqual(set(from_py["stage_times_s"]), set(from_cli["stage_times_s"]))

    def test_run_out_defaults_to_the_current_folder(self):
        scene = os.path.join(SRC, "samples", "two_spheres.toml")
        with tempfile.TemporaryDirectory() as out:
            here = os.getcwd()
            os.chdir(out)
            try:
                doc = impactdeck.run(scene)
            finally:
                os.chdir(here)
            self.assertTrue(os.path.exists(os.path.join(out, "force_two_spheres.csv")))
        self.assertGreater(doc["impacts"][0]["max_force_N"], 0)

    def test_inspect_returns_the_document_of_inspect_json(self):
        for part, unit, at in [(os.path.join(SRC, "tests", "data", "cube.off"), "m", ["0.5,0.2,1.5", "1,1,1"]),
                               (os.path.join(SRC, "tests", "data", "cad", "screw.step"), "mm", ["-8,0.4,5.4"])]:
            args = ["inspect", part, "--length-unit", unit, "--density-kg-m3", "7850", "--json"]
            for a in at:
                args += ["--at", a]
            rc, stdout, _ = cli(*args)
            self.assertEqual(rc, 0, part)
            from_py = impactdeck.inspect(part, unit, density_kg_m3=7850, at=at)
            self.assertEqual(without_times(from_py), without_times(json.loads(stdout)), part)
        # Points as numbers give the same surface queries.
        doc = impactdeck.inspect(os.path.join(SRC, "tests", "data", "cube.off"), "m", at=[(0.5, 0.2, 1.5)])
        self.assertEqual(doc["points"][0]["surface_point_m"], [0.5, 0.2, 1.0])
        self.assertIsNone(doc["mass_kg"])


class Errors(unittest.TestCase):
    def test_messages_and_classes_are_the_clis(self):
        missing = os.path.join(SRC, "tests", "data", "no_such_part.stl")
        rc, _, stderr = cli("inspect", missing, "--length-unit", "mm")
        self.assertEqual(rc, 3)
        with self.assertRaises(impactdeck.InputError) as e:
            impactdeck.inspect(missing, "mm")
        self.assertEqual("impactdeck: error: " + str(e.exception), stderr.strip())
        self.assertEqual(e.exception.exit_code, 3)
        self.assertIsInstance(e.exception, impactdeck.Error)
        step = os.path.join(SRC, "tests", "data", "cad", "screw.step")
        rc, _, stderr = cli("inspect", step, "--length-unit", "in")
        with self.assertRaises(impactdeck.InputError) as e:
            impactdeck.inspect(step, "in")
        self.assertEqual("impactdeck: error: " + str(e.exception), stderr.strip())
        with self.assertRaises(impactdeck.UsageError) as e:
            impactdeck.inspect(step, "furlong")
        self.assertEqual(e.exception.exit_code, 2)
        bad_scene = os.path.join(SRC, "tests", "data", "bad", "scenes", "unknown_key.toml")
        rc, _, stderr = cli("run", bad_scene, "--out", tempfile.gettempdir())
        with self.assertRaises(impactdeck.InputError) as e:
            impactdeck.run(bad_scene, out=tempfile.gettempdir())
        self.assertEqual("impactdeck: error: " + str(e.exception), stderr.strip())
        self.assertEqual(impactdeck.CheckFailed.exit_code, 4)


class Impact(unittest.TestCase):
    def test_head_on_spheres_match_the_closed_form(self):
        r, rho, v, E, nu = 0.05, 7850.0, 1.0, 2.05e11, 0.3
        m = rho * 4 / 3 * math.pi * r ** 3
        I = [0.4 * m * r * r] * 3
        Estar = 1 / (2 * (1 - nu * nu) / E)
        res = impactdeck.solve_impact(mass1_kg=m, mass2_kg=m, inertia1_kg_m2=I, inertia2_kg_m2=I,
                                      lever_arm1_m=[r, 0, 0], lever_arm2_m=[-r, 0, 0], normal=[1, 0, 0],
                                      velocity1_m_s=[0, 0, 0], velocity2_m_s=[-v, 0, 0], radius_m=r / 2,
                                      effective_modulus_Pa=Estar, restitution=1.0)
        kH = 4 / 3 * Estar * math.sqrt(r / 2)
        xmax = (5 * (m / 2) * v * v / (4 * kH)) ** 0.4
        self.assertAlmostEqual(res["max_force_N"] / (kH * xmax ** 1.5), 1.0, delta=1e-9)
        self.assertAlmostEqual(res["impulse_Ns"] / (2 * (m / 2) * v), 1.0, delta=1e-9)
        self.assertTrue(res["checks"]["passed"])
        self.assertEqual(res["force_N"].shape, (201,))
        self.assertAlmostEqual(res["force_N"].max() / res["max_force_N"], 1.0, delta=1e-3)
        # Curvatures instead of R*: two spheres of radius r give R* = r/2.
        res2 = impactdeck.solve_impact(mass1_kg=m, mass2_kg=m, inertia1_kg_m2=I, inertia2_kg_m2=I,
                                       lever_arm1_m=[r, 0, 0], lever_arm2_m=[-r, 0, 0], normal=[1, 0, 0],
                                       velocity1_m_s=[0, 0, 0], velocity2_m_s=[-v, 0, 0],
                                       curvatures1_per_m=(1 / r, 1 / r), curvatures2_per_m=(1 / r, 1 / r),
                                       effective_modulus_Pa=Estar)
        self.assertAlmostEqual(res2["effective_radius_m"] / (r / 2), 1.0, delta=1e-12)

    def test_plain_numbers_reproduce_an_eccentric_scene(self):
        # The paper's Table 2 case (samples/paper_table2.toml) from its plain numbers: a steel ball
        # r = 50 mm at 400 m/s on the ellipsoid 2000/500/500 mm at (0, 500, 0); E* and R* as the
        # scene's document states them (paper convention, Eq. 26), restitution from Eq. 30.
        scene = os.path.join(SRC, "samples", "paper_table2.toml")
        with tempfile.TemporaryDirectory() as out:
            imp = impactdeck.run(scene, out=out)["impacts"][0]
        rho, a, b, c, r = 7850.0, 2.0, 0.5, 0.5, 0.05
        m1 = rho * 4 / 3 * math.pi * a * b * c
        I1 = [m1 / 5 * (b * b + c * c), m1 / 5 * (a * a + c * c), m1 / 5 * (a * a + b * b)]
        m2 = rho * 4 / 3 * math.pi * r ** 3
        I2 = [0.4 * m2 * r * r] * 3
        res = impactdeck.solve_impact(mass1_kg=m1, mass2_kg=m2, inertia1_kg_m2=I1, inertia2_kg_m2=I2,
                                      lever_arm1_m=[0, 0.5, 0], lever_arm2_m=[0, -r, 0], normal=[0, 1, 0],
                                      velocity1_m_s=[0, 0, 0], velocity2_m_s=[0, -400, 0],
                                      radius_m=imp["effective_radius_m"],
                                      effective_modulus_Pa=imp["effective_modulus_Pa"], restitution="energy-flux")
        for key in ("reduced_mass_kg", "max_force_N", "compression_time_s", "contact_time_s"):
            self.assertAlmostEqual(res[key] / imp[key], 1.0, delta=1e-12, msg=key)
        self.assertAlmostEqual(res["impulse_Ns"] / imp["impulse_total_Ns"], 1.0, delta=1e-12)
        self.assertAlmostEqual(res["restitution"], imp["restitution"], delta=1e-15)


class Parts(unittest.TestCase):
    def test_mesh_and_cad_parts(self):
        cube = impactdeck.load_part(os.path.join(SRC, "tests", "data", "cube.off"), "m")
        self.assertAlmostEqual(cube.volume_m3, 8.0, delta=1e-12)
        np.testing.assert_allclose(cube.inertia_per_density_m5, np.eye(3) * 8 * (4 + 4) / 12, rtol=1e-12, atol=1e-12)
        c = cube.curvature([0.3, 0.1, 2.0])
        self.assertEqual(c["principal_curvatures_1_per_m"], (0.0, 0.0))
        screw = impactdeck.load_part(os.path.join(SRC, "tests", "data", "cad", "screw.step"), "mm")
        self.assertEqual(screw.kind, "cad")
        # OpenCASCADE's adaptive integration of the B-rep (its error estimate: 8.5e-13 relative);
        # the fixed-order Gauss result used before was 9.0e-7 low.
        self.assertAlmostEqual(screw.volume_m3 / 3.7882740173731014e-06, 1.0, delta=1e-9)
        pts, normals = screw.sample_surface(20, seed=3)
        self.assertEqual(pts.shape, (20, 3))
        np.testing.assert_allclose(np.linalg.norm(normals, axis=1), 1.0, rtol=1e-12)

    def test_sweep_arrays(self):
        scene = os.path.join(SRC, "samples", "fig4_sweep.toml")
        r = impactdeck.sweep(scene, cloud="uniform", count=200, seed=2, threads=2)
        f = r["max_force_N"]
        self.assertEqual(f.shape, (200,))
        self.assertEqual(r["point_m"].shape, (200, 3))
        ok = ~r["sharp_feature"]
        self.assertAlmostEqual(r["force_ratio"], f[ok].min() / f[ok].max(), delta=1e-15)
        self.assertEqual(f[r["max_index"]], f[ok].max())
        # Same numbers as the CLI's sweep CSV.
        with tempfile.TemporaryDirectory() as out:
            rc, stdout, _ = cli("sweep", scene, "--cloud", "uniform", "--count", "200", "--seed", "2", "--out", out,
                                "--json", "--quiet", "--no-png")
            self.assertEqual(rc, 0)
            self.assertAlmostEqual(json.loads(stdout)["force_ratio"], r["force_ratio"], delta=1e-15)

    def test_closest_point_far_away_is_finite_or_refused(self):
        cube = impactdeck.load_part(os.path.join(SRC, "tests", "data", "cube.off"), "m")
        # 1e15 m away: the exact distance (to rounding), not Inf.
        s = cube.closest_point([1e15, 0.0, 0.0])
        self.assertTrue(math.isfinite(s["distance_m"]))
        self.assertAlmostEqual(s["distance_m"] / (1e15 - 1.0), 1.0, delta=1e-12)
        # Beyond the coordinates a part may have (1e20 m): a clear error naming the point, not Inf.
        for q in ([1e160, 0.0, 0.0], [0.0, -1e300, 0.0]):
            with self.assertRaises(impactdeck.InputError) as e:
                cube.closest_point(q)
            self.assertIn("farther than 1e20 m", str(e.exception))


class Threads(unittest.TestCase):
    # Two threads making their first numpy-returning call at the same time deadlocked the
    # interpreter (issue 29: 6 of 6 tries). Each try is a fresh interpreter (the first call is what
    # matters), bounded by a timeout so that a regression fails instead of hanging the suite.
    SCRIPT = r"""
import sys, threading
import impactdeck
part = impactdeck.load_part(sys.argv[1], "m")
start = threading.Barrier(4)
results = []
def work():
    start.wait()
    results.append(part.closest_point([0.3, 0.1, 2.0])["point_m"].shape)
    results.append(part.center_of_mass_m.shape)
threads = [threading.Thread(target=work) for _ in range(4)]
for t in threads: t.start()
for t in threads: t.join()
print(len(results), results[0])
"""

    def test_first_numpy_calls_from_threads_at_once(self):
        cube = os.path.join(SRC, "tests", "data", "cube.off")
        for attempt in range(6):
            try:
                p = subprocess.run([sys.executable, "-c", self.SCRIPT, cube], capture_output=True, text=True,
                                   timeout=60, env=os.environ)
            except subprocess.TimeoutExpired:
                self.fail(f"try {attempt + 1}: the threads' first numpy calls deadlocked (no exit within 60 s)")
            self.assertEqual(p.returncode, 0, p.stderr)
            self.assertEqual(p.stdout.strip(), "8 (3,)")


if __name__ == "__main__":
    unittest.main(verbosity=2)
