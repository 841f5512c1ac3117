// Ray payloads of the probe tracer.
struct HitPayload {
  float t;          // < 0: miss
  uint primitive;
  vec2 barycentrics;
  uint backFace;
};
