/* The G-buffer at the AO-map resolution: position and normal of the pixel each AO-map pixel
 * stands for (hao_pick.glsl), computed once per view so that passes drawing many primitives
 * over the AO map (the sphere billboards) read one texel instead of searching a block. */
void main()
{
  ivec2 low = ivec2(gl_GlobalInvocationID.xy);
  if (any(greaterThanEqual(low, (full_size + scale - 1) / scale))) {
    return;
  }
  vec4 p;
  ivec2 pick = pick_gbuffer_pixel(low, p);
  imageStore(low_position, low, p);
  imageStore(low_normal, low, p.w > 0.0 ? imageLoad(gbuf_normal, pick) : vec4(0.0));
}
