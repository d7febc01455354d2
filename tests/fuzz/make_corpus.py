#!/usr/bin/env python3
"""Writes the small seed corpus of the fuzz targets into corpus/<target>/ (deterministic).
Run from anywhere: python3 tests/fuzz/make_corpus.py"""
import os
import random
import struct

HERE = os.path.dirname(os.path.abspath(__file__))


def put(target, name, data):
    d = os.path.join(HERE, "corpus", target)
    os.makedirs(d, exist_ok=True)
    with open(os.path.join(d, name), "wb") as f:
        f.write(data if isinstance(data, bytes) else data.encode())


def box_obj(x0, x1, y0, y1, h, ox=0.0, oy=0.0, name="box"):
    c = [(x0, y0, 0), (x1, y0, 0), (x1, y1, 0), (x0, y1, 0), (x0, y0, h), (x1, y0, h), (x1, y1, h), (x0, y1, h)]
    quads = [(0, 3, 2, 1), (4, 5, 6, 7), (0, 1, 5, 4), (1, 2, 6, 5), (2, 3, 7, 6), (3, 0, 4, 7)]
    groups = ["GroundSurface", "RoofSurface", "WallSurface", "WallSurface", "WallSurface", "WallSurface"]
    out = [f"o {name}"]
    n = 0
    for q, g in zip(quads, groups):
        out.append(f"g {g}")
        for k in q:
            x, y, z = c[k]
            out.append(f"v {x + ox:.3f} {y + oy:.3f} {z:.3f}")
        out.append("f " + " ".join(str(n + i + 1) for i in range(4)))
        n += 4
    return "\n".join(out) + "\n"


def wall_points(n_u, n_v, x0, x1, z1, y, rng, noise=0.005):
    pts = []
    for i in range(n_u):
        for j in range(n_v):
            x = x0 + (x1 - x0) * (i + 0.5) / n_u
            z = 0.2 + (z1 - 0.2) * (j + 0.5) / n_v
            pts.append((x, y + rng.gauss(0, noise), z))
    return pts


def ply(points, fmt="binary_little_endian", typ="float", extra=""):
    head = f"ply\nformat {fmt} 1.0\nelement vertex {len(points)}\n"
    head += "".join(f"property {typ} {a}\n" for a in "xyz") + extra + "end_header\n"
    if fmt == "ascii":
        return (head + "".join(f"{x:.3f} {y:.3f} {z:.3f}\n" for x, y, z in points)).encode()
    code = {"float": "f", "double": "d", "uchar": "B", "short": "h", "int": "i"}[typ]
    endian = "<" if fmt == "binary_little_endian" else ">"
    body = b"".join(struct.pack(endian + code * 3, *p) for p in points)
    return head.encode() + body


MIN_RECORD = [20, 28, 26, 34, 57, 63, 30, 36, 38, 59, 67]


def las(points, minor=2, fmt=1, extra=0, classes=None, offset=(85000.0, 447000.0, 0.0)):
    """Uncompressed LAS 1.minor, point format fmt, scale 1 mm (as write_las in src/formats/las.cpp)."""
    header = {2: 227, 3: 235, 4: 375}[minor]
    rec = MIN_RECORD[fmt] + extra
    n = len(points)
    legacy = n if fmt < 6 else 0
    xs = [p[0] for p in points] or [0]
    ys = [p[1] for p in points] or [0]
    zs = [p[2] for p in points] or [0]
    h = b"LASF" + struct.pack("<HH16sBB32s32sHHHIIBHI5I", 0, 0, b"", 1, minor, b"fuzz", b"fuzz", 1, 2026, header,
                              header, 0, fmt, rec, legacy, legacy, 0, 0, 0, 0)
    h += struct.pack("<3d3d6d", 0.001, 0.001, 0.001, *offset, max(xs), min(xs), max(ys), min(ys), max(zs), min(zs))
    if minor >= 3:
        h += struct.pack("<Q", 0)
    if minor >= 4:
        h += struct.pack("<QIQ15Q", 0, 0, n, n, *([0] * 14))
    assert len(h) == header
    body = b""
    for i, (x, y, z) in enumerate(points):
        r = bytearray(rec)
        struct.pack_into("<3i", r, 0, *(round((v - o) / 0.001) for v, o in zip((x, y, z), offset)))
        c = classes[i] if classes else 1
        if fmt >= 6:
            r[14], r[16] = 0x11, c & 0xFF
        else:
            r[14], r[15] = 0x09, c & 0x1F
        body += bytes(r)
    return h + body


