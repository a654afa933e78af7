/* The G-buffer pixel an AO-map pixel stands for: its block's centre pixel, or else the
 * block's first covered pixel (keeps silhouettes). Shared by every pass that writes the AO
 * map (hao_ao.comp, sphere_far.frag) so they sample the same surface points. */
ivec2 pick_gbuffer_pixel(ivec2 low, out vec4 p)
{
  ivec2 base = low * scale;
  ivec2 pick = min(base + scale / 2, full_size - 1);
  p = imageLoad(gbuf_position, pick);
  for (int k = 0; k < scale * scale && p.w == 0.0; k++) {
    pick = min(base + ivec2(k % scale, k / scale), full_size - 1);
    p = imageLoad(gbuf_position, pick);
  }
  return pick;
}
