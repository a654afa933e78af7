/* Shadow-map gather (the comparison of McGraw & Sowers' Table 1): every texel-list entry is
 * tested against this direction's depth map and adds (V w, w), w = weight(omega . n) / S_f.
 * Each invocation owns its entry, so the float sums need no atomics and are summed in
 * direction order, the same on every run. */
void main()
{
  ivec2 slot = ivec2(gl_GlobalInvocationID.xy);
  if (slot.y * LIST_WIDTH + slot.x >= entry_count) {
    return;
  }
  vec4 position = imageLoad(entry_position, slot); /* xyz normalized world, w = 1 / S_f */
  vec3 normal = imageLoad(entry_normal, slot).xyz;
  float cos_theta = dot(normal, omega.xyz);
  if (cos_theta <= 0.0) {
    return;
  }
#ifdef UNIFORM_WEIGHTING
  float weight = position.w;
#else
  float weight = cos_theta * position.w;
#endif
  vec3 light_pos = (view_proj * vec4(position.xyz, 1.0)).xyz;
  vec2 win = (light_pos.xy * 0.5 + 0.5) * vec2(view_size);
  ivec2 px = ivec2(floor(win));
  float depth = light_pos.z * 0.5 + 0.5;
  float visible = 1.0;
  if (all(greaterThanEqual(px, ivec2(0))) && all(lessThan(px, view_size))) {
    /* Slope-scaled bias against shadow acne: a depth-map pixel spans pixel_size, so a surface
     * tilted by theta changes depth by up to pixel_size * tan(theta) across it. Clamped at
     * tan = 100 (cos ~ 0.01): steeper directions carry almost no cosine weight, and a lower
     * clamp let grazing directions shadow open planes (acne of ~1e-3). */
    float tan_theta = min(sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / cos_theta, 100.0);
    float bias = (1.5 * tan_theta + 0.5) * pixel_depth;
    float stored = texelFetch(depth_tex, px, 0).r;
    visible = (depth - bias <= stored) ? 1.0 : 0.0;
  }
  vec4 sum = imageLoad(accum, slot);
  imageStore(accum, slot, sum + vec4(weight * visible, weight, 0.0, 0.0));
}
