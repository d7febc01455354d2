#!/usr/bin/python3
"""Writes docs/benchmarks.md from measurement outputs; nothing in it is kept by hand.

  scripts/benchmarks.py [-o FILE] [--city-bench DIR]... [SWEEP_DIR]...

SWEEP_DIR   the --out folder of scripts/sweep.sh (its sweep.json): per tile kind one table with
            a row per seed and the pooled row (truth facade and roof RMSE before -> after,
            watertight, made worse, outcomes, refine time median / max), the city path of the
            real tiles, and the ten worst buildings of each kind.
--city-bench DIR
            the DIR of scripts/city_bench.sh (bench.meta, time.<stage>, refine_rss.log, crop.log,
            run/summary.json): wall time, peak memory and throughput per stage, outcomes, pooled
            figures.
-o FILE     output (default: docs/benchmarks.md of this checkout), written atomically.

Each section says the date and commit its figures were measured at; the page says when and at
which commit it was generated. Python 3 standard library only. A missing or unreadable input is
refused in one line (exit 2) and nothing is written.
"""
import datetime
import json
import math
import os
import subprocess
import sys

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
PROG = "benchmarks.py"
KIND_TITLES = {
    "synth": "synth: parametric LoD2 buildings",
    "real": "real: Rotterdam Delfshaven LoD2 geometry",
    "topo": "topo: street facades the model lacks (notch, bay, step)",
}


class InputError(Exception):
    pass


def fail(msg):
    print("%s: error: %s" % (PROG, msg), file=sys.stderr)
    sys.exit(2)


