// The still, opaque geometry the probes' depth cubes draw, simplified as the native client's proxy
// (renderer/src/probe_visibility.h: meshoptimizer to 1.5 % of the probes' reach, about a cube
// texel where probes look): each still mesh's triangles in world space, welded by position and
// simplified to that absolute error. Moving meshes (skinned, instanced, morphed, or under a node an
// animation moves) and cut-outs are drawn as they are. On a detailed scene the cubes then draw a
// fraction of its triangles.
import * as THREE from 'three';
import { mergeVertices } from 'three/addons/utils/BufferGeometryUtils.js';
import { MeshoptSimplifier } from 'three/addons/libs/meshopt_simplifier.module.js';
import { leftOutOfMaps } from './offscreen.js';

export const kProxyError = 0.015;  // kVisibilityProxyError: of the probes' reach
let simplifierReady = false;
MeshoptSimplifier.ready.then(() => { simplifierReady = true; }).catch(() => {});

// The meshes under `root` that move: skinned, instanced, batched or morphed ones, and those under a
// node one of the glTF's animations targets (`parser`: GLTFLoader's, or null: none known).
export function movingMeshes(root, parser) {
  const targets = new Set();
  for (const a of parser?.json?.animations ?? []) for (const c of a.channels ?? []) targets.add(c.target?.node);
  const animated = (o) => {
    for (let n = o; n; n = n.parent) if (targets.has(parser?.associations?.get(n)?.nodes)) return true;
    return false;
  };
  const moving = new Set();
  root.traverse((o) => {
    if (!o.isMesh) return;
    if (o.isSkinnedMesh || o.isInstancedMesh || o.isBatchedMesh || o.geometry?.morphAttributes?.position || animated(o))
      moving.add(o);
  });
  return moving;
}

// A mesh the proxy stands in for: still, drawn into the maps, every material solid (no cut-out).
function replaceable(o, moving) {
  if (!o.isMesh || moving.has(o) || leftOutOfMaps(o) || !o.geometry?.attributes?.position) return false;
  const mats = Array.isArray(o.material) ? o.material : [o.material];
  return mats.every((m) => m && !(m.alphaTest > 0 && m.map));
}

// One mesh's triangles in world space, welded and simplified to `error` metres.
function simplifiedMesh(o, error) {
  const src = o.geometry.attributes.position, n = src.count;
  const pos = new Float32Array(3 * n), v = new THREE.Vector3();
  for (let i = 0; i < n; ++i) v.fromBufferAttribute(src, i).applyMatrix4(o.matrixWorld).toArray(pos, 3 * i);
  const g = new THREE.BufferGeometry();
  g.setAttribute('position', new THREE.BufferAttribute(pos, 3));
  if (o.geometry.index) g.setIndex(Array.from(o.geometry.index.array));
  const welded = mergeVertices(g);
  const indices = Uint32Array.from(welded.index.array);
  const positions = Float32Array.from(welded.attributes.position.array);
  const simplifiable = indices.length >= 3 && positions.every(Number.isFinite);  // as native: else as it is
  const [kept] = simplifiable ? MeshoptSimplifier.simplify(indices, positions, 3, 0, error, ['ErrorAbsolute']) : [indices];
  const out = new THREE.BufferGeometry();
  out.setAttribute('position', new THREE.BufferAttribute(positions, 3));
  out.setIndex(new THREE.BufferAttribute(kept, 1));
  out.computeBoundingSphere();
  return out;
}

export class VisibilityProxy {
  // root: the glTF scene, posed; moving: movingMeshes(root, parser).
  constructor(root, moving) {
    this.root = root;
    this.moving = moving;
    this.error = -1;
    this.group = null;
    this.replaced = new Set();
    this.triangles = { scene: 0, proxy: 0 };
  }

  // The proxy for probes of `reach` (made once per error), or null while the simplifier is not
  // loaded or the reach is unlimited (then the scene is drawn as it is).
  for(reach) {
    if (!simplifierReady || !Number.isFinite(reach)) return null;
    const error = kProxyError * reach;
    if (error === this.error) return this.group;
    this.dispose();
    this.error = error;
    this.group = new THREE.Group();
    this.replaced = new Set();
    this.triangles = { scene: 0, proxy: 0 };
    const material = new THREE.MeshBasicMaterial();
    this.root.updateMatrixWorld(true);
    this.root.traverse((o) => {
      if (!replaceable(o, this.moving)) return;
      const g = simplifiedMesh(o, error);
      this.triangles.scene += (o.geometry.index ? o.geometry.index.count : o.geometry.attributes.position.count) / 3;
      this.triangles.proxy += g.index.count / 3;
      this.group.add(new THREE.Mesh(g, material));  // a piece a mesh: each culled against each face
      this.replaced.add(o);
    });
    return this.group;
  }

  dispose() {
    this.group?.traverse((o) => o.geometry?.dispose());
    this.group?.children[0]?.material.dispose();
    this.group = null;
  }
}
