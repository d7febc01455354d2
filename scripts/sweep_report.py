#!/usr/bin/python3
"""Helper of scripts/sweep.sh (not meant to be run by hand, but it can be).

  sweep_report.py counts TILE     per-building truth sample counts of a generated tile, cached in
                                  TILE/.sweep_counts.json (depends only on the tile)
  sweep_report.py report OUT ...  reads OUT/manifest.tsv and every run folder, prints the summary,
                                  writes OUT/sweep.json and OUT/sweep.md

Pooling. score.py's rows give per building the truth facade RMSE before/after and the roof RMSE
after, but not how many truth samples each was computed on; its per-tile summary pools over
samples. `counts` recomputes those sample counts by the very sampling score.py does (same weld,
triangulation, normal classes, surface_samples with rng seed 1, same scanned-facade filter), and
`report` checks them: per tile, sqrt(sum n*rmse^2 / sum n) over the rows must equal score.py's
own pooled truth_facade_rmse_orig (and roof_rmse_ref). When that holds the per-kind figures are
true pooled RMSEs over all samples of all tiles of the kind; when it does not (a scorer change),
the report falls back to pooling per building (sqrt of the mean of squared per-building RMSEs)
and says so in "pooling". Roof "before" has no per-building value in score.json: it is pooled
from score.py's per-tile roof_rmse_orig weighted by the tile's roof sample count.
As in score.py, "before" is over every building, "after" over the buildings produced (a lost
building -- refine failed or timed out -- is counted in "lost" and is not watertight);
before_same_set is "before" over the produced buildings only.
"""
import ast, json, math, os, re, statistics, sys
from collections import Counter

DEVTILES = os.environ.get("DEVTILES") or os.path.join(os.path.dirname(os.path.abspath(__file__)), "..", "..", "shared", "devtiles")
WORSE_TOL = 1e-3      # made worse: truth facade after > before + 1 mm
MOVED_TOL = "5 cm"    # city_check's own threshold


# ------------------------------------------------------------------------------------ counts
def counts(tile):
    path = os.path.join(tile, ".sweep_counts.json")
    if os.path.exists(path):
        return
    import numpy as np
    from scipy.spatial import cKDTree
    sys.path.insert(0, os.path.abspath(DEVTILES))
    from meshlib import read_obj, read_ply_xyz, triangulate, surface_samples, weld
    meta = json.load(open(os.path.join(tile, "meta.json")))
    origin = np.array(meta["origin"])
    out = {}
    for bi, b in enumerate(meta["buildings"]):
        bid = b["id"]
        Vt, Ft = read_obj(os.path.join(tile, "truth", bid + ".obj")); Vt -= origin
        Vt, Ft = weld(Vt, Ft)
        c = read_ply_xyz(os.path.join(tile, "clouds", bid + ".ply"), want=("x", "y", "z", "label", "building"))
        X = np.stack([c["x"], c["y"], c["z"]], 1) - origin
        P = X[(c["building"].astype(int) == bi) & (c["label"].astype(int) <= 1)]
        Tt = triangulate(Vt, Ft)
        Nt = np.cross(Vt[Tt[:, 1]] - Vt[Tt[:, 0]], Vt[Tt[:, 2]] - Vt[Tt[:, 0]])
        Nt /= np.linalg.norm(Nt, axis=1, keepdims=True)
        rng = np.random.default_rng(1)
        roof_T = Tt[Nt[:, 2] > 0.2]
        S_roof = surface_samples(Vt, roof_T, 0.3, rng) if len(roof_T) else np.zeros((0, 3))
        wall_T = Tt[np.abs(Nt[:, 2]) < 0.1]
        S_wall = surface_samples(Vt, wall_T, 0.2, rng)
        if len(P):
            dd, _ = cKDTree(P).query(S_wall, k=1)
            n_f = int(((dd < 0.5) & (S_wall[:, 2] < P[:, 2].max())).sum())
        else:
            n_f = 0
        out[bid] = dict(n_facade=n_f, n_roof=int(len(S_roof)))
    tmp = path + ".tmp%d" % os.getpid()
    json.dump(out, open(tmp, "w"))
    os.replace(tmp, path)


