"""Tests of the Python module `scallop` (python/scallop_module.cpp), run by ctest as Python.Module.

Every expected value is derived here, independently of the program: closed forms (a flat chain's
tool path is 2 + pi/2 long), exact geometry (a ball over a flat square stands R above it, and
sqrt(R^2 - d^2) at a distance d beyond its edge), invariance under rigid motions and scaling,
and a G-code grammar written here. The plans run on paper-1 with a coarse scallop height
(0.01 in), so the whole file takes some ten seconds. The mesh plans are checked against the
command-line program (SCALLOP_CLI, which ctest sets) byte for byte, on OCCT's own sample parts
(Debian's occt-misc): shape.stl, and screw.step through its tessellation.

    PYTHONPATH=<build>/python python3 -m unittest discover -s python/tests -v
"""

import json
import math
import os
import re
import subprocess
import tempfile
import threading
import time
import unittest
import _thread

import numpy as np

import scallop

# A unit square in z = 0, one bilinear patch (p_jk: row j along v).
FLAT_SQUARE = [[[[0.0, 0.0, 0.0], [0.0, 1.0, 0.0]], [[1.0, 0.0, 0.0], [1.0, 1.0, 0.0]]]]

# A parabolic cylinder z = x^2 over x in [-1, 1], y in [0, 1]: quadratic along u (x),
# linear along v (y). Every normal lies in the xz plane.
PARABOLIC_CYLINDER = [[[[-1.0, 0.0, 1.0], [-1.0, 1.0, 1.0]],
                       [[0.0, 0.0, -1.0], [0.0, 1.0, -1.0]],
                       [[1.0, 0.0, 1.0], [1.0, 1.0, 1.0]]]]

COARSE_H = 0.01  # in: coarse scallop height for quick plans on paper-1 (R = 0.25 in)


def distance_to_chain(points, chain):
    """Distance from each (x, z) point to the polyline `chain`, by brute force."""
    a, b = chain[:-1], chain[1:]
    d = b - a
    length2 = np.maximum((d * d).sum(axis=1), 1e-300)
    p = points[:, None, :]
    t = np.clip(((p - a) * d).sum(axis=2) / length2, 0.0, 1.0)
    nearest = a + t[..., None] * d
    return np.sqrt(((p - nearest) ** 2).sum(axis=2)).min(axis=1)


def drop_height_over_unit_square(points, radius):
    """Centre height of a ball of `radius` dropped onto the unit square [0, 1]^2 in z = 0."""
    dx = np.maximum(0.0, np.maximum(-points[:, 0], points[:, 0] - 1.0))
    dy = np.maximum(0.0, np.maximum(-points[:, 1], points[:, 1] - 1.0))
    d = np.hypot(dx, dy)
    return np.sqrt(np.maximum(radius * radius - d * d, 0.0))


# RS-274 as scallop writes it: a block is words (a letter and a decimal number, no exponent),
# with comments in parentheses; or '%'.
GCODE_WORD = r"[A-Z][-+]?(?:\d+(?:\.\d*)?|\.\d+)"
GCODE_BLOCK = re.compile(r"^\s*(?:" + GCODE_WORD + r"\s*)*$")


def gcode_problems(program):
    """Lines of `program` outside the grammar above, and any number in exponent notation."""
    problems = []
    for number, line in enumerate(program.splitlines(), 1):
        code = re.sub(r"\([^()]*\)", "", line).strip()
        if code == "%" or GCODE_BLOCK.match(code.upper()):
            pass
        else:
            problems.append(f"line {number}: {line!r}")
        if re.search(r"\d[eE][-+]?\d", code):
            problems.append(f"line {number}: exponent: {line!r}")
    return problems


class ModuleTest(unittest.TestCase):
    def test_exception_hierarchy(self):
        self.assertTrue(issubclass(scallop.Error, RuntimeError))
        self.assertTrue(issubclass(scallop.Cancelled, scallop.Error))

    def test_thread_count(self):
        scallop.set_thread_count(1)
        self.assertEqual(scallop.thread_count(), 1)
        scallop.set_thread_count(0)
        self.assertGreaterEqual(scallop.thread_count(), 1)
        with self.assertRaises(TypeError):
            scallop.set_thread_count(-1)


