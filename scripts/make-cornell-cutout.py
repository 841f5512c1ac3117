#!/usr/bin/env python3
"""Writes tests/data/scenes/cornell-cutout/: the Cornell box of tests/data/scenes/cornell-box with a
cut-out (alphaMode MASK) checkerboard screen hung under its ceiling light, so that the light's
shadow and the probes' view through the screen depend on what the material cuts away. Standard
library only."""
import json
import os
import struct
import zlib

HERE = os.path.dirname(os.path.abspath(__file__))
SCENES = os.path.join(HERE, '..', 'tests', 'data', 'scenes')


def png_rgba(size, cells):
    """A size² RGBA checkerboard of cells² squares: opaque white and fully transparent."""
    rows = []
    for y in range(size):
        row = bytearray([0])  # filter: none
        for x in range(size):
            solid = ((x * cells // size) + (y * cells // size)) % 2 == 0
            row += bytes([235, 235, 235, 255 if solid else 0])
        rows.append(bytes(row))
    def chunk(kind, data):
        return struct.pack('>I', len(data)) + kind + data + struct.pack('>I', zlib.crc32(kind + data) & 0xffffffff)
    header = struct.pack('>IIBBBBB', size, size, 8, 6, 0, 0, 0)
    return b'\x89PNG\r\n\x1a\n' + chunk(b'IHDR', header) + chunk(b'IDAT', zlib.compress(b''.join(rows), 9)) + chunk(b'IEND', b'')


def main():
    base = json.load(open(os.path.join(SCENES, 'cornell-box', 'CornellBox-Original.gltf')))
    blob = bytearray(open(os.path.join(SCENES, 'cornell-box', 'CornellBox-Original.bin'), 'rb').read())
    # The screen: a square at y = 1.5 m, 1.2 m a side, facing down and up (double-sided), with uvs.
    h, y = 0.6, 1.5
    positions = [(-h, y, -h), (h, y, -h), (h, y, h), (-h, y, -h), (h, y, h), (-h, y, h)]
    normals = [(0.0, -1.0, 0.0)] * 6
    uvs = [(0, 0), (1, 0), (1, 1), (0, 0), (1, 1), (0, 1)]
    def add(values, fmt, count, kind, bounds=False):
        while len(blob) % 4:
            blob.append(0)
        offset = len(blob)
        for v in values:
            blob.extend(struct.pack(fmt, *v))
        base['bufferViews'].append({'buffer': 0, 'byteOffset': offset, 'byteLength': len(blob) - offset})
        accessor = {'bufferView': len(base['bufferViews']) - 1, 'componentType': 5126, 'count': count, 'type': kind}
        if bounds:
            accessor['min'] = [min(v[i] for v in values) for i in range(3)]
            accessor['max'] = [max(v[i] for v in values) for i in range(3)]
        base['accessors'].append(accessor)
        return len(base['accessors']) - 1
    pos = add(positions, '<3f', 6, 'VEC3', bounds=True)
    nrm = add(normals, '<3f', 6, 'VEC3')
    uv = add(uvs, '<2f', 6, 'VEC2')
    base['buffers'] = [{'uri': 'cornell-cutout.bin', 'byteLength': len(blob)}]
    base['images'] = [{'uri': 'checker.png'}]
    base['samplers'] = [{'magFilter': 9728, 'minFilter': 9728}]  # nearest: sharp cells
    base['textures'] = [{'source': 0, 'sampler': 0}]
    base['materials'].append({'name': 'screen', 'alphaMode': 'MASK', 'alphaCutoff': 0.5, 'doubleSided': True,
                              'pbrMetallicRoughness': {'baseColorTexture': {'index': 0}, 'metallicFactor': 0.0,
                                                       'roughnessFactor': 0.9}})
    base['meshes'].append({'name': 'screen', 'primitives': [{'attributes': {'POSITION': pos, 'NORMAL': nrm, 'TEXCOORD_0': uv},
                                                             'material': len(base['materials']) - 1}]})
    base['nodes'].append({'name': 'screen', 'mesh': len(base['meshes']) - 1})
    base['scenes'][base.get('scene', 0)]['nodes'].append(len(base['nodes']) - 1)
    out = os.path.join(SCENES, 'cornell-cutout')
    os.makedirs(out, exist_ok=True)
    open(os.path.join(out, 'cornell-cutout.bin'), 'wb').write(blob)
    open(os.path.join(out, 'checker.png'), 'wb').write(png_rgba(64, 4))
    with open(os.path.join(out, 'cornell-cutout.gltf'), 'w') as f:
        json.dump(base, f, indent=1)


if __name__ == '__main__':
    main()
