/* McGraw & Sowers, stages 1 and 2 in one fragment pass over the target's triangles, drawn
 * without depth test after a depth pre-pass of target and occluders.
 *
 * Each target fragment carries the weight (omega . n) |J| / S_f of equation 8 with the exact
 * constant, where |J| is the UV area of this pixel in texels (the view is orthographic, so UV
 * is affine in window space within a triangle and dFdx/dFdy are exact). It is splatted into
 * the texel it maps to twice: into the denominator always, and into the numerator when it is
 * the visible surface at its pixel. The map is numerator / denominator: both sums see the
 * same pixel grid, so the aliasing between light-view pixels and texels cancels and an
 * unoccluded texel is exactly 1. (The paper renders the visible texels to a buffer and draws
 * one point per pixel with additive blending; fragment image atomics do the same scatter.) */
void main()
{
  float cos_theta = dot(face_data.xyz, omega.xyz);
  if (face_data.w <= 0.0 || cos_theta <= 0.0) {
    discard;
  }
  vec2 dx = dFdx(uv_texel);
  vec2 dy = dFdy(uv_texel);
  float jacobian = abs(dx.x * dy.y - dx.y * dy.x);
#ifdef UNIFORM_WEIGHTING
  float weight = jacobian * face_data.w;
#else
  float weight = jacobian * cos_theta * face_data.w;
#endif
  /* Visible: this fragment is the nearest surface. Both passes run the same vertex shader,
   * so the depths agree to the last bit on conforming drivers; the tolerance only absorbs
   * drivers that reassociate arithmetic between programs. */
  float nearest = texelFetch(depth_tex, ivec2(gl_FragCoord.xy), 0).r;
  float visible = (gl_FragCoord.z <= nearest + depth_tolerance) ? 1.0 : 0.0;
  splat_bilinear(uv_texel, weight * visible, weight);
  dummy_out = 0.0;
}
