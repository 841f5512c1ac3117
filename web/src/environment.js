// The distant light around the stream's scene (its manifest's "lighting"), drawn behind it as the
// native raster client draws it: the map's texel each pixel's ray falls in (nearest, the project's
// equirect convention: top row +Y, centre facing −Z, turned about +Y by the rotation), with the
// intensity applied, through the same curve as the scene. A uniform sky is a 1 × 1 map.
import * as THREE from 'three';
import { printable } from './scene_rules.js';

export const kMaxEnvironmentTexels = 8192 * 4096;

// RGBA floats, top row first, from an .hdr or .exr file's bytes (ArrayBuffer). Throws an Error
// naming the file for a map the page cannot use. The loaders are fetched only when a map is.
// maxSize: the largest texture side the renderer takes.
export async function decodeEnvironment(buffer, path, maxSize = 16384) {
  const lower = path.toLowerCase();
  const hdr = lower.endsWith('.hdr');
  if (!hdr && !lower.endsWith('.exr')) throw new Error(`environment map ${path}: not .hdr or .exr`);
  const loader = hdr ? new (await import('three/addons/loaders/HDRLoader.js')).HDRLoader()
    : new (await import('three/addons/loaders/EXRLoader.js')).EXRLoader();
  loader.setDataType(THREE.FloatType);
  let t;
  try {
    t = loader.parse(buffer);
  } catch (e) {
    throw new Error(`environment map ${path}: unreadable (${e.message})`);
  }
  const { width: w, height: h } = t || {};
  if (!(w >= 1 && h >= 1) || w * h > kMaxEnvironmentTexels || w > maxSize || h > maxSize || !t.data)
    throw new Error(`environment map ${path}: ${w}x${h} is not a map this page takes (at most ${kMaxEnvironmentTexels} texels, ${maxSize} a side)`);
  const channels = t.data.length / (w * h);
  if (channels !== 4) throw new Error(`environment map ${path}: ${channels} channels, not RGBA`);
  const rgba = new Float32Array(w * h * 4);
  // HDRLoader gives rows top first; EXRLoader bottom first (its texture is not flipped).
  const bottomFirst = !hdr;
  for (let y = 0; y < h; ++y) {
    const from = (bottomFirst ? h - 1 - y : y) * w * 4;
    rgba.set(t.data.subarray(from, from + w * 4), y * w * 4);
  }
  for (let i = 0; i < rgba.length; ++i)
    if (!(rgba[i] >= 0) || !Number.isFinite(rgba[i])) throw new Error(`environment map ${path}: texel ${Math.floor(i / 4)} is not finite and non-negative`);
  return { width: w, height: h, rgba };
}

// A mesh that draws `map` ({ width, height, rgba }) behind everything, for any camera (the box
// follows the view's rotation only and lies on the far plane).
// The map's texels are scaled in place (it is not kept).
export function backgroundMesh(map, intensity, rotationDegrees) {
  const data = map.rgba;
  for (let i = 0; i < data.length; i += 4) {
    data[i] *= intensity;
    data[i + 1] *= intensity;
    data[i + 2] *= intensity;
    data[i + 3] = 1;
  }
  const texture = new THREE.DataTexture(data, map.width, map.height, THREE.RGBAFormat, THREE.FloatType);
  texture.minFilter = texture.magFilter = THREE.NearestFilter;
  texture.needsUpdate = true;
  const material = new THREE.ShaderMaterial({
    uniforms: { envMap: { value: texture }, envSize: { value: new THREE.Vector2(map.width, map.height) },
                envRotation: { value: THREE.MathUtils.degToRad(rotationDegrees) } },
    vertexShader: `varying vec3 vEnvDir;
void main() {
  vEnvDir = position;
  vec4 clip = projectionMatrix * vec4(mat3(viewMatrix) * position, 1.0);
  gl_Position = clip.xyww;
}`,
    fragmentShader: `precision highp sampler2D;
uniform sampler2D envMap;
uniform vec2 envSize;
uniform float envRotation;
varying vec3 vEnvDir;
void main() {
  vec3 d = normalize(vEnvDir);
  float c = cos(envRotation), s = sin(envRotation);
  vec3 m = vec3(d.x * c - d.z * s, d.y, d.x * s + d.z * c);  // world to map: R_y(-rotation)
  float theta = acos(clamp(m.y, -1.0, 1.0)), phi = atan(m.x, -m.z);
  const float pi = 3.14159265358979;
  vec2 uv = vec2(phi / (2.0 * pi) + 0.5, theta / pi);
  ivec2 texel = clamp(ivec2(floor(uv * envSize)), ivec2(0), ivec2(envSize) - 1);
  gl_FragColor = vec4(texelFetch(envMap, texel, 0).rgb, 1.0);
  #include <tonemapping_fragment>
  #include <colorspace_fragment>
}`,
    side: THREE.BackSide,
    depthWrite: false,
  });
  material.toneMapped = true;
  const mesh = new THREE.Mesh(new THREE.BoxGeometry(2, 2, 2), material);
  mesh.frustumCulled = false;
  mesh.renderOrder = -1e9;  // first: the scene draws over it
  mesh.userData.probecastBackground = true;
  return mesh;
}

// The background of a manifest's lighting: { environment: { file, intensity, rotation_deg } }
// (`fetchFile(path)` gives its bytes), { sky: [r, g, b] }, or {} (none: black, as natively); any
// other kind, or more than one, is refused as the native viewer refuses it. maxSize: as above.
export async function lightingBackground(lighting, maxSize, fetchFile) {
  if (lighting === undefined) return null;
  if (!lighting || typeof lighting !== 'object' || Array.isArray(lighting) || Object.keys(lighting).length > 1 ||
      Object.keys(lighting).some((k) => k !== 'environment' && k !== 'sky'))
    throw new Error('the stream\'s scene lighting is not {} or one known kind');
  if (lighting.environment) {
    const e = lighting.environment;
    if (typeof e.file !== 'string' || !(e.intensity >= 0) || !Number.isFinite(e.intensity) || !Number.isFinite(e.rotation_deg))
      throw new Error('the stream\'s environment needs a file, an intensity >= 0 and a rotation');
    return backgroundMesh(await decodeEnvironment(await fetchFile(e.file), printable(e.file), maxSize), e.intensity, e.rotation_deg);
  }
  if (lighting.sky) {
    const s = lighting.sky;
    if (!Array.isArray(s) || s.length !== 3 || !s.every((v) => v >= 0 && Number.isFinite(v)))
      throw new Error('the stream\'s sky is not 3 numbers >= 0');
    return backgroundMesh({ width: 1, height: 1, rgba: new Float32Array([...s, 1]) }, 1, 0);
  }
  return null;
}