class SurfaceTest(unittest.TestCase):
    def test_examples(self):
        names = scallop.example_surface_names()
        for name in ("paper-1", "paper-2", "teapot"):
            self.assertIn(name, names)
        paper = scallop.example_surface("paper-1")
        self.assertEqual(paper.units, "in")
        self.assertEqual(len(paper), paper.patch_count)
        self.assertEqual(paper.degrees(0), (3, 3))
        self.assertEqual(paper.control_points(0).shape, (4, 4, 3))
        self.assertIsNone(paper.weights(0))
        self.assertEqual(scallop.example_surface("teapot").patch_count, 32)

    def test_round_trip_through_numpy_and_a_file(self):
        teapot = scallop.example_surface("teapot-body")
        control = np.stack([teapot.control_points(i) for i in range(teapot.patch_count)])
        copy = scallop.Surface(control, units="inch")
        self.assertEqual(copy.to_json(), teapot.to_json())
        with tempfile.TemporaryDirectory() as folder:
            path = os.path.join(folder, "body.json")
            with open(path, "w") as file:
                file.write(copy.to_json())
            loaded = scallop.load_surface(path)
        self.assertEqual(loaded.patch_count, teapot.patch_count)
        for i in range(loaded.patch_count):
            np.testing.assert_array_equal(loaded.control_points(i), control[i])

    def test_patches_of_different_degrees_and_weights(self):
        bicubic = scallop.example_surface("paper-1").control_points(0)
        # A quarter of a unit cylinder, exact: the rational quadratic arc (1, 0), (1, 1), (0, 1)
        # with weights 1, sqrt(2)/2, 1, swept along y.
        arc = np.array([[1.0, 0.0], [1.0, 1.0], [0.0, 1.0]])
        cylinder = np.array([[[x, y, z] for y in (0.0, 2.0)] for x, z in arc])
        w = math.sqrt(0.5)
        weights = [np.ones((4, 4)), np.array([[1.0, 1.0], [w, w], [1.0, 1.0]])]
        surface = scallop.Surface([bicubic, cylinder], units="mm", weights=weights)
        self.assertEqual(surface.units, "mm")
        self.assertEqual([surface.degrees(i) for i in range(2)], [(3, 3), (2, 1)])
        np.testing.assert_array_equal(surface.weights(1), weights[1])
        np.testing.assert_array_equal(surface.control_points(1), cylinder)

    def test_bad_input_is_refused_with_its_name(self):
        control = scallop.example_surface("paper-1").control_points(0)
        with self.assertRaisesRegex(ValueError, r"shape \(patches, m \+ 1, n \+ 1, 3\).*\(4, 4, 3\)"):
            scallop.Surface(control)  # one patch without its patch axis
        with self.assertRaisesRegex(ValueError, "shape"):
            scallop.Surface(control[None, :, :, :2])
        nan = control.copy()
        nan[1, 2, 0] = float("nan")
        with self.assertRaisesRegex(scallop.Error, r"patches\[0\]\.control_points\[1\]\[2\].*finite"):
            scallop.Surface(nan[None])
        with self.assertRaisesRegex(ValueError, "units"):
            scallop.Surface(control[None], units="ft")
        with self.assertRaisesRegex(ValueError, "weights"):
            scallop.Surface(control[None], weights=np.ones((1, 4, 3)))
        with self.assertRaisesRegex(scallop.Error, "weight"):
            scallop.Surface(control[None], weights=-np.ones((1, 4, 4)))
        with self.assertRaisesRegex(scallop.Error, "no patches"):
            scallop.Surface(np.zeros((0, 4, 4, 3)))
        with self.assertRaisesRegex(scallop.Error, "degenerate"):
            scallop.Surface(np.zeros((1, 4, 4, 3)))
        with self.assertRaises(TypeError):
            scallop.Surface("not an array")
        with self.assertRaises(IndexError):
            scallop.example_surface("paper-1").control_points(1)
        with self.assertRaisesRegex(scallop.Error, "paper-1"):
            scallop.example_surface("no-such-surface")
        with self.assertRaisesRegex(scallop.Error, "no-such-file"):
            scallop.load_surface("/no-such-file.json")


class HullTest(unittest.TestCase):
    def test_flat_chain(self):
        # A ball of radius 0.5 over [0, 2]: a quarter arc around (0, 0), the line z = 0.5,
        # a quarter arc around (2, 0): 2 + pi/2 long.
        hull = scallop.hull(np.array([[0.0, 0.0], [2.0, 0.0]]), 0.5)
        self.assertAlmostEqual(hull.length, 2.0 + math.pi / 2.0, delta=1e-12)
        np.testing.assert_array_equal(hull.is_arc, [True, False, True])
        path = hull.toolpath
        np.testing.assert_allclose(path[0, :2], [-0.5, 0.0])
        np.testing.assert_allclose(path[-1, 2:4], [2.5, 0.0])
        np.testing.assert_allclose(path[0, 4:6], [0.0, 0.0])
        np.testing.assert_allclose(path[2, 4:6], [2.0, 0.0])
        self.assertTrue(np.isnan(path[1, 4:6]).all())
        self.assertEqual(hull.height_at(1.0), 0.5)
        np.testing.assert_array_equal(hull.height_at(np.array([1.0, 2.0, 3.0])), [0.5, 0.5, -math.inf])
        self.assertEqual(json.loads(hull.to_json())["toolpath_length"], hull.length)

    def test_path_stays_at_the_radius_from_the_chain(self):
        chain = scallop.example_chain("sine")
        r = 0.5  # below the least radius of curvature (1): the path follows the whole wave
        hull = scallop.hull(chain, r)
        path = hull.toolpath
        # Contiguous, bit for bit, and x never decreasing.
        np.testing.assert_array_equal(path[1:, :2], path[:-1, 2:4])
        self.assertTrue((path[:, 2] >= path[:, 0]).all())
        ends = np.vstack([path[:, :2], path[-1:, 2:4]])
        tau = 1e-12 * max(r, np.abs(chain).max())
        np.testing.assert_allclose(distance_to_chain(ends, chain), r, atol=10 * tau)
        # The polyline circumscribes the arcs: never closer to the material than r.
        polyline = hull.polyline(1e-4)
        self.assertGreaterEqual(distance_to_chain(polyline, chain).min(), r - 10 * tau)
        self.assertLessEqual(distance_to_chain(polyline, chain).max(), r + 1e-4 + 10 * tau)
        # Links lie on chain edges; lids (the sampled wave's concave corners) on none.
        np.testing.assert_array_equal(hull.edges >= 0, ~hull.is_lid)

    def test_translation_moves_the_path(self):
        chain = scallop.example_chain("figure2")
        shift = np.array([3.0, -1.0])
        a, b = scallop.hull(chain, 1.0), scallop.hull(chain + shift, 1.0)
        self.assertEqual(len(a.toolpath), len(b.toolpath))
        self.assertGreater(a.is_lid.sum(), 0)  # the pits are bridged by lids
        np.testing.assert_allclose(b.toolpath[:, :4], a.toolpath[:, :4] + np.tile(shift, 2), atol=1e-9)
        self.assertAlmostEqual(a.length, b.length, delta=1e-9)

    def test_stats_count_the_exact_steps(self):
        # A walk without vertical edges: the filtered pass decides every edge. A vertical edge
        # goes to the exact pass; the counters stay linear.
        walk = [[0.0, 0.0], [1.0, 2.0], [2.0, 0.5], [3.0, 3.0], [4.0, 1.0]]
        plain = scallop.hull(walk, 0.5).stats
        self.assertEqual(plain["exact_steps"], 0)
        self.assertEqual(plain["pushes"], len(walk) - 1)
        wall = scallop.hull([[0.0, 0.0], [1.0, 2.0], [1.0, -1.0], [3.0, 3.0], [4.0, 1.0]], 0.5).stats
        self.assertGreaterEqual(wall["exact_steps"], 1)
        self.assertLessEqual(wall["pushes"], 4)
        self.assertLessEqual(wall["pops"], wall["pushes"])

    def test_infinite_radius_is_the_upper_convex_hull(self):
        hull = scallop.hull([[0.0, 0.0], [1.0, -1.0], [2.0, 0.0]], math.inf)
        self.assertEqual(len(hull.toolpath), 0)
        np.testing.assert_array_equal(hull.is_lid, [True])
        np.testing.assert_array_equal(hull.elements[0, :4], [0.0, 0.0, 2.0, 0.0])

    def test_bad_input(self):
        with self.assertRaisesRegex(scallop.Error, "radius"):
            scallop.hull([[0.0, 0.0], [2.0, 0.0]], -0.5)
        with self.assertRaisesRegex(scallop.Error, "point 2"):
            scallop.hull([[0.0, 0.0], [2.0, 0.0], [1.0, 0.0]], 0.5)
        with self.assertRaisesRegex(scallop.Error, "finite"):
            scallop.hull([[0.0, 0.0], [float("nan"), 0.0]], 0.5)
        with self.assertRaisesRegex(ValueError, r"\(n, 2\).*\(2, 3\)"):
            scallop.hull([[0.0, 0.0, 0.0], [2.0, 0.0, 0.0]], 0.5)