# ------------------------------------------------------------------------------------ report
def fnum(x):
    return isinstance(x, (int, float)) and not isinstance(x, bool) and math.isfinite(x)


def pooled(pairs):
    """pairs of (weight, rmse) -> sqrt(sum w rmse^2 / sum w) over finite ones."""
    pairs = [(w, r) for w, r in pairs if fnum(r) and w > 0]
    sw = sum(w for w, _ in pairs)
    return math.sqrt(sum(w * r * r for w, r in pairs) / sw) if sw else float("nan")


def f3(x):
    return "%.3f" % x if fnum(x) else "n/a"


def pct(a, b):
    return 100.0 * a / b if b else float("nan")


def read_time(run, bid):
    try:
        t = open(os.path.join(run, bid + ".time")).read().split()
        return int(t[1].split("=")[1]), float(t[2])
    except Exception:
        return None, float("nan")


def last_line(path, n=160):
    try:
        lines = [l for l in open(path, errors="replace").read().splitlines() if l.strip()]
        return lines[-1][:n] if lines else ""
    except Exception:
        return ""


def parse_city(run, mode):
    txt_path = os.path.join(run, mode + ".txt")
    r = dict(mode=mode, ran=os.path.exists(txt_path))
    if not r["ran"]:
        return r
    txt = open(txt_path, errors="replace").read()
    try:
        rc, sec = open(os.path.join(run, mode + ".rc")).read().split()
        r["exit"], r["seconds"] = int(rc), float(sec)
    except Exception:
        r["exit"], r["seconds"] = None, float("nan")
    r["timed_out"] = r["exit"] in (124, 137)
    m = re.search(r"city refine: exit (\d+), ([\d.]+) s, peak (\d+) MB; ?(.*)", txt)
    if m:
        r.update(refine_exit=int(m.group(1)), refine_seconds=float(m.group(2)), refine_peak_mb=int(m.group(3)),
                 refine_line=m.group(4).strip())
    m = re.search(r"correct buildings \(their scan is their truth\) changed: (\d+) of (\d+); moved > 5 cm: (\d+) "
                  r"\(largest (\S+) m\); tile outcomes (\{.*\})", txt)
    if m:
        r.update(changed=int(m.group(1)), correct=int(m.group(2)), moved_5cm=int(m.group(3)),
                 largest=float(m.group(4)))
        try:
            r["outcomes"] = {str(k): int(v) for k, v in ast.literal_eval(m.group(5)).items()}
        except Exception:
            r["outcomes"] = {}
    r["summary_line"] = next((l for l in txt.splitlines() if l.startswith("correct buildings")), "")
    r["changed_lines"] = [l for l in txt.splitlines() if l.startswith("changed: ")]
    r["failed"] = "city path failed" in txt or "moved_5cm" not in r
    sj = os.path.join(run, mode, "score.json")
    if mode == "city" and os.path.exists(sj):
        try:
            s = json.load(open(sj))
            rows = s["rows"]
            r["score"] = dict(buildings=len(rows), produced=s["summary"]["produced"],
                              watertight=sum(bool(x.get("watertight")) for x in rows),
                              truth_facade_rmse_orig=s["summary"]["truth_facade_rmse_orig"],
                              truth_facade_rmse_ref=s["summary"]["truth_facade_rmse_ref"],
                              roof_rmse_ref=s["summary"]["roof_rmse_ref"])
        except Exception as e:
            r["score_error"] = str(e)
    return r


