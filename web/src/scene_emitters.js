// A three.js scene's emitting triangles as the area-light rule (area_lights.js) takes them. No
// shaders here: web/test/area_lights_test.mjs runs it in Node.
import * as THREE from 'three';

// The scene's materials and world-space triangles as extractAreaLights takes them, posed as the
// scene stands now. Materials are numbered by their glTF index (three.js may hold copies of one;
// parser.associations maps them back), as the native loader numbers them, and described from the
// glTF itself (alpha mode, transmission, emissive texture); materials three.js made up follow.
// Only triangles of emitting materials are walked: the others emit nothing and change nothing.
export function sceneEmitters(root, parser) {
  const json = parser?.json?.materials ?? [];
  const materials = json.map(() => ({ emission: [0, 0, 0], textured: false, opaque: true }));
  const extra = new Map(), corners = [], triangleMaterial = [];
  const materialOf = (m) => {
    const gltfIndex = parser?.associations?.get(m)?.materials;
    let i = Number.isInteger(gltfIndex) && gltfIndex < materials.length ? gltfIndex : extra.get(m.uuid);
    if (i === undefined) {
      i = materials.length;
      extra.set(m.uuid, i);
      materials.push({ emission: [0, 0, 0], textured: !!m.emissiveMap, opaque: !m.transparent && !(m.transmission > 0) });
    }
    const e = m.emissive ? [m.emissive.r, m.emissive.g, m.emissive.b].map((c) => c * (m.emissiveIntensity ?? 1)) : [0, 0, 0];
    materials[i].emission = e;
    const j = json[i];
    if (j && i === gltfIndex) {
      const transmission = j.extensions?.KHR_materials_transmission?.transmissionFactor ?? 0;
      materials[i].textured = j.emissiveTexture !== undefined;
      materials[i].opaque = (j.alphaMode ?? 'OPAQUE') === 'OPAQUE' && !(transmission > 0);
    }
    return i;
  };
  root.updateMatrixWorld(true);
  const v = [new THREE.Vector3(), new THREE.Vector3(), new THREE.Vector3()];
  root.traverse((o) => {
    if (!o.isMesh || !o.visible || !o.geometry?.attributes?.position) return;
    const g = o.geometry, pos = g.attributes.position, idx = g.index;
    const count = idx ? idx.count : pos.count;
    const flip = o.matrixWorld.determinant() < 0;  // mirrored nodes reverse winding
    const groups = Array.isArray(o.material) ? g.groups : [{ start: 0, count, materialIndex: 0 }];
    for (const grp of groups) {
      const mat = Array.isArray(o.material) ? o.material[grp.materialIndex] : o.material;
      if (!mat) continue;
      const m = materialOf(mat);
      if (!materials[m].emission.some((c) => c > 0)) continue;
      const end = Math.min(grp.start + grp.count, count);
      for (let i = grp.start; i + 3 <= end; i += 3) {
        for (let k = 0; k < 3; ++k) v[k].fromBufferAttribute(pos, idx ? idx.getX(i + k) : i + k).applyMatrix4(o.matrixWorld);
        const order = flip ? [0, 2, 1] : [0, 1, 2];
        for (const k of order) corners.push(v[k].x, v[k].y, v[k].z);
        triangleMaterial.push(m);
      }
    }
  });
  return { materials, corners, triangleMaterial };
}