class OrientTest(unittest.TestCase):
    def test_plane(self):
        # Every normal is +z: any horizontal N is 90 degrees from it.
        o = scallop.orient(scallop.Surface(FLAT_SQUARE))
        self.assertEqual(o.method, "plane")
        self.assertAlmostEqual(o.alpha_deg, 90.0, delta=1e-9)
        self.assertAlmostEqual(np.linalg.norm(o.normal), 1.0, delta=1e-12)
        self.assertAlmostEqual(o.normal[2], 0.0, delta=1e-12)

    def test_cylinder(self):
        # The normals lie in the xz plane: +-y is 90 degrees from all of them, and nothing else.
        o = scallop.orient(scallop.Surface(PARABOLIC_CYLINDER))
        self.assertAlmostEqual(abs(o.normal[1]), 1.0, delta=1e-9)
        self.assertAlmostEqual(o.alpha_deg, 90.0, delta=1e-6)
        self.assertTrue(o.certified)

    def test_rotation_and_scaling_invariance(self):
        paper = scallop.example_surface("paper-1")
        control = paper.control_points(0)
        angle = 0.7
        rz = np.array([[math.cos(angle), -math.sin(angle), 0.0], [math.sin(angle), math.cos(angle), 0.0],
                       [0.0, 0.0, 1.0]])
        base = scallop.orient(paper)
        turned = scallop.orient(scallop.Surface((control @ rz.T)[None]))
        scaled = scallop.orient(scallop.Surface((control * 25.4)[None], units="mm"))
        self.assertTrue(base.certified)
        self.assertGreater(base.alpha_deg, 0.0)
        self.assertLess(base.alpha_deg, 90.0)
        for other in (turned, scaled):
            self.assertAlmostEqual(other.alpha_deg, base.alpha_deg, delta=1e-7)
        # N* is defined up to sign.
        self.assertAlmostEqual(abs(np.dot(turned.normal, rz @ base.normal)), 1.0, delta=1e-9)
        self.assertAlmostEqual(abs(np.dot(scaled.normal, base.normal)), 1.0, delta=1e-9)
        report = json.loads(base.to_json())
        self.assertEqual(report["normal"], list(base.normal))
        self.assertIn("<svg", base.gauss_map_svg())
        self.assertIn("<svg", base.stereographic_svg())


