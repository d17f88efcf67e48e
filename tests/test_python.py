"""The Python module `impactdeck` against the CLI and closed forms (run by ctest with Debian's
python3 and PYTHONPATH=build/python):  test_python.py IMPACTDECK_EXE SOURCE_DIR"""
import ast
import json
import math
import os
import pathlib
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


class Overrides(unittest.TestCase):
    """`overrides` are `--set KEY=VALUE`: the same document, and the same errors naming the override."""

    def test_run_with_overrides_is_run_with_set(self):
        scene = os.path.join(SRC, "samples", "two_spheres.toml")
        with tempfile.TemporaryDirectory() as out:
            rc, stdout, _ = cli("run", scene, "--out", out, "--json", "--set", "impacts[0].restitution=0.5",
                                "--set", "bodies[0].velocity_m_s=[1.5, 0, 0]", "--set", 'impacts[0].contact_radius="mean"')
            self.assertEqual(rc, 0)
            from_py = impactdeck.run(pathlib.Path(scene), out=pathlib.Path(out),
                                     overrides={"impacts[0].restitution": np.float32(0.5),
                                                "bodies[0].velocity_m_s": np.array([1.5, 0, 0]),
                                                "impacts[0].contact_radius": "mean"})
        self.assertEqual(without_times(from_py), without_times(json.loads(stdout)))
        self.assertEqual(from_py["impacts"][0]["restitution"], 0.5)

    def test_bad_overrides_fail_as_on_the_command_line(self):
        scene = os.path.join(SRC, "samples", "two_spheres.toml")
        for key, value, text in [("impacts[0].restitution", 2, "2"),          # out of range: validation
                                 ("impacts[7].restitution", 0.5, "0.5"),      # no such impact
                                 ("impacts[0].restitutio", 0.5, "0.5"),       # unknown key
                                 ("bodies[0].velocity_m_s", "fast", '"fast"'),  # wrong type
                                 ("impacts[0.restitution", 0.5, "0.5")]:      # malformed key
            with tempfile.TemporaryDirectory() as out:
                rc, _, stderr = cli("run", scene, "--out", out, "--set", f"{key}={text}")
                self.assertEqual(rc, 3, key)
                with self.assertRaises(impactdeck.InputError, msg=key) as e:
                    impactdeck.run(scene, out=out, overrides={key: value})
                self.assertEqual("impactdeck: error: " + str(e.exception), stderr.strip())
                self.assertIn(key.split("[")[0], str(e.exception))
                self.assertEqual(os.listdir(out), [], key)
        with self.assertRaises(impactdeck.UsageError) as e:
            impactdeck.run(scene, overrides={"impacts[0].restitution": object()})
        self.assertIn("impacts[0].restitution", str(e.exception))
        with self.assertRaises(impactdeck.UsageError):
            impactdeck.run(scene, overrides=["impacts[0].restitution=0.5"])

    def test_overrides_are_validated_and_never_crash(self):
        # Issue 43: a key with '=' was split (its value silently replaced), a lone surrogate raised an
        # undocumented RuntimeError, and a list nested 20 000 deep killed the interpreter (SIGSEGV).
        # In a child interpreter, so that a crash is a failure here, not the end of the suite.
        code = '''
import sys
sys.path.insert(0, sys.argv[1])
import impactdeck
scene = sys.argv[2]
deep = 0.5
for _ in range(20000):
    deep = [deep]
cycle = []
cycle.append(cycle)
cases = [({"impacts[0].restitution=0.5": 0.9}, ValueError, "holds '='"),
         ({"impacts[0].restitution": deep}, ValueError, "nested deeper than 64 levels"),
         ({"impacts[0].restitution": cycle}, ValueError, "nested deeper than 64 levels"),
         ({"impacts[0].restitution": {"a": deep}}, ValueError, "nested deeper than 64 levels"),
         ({"impacts[0].na\\udc80me": 1}, ValueError, "lone surrogate"),
         ({"impacts[0].name": "x\\ud800"}, ValueError, "lone surrogate"),
         ({"impacts[0].name": {"k\\udfff": 1}}, ValueError, "lone surrogate")]
for overrides, kind, text in cases:
    key = next(iter(overrides))
    try:
        impactdeck.run(scene, overrides=overrides)
        print("no error for", ascii(key)); sys.exit(1)
    except kind as e:
        if text not in str(e) or ascii(key)[1:-1].split("=")[0][:10] not in str(e):
            print("message", ascii(str(e))); sys.exit(1)
print("ok")
'''
        scene = os.path.join(SRC, "samples", "two_spheres.toml")
        p = subprocess.run([sys.executable, "-c", code, os.path.dirname(impactdeck.__file__), scene],
                           stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, timeout=120)
        self.assertEqual((p.returncode, p.stdout.strip()), (0, "ok"), p.stderr[-2000:])

    def test_sweep_takes_overrides(self):
        scene = os.path.join(SRC, "samples", "fig4_sweep.toml")
        a = impactdeck.sweep(scene, cloud="uniform", count=50, seed=2)
        b = impactdeck.sweep(pathlib.Path(scene), cloud="uniform", count=50, seed=2,
                             overrides={"impacts[0].approach_speed_m_s": 2.0})
        self.assertFalse(np.array_equal(a["max_force_N"], b["max_force_N"]))


