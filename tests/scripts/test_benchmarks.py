#!/usr/bin/python3
"""scripts/benchmarks.py on tiny fixture folders: a sweep's sweep.json and a city bench's files
give the tables docs/benchmarks.md is made of; a missing input is refused in one line, exit 2,
nothing written. CTest `BenchmarksScript`; also `python3 tests/scripts/test_benchmarks.py`."""
import json
import os
import subprocess
import sys
import tempfile
import unittest

ROOT = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
SCRIPT = os.path.join(ROOT, "scripts", "benchmarks.py")


def seed_row(seed, before, after, outcomes, city=None):
    row = dict(seed=seed, buildings=2, produced=2, facade_before=before, facade_after=after, roof_before=0.1,
               roof_after=0.05, watertight_pct=100.0, worse=0, outcomes=outcomes, time_median=0.2, time_max=0.4,
               problems=[])
    if city is not None:
        row["city"] = city
        row["city_truth"] = dict(city, score=None)
    return row


def kind(name, rows, facade_after, **extra):
    k = dict(kind=name, buildings=4, produced=4, lost=0, pooling="over truth samples", facade_before=0.5,
             facade_after=facade_after, roof_before=0.1, roof_after=0.05, watertight_pct=100.0, worse=1,
             outcomes={"refined": 3, "kept": 1}, time_median=0.25, time_max=0.9, per_seed=rows,
             worst=[dict(seed=7, id="B1", kind="gable", facade_before=0.3, facade_after=0.2, outcome="refined",
                         reason="2 face(s) selected | 1 wall(s) moved")])
    k.update(extra)
    return k


def write_sweep(d):
    os.makedirs(d)
    city = dict(ran=True, moved_5cm=1, changed=3, correct=50, largest=0.07, outcomes={"refined": 2},
                refine_seconds=4.5, score=dict(watertight=2, buildings=2, truth_facade_rmse_orig=0.4,
                                               truth_facade_rmse_ref=0.05))
    s = dict(meta=dict(date="2031-05-06T07:08:09+00:00", head="abc1234", dirty=0, version="lodrefine 9.9.9",
                       k=2, n=2, first_seed=7, jobs=2, timeout=120, extra_args=[], t_sweep=10.0, t_refine=1.0,
                       t_score=5.0, t_city=4.0, bin_changed=False),
             kinds=[kind("synth", [seed_row(7, 0.61, 0.011, {"refined": 2}), seed_row(8, 0.42, 0.044, {"refined": 1, "kept": 1})], 0.031),
                    kind("real", [seed_row(7, 0.35, 0.06, {"refined": 2}, city), seed_row(8, 0.36, 0.07, {"refined": 2}, city)], 0.065,
                         city=dict(moved_5cm=2, changed=6, correct=100, largest=0.07, outcomes={"refined": 4},
                                   watertight=4, scored=4),
                         city_truth=dict(moved_5cm=2, changed=6, correct=106))],
             buildings=[])
    with open(os.path.join(d, "sweep.json"), "w") as f:
        json.dump(s, f)


def write_city_bench(d):
    os.makedirs(os.path.join(d, "run"))
    files = {"bench.meta": "date=2031-05-07T00:00:00Z\nhead=def5678\ndirty=0\nversion=lodrefine 9.9.9\n"
                           "buildings=10\npoints=1000000\njobs=2\n",
             "time.synth": "2.00 10240\n", "time.crop": "0.50 20480\n", "time.refine": "5.00 30720\n",
             "time.eval": "4.00 40960\n", "refine_rss.log": "20480\n25600\n",
             "crop.log": "b1: 100 points\n1000000 tile points, 10 buildings cropped, 0 skipped\n"}
    for name, text in files.items():
        with open(os.path.join(d, name), "w") as f:
            f.write(text)
    stats = lambda r: dict(count=100, rmse=r)
    pooled = dict(buildings=10, outcomes=dict(refined=9, kept=1, failed=0), facades_moved=dict(count=12, max=0.9, mean=0.5),
                  pooled_over_points=dict(c2m=dict(original=stats(0.4), refined=stats(0.02)),
                                          truth_facade=dict(original=stats(0.45), refined=stats(0.03)),
                                          truth_roof=dict(original=stats(0.06), refined=stats(0.05))),
                  watertight_rate=dict(original=0.0, refined=1.0))
    with open(os.path.join(d, "run", "summary.json"), "w") as f:
        json.dump(dict(pooled=pooled, buildings=[]), f)