def tile_result(kind, seed, n, tile, run):
    res = dict(kind=kind, seed=int(seed), n=int(n), tile=tile, run=run, problems=[])
    meta = json.load(open(os.path.join(tile, "meta.json")))
    try:
        score = json.load(open(os.path.join(run, "score.json")))
    except Exception as e:
        score = None
        res["problems"].append("score.py gave no score.json (%s): see %s/score.txt" % (e, run))
    try:
        cnt = json.load(open(os.path.join(tile, ".sweep_counts.json")))
    except Exception:
        cnt = None
    srows = {r["id"]: r for r in (score["rows"] if score else [])}
    rows = []
    for b in meta["buildings"]:
        bid = b["id"]
        sr = srows.get(bid, {})
        rc, sec = read_time(run, bid)
        rep = None
        try:
            rep = json.load(open(os.path.join(run, bid + ".json")))
        except Exception:
            pass
        if rc is None:
            outcome, reason = "failed", "not run"
        elif rc in (124, 137):
            outcome, reason = "failed", "timeout"
        elif rc != 0:
            outcome, reason = "failed", "exit %d: %s" % (rc, last_line(os.path.join(run, bid + ".log")))
        elif rep is None:
            outcome, reason = "failed", "no report: " + last_line(os.path.join(run, bid + ".log"))
        else:
            outcome, reason = str(rep.get("outcome", "?")), str(rep.get("reason", "") or "")
        produced = bool(sr) and sr.get("ref") is not None
        c = (cnt or {}).get(bid, {})
        rows.append(dict(seed=int(seed), id=bid, kind=b.get("kind", sr.get("kind", "?")), produced=produced,
                         facade_before=sr.get("truth_facade_orig", float("nan")),
                         facade_after=sr.get("truth_facade_ref", float("nan")) if produced else float("nan"),
                         roof_after=sr.get("roof_ref", float("nan")) if produced else float("nan"),
                         watertight=bool(sr.get("watertight")) if produced else False,
                         n_facade=c.get("n_facade"), n_roof=c.get("n_roof"),
                         outcome=outcome, reason=reason, exit=rc, seconds=sec))
    res["rows"] = rows
    res["score_summary"] = score["summary"] if score else None
    # check the sample counts against score.py's own pooling
    ok = cnt is not None and score is not None and all(r["n_facade"] is not None for r in rows)
    if ok:
        s = score["summary"]
        mine_f = pooled([(r["n_facade"], r["facade_before"]) for r in rows])
        mine_r = pooled([(r["n_roof"], r["roof_after"]) for r in rows if r["produced"]])
        for a, b_ in ((mine_f, s["truth_facade_rmse_orig"]), (mine_r, s["roof_rmse_ref"])):
            if fnum(a) != fnum(b_) or (fnum(a) and abs(a - b_) > 1e-9 * max(1.0, abs(b_))):
                ok = False
        if not ok:
            res["problems"].append("sample counts do not reproduce score.py's pooled RMSE: pooled per building")
    res["counts_ok"] = ok
    return res