class PathsTest(unittest.TestCase):
    def test_contour_over_a_flat_square(self):
        # Planes x = 0.1 k cut the square z = 0 in lines; a ball of radius R on them stands R
        # above the square, and drops to sqrt(R^2 - d^2) at a distance d beyond its edge.
        radius = 0.1
        paths = scallop.paths(scallop.Surface(FLAT_SQUARE), radius, spacing=0.1, normal=[1.0, 0.0, 0.0])
        self.assertEqual(paths.planes, 11)
        self.assertEqual(paths.strategy, "contour")
        self.assertAlmostEqual(paths.alpha_deg, 90.0, delta=1e-3)
        points = np.vstack(paths.passes)
        k = points[:, 0] / 0.1
        np.testing.assert_allclose(k, np.round(k), atol=1e-9)
        self.assertEqual(sorted(set(np.round(k).astype(int))), list(range(11)))
        np.testing.assert_allclose(points[:, 2], drop_height_over_unit_square(points, radius), atol=1e-9)
        self.assertEqual(paths.gouge_depth, 0.0)
        report = json.loads(paths.report_json)
        self.assertEqual(len(report["passes"]), len(paths.passes))
        self.assertEqual(report["passes"][3]["start"], list(paths.passes[3][0]))
        self.assertEqual(gcode_problems(paths.gcode()), [])
        self.assertEqual(gcode_problems(paths.gcode("grbl")), [])

    def test_raster_arcs(self):
        radius = 0.1
        paths = scallop.paths(scallop.Surface(FLAT_SQUARE), radius, spacing=0.1, strategy="raster", angle_deg=0.0)
        arcs = 0
        for i, (points, flags) in enumerate(zip(paths.passes, paths.arc_flags)):
            moves = paths.pass_moves(i)
            np.testing.assert_array_equal(moves["end"], points[1:])
            np.testing.assert_array_equal(moves["arc"], flags[1:])
            starts = points[:-1][moves["arc"]]
            ends = points[1:][moves["arc"]]
            centres = moves["center"][moves["arc"]]
            arcs += len(centres)
            # Arcs of radius R around the square's edge.
            np.testing.assert_allclose(np.linalg.norm(starts - centres, axis=1), radius, atol=1e-9)
            np.testing.assert_allclose(np.linalg.norm(ends - centres, axis=1), radius, atol=1e-9)
            np.testing.assert_allclose(centres[:, 2], 0.0, atol=1e-12)
            self.assertTrue(np.isnan(moves["center"][~moves["arc"]]).all())
        self.assertGreater(arcs, 0)

    def test_bad_input(self):
        surface = scallop.Surface(FLAT_SQUARE)
        with self.assertRaisesRegex(scallop.Error, "tool radius"):
            scallop.paths(surface, -0.25, spacing=0.1)
        with self.assertRaisesRegex(ValueError, "scallop_height and spacing"):
            scallop.paths(surface, 0.25)
        with self.assertRaisesRegex(ValueError, "normal"):
            scallop.paths(surface, 0.25, spacing=0.1, normal=[1.0, 0.0])
        with self.assertRaisesRegex(ValueError, "normal"):
            scallop.paths(surface, 0.25, spacing=0.1, strategy="raster", normal=[1.0, 0.0, 0.0])
        with self.assertRaisesRegex(scallop.Error, "zigzag"):
            scallop.paths(surface, 0.25, spacing=0.1, strategy="zigzag")


class PlanTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.surface = scallop.example_surface("paper-1")
        cls.progress = []
        cls.plan = scallop.plan(cls.surface, scallop_height=COARSE_H,
                                progress=lambda fraction, stage: cls.progress.append((fraction, stage)))

    def test_progress(self):
        fractions = [fraction for fraction, _ in self.progress]
        self.assertGreater(len(fractions), 2)
        self.assertTrue(all(0.0 <= f <= 1.0 for f in fractions))
        self.assertTrue(all(a <= b for a, b in zip(fractions, fractions[1:])), "progress went back")
        self.assertEqual(fractions[-1], 1.0)
        self.assertTrue(all(isinstance(stage, str) and stage for _, stage in self.progress))

    def test_program(self):
        plan = self.plan
        self.assertEqual(plan.program_name, "toolpath.ngc")
        self.assertEqual(gcode_problems(plan.program), [])
        self.assertIn("G20", plan.program)  # paper-1 is in inches
        self.assertGreater(plan.program.count("\nG1 "), 100)

    def test_figures_and_files(self):
        plan = self.plan
        self.assertEqual(plan.units, "in")
        self.assertEqual(plan.tool_radius, 0.25)
        self.assertEqual(plan.scallop_height, COARSE_H)
        self.assertGreater(plan.planes, 5)
        self.assertLess(plan.max_gouge, 1e-3)
        self.assertLessEqual(plan.max_scallop, COARSE_H * 1.05)
        self.assertTrue(plan.orientation.certified)
        self.assertEqual(plan.stock_heights.shape, plan.design_heights.shape)
        files = plan.files()
        self.assertEqual(list(files)[:2], ["toolpath.ngc", "report.json"])
        self.assertEqual(files["toolpath.ngc"], plan.program)
        report = json.loads(files["report.json"])
        self.assertEqual(report, json.loads(plan.report_json))
        self.assertEqual(report["verification"]["max_gouge"], plan.max_gouge)
        self.assertEqual(len(report["passes"]), len(plan.passes))
        for name in ("verify.svg", "paths.svg", "paths-plan.svg", "gauss-map.svg", "stereographic.svg"):
            self.assertIn("<svg", files[name])

    def test_verify_the_program(self):
        program = self.plan.program
        as_planned = scallop.verify(self.surface, program, 0.25, COARSE_H)
        self.assertLess(as_planned.max_gouge, 1e-3)
        self.assertEqual(json.loads(as_planned.report_json)["tool_radius"], 0.25)
        # The same program on the surface raised by 0.05 in cuts 0.05 in into all of it.
        raised = self.surface.control_points(0)
        raised[..., 2] += 0.05
        gouged = scallop.verify(scallop.Surface(raised[None]), program, 0.25, COARSE_H, resolution=0.05)
        self.assertAlmostEqual(gouged.max_gouge, 0.05, delta=1e-3)
        self.assertGreater(gouged.gouge_points, 0)
        with self.assertRaisesRegex(scallop.Error, "program:1"):
            scallop.verify(self.surface, "G1 X1\n", 0.25)
        with self.assertRaisesRegex(scallop.Error, "tool radius"):
            scallop.verify(self.surface, program, -0.25)

    def test_same_program_on_one_thread(self):
        scallop.set_thread_count(1)
        try:
            again = scallop.plan(self.surface, scallop_height=COARSE_H)
        finally:
            scallop.set_thread_count(0)
        self.assertEqual(again.program, self.plan.program)
        self.assertEqual(again.report_json, self.plan.report_json)

    def test_bad_input(self):
        with self.assertRaisesRegex(scallop.Error, "tool radius"):
            scallop.plan(self.surface, tool_radius=-0.25)
        with self.assertRaisesRegex(scallop.Error, "scallop height"):
            scallop.plan(self.surface, scallop_height=float("nan"))
        with self.assertRaisesRegex(ValueError, "dialect"):
            scallop.plan(self.surface, dialect="fanuc")
        with self.assertRaisesRegex(TypeError, "progress"):
            scallop.plan(self.surface, progress=3)
        with self.assertRaises(TypeError):
            scallop.plan(self.surface, cancel="yes")


