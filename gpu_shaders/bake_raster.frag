/* Writes, for the visible surface at this pixel, its UV in texel units and the weight
 *   (omega . n) |J| / S_f      (McGraw & Sowers, equation 8, with the exact constant),
 * where |J| is the UV area covered by this pixel in texels. The view is orthographic, so
 * UV is an affine function of the window position inside a triangle and dFdx/dFdy give
 * |J| exactly (helper pixels of a 2x2 quad extrapolate the same plane). */
void main()
{
  float cos_theta = dot(face_data.xyz, omega.xyz);
  float weight = 0.0;
  if (face_data.w > 0.0 && cos_theta > 0.0) {
    vec2 dx = dFdx(uv_texel);
    vec2 dy = dFdy(uv_texel);
    float jacobian = abs(dx.x * dy.y - dx.y * dy.x);
#ifdef UNIFORM_WEIGHTING
    weight = jacobian * face_data.w;
#else
    weight = jacobian * cos_theta * face_data.w;
#endif
  }
  vis_out = vec4(uv_texel, weight, 1.0);
}
