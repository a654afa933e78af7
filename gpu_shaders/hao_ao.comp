/* AO sampling (HAO paper, equation 4) at the reduced resolution: N rays of a regular,
 * cosine-distributed pattern jittered by an object-space hash, S fixed steps each against
 * the bit-packed voxel grid, Wendland weight of the first hit distance. The numpy mirror is
 * hao_addon/core/ao_pattern.py. Output: accessibility, 1 for background and skipped pixels. */
bool occupied(ivec3 g)
{
  if (any(lessThan(g, ivec3(0))) || any(greaterThanEqual(g, grid_dims.xyz))) {
    return false;
  }
  uint word = imageLoad(grid, ivec3(g.xy, g.z >> 5)).r;
  return ((word >> uint(g.z & 31)) & 1u) != 0u;
}

void main()
{
  ivec2 low = ivec2(gl_GlobalInvocationID.xy);
  ivec2 low_size = (full_size + scale - 1) / scale;
  if (any(greaterThanEqual(low, low_size))) {
    return;
  }
  vec4 p;
  ivec2 pick = pick_gbuffer_pixel(low, p);
  float voxel = grid_origin.w;
  vec3 g0 = (p.xyz - grid_origin.xyz) / voxel;
  /* Background, objects with a baked map, and points outside the region: nothing to do. */
  if (p.w < 1.0 || any(lessThan(g0, vec3(0.0))) || any(greaterThanEqual(g0, vec3(grid_dims.xyz)))) {
    imageStore(ao_low, low, vec4(1.0));
    return;
  }
  imageAtomicAdd(sampled_count, ivec2(0), 1u);
  vec3 n = imageLoad(gbuf_normal, pick).xyz;
  vec3 jit = vec3(pcg3d(uvec3(ivec3(floor(p.xyz / voxel))))) * (1.0 / 4294967296.0);
  vec3 t, s;
  tangent_frame(n, t, s);
  float sin_max = sin(spread * 1.5707963267948966);
  float sin_max2 = sin_max * sin_max;
  float offset = HAO_SELF_OFFSET * voxel;
  vec3 start = (p.xyz + n * offset - grid_origin.xyz) / voxel; /* grid units from here on */
  float reach = max_distance / voxel;
  float occlusion = 0.0;
  for (int i = 0; i < rays; i++) {
    float r2 = (float(i) + jit.y) / float(rays) * sin_max2;
    float phi = 6.283185307179586 * fract(float(i) * HAO_GOLDEN_FRACTION + jit.x);
    float r = sqrt(r2);
    vec3 dir = r * cos(phi) * t + r * sin(phi) * s + sqrt(max(1.0 - r2, 0.0)) * n;
    for (int j = 0; j < steps; j++) {
      float tt = (float(j) + jit.z) / float(steps);
      if (occupied(ivec3(floor(start + dir * (tt * reach))))) {
        occlusion += wendland(tt * max_distance + offset, max_distance);
        break;
      }
    }
  }
  imageStore(ao_low, low, vec4(1.0 - occlusion / float(rays)));
}