def kind_summary(kind, tiles):
    rows = [r for t in tiles for r in t["rows"]]
    prod = [r for r in rows if r["produced"]]
    counts_ok = bool(tiles) and all(t["counts_ok"] for t in tiles)
    w = (lambda r, key: r[key]) if counts_ok else (lambda r, key: 1)
    k = dict(kind=kind, tiles=len(tiles), seeds=[t["seed"] for t in tiles], buildings=len(rows), produced=len(prod),
             lost=len(rows) - len(prod),
             pooling=("over truth samples (sqrt(sum n*rmse^2/sum n), counts checked against score.py)" if counts_ok
                      else "per building (sqrt(mean rmse^2)); sample counts unavailable or unverified"))
    k["facade_before"] = pooled([(w(r, "n_facade"), r["facade_before"]) for r in rows])
    k["facade_before_same_set"] = pooled([(w(r, "n_facade"), r["facade_before"]) for r in prod])
    k["facade_after"] = pooled([(w(r, "n_facade"), r["facade_after"]) for r in prod])
    if counts_ok:
        k["roof_before"] = pooled([(sum(r["n_roof"] for r in t["rows"]), t["score_summary"]["roof_rmse_orig"]) for t in tiles])
    else:
        k["roof_before"] = pooled([(len(t["rows"]), t["score_summary"]["roof_rmse_orig"]) for t in tiles if t["score_summary"]])
    k["roof_after"] = pooled([(w(r, "n_roof"), r["roof_after"]) for r in prod])
    k["watertight"] = sum(r["watertight"] for r in rows)
    k["watertight_pct"] = pct(k["watertight"], len(rows))
    k["worse"] = sum(1 for r in prod if fnum(r["facade_after"]) and fnum(r["facade_before"])
                     and r["facade_after"] > r["facade_before"] + WORSE_TOL)
    k["outcomes"] = dict(Counter(r["outcome"] for r in rows).most_common())
    k["timeouts"] = sum(1 for r in rows if r["reason"] == "timeout")
    ts = [r["seconds"] for r in rows if fnum(r["seconds"])]
    k["time_median"] = statistics.median(ts) if ts else float("nan")
    k["time_max"] = max(ts) if ts else float("nan")
    key = lambda r: (1, r["facade_after"]) if r["produced"] and fnum(r["facade_after"]) else ((2, 0) if not r["produced"] else (0, 0))
    k["worst"] = [dict(seed=r["seed"], id=r["id"], kind=r["kind"], facade_before=r["facade_before"],
                       facade_after=r["facade_after"] if r["produced"] else None, outcome=r["outcome"], reason=r["reason"],
                       seconds=r["seconds"])
                  for r in sorted(rows, key=key, reverse=True)[:10]]
    k["per_seed"] = []
    for t in tiles:
        tr = t["rows"]; tp = [r for r in tr if r["produced"]]; s = t["score_summary"] or {}
        tt = [r["seconds"] for r in tr if fnum(r["seconds"])]
        ps = dict(seed=t["seed"], buildings=len(tr), produced=len(tp),
                  facade_before=s.get("truth_facade_rmse_orig", float("nan")),
                  facade_after=s.get("truth_facade_rmse_ref", float("nan")),
                  roof_before=s.get("roof_rmse_orig", float("nan")), roof_after=s.get("roof_rmse_ref", float("nan")),
                  watertight_pct=pct(sum(r["watertight"] for r in tr), len(tr)),
                  worse=sum(1 for r in tp if fnum(r["facade_after"]) and fnum(r["facade_before"])
                            and r["facade_after"] > r["facade_before"] + WORSE_TOL),
                  outcomes=dict(Counter(r["outcome"] for r in tr).most_common()),
                  time_median=statistics.median(tt) if tt else float("nan"), time_max=max(tt) if tt else float("nan"),
                  problems=t["problems"])
        if kind == "real":
            ps["city"] = t.get("city"); ps["city_truth"] = t.get("city_truth")
        k["per_seed"].append(ps)
    if kind == "real":
        cs = [t.get("city") or {} for t in tiles]; ct = [t.get("city_truth") or {} for t in tiles]
        sc = [c["score"] for c in cs if "score" in c]
        oc = Counter()
        for c in cs: oc.update(c.get("outcomes", {}))
        k["city"] = dict(
            runs_ok=sum(1 for c in cs if not c.get("failed", True)),
            changed=sum(c.get("changed", 0) for c in cs), moved_5cm=sum(c.get("moved_5cm", 0) for c in cs),
            correct=sum(c.get("correct", 0) for c in cs),
            largest=max([c["largest"] for c in cs if "largest" in c] or [float("nan")]),
            outcomes=dict(oc.most_common()),
            watertight=sum(s["watertight"] for s in sc), scored=sum(s["buildings"] for s in sc),
            watertight_pct=pct(sum(s["watertight"] for s in sc), sum(s["buildings"] for s in sc)),
            refine_seconds=[c.get("refine_seconds") for c in cs])
        k["city_truth"] = dict(
            runs_ok=sum(1 for c in ct if not c.get("failed", True)),
            changed=sum(c.get("changed", 0) for c in ct), moved_5cm=sum(c.get("moved_5cm", 0) for c in ct),
            correct=sum(c.get("correct", 0) for c in ct),
            largest=max([c["largest"] for c in ct if "largest" in c] or [float("nan")]),
            refine_seconds=[c.get("refine_seconds") for c in ct])
    return k


def outc(d):
    return ", ".join("%s %d" % (a, b) for a, b in d.items()) or "-"


