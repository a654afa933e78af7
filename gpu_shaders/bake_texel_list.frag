/* Appends one entry per fragment (texel centre x face) to the texel list, grouped by normal
 * bin: the face's, or with shading normals the bin of the fragment's own shading normal as
 * stored (core/bake/normal_bins.py, whose cell cones then bound it). The count variant counts the entries of each bin, so the list can be
 * allocated at its exact size with each bin's range known; the fill variant stores every
 * entry in its bin's range (bin_start holds the ranges' first entries, as float bits).
 * Overlapping UV islands give one entry per island, and their sums average later. Entry
 * order within a bin follows the rasterizer's threads; every entry is processed on its own,
 * so the order does not change any result. */

/* The fragment's barycentric coordinates moved SAMPLE_INSET inside its face: the rasterizer
 * snaps a covered centre up to 1/256 texel past the face's edge, and interpolation can put it
 * just behind a neighbouring face at a concave crease (core/bake/uv_raster.inset_barycentrics,
 * the CPU twin). */
vec3 inset_bary()
{
  vec3 b = max(face_bary, vec3(SAMPLE_INSET));
  return b / (b.x + b.y + b.z);
}

void main()
{
  /* llvmpipe skips fragment shaders with side effects when no colour is written. */
  list_out = vec4(0.0);
  if (face_data.w <= 0.0) {
    return; /* a face no direction sees (or of zero area) contributes nothing */
  }
#ifdef SHADING_NORMALS
  vec2 shading_oct = octahedral_encode(normalize(face_data.xyz));
  ivec2 cell = clamp(ivec2((shading_oct + 1.0) * (0.5 * float(OCT_SIDE))), ivec2(0), ivec2(OCT_SIDE - 1));
  int entry_bin = cell.y * OCT_SIDE + cell.x;
#else
  int entry_bin = face_bin;
#endif
#ifdef INTERLEAVE_SIDE
  /* Each texel class's bins follow the one before's (core/bake/interleave.texel_classes). */
  ivec2 texel = ivec2(gl_FragCoord.xy);
  entry_bin += BIN_COUNT * ((texel.x % INTERLEAVE_SIDE) + INTERLEAVE_SIDE * (texel.y % INTERLEAVE_SIDE));
#endif
  uint index = imageAtomicAdd(bin_count, ivec2(entry_bin, 0), 1u);
#ifdef FILL
  index += floatBitsToUint(imageLoad(bin_start, ivec2(entry_bin, 0)).r);
  if (index >= uint(capacity)) {
    return;
  }
  ivec2 slot = ivec2(int(index % uint(LIST_WIDTH)), int(index / uint(LIST_WIDTH)));
  vec3 bary = inset_bary();
  imageStore(entry_position, slot, vec4(face_v0 * bary.x + face_v1 * bary.y + face_v2 * bary.z, face_data.w));
#  ifdef SHADING_NORMALS
  /* Both normals: the weight is about the shading one, visibility and its bias belong to the
   * true surface. */
  imageStore(entry_normal, slot, vec4(shading_oct, octahedral_encode(geometric_normal)));
#  else
  imageStore(entry_normal, slot, vec4(face_data.xyz, 0.0));
#  endif
  imageStore(entry_texel, slot, uvec4((uint(gl_FragCoord.y) << 16) | uint(gl_FragCoord.x)));
#  ifdef TERMINATOR_OFFSET
  imageStore(entry_lift, slot, vec4(smooth_surface_lift(face_v0, face_v1, face_v2, lift_n0, lift_n1, lift_n2,
                                                        bary, geometric_normal), 0.0));
#  endif
#endif
}
