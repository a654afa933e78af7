/* One level of the occupancy pyramid (numpy twin: core/hao/voxel_grid.occupancy_pyramid):
 * cell (x, y, z) of a level is occupied when any of the eight cells (2x + i, 2y + j, 2z + k)
 * of the level below is. Both sit in the atlas (`grid`) at their x offsets, bits along z: a
 * coarse word holds 32 coarse cells = 64 fine cells = two fine words, whose bit pairs are
 * ORed and compacted to 16 bits each. A cascade's atlas starts at row atlas_y. */
uint compact_pairs(uint f)
{
  uint g = (f | (f >> 1u)) & 0x55555555u;
  g = (g | (g >> 1u)) & 0x33333333u;
  g = (g | (g >> 2u)) & 0x0F0F0F0Fu;
  g = (g | (g >> 4u)) & 0x00FF00FFu;
  return (g | (g >> 8u)) & 0x0000FFFFu;
}

void main()
{
  ivec3 c = ivec3(gl_GlobalInvocationID.xyz); /* (x, y, word) of the coarse level */
  if (any(greaterThanEqual(c, coarse_words.xyz))) {
    return;
  }
  uint word = 0u;
  for (int j = 0; j < 2; j++) {
    for (int i = 0; i < 2; i++) {
      ivec2 f = 2 * c.xy + ivec2(i, j);
      if (f.x >= fine_words.x || f.y >= fine_words.y) {
        continue;
      }
      for (int half_word = 0; half_word < 2; half_word++) {
        int w = 2 * c.z + half_word;
        if (w < fine_words.z) {
          uint fine = imageLoad(grid, ivec3(fine_words.w + f.x, f.y + atlas_y, w)).r;
          word |= compact_pairs(fine) << uint(16 * half_word);
        }
      }
    }
  }
  imageStore(grid, ivec3(coarse_words.w + c.x, c.y + atlas_y, c.z), uvec4(word));
}
