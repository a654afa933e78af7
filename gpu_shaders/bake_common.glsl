/* Shared by the bake passes: fixed-point tent splats into R32UI accumulators.
 *
 * Float image atomics do not exist on every driver (llvmpipe has none) and would make sums
 * depend on execution order. Integer adds are associative, so bakes are bit-identical run to
 * run. The caller chooses `fixed_scale` so that a chunk of directions cannot overflow 2^32
 * (see hao_addon/gpu/bake_scatter.py). */
void splat_bilinear(vec2 texel_pos, float weight_num, float weight_den)
{
  /* Tent (bilinear) splat over the four nearest texel centres: a fragment's UV footprint is
   * spread the way bilinear filtering reads it back, which removes most of the aliasing of
   * nearest-texel binning when light-view pixels and texels are of similar size. */
  vec2 q = texel_pos - 0.5;
  vec2 base = floor(q);
  vec2 f = q - base;
  ivec2 i0 = ivec2(base);
  ivec2 size = imageSize(accum_den);
  vec4 wts = vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
  for (int k = 0; k < 4; k++) {
    ivec2 c = i0 + ivec2(k & 1, k >> 1);
    if (c.x < 0 || c.y < 0 || c.x >= size.x || c.y >= size.y) {
      continue;
    }
    uint add_den = uint(weight_den * wts[k] * fixed_scale + 0.5);
    if (add_den != 0u) {
      imageAtomicAdd(accum_den, c, add_den);
      uint add_num = uint(weight_num * wts[k] * fixed_scale + 0.5);
      if (add_num != 0u) {
        imageAtomicAdd(accum_num, c, add_num);
      }
    }
  }
}
