/* Surface pass: mark the voxel of this column that holds the triangle's point (imageAtomicOr
 * into a bit-packed grid, bits along z, at y offset grid_dims.w: the cascade's place in the
 * texture). Solid pass: flip every voxel of the column whose
 * centre lies below the triangle (parity; see hao_addon/core/hao/voxel_grid.py). */
void main()
{
  voxel_out = vec4(0.0); /* llvmpipe runs fragment side effects only with a colour write */
  ivec2 col = ivec2(gl_FragCoord.xy);
#ifdef SOLID
  if (col.x >= grid_dims.x || col.y >= grid_dims.y) {
    return;
  }
  int count = clamp(int(ceil(grid_pos.z - 0.5)), 0, grid_dims.z);
  int full = count >> 5;
  for (int w = 0; w < full; w++) {
    imageAtomicXor(grid, ivec3(col.x, col.y + grid_dims.w, w), 0xFFFFFFFFu);
  }
  int rest = count & 31;
  if (rest != 0) {
    imageAtomicXor(grid, ivec3(col.x, col.y + grid_dims.w, full), (1u << uint(rest)) - 1u);
  }
#else
  ivec3 v = ivec3(floor(grid_pos));
  if (axis_id == 0) {
    v.yz = col;
  }
  else if (axis_id == 1) {
    v.zx = col;
  }
  else {
    v.xy = col;
  }
  if (any(lessThan(v, ivec3(0))) || any(greaterThanEqual(v, grid_dims.xyz))) {
    return;
  }
  imageAtomicOr(grid, ivec3(v.x, v.y + grid_dims.w, v.z >> 5), 1u << uint(v.z & 31));
#endif
}
