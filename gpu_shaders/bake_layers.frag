/* Max-distance bakes need, for each target fragment, the occluder nearest to *it* along the
 * ray towards the light, which a depth buffer (nearest to the light) cannot give. This pass
 * appends the depth of every fragment of target and occluders to a per-pixel list of up to
 * LAYERS entries (a 3D R32UI image; the count image hands out slots). Overflowing pixels are
 * counted so the bake can report them. */
void main()
{
#ifdef ALPHA
  if (!alpha_keeps()) {
    dummy_out = 0.0;
    return;  /* no list entry: the light passes this surface here */
  }
#endif
  ivec2 px = ivec2(gl_FragCoord.xy);
  uint slot = imageAtomicAdd(layer_count, px, 1u);
  if (slot < uint(LAYERS)) {
    imageStore(layer_depth, ivec3(px, int(slot)), uvec4(floatBitsToUint(gl_FragCoord.z)));
  }
  else if (slot == uint(LAYERS)) {
    imageAtomicAdd(overflow, ivec2(0, 0), 1u);
  }
  dummy_out = 0.0;
}
