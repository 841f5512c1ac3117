#!/usr/bin/env python3
"""Writes tests/data/scenes/sun-court/: a 24 m square courtyard open to the sky, walls 6 m high,
four pillars and a low block, a chequered stone floor (a PNG texture repeated every 2 m), a sun
falling across it at a slant and a camera in one corner. Larger than a room, so a sun's shadow has
to cover tens of metres; textured, so minified texels show. Standard library only.

    python3 scripts/make-sun-court.py [OUT_DIR]
"""
import json
import math
import os
import struct
import sys
import zlib


def png(width, height, rgb_rows):
    def chunk(kind, data):
        return struct.pack(">I", len(data)) + kind + data + struct.pack(">I", zlib.crc32(kind + data) & 0xFFFFFFFF)
    raw = b"".join(b"\x00" + bytes(row) for row in rgb_rows)
    return (b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", struct.pack(">IIBBBBB", width, height, 8, 2, 0, 0, 0))
            + chunk(b"IDAT", zlib.compress(raw, 9)) + chunk(b"IEND", b""))


def checker(size=64, cells=8):
    rows = []
    for y in range(size):
        row = []
        for x in range(size):
            light = ((x * cells // size) + (y * cells // size)) % 2 == 0
            row += [200, 190, 170] if light else [70, 66, 60]
        rows.append(row)
    return png(size, size, rows)


def normalize(v):
    n = math.sqrt(sum(x * x for x in v))
    return [x / n for x in v]


def look_rotation(direction):
    """The quaternion (x, y, z, w) turning −Z to `direction` by yaw about +Y then pitch, no roll."""
    d = normalize(direction)
    yaw = math.atan2(-d[0], -d[2])
    pitch = math.asin(d[1])
    cy, sy, cp, sp = math.cos(yaw / 2), math.sin(yaw / 2), math.cos(pitch / 2), math.sin(pitch / 2)
    # q = q_yaw(Y) · q_pitch(X)
    return [round(v, 6) for v in (cy * sp, sy * cp, -sy * sp, cy * cp)]


class Mesh:
    def __init__(self):
        self.positions, self.normals, self.uvs, self.indices = [], [], [], []

    def quad(self, corners, normal, uv_scale=(1.0, 1.0)):
        base = len(self.positions)
        for p, uv in zip(corners, [(0, 1), (1, 1), (1, 0), (0, 0)]):
            self.positions.append(p)
            self.normals.append(normal)
            self.uvs.append((uv[0] * uv_scale[0], uv[1] * uv_scale[1]))
        self.indices += [base, base + 1, base + 2, base, base + 2, base + 3]

    def box(self, lo, hi):
        (x0, y0, z0), (x1, y1, z1) = lo, hi
        self.quad([(x0, y1, z1), (x1, y1, z1), (x1, y1, z0), (x0, y1, z0)], (0, 1, 0))
        self.quad([(x0, y0, z0), (x1, y0, z0), (x1, y0, z1), (x0, y0, z1)], (0, -1, 0))
        self.quad([(x0, y0, z1), (x1, y0, z1), (x1, y1, z1), (x0, y1, z1)], (0, 0, 1))
        self.quad([(x1, y0, z0), (x0, y0, z0), (x0, y1, z0), (x1, y1, z0)], (0, 0, -1))
        self.quad([(x1, y0, z1), (x1, y0, z0), (x1, y1, z0), (x1, y1, z1)], (1, 0, 0))
        self.quad([(x0, y0, z0), (x0, y0, z1), (x0, y1, z1), (x0, y1, z0)], (-1, 0, 0))


def pack_meshes(meshes):
    """[(name, Mesh, material)] → the buffer's bytes, bufferViews, accessors and glTF meshes."""
    blob, views, accessors = bytearray(), [], []

    def add(data, fmt, count, kind, target, minmax=None):
        while len(blob) % 4:
            blob.append(0)
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data), "target": target})
        blob.extend(data)
        acc = {"bufferView": len(views) - 1, "componentType": fmt, "count": count, "type": kind}
        if minmax:
            acc["min"], acc["max"] = minmax
        accessors.append(acc)
        return len(accessors) - 1

    def flat(vs):
        return b"".join(struct.pack("<%df" % len(v), *v) for v in vs)

    gltf_meshes = []
    for name, m, material in meshes:
        lo = [min(p[i] for p in m.positions) for i in range(3)]
        hi = [max(p[i] for p in m.positions) for i in range(3)]
        attrs = {"POSITION": add(flat(m.positions), 5126, len(m.positions), "VEC3", 34962, (lo, hi)),
                 "NORMAL": add(flat(m.normals), 5126, len(m.normals), "VEC3", 34962),
                 "TEXCOORD_0": add(flat(m.uvs), 5126, len(m.uvs), "VEC2", 34962)}
        idx = add(struct.pack("<%dI" % len(m.indices), *m.indices), 5125, len(m.indices), "SCALAR", 34963)
        gltf_meshes.append({"name": name, "primitives": [{"attributes": attrs, "indices": idx, "material": material}]})
    return blob, views, accessors, gltf_meshes


