/* AO sampling (HAO paper, equation 4) at the reduced resolution: N rays of a regular,
 * cosine-distributed pattern jittered by an object-space hash, marched through the voxel
 * grid (hao_march.glsl: hierarchical, or the paper's fixed steps), each hit weighted by the
 * falloff of its distance. The numpy mirror is hao_addon/core/hao/ao_pattern.py. Output:
 * accessibility, 1 for background and skipped pixels. Counters: [0] sampled pixels, [1]
 * rays that spent their step budget. */

/* Occlusion of a hit at distance t (world units, the start offset included). */
float hit_weight(float t)
{
  if (max_distance <= 0.0) {
    return 1.0; /* unlimited: every hit occludes fully */
  }
#ifdef WENDLAND_FALLOFF
  return wendland(t, max_distance);
#else
  return (t < max_distance) ? 1.0 : 0.0;
#endif
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
  imageAtomicAdd(counters, ivec2(0), 1u);
  vec3 n = imageLoad(gbuf_normal, pick).xyz;
  vec3 jit = vec3(pcg3d(uvec3(ivec3(floor(p.xyz / voxel))))) * (1.0 / 4294967296.0);
  vec3 t, s;
  tangent_frame(n, t, s);
  float sin_max = sin(spread * 1.5707963267948966);
  float sin_max2 = sin_max * sin_max;
#ifdef MARCH_HIERARCHICAL
  float offset = 0.0; /* rays start on the surface; the march skips the receiver's own voxels */
#else
  float offset = HAO_SELF_OFFSET * voxel;
#endif
  vec3 start = (p.xyz + n * offset - grid_origin.xyz) / voxel; /* grid units from here on */
#ifdef MARCH_HIERARCHICAL
  float limit = (max_distance > 0.0) ? max_distance / voxel : 1e30;
  bool exhausted = false;
  int exhausted_rays = 0;
#else
  float reach = (max_distance > 0.0) ? max_distance / voxel : length(vec3(grid_dims.xyz));
#endif
  float occlusion = 0.0;
  for (int i = 0; i < rays; i++) {
    float r2 = (float(i) + jit.y) / float(rays) * sin_max2;
    float phi = 6.283185307179586 * fract(float(i) * HAO_GOLDEN_FRACTION + jit.x);
    float r = sqrt(r2);
    vec3 dir = r * cos(phi) * t + r * sin(phi) * s + sqrt(max(1.0 - r2, 0.0)) * n;
#ifdef MARCH_HIERARCHICAL
    float hit = march_hierarchical(start, n, dir, limit, steps, levels, exhausted);
    exhausted_rays += exhausted ? 1 : 0;
    exhausted = false;
#else
    float hit = march_fixed(start, dir, reach, steps, jit.z);
#endif
    if (hit >= 0.0) {
      occlusion += hit_weight(hit * voxel + offset);
    }
  }
#ifdef MARCH_HIERARCHICAL
  if (exhausted_rays > 0) {
    imageAtomicAdd(counters, ivec2(1, 0), uint(exhausted_rays));
  }
#endif
  imageStore(ao_low, low, vec4(1.0 - occlusion / float(rays)));
}
