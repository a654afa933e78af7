/* One axis of the separable joint bilateral upsampling (HAO paper, equations 5 to 8); the
 * numpy reference is hao_addon/core/bilateral.py. The first pass (UPSAMPLE) reads the low
 * resolution map at y / scale, the second the first pass's full-resolution output. */
float fetch_ao(ivec2 y)
{
#ifdef UPSAMPLE
  return imageLoad(ao_src, y / scale).r;
#else
  return imageLoad(ao_src, y).r;
#endif
}

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
  float hx = fetch_ao(x);
  int radius = filter_size / 2;
  ivec2 dir = (AXIS == 0) ? ivec2(1, 0) : ivec2(0, 1);
  float num = 0.0;
  float den = 0.0;
  for (int d = -radius; d <= radius; d++) {
    ivec2 y = x + dir * d;
    if (any(lessThan(y, ivec2(0))) || any(greaterThanEqual(y, full_size))) {
      continue;
    }
    vec4 py = imageLoad(gbuf_position, y);
    if (py.w < 1.0) {
      continue;
    }
    vec3 ny = imageLoad(gbuf_normal, y).xyz;
    float hy = fetch_ao(y);
    float wd = filter_size > 0 ? wendland(abs(float(d)), float(filter_size)) : 1.0;
    float wt = wd * wendland(clamp(1.0 - dot(nx, ny), 0.0, 2.0), 2.0) *
               wendland(length(px.xyz - py.xyz), max_distance) * wendland(abs(hx - hy), 1.0);
    num += wt * hy;
    den += wt;
  }
  imageStore(ao_dst, x, vec4(den > 0.0 ? num / den : hx));
}
