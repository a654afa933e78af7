/* One axis of the separable joint bilateral upsampling (HAO paper, equations 5 to 8); the
 * numpy reference is hao_addon/core/hao/bilateral.py. The first pass (UPSAMPLE) weighs the
 * AO-map samples of the blocks in its window by the position and normal of the G-buffer
 * pixel each was computed at (low_position, low_normal: LowGBufferPass), without the AO
 * range weight (the pixel has no AO of its own yet); the second pass filters the first
 * pass's full-resolution output with all four weights. */
void main()
{
  ivec2 x = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(x, full_size))) {
    return;
  }
  vec4 px = imageLoad(gbuf_position, x);
  if (px.w < 1.0) {
    imageStore(ao_dst, x, vec4(1.0));
    return;
  }
  vec3 nx = imageLoad(gbuf_normal, x).xyz;
#ifdef UPSAMPLE
  float hx = imageLoad(ao_src, x / scale).r; /* kept where no sample matches */
#else
  float hx = imageLoad(ao_src, x).r;
#endif
  int radius = filter_size / 2;
  ivec2 dir = (AXIS == 0) ? ivec2(1, 0) : ivec2(0, 1);
  int here = x[AXIS];
  int first = max(here - radius, 0);
  int last = min(here + radius, full_size[AXIS] - 1);
  float num = 0.0;
  float den = 0.0;
#ifdef UPSAMPLE
  /* The window's pixels of one block share its sample: one look-up per block, weighted by
   * the distance weights of its pixels summed (the same sum as pixel by pixel). */
  ivec2 low_x = x / scale;
  for (int b = first / scale; b <= last / scale; b++) {
    float wd = 0.0;
    for (int y = max(b * scale, first); y <= min(b * scale + scale - 1, last); y++) {
      wd += filter_size > 0 ? wendland(abs(float(y - here)), float(filter_size)) : 1.0;
    }
    ivec2 by = (AXIS == 0) ? ivec2(b, low_x.y) : ivec2(low_x.x, b);
    vec4 py = imageLoad(low_position, by);
    if (py.w < 1.0) {
      continue;
    }
    vec3 ny = imageLoad(low_normal, by).xyz;
    float hy = imageLoad(ao_src, by).r;
    float wt = wd * wendland(clamp(1.0 - dot(nx, ny), 0.0, 2.0), 2.0) * wendland(length(px.xyz - py.xyz), max_distance);
    num += wt * hy;
    den += wt;
  }
#else
  for (int k = first; k <= last; k++) {
    ivec2 y = x + dir * (k - here);
    vec4 py = imageLoad(gbuf_position, y);
    if (py.w < 1.0) {
      continue;
    }
    vec3 ny = imageLoad(gbuf_normal, y).xyz;
    float hy = imageLoad(ao_src, y).r;
    float wd = filter_size > 0 ? wendland(abs(float(k - here)), float(filter_size)) : 1.0;
    float wt = wd * wendland(clamp(1.0 - dot(nx, ny), 0.0, 2.0), 2.0) * wendland(length(px.xyz - py.xyz), max_distance)
        * wendland(abs(hx - hy), 1.0);
    num += wt * hy;
    den += wt;
  }
#endif
  imageStore(ao_dst, x, vec4(den > 0.0 ? num / den : hx));
}
