/* AO sampling (HAO paper, equation 4) at the reduced resolution: N rays of a regular,
 * cosine-distributed pattern jittered by an object-space hash, marched through the voxel
 * grids (hao_march.glsl: hierarchical from the finest cascade holding the point outwards,
 * or the paper's fixed steps in one grid), each hit weighted by the falloff of its distance.
 * The numpy mirror is hao_addon/core/hao/ao_pattern.py. Output: accessibility, 1 for
 * background and skipped pixels. Counters: [0] sampled pixels, [1] rays that spent their
 * step budget. */

/* The finest cascade holding point q, or -1 (outside the region). */
int cascade_of(vec3 q)
{
  for (int k = 0; k < cascades.count.x; k++) {
    vec3 g = (q - cascades.origin_voxel[k].xyz) / cascades.origin_voxel[k].w;
    if (all(greaterThanEqual(g, vec3(0.0))) && all(lessThan(g, vec3(cascades.dims[k].xyz)))) {
      return k;
    }
  }
  return -1;
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
  int first = (p.w < 1.0) ? -1 : cascade_of(p.xyz);
  /* Background, objects with a baked map, and points outside the region: nothing to do. */
  if (first < 0) {
    imageStore(ao_low, low, vec4(1.0));
    return;
  }
  imageAtomicAdd(counters, ivec2(0), 1u);
  vec3 n = imageLoad(gbuf_normal, pick).xyz;
  float voxel = cascades.origin_voxel[first].w;
  vec3 jit = vec3(pcg3d(uvec3(ivec3(floor(p.xyz / voxel))))) * (1.0 / 4294967296.0);
  vec3 t, s;
  tangent_frame(n, t, s);
  float sin_max = sin(spread * 1.5707963267948966);
  float sin_max2 = sin_max * sin_max;
#ifdef MARCH_HIERARCHICAL
  int exhausted_rays = 0;
#else
  use_cascade(first);
  float offset = HAO_SELF_OFFSET * voxel;
  vec3 start = (p.xyz + n * offset - cascades.origin_voxel[first].xyz) / voxel;
  float reach = (max_distance > 0.0) ? max_distance / voxel : length(vec3(cascade_dims));
#endif
  float occlusion = 0.0;
  for (int i = 0; i < rays; i++) {
    float r2 = (float(i) + jit.y) / float(rays) * sin_max2;
    float phi = 6.283185307179586 * fract(float(i) * HAO_GOLDEN_FRACTION + jit.x);
    float r = sqrt(r2);
    vec3 dir = r * cos(phi) * t + r * sin(phi) * s + sqrt(max(1.0 - r2, 0.0)) * n;
#ifdef MARCH_HIERARCHICAL
    /* Rays start on the surface (the march skips the receiver's own voxels) and move to the
     * next coarser cascade where they leave one, with one budget for the whole way. */
    float hit = -1.0;
    float travelled = 0.0;
    int budget = steps;
    for (int k = first; k < cascades.count.x && hit < 0.0 && budget > 0; k++) {
      vec4 ov = cascades.origin_voxel[k];
      use_cascade(k);
      float limit = (max_distance > 0.0) ? max_distance / ov.w : 1e30;
      float left;
      float h = march_hierarchical((p.xyz - ov.xyz) / ov.w, n, dir, travelled / ov.w, limit, budget, left);
      if (h >= 0.0) {
        hit = h * ov.w;
      }
      travelled = max(travelled, left * ov.w);
    }
    exhausted_rays += (hit < 0.0 && budget <= 0) ? 1 : 0;
#else
    float hit = march_fixed(start, dir, reach, steps, jit.z);
    hit = (hit >= 0.0) ? hit * voxel + offset : -1.0;
#endif
    if (hit >= 0.0) {
      occlusion += occlusion_weight(hit, max_distance); /* hit: world units, start offset included */
    }
  }
#ifdef MARCH_HIERARCHICAL
  if (exhausted_rays > 0) {
    imageAtomicAdd(counters, ivec2(1, 0), uint(exhausted_rays));
  }
#endif
  imageStore(ao_low, low, vec4(1.0 - occlusion / float(rays)));
}