class CancelTest(unittest.TestCase):
    surface = scallop.example_surface("paper-1")

    def test_cancel_from_the_progress_callback(self):
        token = scallop.CancelToken()
        calls = []

        def progress(fraction, stage):
            calls.append(fraction)
            if fraction > 0.3 and not token.cancelled:
                token.cancel()

        with self.assertRaises(scallop.Cancelled) as caught:
            scallop.plan(self.surface, scallop_height=COARSE_H, progress=progress, cancel=token)
        self.assertIsInstance(caught.exception, scallop.Error)
        self.assertTrue(token.cancelled)
        self.assertLess(max(calls), 1.0)
        # Nothing of the cancelled job is left on this thread: the next one runs to the end.
        flat = scallop.paths(scallop.Surface(FLAT_SQUARE), 0.1, spacing=0.1, progress=lambda f, s: None)
        self.assertEqual(flat.planes, 11)

    def test_cancel_from_another_thread(self):
        # The default plan (H = 0.001 in) takes seconds; the timer's thread can only run while
        # plan has released the GIL.
        token = scallop.CancelToken()
        timer = threading.Timer(0.2, token.cancel)
        start = time.monotonic()
        timer.start()
        try:
            with self.assertRaises(scallop.Cancelled):
                scallop.plan(self.surface, cancel=token)
        finally:
            timer.cancel()
        self.assertLess(time.monotonic() - start, 5.0)

    def test_orient_and_verify_take_a_cancel_token(self):
        token = scallop.CancelToken()
        token.cancel()
        with self.assertRaises(scallop.Cancelled):
            scallop.orient(self.surface, cancel=token)
        program = scallop.plan(self.surface, scallop_height=COARSE_H).program
        with self.assertRaises(scallop.Cancelled):
            scallop.verify(self.surface, program, 0.25, COARSE_H, cancel=token)
        # A fresh token: both run to the end.
        self.assertTrue(scallop.orient(self.surface, cancel=scallop.CancelToken()).certified)

    def test_exception_from_the_progress_callback(self):
        class Stop(Exception):
            pass

        raised = Stop("from the callback")

        def progress(fraction, stage):
            if fraction > 0.1:
                raise raised

        with self.assertRaises(Stop) as caught:
            scallop.plan(self.surface, scallop_height=COARSE_H, progress=progress)
        self.assertIs(caught.exception, raised)

    def test_keyboard_interrupt(self):
        # Ctrl-C is checked at every progress report, with or without a callback.
        timer = threading.Timer(0.2, _thread.interrupt_main)
        timer.start()
        try:
            with self.assertRaises(KeyboardInterrupt):
                scallop.plan(self.surface)
        finally:
            timer.cancel()


# OCCT's sample parts (Debian's occt-misc), as the C++ tests read them.
OCCT_SAMPLES = "/usr/share/opencascade/data"
SHAPE_STL = os.path.join(OCCT_SAMPLES, "stl", "shape.stl")  # 494 triangles, ASCII, mm
SCREW_STEP = os.path.join(OCCT_SAMPLES, "step", "screw.step")  # 10 faces, 8 trimmed, mm


def scallop_cli():
    """The command-line program: SCALLOP_CLI (ctest), else the build tree's beside the module."""
    cli = os.environ.get("SCALLOP_CLI") or os.path.join(os.path.dirname(scallop.__file__), os.pardir, "scallop")
    return cli if os.access(cli, os.X_OK) else None


def cli_plan(arguments, folder):
    """Runs `scallop plan ARGUMENTS --out FOLDER/out`: the files it wrote (name -> bytes) and
    the stages it printed on stderr ("scallop plan: <stage>...")."""
    out = os.path.join(folder, "out")
    run = subprocess.run([scallop_cli(), "plan", *arguments, "--out", out], capture_output=True, text=True,
                         check=False)
    if run.returncode != 0:
        raise AssertionError(f"scallop plan {' '.join(arguments)}: exit {run.returncode}: {run.stderr}")
    files = {}
    for name in sorted(os.listdir(out)):
        with open(os.path.join(out, name), "rb") as file:
            files[name] = file.read()
    stages = [line[len("scallop plan: "):-len("...")] for line in run.stderr.splitlines()
              if line.startswith("scallop plan: ") and line.endswith("...")]
    return files, stages


