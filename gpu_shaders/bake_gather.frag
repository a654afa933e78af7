/* Visibility of this texel centre from the light by a depth-map lookup, with a slope-scaled
 * bias against shadow acne: a depth-map pixel spans pixel_size, so a surface tilted by theta
 * changes depth by up to pixel_size * tan(theta) across it. Output (V w, w) with
 * w = weight(omega . n) / S_f, summed over directions by additive blending. */
void main()
{
  float cos_theta = dot(face_data.xyz, omega.xyz);
  if (face_data.w <= 0.0 || cos_theta <= 0.0) {
    discard;
  }
#ifdef UNIFORM_WEIGHTING
  float weight = face_data.w;
#else
  float weight = cos_theta * face_data.w;
#endif
  vec2 win = (light_pos.xy * 0.5 + 0.5) * vec2(view_size);
  ivec2 px = ivec2(floor(win));
  float depth = light_pos.z * 0.5 + 0.5;
  float visible = 1.0;
  if (all(greaterThanEqual(px, ivec2(0))) && all(lessThan(px, view_size))) {
    /* Clamped at tan = 100 (cos ~ 0.01): steeper directions carry almost no cosine weight, and
     * a lower clamp let grazing directions shadow open planes (acne of ~1e-3). */
    float tan_theta = min(sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / cos_theta, 100.0);
    float bias = (1.5 * tan_theta + 0.5) * pixel_depth;
    float stored = texelFetch(depth_tex, px, 0).r;
    visible = (depth - bias <= stored) ? 1.0 : 0.0;
  }
  gather_out = vec4(weight * visible, weight, 0.0, 0.0);
}
