/* Appends one entry per fragment (texel centre x face) to the texel list. The count variant
 * only counts, so the list can be allocated at its exact size; the fill variant stores the
 * entries. Overlapping UV islands give one entry per island, and their sums average later.
 * Entry order follows the rasterizer's threads; every entry is processed independently, so
 * the order does not change any result. */
void main()
{
  /* llvmpipe skips fragment shaders with side effects when no colour is written. */
  list_out = vec4(0.0);
  if (face_data.w <= 0.0) {
    return; /* a face no direction sees (or of zero area) contributes nothing */
  }
  uint index = imageAtomicAdd(entry_count, ivec2(0, 0), 1u);
#ifdef FILL
  if (index >= uint(capacity)) {
    return;
  }
  ivec2 slot = ivec2(int(index % uint(LIST_WIDTH)), int(index / uint(LIST_WIDTH)));
  imageStore(entry_position, slot, vec4(world_pos, face_data.w));
  imageStore(entry_normal, slot, vec4(face_data.xyz, 0.0));
  imageStore(entry_texel, slot, uvec4((uint(gl_FragCoord.y) << 16) | uint(gl_FragCoord.x)));
#endif
}