def stages_of(progress):
    """The stages of (fraction, stage) reports as the CLI prints them: each new one once, not "done"."""
    stages = []
    for _, stage in progress:
        if stage != "done" and (not stages or stages[-1] != stage):
            stages.append(stage)
    return stages


def assert_progress(test, progress):
    fractions = [fraction for fraction, _ in progress]
    test.assertGreater(len(fractions), 2)
    test.assertTrue(all(0.0 <= f <= 1.0 for f in fractions))
    test.assertTrue(all(a <= b for a, b in zip(fractions, fractions[1:])), "progress went back")
    test.assertEqual(progress[-1], (1.0, "done"))


def write_file(folder, name, contents):
    path = os.path.join(folder, name)
    with open(path, "wb") as file:
        file.write(contents)
    return path


class MeshTest(unittest.TestCase):
    R = 0.1

    # The unit square [0, 1]^2 in z = 0 as two triangles, normals up.
    SQUARE_VERTICES = [[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]]
    SQUARE_TRIANGLES = [[0, 1, 2], [0, 2, 3]]

    def square(self):
        return scallop.Mesh(self.SQUARE_VERTICES, self.SQUARE_TRIANGLES, units="in")

    def test_round_trip_through_numpy(self):
        mesh = self.square()
        self.assertEqual(mesh.units, "in")
        np.testing.assert_array_equal(mesh.vertices, self.SQUARE_VERTICES)
        self.assertEqual(mesh.triangles.dtype, np.uint32)
        np.testing.assert_array_equal(mesh.triangles, self.SQUARE_TRIANGLES)
        self.assertIn("2 triangles", repr(mesh))

    def test_raster_over_a_flat_square_stands_R_above_it(self):
        # Over the square a dropped ball's centre is R above it, and off it the raster runs R
        # above the lowest point seen from above (z = 0): every centre at z = R, every line
        # at most the spacing apart, the ball never inside the square.
        paths = scallop.mesh_paths(self.square(), tool_radius=self.R, spacing=0.1)
        self.assertEqual((paths.strategy, paths.units, paths.tool_radius, paths.spacing), ("raster", "in", self.R, 0.1))
        self.assertEqual(paths.unproven_moves, 0)
        points = np.vstack(paths.passes)
        self.assertTrue(np.all(np.abs(points[:, 2] - self.R) <= paths.eps), points[:, 2].min())
        # The lines (along x: constant y, the links between them a few points each) cover the
        # square and more, at most 0.1 apart, each from (at least) R before it to R beyond it.
        ys, counts = np.unique(np.round(points[:, 1], 9), return_counts=True)
        lines = ys[counts > 4]
        self.assertEqual(paths.lines, len(lines))
        self.assertLessEqual(lines.min(), 0.0)
        self.assertGreaterEqual(lines.max(), 1.0)
        self.assertLessEqual(np.diff(lines).max(), 0.1 + 1e-12)
        on_line = np.isin(np.round(points[:, 1], 9), lines)
        self.assertLessEqual(points[on_line, 0].min(), -self.R)
        self.assertGreaterEqual(points[on_line, 0].max(), 1.0 + self.R)
        self.assertLessEqual(paths.gouge_depth, paths.eps)
        program = paths.gcode()
        self.assertEqual(gcode_problems(program), [])
        self.assertIn("G20", program)
        self.assertEqual(program.splitlines()[0], "(scallop tool path: scallop paths raster mesh)")
        self.assertEqual(json.loads(paths.report_json)["source"], "mesh")

    def test_plan_of_a_flat_square(self):
        # Passes 0.1 apart leave cusps of R - sqrt(R^2 - 0.05^2) on a flat part.
        plan = scallop.plan_mesh(self.square(), tool_radius=self.R, spacing=0.1, source="square")
        cusp = self.R - math.sqrt(self.R ** 2 - 0.05 ** 2)
        self.assertLessEqual(plan.max_gouge, 1e-5)  # the G-code's rounding
        self.assertLessEqual(plan.max_scallop, cusp * 1.01 + 1e-5)
        self.assertGreater(plan.max_scallop, cusp * 0.9)
        files = plan.files()
        self.assertEqual(list(files), ["toolpath.ngc", "report.json", "verify.svg"])
        self.assertEqual(files["toolpath.ngc"], plan.program)
        self.assertEqual(json.loads(files["report.json"])["source"], "square")
        self.assertEqual(files["report.json"], plan.report_json)

    def test_bad_meshes_are_refused(self):
        with self.assertRaisesRegex(scallop.Error, "part-7"):  # vertex 9 of 4
            scallop.plan_mesh(scallop.Mesh(self.SQUARE_VERTICES, [[0, 1, 9]]), source="part-7")
        with self.assertRaisesRegex(scallop.Error, "triangle"):
            scallop.mesh_paths(scallop.Mesh(self.SQUARE_VERTICES, np.zeros((0, 3), dtype=int)))
        with self.assertRaisesRegex(ValueError, r"vertices: expected an array of shape \(n, 3\)"):
            scallop.Mesh([[0.0, 0.0]], [[0, 0, 0]])
        with self.assertRaisesRegex(ValueError, r"triangles: expected an array of shape \(m, 3\)"):
            scallop.Mesh(self.SQUARE_VERTICES, [0, 1, 2])
        with self.assertRaisesRegex(ValueError, "negative"):
            scallop.Mesh(self.SQUARE_VERTICES, [[0, 1, -2]])
        with self.assertRaisesRegex(TypeError, "integers"):
            scallop.Mesh(self.SQUARE_VERTICES, [[0.0, 1.0, 2.0]])
        with self.assertRaisesRegex(TypeError, "mesh: expected a scallop.Mesh"):
            scallop.plan_mesh(scallop.Surface(FLAT_SQUARE))
        with self.assertRaisesRegex(scallop.Error, "scallop height"):
            scallop.plan_mesh(self.square(), tool_radius=self.R, scallop_height=2 * self.R)

    def test_bad_stl_files_name_the_file(self):
        with tempfile.TemporaryDirectory() as folder:
            empty = write_file(folder, "empty.stl", b"")
            with self.assertRaises(scallop.Error) as caught:
                scallop.load_stl(empty)
            self.assertIn(empty, str(caught.exception))
            self.assertIn("empty", str(caught.exception))
            # A binary STL cut short: 84 + 50 bytes of a file whose header counts 2 triangles.
            truncated = write_file(folder, "cut.stl", b"\0" * 80 + (2).to_bytes(4, "little") + b"\0" * 50)
            with self.assertRaisesRegex(scallop.Error, re.escape(truncated) + ".*truncated"):
                scallop.load_stl(truncated)
            # Three points on a line: refused, and the keyword that skips it named.
            facet = "facet normal 0 0 1\nouter loop\nvertex 0 0 0\nvertex {}\nvertex {}\nendloop\nendfacet\n"
            text = "solid s\n" + facet.format("1 0 0", "2 0 0") + facet.format("1 0 0", "0 1 0") + "endsolid s\n"
            zero = write_file(folder, "zero.stl", text.encode())
            with self.assertRaisesRegex(scallop.Error, re.escape(zero) + ".*zero area.*drop_zero_area=True"):
                scallop.load_stl(zero)
            read = scallop.load_stl(zero, units="in", drop_zero_area=True)
            self.assertEqual((read.format, read.triangles_read, read.zero_area_dropped), ("ascii", 2, 1))
            self.assertEqual(read.mesh.units, "in")
            self.assertEqual(read.description, "1 triangles (ASCII STL)")
            with self.assertRaisesRegex(scallop.Error, "missing.stl"):
                scallop.load_stl(os.path.join(folder, "missing.stl"))
            with self.assertRaisesRegex(ValueError, "units"):
                scallop.load_stl(zero, units="m")


