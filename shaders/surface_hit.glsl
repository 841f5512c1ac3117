// The surface point an any-hit shader is looking at: its material and texture coordinates. The
// instance's custom index is the BLAS's first triangle in the scene's order (vk_acceleration.cpp).
hitAttributeEXT vec2 attribs;

uint hitTriangle() { return uint(gl_InstanceCustomIndexEXT) + uint(gl_PrimitiveID); }

vec4 hitTexcoords(uint tri) {
  vec3 bary = vec3(1.0 - attribs.x - attribs.y, attribs);
  vec4 uvs = vec4(0.0);
  for (int k = 0; k < 3; ++k) {
    uint i = indices[3 * tri + uint(k)];
    uvs += bary[k] * vec4(texcoords[4 * i], texcoords[4 * i + 1], texcoords[4 * i + 2], texcoords[4 * i + 3]);
  }
  return uvs;
}