def run(*args):
    return subprocess.run([sys.executable, SCRIPT] + list(args), capture_output=True, text=True)


class Benchmarks(unittest.TestCase):
    def setUp(self):
        base = os.environ.get("TEST_TMPDIR")
        if base:
            os.makedirs(base, exist_ok=True)
        self.tmp = tempfile.TemporaryDirectory(dir=base)
        self.dir = self.tmp.name
        self.sweep = os.path.join(self.dir, "sweep")
        self.bench = os.path.join(self.dir, "bench")
        self.out = os.path.join(self.dir, "benchmarks.md")
        write_sweep(self.sweep)
        write_city_bench(self.bench)

    def tearDown(self):
        self.tmp.cleanup()

    def test_tables_per_kind_and_city_bench(self):
        r = run("-o", self.out, self.sweep, "--city-bench", self.bench)
        self.assertEqual(r.returncode, 0, r.stderr)
        with open(self.out) as f:
            text = f.read()
        # stamped: generated at a commit, each section with its own date and commit
        self.assertIn("Generated by scripts/benchmarks.py", text)
        self.assertRegex(text, r"Generated \d{4}-\d\d-\d\d \d\d:\d\d UTC at (commit|`)")
        self.assertIn("## Fresh tiles (`scripts/sweep.sh`): 2031-05-06, `abc1234`", text)
        self.assertIn("## City-scale bench (`scripts/city_bench.sh`): 2031-05-07, `def5678`", text)
        # one table per tile kind: a row per seed and the pooled row
        self.assertIn("### synth: parametric LoD2 buildings", text)
        self.assertIn("### real: Rotterdam Delfshaven LoD2 geometry", text)
        self.assertIn("| seed | written | truth facade RMSE | truth roof RMSE | watertight | made worse | outcomes | time median / max (s) |", text)
        self.assertIn("| 7 | 2/2 | 0.610 → 0.011 | 0.100 → 0.050 | 100 % | 0 | refined 2 | 0.20 / 0.40 |", text)
        self.assertIn("| 8 | 2/2 | 0.420 → 0.044 | 0.100 → 0.050 | 100 % | 0 | refined 1, kept 1 | 0.20 / 0.40 |", text)
        self.assertIn("| **pooled** | 4/4 | **0.500 → 0.031** | 0.100 → 0.050 | 100.0 % | 1 | refined 3, kept 1 | 0.25 / 0.90 |", text)
        self.assertIn("| **pooled** | 4/4 | **0.500 → 0.065** |", text)
        # the real tiles' city path, and a reason's | escaped
        self.assertIn("| **all** | 2 (6 changed of 100, largest 0.070 m) | refined 4 | 4/4 |", text)
        self.assertIn("2 face(s) selected \\| 1 wall(s) moved", text)
        # city bench: stages, throughput, pooled figures
        self.assertIn("| crop (one streaming pass) | 0.5 | 20 | 2.0 M points/s |", text)
        self.assertIn("| refine (`batch.mk`) | 5.0 | 25 (largest building) | 2.0 buildings/s |", text)
        self.assertIn("| truth facade RMSE (m) | 0.450 | 0.030 |", text)
        self.assertIn("| watertight | 0.0 % | 100.0 % |", text)

    def assert_refused(self, r, words):
        self.assertEqual(r.returncode, 2)
        lines = r.stderr.splitlines()
        self.assertEqual(len(lines), 1, r.stderr)
        self.assertTrue(lines[0].startswith("benchmarks.py: error: "), lines[0])
        self.assertIn(words, lines[0])
        self.assertFalse(os.path.exists(self.out))

    def test_missing_inputs_refused_in_one_line(self):
        self.assert_refused(run("-o", self.out), "no input")
        self.assert_refused(run("-o", self.out, os.path.join(self.dir, "nope")), "no such folder")
        self.assert_refused(run("-o", self.out, self.bench), "no sweep.json")
        self.assert_refused(run("-o", self.out, self.sweep, "--city-bench", self.sweep), "no bench.meta")
        os.remove(os.path.join(self.bench, "time.eval"))
        self.assert_refused(run("-o", self.out, "--city-bench", self.bench), "no time.eval")
        with open(os.path.join(self.sweep, "sweep.json"), "w") as f:
            f.write("{}")
        self.assert_refused(run("-o", self.out, self.sweep), "no meta and tile kinds")
        self.assert_refused(run("-o", self.out, "--bogus"), "unknown option")


if __name__ == "__main__":
    unittest.main()