def num(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def f3(x):
    return "%.3f" % x if num(x) else "n/a"


def f1(x):
    return "%.1f" % x if num(x) else "n/a"


def f2(x):
    return "%.2f" % x if num(x) else "n/a"


def pct(x, digits=1):
    return ("%." + str(digits) + "f %%") % x if num(x) else "n/a"


def arrow(a, b):
    return "%s → %s" % (f3(a), f3(b))


def cell(s):
    return str(s).replace("|", "\\|").replace("\n", " ")


def outcomes(d):
    return ", ".join("%s %d" % (k, v) for k, v in (d or {}).items()) or "-"


def day(iso):
    return str(iso)[:10] if iso else "date not recorded"


def commit(head, dirty):
    s = "`%s`" % head if head else "commit not recorded"
    try:
        if int(dirty):
            s += " (+%d modified tracked files)" % int(dirty)
    except (TypeError, ValueError):
        pass
    return s


def table(header, rows):
    out = ["| " + " | ".join(header) + " |", "|" + "---|" * len(header)]
    out += ["| " + " | ".join(cell(c) for c in r) + " |" for r in rows]
    return out


# ------------------------------------------------------------------------------------ sweep
def read_sweep(d):
    path = os.path.join(d, "sweep.json")
    if not os.path.isdir(d):
        raise InputError("%s: no such folder (give the --out folder of scripts/sweep.sh)" % d)
    if not os.path.isfile(path):
        raise InputError("%s: no sweep.json (not an --out folder of scripts/sweep.sh, or the sweep did not finish)" % d)
    try:
        with open(path) as f:
            s = json.load(f)
    except (OSError, ValueError) as e:
        raise InputError("%s: unreadable: %s" % (path, e))
    if not isinstance(s, dict) or not isinstance(s.get("meta"), dict) or not isinstance(s.get("kinds"), list) or not s["kinds"]:
        raise InputError("%s: no meta and tile kinds (not written by scripts/sweep_report.py)" % path)
    for k in s["kinds"]:
        if not isinstance(k, dict) or not isinstance(k.get("kind"), str) or not isinstance(k.get("per_seed"), list):
            raise InputError("%s: a tile kind without its name or per-seed figures" % path)
    return s


def city_cell(c):
    if not c or not c.get("ran"):
        return "not run"
    if "moved_5cm" not in c:
        return "failed (exit %s%s)" % (c.get("exit"), ", timeout" if c.get("timed_out") else "")
    return "%d (%d changed of %d, largest %s m)" % (c["moved_5cm"], c.get("changed", 0), c.get("correct", 0), f3(c.get("largest")))


def sweep_section(d, s):
    m = s["meta"]
    k0, n = m.get("k", "?"), m.get("n", "?")
    first = m.get("first_seed")
    seeds = "%s..%s" % (first, first + k0 - 1) if isinstance(first, int) and isinstance(k0, int) else "?"
    extra = " ".join(m.get("extra_args") or []) or "none (the defaults)"
    L = ["## Fresh tiles (`scripts/sweep.sh`): %s, %s" % (day(m.get("date")), commit(m.get("head"), m.get("dirty"))), "",
         "`%s`; %s tiles per kind of %s buildings, seeds %s; extra refine arguments: %s; %s jobs, refine timeout %s s. "
         "Sweep proper %s s (refine %s, score %s, city path %s). Source: `%s`." % (
             m.get("version", "?"), k0, n, seeds, extra, m.get("jobs", "?"), m.get("timeout", "?"),
             f1(m.get("t_sweep")), f1(m.get("t_refine")), f1(m.get("t_score")), f1(m.get("t_city")), d), ""]
    if m.get("bin_changed"):
        L += ["**The binary changed during this sweep: its figures mix two builds.**", ""]
    L += ["Truth RMSE in metres, before → after; *pooled* is over every truth sample of the kind's tiles "
          "(per seed: the scorer's own figures). Made worse: truth facade RMSE after > before + 1 mm. "
          "Time: one refine process per building, wall clock.", ""]
    for k in s["kinds"]:
        L += ["### %s" % KIND_TITLES.get(k["kind"], k["kind"]), ""]
        rows = []
        for p in k["per_seed"]:
            rows.append([p.get("seed"), "%s/%s" % (p.get("produced"), p.get("buildings")),
                         arrow(p.get("facade_before"), p.get("facade_after")), arrow(p.get("roof_before"), p.get("roof_after")),
                         pct(p.get("watertight_pct"), 0), p.get("worse"), outcomes(p.get("outcomes")),
                         "%s / %s" % (f2(p.get("time_median")), f2(p.get("time_max")))])
        rows.append(["**pooled**", "%s/%s" % (k.get("produced"), k.get("buildings")),
                     "**%s**" % arrow(k.get("facade_before"), k.get("facade_after")), arrow(k.get("roof_before"), k.get("roof_after")),
                     pct(k.get("watertight_pct")), k.get("worse"), outcomes(k.get("outcomes")),
                     "%s / %s" % (f2(k.get("time_median")), f2(k.get("time_max")))])
        L += table(["seed", "written", "truth facade RMSE", "truth roof RMSE", "watertight", "made worse", "outcomes",
                    "time median / max (s)"], rows)
        if k.get("pooling"):
            L += ["", "Pooling: %s." % k["pooling"]]
        problems = [pr for p in k["per_seed"] for pr in (p.get("problems") or [])]
        if problems:
            L += [""] + ["- problem: %s" % cell(pr) for pr in problems]
        if k["kind"] == "real" and isinstance(k.get("city"), dict):
            L += ["", "City path (the tile's buildings refined inside their real city file, `gen/city_check.py`): "
                  "correct buildings moved over 5 cm.", ""]
            rows = []
            for p in k["per_seed"]:
                c, ct = p.get("city") or {}, p.get("city_truth") or {}
                sc = c.get("score") or {}
                rows.append([p.get("seed"), city_cell(c), outcomes(c.get("outcomes")),
                             "%s/%s" % (sc.get("watertight", "?"), sc.get("buildings", "?")),
                             arrow(sc.get("truth_facade_rmse_orig"), sc.get("truth_facade_rmse_ref")), city_cell(ct),
                             f1(c.get("refine_seconds"))])
            c, ct = k["city"], k.get("city_truth") or {}
            rows.append(["**all**", "%s (%s changed of %s, largest %s m)" % (c.get("moved_5cm"), c.get("changed"), c.get("correct"), f3(c.get("largest"))),
                         outcomes(c.get("outcomes")), "%s/%s" % (c.get("watertight"), c.get("scored")), "",
                         "%s (%s changed of %s)" % (ct.get("moved_5cm"), ct.get("changed"), ct.get("correct")), ""])
            L += table(["seed", "moved > 5 cm", "tile outcomes", "watertight", "truth facade RMSE",
                        "`--truth-city`: moved > 5 cm", "city refine (s)"], rows)
        worst = k.get("worst") or []
        if worst:
            L += ["", "Worst by truth facade RMSE after (lost first):", ""]
            L += table(["seed", "building", "type", "truth facade RMSE", "outcome", "reason"],
                       [[w.get("seed"), "`%s`" % w.get("id"), w.get("kind"),
                         arrow(w.get("facade_before"), w.get("facade_after")) if w.get("facade_after") is not None
                         else "%s → lost" % f3(w.get("facade_before")), w.get("outcome"), w.get("reason", "")]
                        for w in worst])
        L.append("")
    return L


# ------------------------------------------------------------------------------------ city bench
def read_city_bench(d):
    if not os.path.isdir(d):
        raise InputError("%s: no such folder (give the DIR of scripts/city_bench.sh)" % d)
    need = ["bench.meta", "crop.log", "refine_rss.log", os.path.join("run", "summary.json")] + \
           ["time." + s for s in ("synth", "crop", "refine", "eval")]
    missing = [n for n in need if not os.path.isfile(os.path.join(d, n))]
    if missing:
        raise InputError("%s: no %s (not a finished scripts/city_bench.sh DIR%s)" % (
            d, ", ".join(missing), "; bench.meta is written since city_bench.sh records its commit" if missing == ["bench.meta"] else ""))
    try:
        meta = {}
        with open(os.path.join(d, "bench.meta")) as f:
            for line in f:
                if "=" in line:
                    key, value = line.rstrip("\n").split("=", 1)
                    meta[key] = value
        times = {}
        for s in ("synth", "crop", "refine", "eval"):
            with open(os.path.join(d, "time." + s)) as f:
                wall, kb = f.read().split()[:2]
            times[s] = (float(wall), int(kb) / 1024.0)
        with open(os.path.join(d, "refine_rss.log")) as f:
            rss = [int(x) for x in f.read().split() if x.isdigit()]
        with open(os.path.join(d, "crop.log")) as f:
            last = [l for l in f.read().splitlines() if l.strip()][-1]
        points = int(last.split()[0])
        with open(os.path.join(d, "run", "summary.json")) as f:
            pooled = json.load(f)["pooled"]
    except (OSError, ValueError, KeyError, IndexError, TypeError) as e:
        raise InputError("%s: unreadable city bench output: %s" % (d, e))
    return dict(meta=meta, times=times, refine_peak_mb=max(rss) / 1024.0 if rss else float("nan"), points=points, pooled=pooled)


def city_bench_section(d, b):
    m, t, p = b["meta"], b["times"], b["pooled"]
    try:
        n = int(m.get("buildings") or p["buildings"])
    except (TypeError, ValueError, KeyError):
        n = 0
    per = lambda s: "%.1f buildings/s" % (n / t[s][0]) if t[s][0] > 0 else "n/a"
    L = ["## City-scale bench (`scripts/city_bench.sh`): %s, %s" % (day(m.get("date")), commit(m.get("head"), m.get("dirty"))), "",
         "`%s`; %d buildings, %d tile points (%.2f GB PLY), %s refine jobs. Source: `%s`." % (
             m.get("version", "?"), n, b["points"], b["points"] * 24 / 1e9, m.get("jobs", "?"), d), ""]
    crop_rate = "%.1f M points/s" % (b["points"] / t["crop"][0] / 1e6) if t["crop"][0] > 0 else "n/a"
    L += table(["stage", "wall (s)", "peak memory (MB)", "throughput"], [
        ["generate (`synth --tile`)", "%.1f" % t["synth"][0], "%.0f" % t["synth"][1], per("synth")],
        ["crop (one streaming pass)", "%.1f" % t["crop"][0], "%.0f" % t["crop"][1], crop_rate],
        ["refine (`batch.mk`)", "%.1f" % t["refine"][0], "%.0f (largest building)" % b["refine_peak_mb"], per("refine")],
        ["eval + report (`eval --dir --html`)", "%.1f" % t["eval"][0], "%.0f" % t["eval"][1], per("eval")],
        ["all four", "%.1f" % sum(v[0] for v in t.values()), "", ""]])
    fm = p.get("facades_moved") or {}
    L += ["", "Outcomes: %s; facades moved %s (max %s m, mean %s m)." % (
        outcomes(p.get("outcomes")), fm.get("count", "?"), f3(fm.get("max")), f3(fm.get("mean"))), ""]
    po = p.get("pooled_over_points") or {}
    rmse = lambda key, side: ((po.get(key) or {}).get(side) or {}).get("rmse")
    wt = p.get("watertight_rate") or {}
    L += table(["pooled over points", "before", "after"], [
        ["C2M RMSE (m)", f3(rmse("c2m", "original")), f3(rmse("c2m", "refined"))],
        ["truth facade RMSE (m)", f3(rmse("truth_facade", "original")), f3(rmse("truth_facade", "refined"))],
        ["truth roof RMSE (m)", f3(rmse("truth_roof", "original")), f3(rmse("truth_roof", "refined"))],
        ["watertight", pct(100 * wt["original"]) if num(wt.get("original")) else "n/a",
         pct(100 * wt["refined"]) if num(wt.get("refined")) else "n/a"]])
    L.append("")
    return L


# ------------------------------------------------------------------------------------ page
def git_stamp():
    try:
        head = subprocess.run(["git", "-C", ROOT, "rev-parse", "--short", "HEAD"], capture_output=True, text=True,
                              check=True).stdout.strip()
        dirty = len(subprocess.run(["git", "-C", ROOT, "status", "--porcelain", "--untracked-files=no"],
                                   capture_output=True, text=True, check=True).stdout.splitlines())
        return head, dirty
    except (OSError, subprocess.CalledProcessError):
        return None, 0


def parse_args(argv):
    out, sweeps, benches = os.path.join(ROOT, "docs", "benchmarks.md"), [], []
    i = 0
    while i < len(argv):
        a = argv[i]
        if a in ("-h", "--help"):
            print(__doc__.strip())
            sys.exit(0)
        if a in ("-o", "--out", "--city-bench"):
            if i + 1 >= len(argv):
                fail("%s needs a value" % a)
            if a == "--city-bench":
                benches.append(argv[i + 1])
            else:
                out = argv[i + 1]
            i += 2
            continue
        if a.startswith("-"):
            fail("unknown option '%s' (see --help)" % a)
        sweeps.append(a)
        i += 1
    if not sweeps and not benches:
        fail("no input: give a sweep folder (scripts/sweep.sh --out) and/or --city-bench DIR (see --help)")
    return out, sweeps, benches


def main(argv):
    out, sweeps, benches = parse_args(argv)
    try:
        read_sweeps = [(d, read_sweep(d)) for d in sweeps]
        read_benches = [(d, read_city_bench(d)) for d in benches]
    except InputError as e:
        fail(str(e))
    head, dirty = git_stamp()
    now = datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%d %H:%M UTC")
    cmd = "python3 scripts/benchmarks.py " + " ".join(
        sweeps + ["--city-bench %s" % d for d in benches])
    L = ["# Benchmarks", "",
         "<!-- Generated by scripts/benchmarks.py: do not edit by hand, run it again. -->", "",
         "Generated %s at commit %s by `%s`. Each section gives the date and commit its figures were "
         "measured at. How to measure: [README, Results](../README.md#results)." % (now, commit(head, dirty), cmd), ""]
    for d, s in read_sweeps:
        L += sweep_section(d, s)
    for d, b in read_benches:
        L += city_bench_section(d, b)
    text = "\n".join(L).rstrip("\n") + "\n"
    out_dir = os.path.dirname(os.path.abspath(out))
    if not os.path.isdir(out_dir):
        fail("%s: no such folder for the output" % out_dir)
    tmp = os.path.join(out_dir, ".%s.tmp%d" % (os.path.basename(out), os.getpid()))
    with open(tmp, "w") as f:
        f.write(text)
    os.replace(tmp, out)
    print("wrote %s (%d sweep(s), %d city bench(es))" % (out, len(read_sweeps), len(read_benches)))


if __name__ == "__main__":
    main(sys.argv[1:])