class PathLike(unittest.TestCase):
    def test_every_path_argument_takes_a_path(self):
        cube = pathlib.Path(SRC) / "tests" / "data" / "cube.off"
        part = impactdeck.load_part(cube, "m")
        self.assertEqual(part.file, str(cube))
        self.assertEqual(impactdeck.inspect(cube, "m")["volume_m3"], impactdeck.inspect(str(cube), "m")["volume_m3"])
        with self.assertRaises(impactdeck.InputError):
            impactdeck.fem_check(pathlib.Path(SRC) / "no_such_deck")
        with self.assertRaises(impactdeck.InputError):
            impactdeck.campaign_collect(pathlib.Path(SRC) / "no_such_campaign")


class FemCheck(unittest.TestCase):
    def test_fem_check_is_fem_check_json(self):
        # The paper's coarse FEM sample with its deck written but not run (overrides of a str and
        # a bool), then checked from Python: ccx runs (seconds), the results are published in the
        # deck folder, and `fem-check --no-run --json` reads the same numbers back from them.
        scene = os.path.join(SRC, "samples", "paper_table2_fem.toml")
        with tempfile.TemporaryDirectory() as out:
            doc = impactdeck.run(scene, out=out, overrides={"outputs.fem.run": "none", "outputs.fem.code_aster": False})
            deck = pathlib.Path(out) / "fem_table2"
            self.assertFalse((deck / "impact.dat").exists())
            self.assertNotIn("fem_run", doc["stages_run"])
            r = impactdeck.fem_check(deck, threads=1)
            self.assertTrue(r["passed"])
            self.assertTrue((deck / "impact.dat").exists())
            rc, stdout, _ = cli("fem-check", str(deck), "--no-run", "--json")
            self.assertEqual(rc, 0)
            c = json.loads(stdout)
            for key in ("fe_mass_kg", "solver_mass_kg", "impulse_Ns", "linear_momentum_relative_error", "passed"):
                self.assertEqual(r[key], c[key], key)
            again = impactdeck.fem_check(deck, run=False)
            self.assertEqual(again["linear_momentum_relative_error"], r["linear_momentum_relative_error"])
            # A tolerance the run cannot meet: CheckFailed with the document, the folder unchanged.
            before = sorted(os.listdir(deck))
            with self.assertRaises(impactdeck.CheckFailed) as e:
                impactdeck.fem_check(deck, run=False, linear_tolerance=1e-300)
            self.assertFalse(e.exception.document["passed"])
            self.assertIn("FEM check failed", str(e.exception))
            self.assertEqual(sorted(os.listdir(deck)), before)


class CompareContact(unittest.TestCase):
    def test_refusals_are_the_commands(self):
        # The full comparison takes minutes of ccx (tests/test_compare_contact.cpp runs it); here
        # the binding's refusals, which must be the command's: an unknown impact.
        scene = os.path.join(SRC, "samples", "two_spheres.toml")
        with tempfile.TemporaryDirectory() as out:
            rc, _, stderr = cli("compare-contact", scene, "--impact", "nope", "--out", out)
            self.assertEqual(rc, 3)
            with self.assertRaises(impactdeck.InputError) as e:
                impactdeck.compare_contact(pathlib.Path(scene), out=out, impact="nope")
            self.assertEqual("impactdeck: error: " + str(e.exception), stderr.strip())
            self.assertEqual(os.listdir(out), [])
        with self.assertRaises(impactdeck.UsageError):
            impactdeck.compare_contact(scene, threshold=-1)