def city_cell(c):
    if not c or not c.get("ran"):
        return "not run"
    if "moved_5cm" not in c:
        return "FAILED (exit %s%s)" % (c.get("exit"), ", timeout" if c.get("timed_out") else "")
    return "%d moved >5 cm (%d changed of %d, largest %s m)" % (c["moved_5cm"], c["changed"], c["correct"], f3(c["largest"]))


def render_text(S):
    L = []
    m = S["meta"]
    L.append("sweep %s  head %s%s  %s  K=%d N=%d seeds %d..%d  jobs %d  timeout %d s  extra args: %s" % (
        m["date"], m["head"], " (+%s modified files)" % m["dirty"] if m["dirty"] else "", m["version"], m["k"], m["n"],
        m["first_seed"], m["first_seed"] + m["k"] - 1, m["jobs"], m["timeout"], " ".join(m["extra_args"]) or "-"))
    if m["bin_changed"]:
        L.append("WARNING: the binary changed during the sweep: results mix two builds")
    L.append("times: generation %.1f s; sweep proper %.1f s (refine %.1f, score %.1f, city_check %.1f)" % (
        m["t_gen"], m["t_sweep"], m["t_refine"], m["t_score"], m["t_city"]))
    L.append("")
    hdr = "%-6s %9s %-15s %-15s %7s %5s %4s  %-34s %-14s" % ("kind", "buildings", "facade RMSE m", "roof RMSE m",
                                                          "wt %", "worse", "lost", "outcomes", "time med/max s")
    L.append(hdr); L.append("-" * len(hdr))
    for k in S["kinds"]:
        L.append("%-6s %9d %-15s %-15s %7.1f %5d %4d  %-34s %s/%s" % (
            k["kind"], k["buildings"], f3(k["facade_before"]) + " -> " + f3(k["facade_after"]),
            f3(k["roof_before"]) + " -> " + f3(k["roof_after"]), k["watertight_pct"], k["worse"], k["lost"],
            outc(k["outcomes"]), "%.2f" % k["time_median"], "%.2f" % k["time_max"]))
    L.append("pooling: " + "; ".join(sorted({"%s: %s" % (k["kind"], k["pooling"]) for k in S["kinds"]})))
    for k in S["kinds"]:
        L.append("")
        L.append("== %s: per seed (score.py's per-tile pooled figures)" % k["kind"])
        for p in k["per_seed"]:
            L.append("  seed %d: %d/%d produced, facade %s -> %s, roof %s -> %s, wt %.0f %%, worse %d, %s; time med %.2f max %.2f s" % (
                p["seed"], p["produced"], p["buildings"], f3(p["facade_before"]), f3(p["facade_after"]),
                f3(p["roof_before"]), f3(p["roof_after"]), p["watertight_pct"], p["worse"], outc(p["outcomes"]),
                p["time_median"], p["time_max"]))
            for pr in p["problems"]:
                L.append("    PROBLEM: " + pr)
            if k["kind"] == "real":
                c, ct = p.get("city") or {}, p.get("city_truth") or {}
                sc = c.get("score", {})
                L.append("    city path: %s; tile outcomes %s; watertight %s/%s; facade %s -> %s" % (
                    city_cell(c), outc(c.get("outcomes", {})), sc.get("watertight", "?"), sc.get("buildings", "?"),
                    f3(sc.get("truth_facade_rmse_orig")), f3(sc.get("truth_facade_rmse_ref"))))
                for l in c.get("changed_lines", []):
                    L.append("      " + l)
                L.append("    --truth-city: %s" % city_cell(ct))
                for l in ct.get("changed_lines", []):
                    L.append("      " + l)
        if k["kind"] == "real":
            c, ct = k["city"], k["city_truth"]
            L.append("  city path, all seeds: correct buildings moved > 5 cm: %d (changed %d of %d, largest %s m); "
                     "outcomes %s; watertight %d/%d (%.1f %%)" % (c["moved_5cm"], c["changed"], c["correct"], f3(c["largest"]),
                                                               outc(c["outcomes"]), c["watertight"], c["scored"], c["watertight_pct"]))
            L.append("  --truth-city, all seeds: correct buildings moved > 5 cm: %d (changed %d of %d, largest %s m)" % (
                ct["moved_5cm"], ct["changed"], ct["correct"], f3(ct["largest"])))
        L.append("  ten worst by truth facade RMSE after (lost first):")
        for w in k["worst"]:
            L.append("    seed %-5d %-20s %-10s %s -> %-6s %-12s %s" % (
                w["seed"], w["id"], w["kind"], f3(w["facade_before"]), f3(w["facade_after"]) if w["facade_after"] is not None else "LOST",
                w["outcome"], w["reason"][:90]))
    return "\n".join(L)


