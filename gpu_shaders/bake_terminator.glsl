/* Cycles' shadow-terminator geometry offset: the GLSL twin of hao_addon/core/bake/terminator.py
 * (see there; Cycles: kernel/light/sample.h). */

/* n * h, how far a ray start at barycentric `bary` of the facet (v0, v1, v2) with corner
 * normals (n0, n1, n2) and facet normal `geometric` is lifted at full amount. */
vec3 smooth_surface_lift(vec3 v0, vec3 v1, vec3 v2, vec3 n0, vec3 n1, vec3 n2, vec3 bary, vec3 geometric)
{
  float u = bary.x, v = bary.y, w = bary.z;
  vec3 p = v0 * u + v1 * v + v2 * w;
  vec3 n = n0 * u + n1 * v + n2 * w;
  float a = dot(n2 - n0, v0 - v2);
  float b = dot(n2 - n1, v1 - v2);
  float c = dot(n1 - n0, v1 - v0);
  float h = a * u * (u - 1.0) + (a + b + c) * u * v + b * v * (v - 1.0);
  float s = (dot(n, geometric) > 0.0) ? 1.0 : -1.0;
  float h0 = max(max(s * dot(v1 - v0, n0), s * dot(v2 - v0, n0)), 0.0);
  float h1 = max(max(s * dot(v0 - v1, n1), s * dot(v2 - v1, n1)), 0.0);
  float h2 = max(max(s * dot(v0 - v2, n2), s * dot(v1 - v2, n2)), 0.0);
  h0 = max(s * dot(v0 - p, n0) + h0, 0.0);
  h1 = max(s * dot(v1 - p, n1) + h1, 0.0);
  h2 = max(s * dot(v2 - p, n2) + h2, 0.0);
  float envelope = min(min(h0, h1), h2);
  float lifted = (s > 0.0) ? max(envelope, 0.5 * h) : min(-envelope, 0.5 * h);
  return n * lifted;
}

/* The share of the lift a direction gets (cos_shading > 0, cos_true about the facet). */
float lift_amount(float cos_shading, float cos_true, float cutoff)
{
  if (cutoff <= 0.0) {
    return 0.0;
  }
  return (cos_shading < cutoff) ? clamp(2.0 - (cos_true + cos_shading) / cutoff, 0.0, 1.0) :
                                  clamp(1.0 - cos_true / cutoff, 0.0, 1.0);
}