class Campaign(unittest.TestCase):
    TARGET = ('length_unit = "mm"\n[materials.steel]\nyoungs_modulus_Pa = 2.05e11\npoisson_ratio = 0.3\n'
              'density_kg_m3 = 7850\nyield_strength_Pa = 3.5e8\n[[bodies]]\nname = "t"\nshape = "ellipsoid"\n'
              'semi_axes = [200, 50, 50]\nmaterial = "steel"\n[[bodies]]\nname = "b"\nshape = "sphere"\nradius = 10\n'
              'material = "steel"\n[[impacts]]\ntarget = "t"\nimpactor = "b"\npoint = [200, 0, 0]\n'
              'approach_speed_m_s = 1\nrestitution = 0.5\n')
    POINTS = 'scene = "target.toml"\n[points]\ncount = 6\n'

    def test_plan_run_collect_as_the_commands(self):
        with tempfile.TemporaryDirectory() as tmp:
            t = pathlib.Path(tmp)
            (t / "target.toml").write_text(self.TARGET)
            (t / "points.toml").write_text(self.POINTS)
            for args in (["plan", "points.toml", "--out", "cli"], ["run", "cli", "--quiet"], ["collect", "cli"]):
                rc, _, stderr = cli("campaign", *args, cwd=tmp)
                self.assertEqual(rc, 0, stderr)
            plan = impactdeck.campaign_plan(t / "points.toml", t / "py")
            self.assertEqual(plan["cases"], 6)
            self.assertFalse(plan["already_planned"])
            self.assertTrue(impactdeck.campaign_plan(t / "points.toml", t / "py")["already_planned"])
            run = impactdeck.campaign_run(t / "py", jobs=2, executable=pathlib.Path(EXE))
            self.assertEqual((run["total"], run["done"], run["failed"], run["exit_code"]), (6, 6, 0, 0))
            self.assertEqual(impactdeck.campaign_run(t / "py", executable=EXE)["skipped"], 6)
            col = impactdeck.campaign_collect(t / "py")
            self.assertEqual((col["done"], col["failed"], col["pending"]), (6, 0, 0))
            self.assertTrue(os.path.exists(col["report_html"]) and os.path.exists(col["map_svg"]))
            # The same table as the command's, but for the folder names in it.
            ours = (t / "py" / "collect" / "cases.csv").read_text().replace(str(t / "py"), "DIR")
            theirs = (t / "cli" / "collect" / "cases.csv").read_text().replace(str(t / "cli"), "DIR")
            self.assertEqual(ours, theirs)

    def test_failed_cases_raise_with_the_summary(self):
        with tempfile.TemporaryDirectory() as tmp:
            t = pathlib.Path(tmp)
            (t / "target.toml").write_text(self.TARGET)
            # Case 1 of 2 loses its scene file after the plan (as tests/campaign_test.sh does).
            (t / "c.toml").write_text('scene = "target.toml"\n[product]\n"impacts[0].restitution" = [0.5, 0.7]\n')
            impactdeck.campaign_plan(t / "c.toml", t / "c")
            (t / "c" / "cases" / "1" / "scene.toml").unlink()
            with self.assertRaises(impactdeck.InputError) as e:
                impactdeck.campaign_run(t / "c", executable=EXE)
            self.assertEqual(e.exception.document["failed_ids"], [1])
            self.assertEqual(e.exception.document["exit_code"], 3)


class Documentation(unittest.TestCase):
    """Docstrings and reprs on everything public, and the type stubs (python/impactdeck.pyi) naming
    exactly the module's public names."""

    def public(self, obj):
        return {n for n in dir(obj) if not n.startswith("_")}

    def test_docstrings_and_reprs(self):
        for name in self.public(impactdeck):
            obj = getattr(impactdeck, name)
            if callable(obj):
                self.assertTrue((obj.__doc__ or "").strip(), name)
        for name in self.public(impactdeck.Part):
            self.assertTrue((getattr(impactdeck.Part, name).__doc__ or "").strip(), "Part." + name)
        part = impactdeck.load_part(os.path.join(SRC, "tests", "data", "cube.off"), "m")
        self.assertRegex(repr(part), r"^<impactdeck.Part '.*cube.off' off \(mesh\), volume 8 m\^3, size [0-9.]+ m>$")

    def test_stubs_name_every_public_name(self):
        stub = os.environ.get("IMPACTDECK_STUB") or os.path.join(os.path.dirname(impactdeck.__file__), "impactdeck.pyi")
        tree = ast.parse(pathlib.Path(stub).read_text())
        names, part = set(), set()
        for node in tree.body:
            if isinstance(node, (ast.FunctionDef, ast.ClassDef)):
                names.add(node.name)
            elif isinstance(node, ast.AnnAssign):
                names.add(node.target.id)
            elif isinstance(node, ast.Assign):
                names.update(t.id for t in node.targets)
            if isinstance(node, ast.ClassDef) and node.name == "Part":
                part = {n.name for n in node.body if isinstance(n, ast.FunctionDef)}
        self.assertEqual({n for n in names if not n.startswith("_")} | {"__version__"},
                         self.public(impactdeck) | {"__version__"})
        self.assertEqual({n for n in part if not n.startswith("_")}, self.public(impactdeck.Part))
        # Every function's parameters as in the module's own signature line.
        for node in tree.body:
            if isinstance(node, ast.FunctionDef):
                sig = getattr(impactdeck, node.name).__doc__.splitlines()[0]
                params = [a.arg for a in node.args.args + node.args.kwonlyargs]
                self.assertEqual(params, [p.split(":")[0].strip().lstrip("*") for p in
                                          sig[sig.index("(") + 1:sig.rindex(") ->")].split(", ") if p.strip() != "*"],
                                 node.name)


if __name__ == "__main__":
    unittest.main(verbosity=2)