def md_escape(s):
    return str(s).replace("|", "\\|").replace("\n", " ")


def render_md(S):
    m = S["meta"]
    L = ["# lodrefine sweep over fresh tiles", "",
         "- date: %s" % m["date"], "- head: `%s`%s" % (m["head"], " (working tree: %s modified tracked files)" % m["dirty"] if m["dirty"] else ""),
         "- binary: `%s` (`%s`, sha256 %s…%s)" % (m["version"], m["bin"], m["bin_sha256"],
                                                    "; CHANGED during the sweep" if m["bin_changed"] else ""),
         "- K=%d tiles per kind, N=%d buildings, seeds %d..%d; refine timeout %d s; extra refine args: `%s`" % (
             m["k"], m["n"], m["first_seed"], m["first_seed"] + m["k"] - 1, m["timeout"], " ".join(m["extra_args"]) or "-"),
         "- times: generation %.1f s; sweep proper %.1f s (refine %.1f, score %.1f, city_check %.1f), %d jobs" % (
             m["t_gen"], m["t_sweep"], m["t_refine"], m["t_score"], m["t_city"], m["jobs"]),
         "", "## Per kind", "",
         "| kind | buildings | truth facade RMSE (m) | truth roof RMSE (m) | watertight | made worse | lost | outcomes | refine time median / max (s) |",
         "|---|---|---|---|---|---|---|---|---|"]
    for k in S["kinds"]:
        L.append("| %s | %d | %s → %s | %s → %s | %.1f %% | %d | %d | %s | %.2f / %.2f |" % (
            k["kind"], k["buildings"], f3(k["facade_before"]), f3(k["facade_after"]), f3(k["roof_before"]), f3(k["roof_after"]),
            k["watertight_pct"], k["worse"], k["lost"], md_escape(outc(k["outcomes"])), k["time_median"], k["time_max"]))
    L += ["", "Pooling: " + "; ".join("%s %s" % (k["kind"], k["pooling"]) for k in S["kinds"]) +
          ". Made worse: truth facade RMSE after > before + 1 mm.", ""]
    real = [k for k in S["kinds"] if k["kind"] == "real"]
    if real:
        c, ct = real[0]["city"], real[0]["city_truth"]
        L += ["## City path (real tiles, `gen/city_check.py`)", "",
              "| seed | correct buildings moved > 5 cm (changed / correct, largest) | tile outcomes | watertight | truth facade RMSE (m) | `--truth-city`: moved > 5 cm (changed / correct, largest) |",
              "|---|---|---|---|---|---|"]
        for p in real[0]["per_seed"]:
            a, b = p.get("city") or {}, p.get("city_truth") or {}
            sc = a.get("score", {})
            L.append("| %d | %s | %s | %s/%s | %s → %s | %s |" % (
                p["seed"], md_escape(city_cell(a)), md_escape(outc(a.get("outcomes", {}))), sc.get("watertight", "?"),
                sc.get("buildings", "?"), f3(sc.get("truth_facade_rmse_orig")), f3(sc.get("truth_facade_rmse_ref")), md_escape(city_cell(b))))
        L.append("| all | %d (%d / %d, %s m) | %s | %d/%d | | %d (%d / %d, %s m) |" % (
            c["moved_5cm"], c["changed"], c["correct"], f3(c["largest"]), md_escape(outc(c["outcomes"])), c["watertight"], c["scored"],
            ct["moved_5cm"], ct["changed"], ct["correct"], f3(ct["largest"])))
        L.append("")
    L += ["## Per seed", "", "| kind | seed | produced | truth facade RMSE (m) | truth roof RMSE (m) | watertight | made worse | outcomes | time median / max (s) |",
          "|---|---|---|---|---|---|---|---|---|"]
    for k in S["kinds"]:
        for p in k["per_seed"]:
            L.append("| %s | %d | %d/%d | %s → %s | %s → %s | %.0f %% | %d | %s | %.2f / %.2f |" % (
                k["kind"], p["seed"], p["produced"], p["buildings"], f3(p["facade_before"]), f3(p["facade_after"]),
                f3(p["roof_before"]), f3(p["roof_after"]), p["watertight_pct"], p["worse"], md_escape(outc(p["outcomes"])),
                p["time_median"], p["time_max"]))
    for k in S["kinds"]:
        L += ["", "## Ten worst: %s" % k["kind"], "", "| seed | id | kind | truth facade RMSE (m) | outcome | reason |", "|---|---|---|---|---|---|"]
        for w in k["worst"]:
            L.append("| %d | %s | %s | %s → %s | %s | %s |" % (
                w["seed"], w["id"], w["kind"], f3(w["facade_before"]), f3(w["facade_after"]) if w["facade_after"] is not None else "LOST",
                w["outcome"], md_escape(w["reason"])))
    return "\n".join(L) + "\n"


