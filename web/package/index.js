// probecast-three: light a three.js scene from a probecast stream (the package's entry; the
// build bundles it, with the codec beside it, into dist/).
export { ProbeStream } from '../src/probe_stream.js';
export { ProbeLighting } from '../src/probe_lighting.js';
export { AreaLighting } from '../src/area_light_shading.js';
export { extractAreaLights, kAreaLightRuleVersion } from '../src/area_lights.js';
export { lightingBackground, decodeEnvironment } from '../src/environment.js';
export { loadCodec } from '../src/codec.js';
export { useProbecastCurve, LinearLightView } from '../src/tone_curve.js';
export { checkedManifest, sceneFileUrl, safePath, sha256Hex } from '../src/scene_rules.js';
