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
#ifdef SHADING_NORMALS
  /* The interpolated shading normal; the weight is about it, visibility from the true
   * (flat) surface this fragment lies on. */
  vec3 normal = normalize(face_data.xyz);
#else
  vec3 normal = face_data.xyz;
#endif
  float cos_theta = dot(normal, omega.xyz);
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
#ifdef SPREAD_COS
  weight *= step(SPREAD_COS, cos_theta); /* outside the spread cone: weighs nothing */
#endif
#ifdef MAX_DISTANCE
  /* The nearest occluder in front of this fragment: the largest listed depth below its own
   * (its own entry is equal and excluded by the tolerance). Depth is linear in an
   * orthographic view, so depth differences times depth_span are distances. */
  ivec2 px = ivec2(gl_FragCoord.xy);
  int count = min(int(imageLoad(layer_count, px).r), LAYERS);
  float z_self = gl_FragCoord.z;
  float z_front = -1.0;
  for (int i = 0; i < count; i++) {
    float z = uintBitsToFloat(imageLoad(layer_depth, ivec3(px, i)).r);
    /* min_distance: nearer occluders are passed by */
    if (z < z_self - depth_tolerance && z > z_front && (z_self - z) * depth_span >= min_distance) {
      z_front = z;
    }
  }
  float visible = (z_front >= 0.0) ? occluder_visibility((z_self - z_front) * depth_span, max_distance) : 1.0;
#else
  /* Visible: this fragment is the nearest surface. Both passes run the same vertex shader,
   * so the depths agree to the last bit on conforming drivers; the tolerance only absorbs
   * drivers that reassociate arithmetic between programs. */
  float nearest = texelFetch(depth_tex, ivec2(gl_FragCoord.xy), 0).r;
  float visible = (gl_FragCoord.z <= nearest + depth_tolerance) ? 1.0 : 0.0;
#endif
#ifdef SHADING_NORMALS
  /* The terminator: directions above the shading hemisphere but below the face count as
   * occluded (Cycles' AO pass traces only directions above the geometric normal). Averted
   * faces are not drawn; the denominator here sums the directions above the face, whose
   * weights total above_fraction of S, so the numerator carries that fraction: the ratio is
   * the whole estimator (core/bake/plan.py, _shading_corners). */
  float weight_den = weight / max(above_fraction, 1e-6);
#else
  float weight_den = weight;
#endif
  /* Footprint-aware splat: where this pixel's UV footprint (the parallelogram spanned by
   * dx and dy) is wider than a texel, spread the weight over an nx x ny grid of points inside
   * it, so no texel under the footprint is skipped (without this, UV regions denser than the
   * light view turn to salt-and-pepper noise). The tent reaches one texel each way, so
   * sub-points up to 1.5 texels apart still reach every texel between them. */
#if MAX_FOOTPRINT == 1
  /* The plan found no UV region much denser than the light view: a single splat, and no
   * loop (llvmpipe runs this shader about 35 % slower when the loop is merely present). */
  splat_bilinear(uv_texel, weight * visible, weight_den);
#else
  int nx = clamp(int(ceil(length(dx) / 1.5)), 1, MAX_FOOTPRINT);
  int ny = clamp(int(ceil(length(dy) / 1.5)), 1, MAX_FOOTPRINT);
  float share = 1.0 / float(nx * ny);
  for (int j = 0; j < ny; j++) {
    for (int i = 0; i < nx; i++) {
      vec2 p = uv_texel + ((float(i) + 0.5) / float(nx) - 0.5) * dx + ((float(j) + 0.5) / float(ny) - 0.5) * dy;
      splat_bilinear(p, weight * visible * share, weight_den * share);
    }
  }
#endif
  dummy_out = 0.0;
}
