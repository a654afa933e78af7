/* Octahedral encoding of unit vectors in two floats (the numpy twin:
 * hao_addon/core/normal_bins.octahedral_coords), so an entry holds two normals in one vec4. */
vec2 octahedral_encode(vec3 n)
{
  vec3 p = n / max(abs(n.x) + abs(n.y) + abs(n.z), 1e-30);
  if (p.z < 0.0) {
    vec2 folded = (1.0 - abs(p.yx)) * vec2(p.x >= 0.0 ? 1.0 : -1.0, p.y >= 0.0 ? 1.0 : -1.0);
    return folded;
  }
  return p.xy;
}

vec3 octahedral_decode(vec2 f)
{
  vec3 n = vec3(f, 1.0 - abs(f.x) - abs(f.y));
  float t = max(-n.z, 0.0);
  n.x += (n.x >= 0.0) ? -t : t;
  n.y += (n.y >= 0.0) ? -t : t;
  return normalize(n);
}
