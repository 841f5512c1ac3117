#!/usr/bin/env python3
"""Writes tests/data/scenes/normal-wall/: a flat brick wall 4 m × 2 m whose relief is only a
tangent-space normal texture (bevelled bricks, sunken mortar), a floor, a sun grazing the wall from
the upper left and a camera facing it. Lit by the sun alone, the picture is mostly the normal
texture: the bricks' top and left bevels face the sun, their bottom and right ones turn away.
Standard library only (shares the PNG and mesh writers of make-sun-court.py).

    python3 scripts/make-normal-wall.py [OUT_DIR]
"""
import importlib.util
import math
import os
import sys

spec = importlib.util.spec_from_file_location("court", os.path.join(os.path.dirname(os.path.abspath(__file__)), "make-sun-court.py"))
court = importlib.util.module_from_spec(spec)
spec.loader.exec_module(court)


def brick_normals(size=128, brick_w=32, brick_h=16, mortar=2, bevel=3):
    """RGB rows: +X right, +Y up the image, +Z out, encoded as (n + 1) / 2 × 255."""
    tilt = math.radians(40.0)
    s, c = math.sin(tilt), math.cos(tilt)
    rows = []
    for y in range(size):
        row = []
        course = y // brick_h
        for x in range(size):
            bx = (x + (brick_w // 2 if course % 2 else 0)) % brick_w
            by = y % brick_h
            n = (0.0, 0.0, 1.0)
            if bx < mortar or by < mortar:
                n = (0.0, 0.0, 1.0)  # the mortar: flat, sunken (flat to the light)
            elif by < mortar + bevel:
                n = (0.0, s, c)      # the brick's top edge faces up the image
            elif by >= brick_h - bevel:
                n = (0.0, -s, c)
            elif bx < mortar + bevel:
                n = (-s, 0.0, c)
            elif bx >= brick_w - bevel:
                n = (s, 0.0, c)
            row += [round((v + 1.0) * 0.5 * 255.0) for v in n]
        rows.append(row)
    return court.png(size, size, rows)


def main():
    out = sys.argv[1] if len(sys.argv) > 1 else os.path.join(os.path.dirname(__file__), "..", "tests", "data", "scenes", "normal-wall")
    os.makedirs(out, exist_ok=True)
    wall = court.Mesh()
    wall.quad([(-2, 0, 0), (2, 0, 0), (2, 2, 0), (-2, 2, 0)], (0, 0, 1), (2.0, 1.0))  # the texture once a 2 m square
    floor = court.Mesh()
    floor.quad([(-3, 0, 3), (3, 0, 3), (3, 0, -0.5), (-3, 0, -0.5)], (0, 1, 0))
    blob, views, accessors, meshes = court.pack_meshes([("wall", wall, 0), ("floor", floor, 1)])
    doc = {
        "asset": {"version": "2.0", "generator": "probecast scripts/make-normal-wall.py"},
        "extensionsUsed": ["KHR_lights_punctual"],
        "scene": 0,
        "scenes": [{"nodes": [0, 1, 2, 3]}],
        "nodes": [{"name": "camera", "camera": 0, "translation": [0.0, 1.0, 3.2]},
                  {"name": "sun", "extensions": {"KHR_lights_punctual": {"light": 0}},
                   "rotation": court.look_rotation([0.6, -0.6, -0.35])},
                  {"name": "wall", "mesh": 0}, {"name": "floor", "mesh": 1}],
        "cameras": [{"type": "perspective", "perspective": {"yfov": 0.7, "aspectRatio": 1.6, "znear": 0.05, "zfar": 50.0}}],
        "meshes": meshes,
        "materials": [
            {"name": "brick", "pbrMetallicRoughness": {"baseColorFactor": [0.62, 0.3, 0.22, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.85},
             "normalTexture": {"index": 0, "scale": 1.0}},
            {"name": "ground", "pbrMetallicRoughness": {"baseColorFactor": [0.4, 0.4, 0.38, 1.0], "metallicFactor": 0.0, "roughnessFactor": 0.9}},
        ],
        "textures": [{"source": 0, "sampler": 0}],
        "samplers": [{"wrapS": 10497, "wrapT": 10497, "magFilter": 9729, "minFilter": 9987}],
        "images": [{"uri": "bricks_normal.png"}],
        "extensions": {"KHR_lights_punctual": {"lights": [{"name": "sun", "type": "directional", "color": [1.0, 0.97, 0.92], "intensity": 3.0}]}},
        "buffers": [{"uri": "normal-wall.bin", "byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": accessors,
    }
    court.write_scene(out, "normal-wall", doc, blob, {"bricks_normal.png": brick_normals()})

if __name__ == "__main__":
    main()
