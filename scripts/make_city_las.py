#!/usr/bin/env python3
"""A district-wide synthetic MLS tile for a CityJSON city file: every wall of every building
sampled on a grid (5 mm noise), the largest wall of each building scanned SHIFT metres out of
place (something to refine), written as one uncompressed LAS 1.2 (point format 0, class 6).

    scripts/make_city_las.py CITY.json OUT.las [POINTS=16600000] [SHIFT=0.3] [SEED=1]

Measures `refine --model CITY --cloud OUT.las` at district scale (README, City files): the
Rotterdam Delfshaven model with 16.6 M points gives a 330 MB LAS in about a minute. Needs numpy.
"""
import json
import struct
import sys

import numpy as np


def polygons(city):
    """Per building: its wall rings as (n, 3) arrays in the file's real coordinates."""
    tf = city.get("transform", {"scale": [1, 1, 1], "translate": [0, 0, 0]})
    verts = np.array(city["vertices"], dtype=float) * tf["scale"] + tf["translate"]
    for obj in city["CityObjects"].values():
        if obj.get("type") not in ("Building", "BuildingPart"):
            continue
        walls = []
        for g in obj.get("geometry", []):
            if not str(g.get("lod", "")).startswith("2") or g.get("type") != "MultiSurface":
                continue
            sem = g.get("semantics", {})
            kinds = [s["type"] for s in sem.get("surfaces", [])]
            for k, surface in enumerate(g["boundaries"]):
                v = sem.get("values", [None] * len(g["boundaries"]))[k]
                if v is not None and kinds[v] == "WallSurface":
                    walls.append(verts[surface[0]])
            break
        if walls:
            yield walls


def basis(ring):
    """Unit normal and two in-plane axes (Newell's normal)."""
    n = np.zeros(3)
    for a, b in zip(ring, np.roll(ring, -1, axis=0)):
        n += [(a[1] - b[1]) * (a[2] + b[2]), (a[2] - b[2]) * (a[0] + b[0]), (a[0] - b[0]) * (a[1] + b[1])]
    area = np.linalg.norm(n) / 2
    if area == 0:
        return None
    n /= np.linalg.norm(n)
    u = np.cross([0, 0, 1], n)
    u = u / np.linalg.norm(u) if np.linalg.norm(u) > 1e-9 else np.array([1.0, 0, 0])
    return n, u, np.cross(n, u), area


def inside(px, py, poly):
    """Even-odd test of many points against one polygon (2D)."""
    c = np.zeros(px.shape, dtype=bool)
    for (x0, y0), (x1, y1) in zip(poly, np.roll(poly, -1, axis=0)):
        crosses = (y0 > py) != (y1 > py)
        with np.errstate(divide="ignore", invalid="ignore"):
            xc = x0 + (py - y0) * (x1 - x0) / (y1 - y0)
        c ^= crosses & (px < xc)
    return c


def sample(ring, step, offset, rng):
    b = basis(ring)
    if b is None:
        return np.zeros((0, 3))
    n, u, v, _ = b
    o = ring[0]
    p2 = np.stack([(ring - o) @ u, (ring - o) @ v], axis=1)
    us = np.arange(p2[:, 0].min() + step / 2, p2[:, 0].max(), step)
    vs = np.arange(p2[:, 1].min() + step / 2, p2[:, 1].max(), step)
    gu, gv = np.meshgrid(us, vs)
    gu, gv = gu.ravel(), gv.ravel()
    keep = inside(gu, gv, p2)
    gu, gv = gu[keep], gv[keep]
    d = offset + rng.normal(0, 0.005, gu.size)
    return o + np.outer(gu, u) + np.outer(gv, v) + np.outer(d, n)


def write_las(path, pts):
    scale = 0.001
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    offset = np.floor(lo)
    rec = np.zeros(len(pts), dtype=[("xyz", "<i4", 3), ("intensity", "<u2"), ("flags", "u1"), ("cls", "u1"),
                                     ("angle", "i1"), ("user", "u1"), ("source", "<u2")])
    rec["xyz"] = np.round((pts - offset) / scale).astype("<i4")
    rec["flags"] = 0b00001001  # return 1 of 1
    rec["cls"] = 6
    header = struct.pack("<4sHHI2sH8sBB32s32sHHHIIBHI5I3d3d6d", b"LASF", 0, 0, 0, b"\0\0", 0, b"\0" * 8, 1, 2,
                         b"lodrefine", b"make_city_las.py", 1, 2026, 227, 227, 0, 0, 20, len(pts),
                         len(pts), 0, 0, 0, 0, scale, scale, scale, *offset,
                         hi[0], lo[0], hi[1], lo[1], hi[2], lo[2])
    assert len(header) == 227
    with open(path, "wb") as f:
        f.write(header)
        f.write(rec.tobytes())


def main():
    if len(sys.argv) < 3:
        sys.exit(__doc__)
    city = json.load(open(sys.argv[1]))
    target = int(sys.argv[3]) if len(sys.argv) > 3 else 16600000
    shift = float(sys.argv[4]) if len(sys.argv) > 4 else 0.3
    rng = np.random.default_rng(int(sys.argv[5]) if len(sys.argv) > 5 else 1)
    buildings = list(polygons(city))
    area = sum(basis(w)[3] for b in buildings for w in b if basis(w) is not None)
    step = np.sqrt(area / target)
    parts = []
    for walls in buildings:
        areas = [basis(w)[3] if basis(w) is not None else 0 for w in walls]
        largest = int(np.argmax(areas))
        parts += [sample(w, step, shift if k == largest else 0.0, rng) for k, w in enumerate(walls)]
    pts = np.concatenate(parts)
    write_las(sys.argv[2], pts)
    print(f"{len(buildings)} buildings, {area:.0f} m2 of walls, step {step * 100:.1f} cm: {len(pts)} points -> {sys.argv[2]}")


if __name__ == "__main__":
    main()