def write_scene(out, name, doc, blob, images):
    """OUT/NAME.gltf, OUT/NAME.bin and the images ({file name: PNG bytes})."""
    with open(os.path.join(out, name + ".bin"), "wb") as f:
        f.write(blob)
    for file, data in images.items():
        with open(os.path.join(out, file), "wb") as f:
            f.write(data)
    with open(os.path.join(out, name + ".gltf"), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")
    print("wrote", os.path.join(out, name + ".gltf"))


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "tests", "data", "scenes", "sun-court")
    os.makedirs(out, exist_ok=True)
    h = 12.0
    floor = Mesh()
    floor.quad([(-h, 0, h), (h, 0, h), (h, 0, -h), (-h, 0, -h)], (0, 1, 0), (12.0, 12.0))
    walls = Mesh()
    for lo, hi in [((-h - 0.5, 0, -h - 0.5), (h + 0.5, 6, -h)), ((-h - 0.5, 0, h), (h + 0.5, 6, h + 0.5)),
                   ((-h - 0.5, 0, -h), (-h, 6, h)), ((h, 0, -h), (h + 0.5, 6, h))]:
        walls.box(lo, hi)
    for x, z in [(-5, -5), (5, -5), (-5, 5), (5, 5)]:
        walls.box((x - 0.6, 0, z - 0.6), (x + 0.6, 4.5, z + 0.6))
    walls.box((-3, 0, -1), (3, 1.2, 1))
    meshes = [("floor", floor, 0), ("walls", walls, 1)]

    blob, views, accessors, gltf_meshes = pack_meshes(meshes)

    # The sun: travelling down and across (−Y, +X, +Z, about 50° above the horizon); the camera in
    # the −X, +Z corner at eye height, looking across the court.
    sun = {"name": "sun", "extensions": {"KHR_lights_punctual": {"light": 0}},
           "rotation": look_rotation([0.55, -1.0, 0.35])}
    camera = {"name": "corner", "camera": 0, "translation": [-10.0, 1.7, 10.0],
              "rotation": look_rotation([13.0, -1.2, -13.0])}
    doc = {
        "asset": {"version": "2.0", "generator": "probecast scripts/make-sun-court.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [camera, sun, {"name": "floor", "mesh": 0}, {"name": "walls", "mesh": 1}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 1.0, "aspectRatio": 1.3333, "znear": 0.05, "zfar": 200.0}}],
        "meshes": gltf_meshes,
        "materials": [
            {"name": "stone floor", "pbrMetallicRoughness": {"baseColorTexture": {"index": 0}, "metallicFactor": 0.0, "roughnessFactor": 0.9}},
            {"name": "plaster", "pbrMetallicRoughness": {"baseColorFactor": [0.75, 0.7, 0.62, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.8}},
        ],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497, "magFilter": 9729, "minFilter": 9987}],
        "images": [{"uri": "floor.png"}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"name": "sun", "type": "directional", "color": [1.0, 0.96, 0.9], "intensity": 3.0}]}},
        "buffers": [{"uri": "sun-court.bin", "byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    write_scene(out, "sun-court", doc, blob, {"floor.png": checker()})

if __name__ == "__main__":
    main()
