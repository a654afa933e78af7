/* Shared by the bake passes: fixed-point tent splats into one R32UI accumulator.
 *
 * Float image atomics do not exist on every driver (llvmpipe has none) and would make sums
 * depend on execution order. Integer adds are associative, so bakes are bit-identical run to
 * run. Numerator and denominator share one 32-bit word, denominator in the high 16 bits and
 * numerator in the low 16: each numerator addend is at most its denominator addend, so the
 * low field cannot carry into the high one while the denominator fits, and one atomic does
 * the work of two (image atomics dominate this pass on llvmpipe). The caller chooses
 * `fixed_scale` and flushes often enough that a chunk's denominator stays below 2^16
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
  ivec2 size = imageSize(accum);
  vec4 wts = vec4((1.0 - f.x) * (1.0 - f.y), f.x * (1.0 - f.y), (1.0 - f.x) * f.y, f.x * f.y);
  for (int k = 0; k < 4; k++) {
    ivec2 c = i0 + ivec2(k & 1, k >> 1);
    if (c.x < 0 || c.y < 0 || c.x >= size.x || c.y >= size.y) {
      continue;
    }
    uint add_den = uint(weight_den * wts[k] * fixed_scale + 0.5);
    if (add_den != 0u) {
      uint add_num = min(uint(weight_num * wts[k] * fixed_scale + 0.5), add_den);
      imageAtomicAdd(accum, c, (add_den << 16) | add_num);
    }
  }
}