@unittest.skipUnless(os.path.exists(SHAPE_STL) and scallop_cli(),
                     "needs OCCT's sample parts (occt-misc) and the scallop program (SCALLOP_CLI)")
class MeshPlanCliTest(unittest.TestCase):
    """plan_mesh on OCCT's shape.stl against `scallop plan shape.stl`, byte for byte."""

    R, H = 6.0, 0.3  # mm: about 1 s a plan
    ARGUMENTS = ["--tool-radius", "6", "--scallop-height", "0.3"]

    @classmethod
    def setUpClass(cls):
        with tempfile.TemporaryDirectory() as folder:
            cls.cli_files, cls.cli_stages = cli_plan([SHAPE_STL, *cls.ARGUMENTS], folder)
        cls.progress = []
        cls.stl = scallop.load_stl(SHAPE_STL)
        cls.plan = scallop.plan_mesh(cls.stl, tool_radius=cls.R, scallop_height=cls.H,
                                     progress=lambda fraction, stage: cls.progress.append((fraction, stage)))

    def test_the_files_are_the_cli_bytes(self):
        files = self.plan.files()
        self.assertEqual(sorted(files), sorted(self.cli_files))
        self.assertEqual(list(files), ["toolpath.ngc", "report.json", "verify.svg"])
        for name, contents in files.items():
            self.assertEqual(contents.encode(), self.cli_files[name], name)

    def test_progress_is_monotone_ends_at_one_and_names_the_cli_stages(self):
        assert_progress(self, self.progress)
        self.assertEqual(self.progress[0][1].split(";")[0], "494 triangles (ASCII STL)")
        # The stages the CLI prints, but its own last line.
        self.assertEqual(stages_of(self.progress), [s for s in self.cli_stages if s != "writing the report"])

    def test_figures_agree_with_the_report(self):
        plan = self.plan
        report = json.loads(plan.report_json)
        self.assertEqual(report["source"], SHAPE_STL)
        self.assertEqual((plan.strategy, plan.units, plan.tool_radius, plan.scallop_height),
                         ("raster", "mm", self.R, self.H))
        self.assertEqual(report["verification"]["max_gouge"], plan.max_gouge)
        self.assertEqual(plan.unproven_moves, 0)
        self.assertLess(plan.max_gouge, 0.01)
        self.assertLessEqual(plan.max_scallop, self.H)
        self.assertEqual(plan.program_name, "toolpath.ngc")
        self.assertEqual(gcode_problems(plan.program), [])
        self.assertIn("G21", plan.program)  # mm
        self.assertEqual(len(plan.passes), len(report["passes"]))

    def test_mesh_paths_are_the_bytes_of_scallop_paths(self):
        # The raster alone, as `scallop paths shape.stl --json --gcode` writes it; and the same
        # from the mesh's own numpy arrays, named as the file.
        with tempfile.TemporaryDirectory() as folder:
            json_path, gcode_path = os.path.join(folder, "paths.json"), os.path.join(folder, "paths.ngc")
            subprocess.run([scallop_cli(), "paths", SHAPE_STL, *self.ARGUMENTS, "--json", json_path,
                            "--gcode", gcode_path], check=True, capture_output=True)
            with open(json_path, "rb") as file:
                cli_json = file.read()
            with open(gcode_path, "rb") as file:
                cli_gcode = file.read()
        paths = scallop.mesh_paths(self.stl, tool_radius=self.R, scallop_height=self.H)
        self.assertEqual(paths.report_json.encode(), cli_json)
        self.assertEqual(paths.gcode().encode(), cli_gcode)
        arrays = scallop.Mesh(self.stl.mesh.vertices, self.stl.mesh.triangles, units="mm")
        again = scallop.mesh_paths(arrays, tool_radius=self.R, scallop_height=self.H, source=SHAPE_STL)
        self.assertEqual(again.report_json, paths.report_json)
        self.assertEqual(again.lines, self.plan.lines)  # the plan's raster, before its rest passes

    def test_cancel_from_the_progress_callback(self):
        token = scallop.CancelToken()
        after = []

        def progress(fraction, stage):
            if token.cancelled:
                after.append(stage)
            elif fraction > 0.3:
                token.cancel()

        with self.assertRaises(scallop.Cancelled) as caught:
            scallop.plan_mesh(self.stl, tool_radius=self.R, scallop_height=self.H, progress=progress, cancel=token)
        self.assertIsInstance(caught.exception, scallop.Error)
        self.assertTrue(token.cancelled)
        self.assertNotIn("done", after)
        # Cancelled before it starts: the raster alone too.
        with self.assertRaises(scallop.Cancelled):
            scallop.mesh_paths(self.stl, tool_radius=self.R, scallop_height=self.H, cancel=token)