class ArithmeticEncoder:
    """LASzip's arithmetic encoder with adaptive models: enough to write a LAZ chunk table."""
    MIN = 1 << 24

    def __init__(self):
        self.base, self.length, self.out = 0, 0xFFFFFFFF, bytearray()

    def _carry(self):
        i = len(self.out) - 1
        while self.out[i] == 0xFF:
            self.out[i] = 0
            i -= 1
        self.out[i] += 1

    def _renorm(self):
        while True:
            self.out.append(self.base >> 24)
            self.base = (self.base << 8) & 0xFFFFFFFF
            self.length = (self.length << 8) & 0xFFFFFFFF
            if self.length >= self.MIN:
                break

    def _moved(self, init_base):
        if init_base > self.base:
            self._carry()
        if self.length < self.MIN:
            self._renorm()

    def symbol(self, m, sym):
        init_base = self.base
        if sym == m.n - 1:
            x = m.dist[sym] * (self.length >> 15)
            self.base = (self.base + x) & 0xFFFFFFFF
            self.length -= x
        else:
            self.length >>= 15
            x = m.dist[sym] * self.length
            self.base = (self.base + x) & 0xFFFFFFFF
            self.length = m.dist[sym + 1] * self.length - x
        self._moved(init_base)
        m.count[sym] += 1
        m.until -= 1
        if m.until == 0:
            m.update()

    def bit(self, m, bit):
        x = m.prob * (self.length >> 13)
        init_base = self.base
        if bit == 0:
            self.length = x
            m.zeros += 1
        else:
            self.base = (self.base + x) & 0xFFFFFFFF
            self.length -= x
        self._moved(init_base)
        m.until -= 1
        if m.until == 0:
            m.update()

    def bits(self, n, value):
        if n > 19:
            self.bits(16, value & 0xFFFF)
            value, n = value >> 16, n - 16
        init_base = self.base
        self.length >>= n
        self.base = (self.base + value * self.length) & 0xFFFFFFFF
        self._moved(init_base)

    def done(self):
        init_base, another = self.base, True
        if self.length > 2 * self.MIN:
            self.base = (self.base + self.MIN) & 0xFFFFFFFF
            self.length = self.MIN >> 1
        else:
            self.base = (self.base + (self.MIN >> 1)) & 0xFFFFFFFF
            self.length = self.MIN >> 9
            another = False
        if init_base > self.base:
            self._carry()
        self._renorm()
        self.out += b"\0\0" + (b"\0" if another else b"")
        return bytes(self.out)


class SymbolModel:
    def __init__(self, n):
        self.n, self.count, self.total, self.cycle = n, [1] * n, 0, n
        self.update()
        self.until = self.cycle = (n + 6) >> 1

    def update(self):
        self.total += self.cycle
        if self.total > 1 << 15:
            self.count = [(c + 1) >> 1 for c in self.count]
            self.total = sum(self.count)
        scale, acc, self.dist = 0x80000000 // self.total, 0, []
        for c in self.count:
            self.dist.append((scale * acc) >> 16)
            acc += c
        self.cycle = min((5 * self.cycle) >> 2, (self.n + 6) << 3)
        self.until = self.cycle