def clean(o):
    if isinstance(o, float) and not math.isfinite(o):
        return None
    if isinstance(o, dict):
        return {k: clean(v) for k, v in o.items()}
    if isinstance(o, (list, tuple)):
        return [clean(v) for v in o]
    return o


def report(out, a):
    import datetime
    tiles = []
    for line in open(os.path.join(out, "manifest.tsv")):
        kind, seed, n, tile, run = line.rstrip("\n").split("\t")
        t = tile_result(kind, seed, n, tile, run)
        if kind == "real":
            t["city"] = parse_city(run, "city"); t["city_truth"] = parse_city(run, "city_truth")
            for c in (t["city"], t["city_truth"]):
                if c.get("ran") and c.get("failed"):
                    t["problems"].append("city_check %s failed (exit %s): see %s/%s.txt" % (c["mode"], c.get("exit"), run, c["mode"]))
        tiles.append(t)
    extra = []
    if a.get("extra_file") and os.path.exists(a["extra_file"]):
        extra = [x for x in open(a["extra_file"], "rb").read().decode(errors="replace").split("\0") if x]
    meta = dict(date=datetime.datetime.now().astimezone().isoformat(timespec="seconds"), head=a.get("head", "?"),
                dirty=int(a.get("dirty", 0)), version=a.get("version", "?"), bin=a.get("bin", "?"),
                bin_sha256=a.get("bin_sha256", "?"), bin_changed=a.get("bin_sha256", "") != a.get("bin_sha256_end", ""),
                k=int(a.get("k", 0)), n=int(a.get("n", 0)), first_seed=int(a.get("first_seed", 0)),
                jobs=int(a.get("jobs", 0)), timeout=int(a.get("timeout", 0)), extra_args=extra,
                **{key: float(a.get(key, "nan")) for key in ("t_gen", "t_refine", "t_score", "t_city", "t_sweep")})
    kinds = []
    for kind in ("synth", "real", "topo"):
        kt = [t for t in tiles if t["kind"] == kind]
        if kt:
            kinds.append(kind_summary(kind, kt))
    S = dict(meta=meta, kinds=kinds,
             buildings=[dict(r, tile_kind=t["kind"]) for t in tiles for r in t["rows"]])
    print(render_text(S))
    json.dump(clean(S), open(os.path.join(out, "sweep.json"), "w"), indent=1)
    open(os.path.join(out, "sweep.md"), "w").write(render_md(S))


def main():
    if len(sys.argv) >= 3 and sys.argv[1] == "counts":
        counts(sys.argv[2])
    elif len(sys.argv) >= 3 and sys.argv[1] == "report":
        a, rest = {}, sys.argv[3:]
        for i in range(0, len(rest) - 1, 2):
            a[rest[i].lstrip("-").replace("-", "_")] = rest[i + 1]
        report(sys.argv[2], a)
    else:
        print(__doc__); sys.exit(2)


main()