@unittest.skipUnless(scallop.has_cad and os.path.exists(SCREW_STEP) and scallop_cli(),
                     "needs scallop::cad, OCCT's sample parts (occt-misc) and the scallop program (SCALLOP_CLI)")
class PartPlanTest(unittest.TestCase):
    """A STEP part through its tessellation, against `scallop plan screw.step`."""

    def test_the_tessellated_part_gives_the_cli_bytes(self):
        # 8 of the screw's 10 faces are trimmed: the CLI cuts it through its tessellation. The
        # part here is a temporary: the tessellation keeps it alive for the judge.
        progress = []
        part = scallop.tessellate_part(scallop.CadPart(SCREW_STEP), tool_radius=6, spacing=6,
                                       progress=lambda fraction, stage: progress.append((fraction, stage)))
        self.assertEqual(progress[0][1], "tessellating its 10 faces with deflection 0.1 mm")  # the flat cusp / 8
        self.assertEqual(progress[-1], (1.0, "done"))
        self.assertEqual(part.warnings, [])  # a spacing: no H to warn about
        self.assertEqual(part.faces, 10)
        self.assertGreater(part.deviation, 0.0)
        self.assertEqual(part.clearance, 1.5 * part.deviation)
        self.assertEqual(part.mesh.units, "mm")
        plan_progress = []
        plan = scallop.plan_mesh(part, tool_radius=6, spacing=6,
                                 progress=lambda fraction, stage: plan_progress.append((fraction, stage)))
        assert_progress(self, plan_progress)
        self.assertEqual(json.loads(plan.report_json)["tessellation"]["design"], "exact faces")
        with tempfile.TemporaryDirectory() as folder:
            cli_files, cli_stages = cli_plan([SCREW_STEP, "--tool-radius", "6", "--spacing", "6"], folder)
        files = plan.files()
        self.assertEqual(sorted(files), sorted(cli_files))
        for name, contents in files.items():
            self.assertEqual(contents.encode(), cli_files[name], name)
        self.assertEqual(stages_of(progress) + stages_of(plan_progress),
                         [s for s in cli_stages[1:] if s != "writing the report"])  # [0]: why it tessellates

    def test_the_warning_names_the_keyword(self):
        part = scallop.CadPart(SCREW_STEP)
        self.assertEqual((part.format, part.units, part.faces), ("STEP", "mm", 10))
        coarse = scallop.tessellate_part(part, deflection=0.2, tool_radius=3, scallop_height=0.05)
        self.assertEqual(coarse.deflection, 0.2)
        self.assertEqual(len(coarse.warnings), 1)
        warning = coarse.warnings[0]
        self.assertIn("3/4 of H = 0.05", warning)
        self.assertIn("(a smaller deflection helps unless", warning)
        self.assertNotIn("--deflection", warning)

    def test_bad_parts(self):
        with tempfile.TemporaryDirectory() as folder:
            empty = write_file(folder, "empty.step", b"")
            with self.assertRaisesRegex(scallop.Error, re.escape(empty)):
                scallop.CadPart(empty)
        part = scallop.CadPart(SCREW_STEP)
        with self.assertRaisesRegex(scallop.Error, "deflection"):
            scallop.tessellate_part(part, deflection=-1.0)
        with self.assertRaisesRegex(scallop.Error, "at most one of a spacing and a scallop height"):
            scallop.tessellate_part(part, spacing=1.0, scallop_height=0.1)
        token = scallop.CancelToken()
        token.cancel()
        with self.assertRaises(scallop.Cancelled):
            scallop.tessellate_part(part, tool_radius=6, spacing=6, cancel=token)


if __name__ == "__main__":
    unittest.main()