class BitModel:
    def __init__(self):
        self.cycle = self.until = 4
        self.prob, self.zeros, self.total = 1 << 12, 1, 2

    def update(self):
        self.total += self.cycle
        if self.total > 1 << 13:
            self.total, self.zeros = (self.total + 1) >> 1, (self.zeros + 1) >> 1
            if self.zeros == self.total:
                self.total += 1
        self.prob = (self.zeros * (0x80000000 // self.total)) >> 18
        self.cycle = min((5 * self.cycle) >> 2, 64)
        self.until = self.cycle


class IntegerCompressor:
    """LASzip's integer compressor for 32-bit values (corrector bits 32, 8 of them modelled)."""

    def __init__(self, contexts):
        self.k_models = [SymbolModel(33) for _ in range(contexts)]
        self.corr = [SymbolModel(1 << min(i, 8)) for i in range(1, 33)]
        self.corr0 = BitModel()

    def compress(self, enc, pred, value, ctx):
        c = (value - pred + (1 << 31)) % (1 << 32) - (1 << 31)
        k = (-c if c <= 0 else c - 1).bit_length()
        enc.symbol(self.k_models[ctx], k)
        if k == 0:
            enc.bit(self.corr0, c)
        elif k < 32:
            c = c + (1 << k) - 1 if c < 0 else c - 1
            if k <= 8:
                enc.symbol(self.corr[k - 1], c)
            else:
                enc.symbol(self.corr[k - 1], c >> (k - 8))
                enc.bits(k - 8, c & ((1 << (k - 8)) - 1))


ITEMS = {  # point format -> LASzip items (type, size, version) before the extra bytes
    0: [(6, 20, 2)], 1: [(6, 20, 2), (7, 8, 2)], 2: [(6, 20, 2), (8, 6, 2)], 3: [(6, 20, 2), (7, 8, 2), (8, 6, 2)],
    6: [(10, 30, 3)], 7: [(10, 30, 3), (11, 6, 3)], 8: [(10, 30, 3), (12, 8, 3)],
}


def laz(las_bytes, variable=False):
    """The LAS file (no VLRs) as LAZ with one point per chunk: each chunk is its point raw, then
    (compressor 2) the empty arithmetic stream or (compressor 3) the point count and empty
    layers. The chunk table is coded as LASzip does (fixed chunks of 1, or variable)."""
    header = struct.unpack_from("<H", las_bytes, 94)[0]
    fmt, rec = las_bytes[104], struct.unpack_from("<H", las_bytes, 105)[0]
    items = list(ITEMS[fmt])
    extra = rec - sum(size for _, size, _ in items)
    layered = fmt >= 6
    if extra:
        items.append((14 if layered else 0, extra, 3 if layered else 2))
    payload = struct.pack("<HHBBHIIqqH", 3 if layered else 2, 0, 3, 4, 3, 0, 0xFFFFFFFF if variable else 1, -1, -1,
                          len(items))
    payload += b"".join(struct.pack("<3H", *it) for it in items)
    vlr = struct.pack("<H16sHH32s", 0, b"laszip encoded", 22204, len(payload), b"fuzz") + payload
    points = [las_bytes[i:i + rec] for i in range(header, len(las_bytes), rec)]
    if layered:
        layers = 9 + (1 if fmt == 7 else 2 if fmt == 8 else 0) + extra
        chunks = [p + struct.pack("<I", 1) + bytes(4 * layers) for p in points]
    else:
        chunks = [p + b"\x01\0\0\0" for p in points]
    enc, ic = ArithmeticEncoder(), IntegerCompressor(2)
    last_count = last_bytes = 0
    for c in chunks:
        if variable:
            ic.compress(enc, last_count, 1, 0)
            last_count = 1
        ic.compress(enc, last_bytes, len(c), 1)
        last_bytes = len(c)
    offset = header + len(vlr)
    data = b"".join(chunks)
    table_at = offset + 8 + len(data)
    h = bytearray(las_bytes[:header])
    h[104] = fmt | 0x80
    struct.pack_into("<II", h, 96, offset, 1)
    table = struct.pack("<II", 0, len(chunks)) + (enc.done() if chunks else b"")
    return bytes(h) + vlr + struct.pack("<q", table_at) + data + table


def main():
    rng = random.Random(7)
    # --- OBJ reader seeds
    put("fuzz_obj", "box.obj", box_obj(0, 6, 0, 4, 3, 85000.0, 447000.0))
    put("fuzz_obj", "tri.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    put("fuzz_obj", "negative.obj", "# id: neg\nv 0 0 0\nv 1 0 0\nv 0 1 0\nf -3 -2 -1\nf 1 2\n")
    put("fuzz_obj", "slashes.obj",
        "mtllib x.mtl\nv 0 0 0\nv 1 0 0 1\nv 0 1 0 0.5 0.5 0.5\nvt 0 0\nvn 0 0 1\ns off\n"
        "usemtl RoofSurface\nf 1/1/1 2/1/1 3/1/1\nf 1//1 2//1 3//1\nf 1/1 2/1 3/1\n")
    put("fuzz_obj", "forward.obj", "f 1 2 3\nv 0 0 0\nv 1 0 0\nv 0 1 0\r\n")
    put("fuzz_obj", "exp.obj", "v 1e3 -2.5E-2 +7\nv 0x1 0 0\nv 1 1 1\nf 1 2 3\n")
    # --- PLY reader seeds
    pts = wall_points(4, 3, 0, 6, 3, 0.0, rng)
    put("fuzz_ply", "ascii.ply", ply(pts, "ascii"))
    put("fuzz_ply", "le_float.ply", ply(pts))
    put("fuzz_ply", "be_double.ply", ply(pts[:4], "binary_big_endian", "double"))
    put("fuzz_ply", "uchar.ply", ply([(1, 2, 3), (4, 5, 6)], typ="uchar"))
    put("fuzz_ply", "short.ply", ply([(1, -2, 3), (400, 5, -6)], typ="short"))
    face_ply = ("ply\nformat ascii 1.0\ncomment made by hand\nelement vertex 3\nproperty float x\nproperty float y\n"
                "property float z\nproperty uchar red\nelement face 1\nproperty list uchar int vertex_indices\n"
                "end_header\n0 0 0 255\n1 0 0 0\n0 1 0 7\n3 0 1 2\n")
    put("fuzz_ply", "faces.ply", face_ply)
    pre = (b"ply\nformat binary_little_endian 1.0\nelement camera 1\nproperty list uchar float m\n"
           b"element vertex 1\nproperty double z\nproperty double y\nproperty double x\nend_header\n"
           + struct.pack("<B2f", 2, 1.0, 2.0) + struct.pack("<3d", 3.0, 2.0, 1.0))
    put("fuzz_ply", "list_first.ply", pre)
    # --- LAS reader seeds: each version, formats 0-10, extra bytes, classes
    geo = [(85000.0 + x, 447000.0 + y, z) for x, y, z in pts[:6]]
    cls = [2, 6, 1, 200, 6, 2]
    put("fuzz_las", "v12_f0.las", las(geo, 2, 0, classes=cls))
    put("fuzz_las", "v12_f1_extra.las", las(geo, 2, 1, extra=3, classes=cls))
    put("fuzz_las", "v13_f3.las", las(geo[:3], 3, 3, classes=cls))
    put("fuzz_las", "v13_f5.las", las(geo[:2], 3, 5, classes=cls))
    put("fuzz_las", "v14_f6.las", las(geo, 4, 6, classes=cls))
    put("fuzz_las", "v14_f10.las", las(geo[:2], 4, 10, classes=cls))
    put("fuzz_las", "v14_f1_empty.las", las([], 4, 1))
    # --- LAZ seeds: the same points compressed, one point per chunk (the LAS twin beside it)
    for name, data in [("v12_f0", las(geo, 2, 0, classes=cls)), ("v12_f1_extra", las(geo, 2, 1, extra=3, classes=cls)),
                       ("v12_f2", las(geo[:4], 2, 2, classes=cls)), ("v13_f3", las(geo[:3], 3, 3, classes=cls)),
                       ("v14_f6", las(geo, 4, 6, classes=cls)), ("v14_f7", las(geo[:3], 4, 7, classes=cls)),
                       ("v14_f8_extra", las(geo[:3], 4, 8, extra=2, classes=cls))]:
        put("fuzz_laz", name + ".las", data)
        put("fuzz_laz", name + ".laz", laz(data, variable=name.endswith("f1_extra") or name.endswith("f7")))
    put("fuzz_laz", "v14_f1_empty.laz", laz(las([], 4, 1)))
    # --- whole refine: [len lo, len hi, flags] + OBJ + PLY
    for name, flags, cloud in [
        ("moved_wall_tiny", 1, wall_points(10, 6, 0.3, 5.7, 2.8, 0.0, rng)),   # model wall at y = -0.4
        ("moved_wall_ascii", 1, None),
        ("few_points", 0, wall_points(2, 2, 1, 5, 2, 0.0, rng)),
    ]:
        obj = box_obj(0, 6, -0.4, 4, 3).encode()
        if cloud is None:
            data = ply(wall_points(8, 5, 0.3, 5.7, 2.8, 0.0, rng), "ascii")
        else:
            data = ply(cloud)
        put("fuzz_refine", name, struct.pack("<HB", len(obj), flags) + obj + data)


if __name__ == "__main__":
    main()
