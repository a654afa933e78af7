/* Shadow-map gather (the comparison of McGraw & Sowers' Table 1): every texel-list entry is
 * tested against the depth maps of VIEWS directions (1 to 4, one dispatch) and adds (V w, w),
 * w = weight(omega . n) / S_f, for each. Loading an entry and its running sums once for
 * several directions is what batching saves (llvmpipe: the loads and the store cost more
 * than the tests). Each invocation owns its entry, so the float sums need no atomics; they
 * are added one direction at a time in direction order, the same arithmetic as one
 * direction per dispatch, and the same on every run. */

#ifndef MAX_DISTANCE
/* Visibility of `position` from one light view: view_proj maps to clip space, view_info is
 * (width, height, pixel depth in clip z units, depth range). */
float visible_from(sampler2D depth_tex, mat4 view_proj, vec4 view_info, vec3 position, float cos_theta)
{
  vec3 light_pos = (view_proj * vec4(position, 1.0)).xyz;
  ivec2 view_size = ivec2(view_info.xy);
  ivec2 px = ivec2(floor((light_pos.xy * 0.5 + 0.5) * view_info.xy));
  if (any(lessThan(px, ivec2(0))) || any(greaterThanEqual(px, view_size))) {
    return 1.0;
  }
  /* Slope-scaled bias against shadow acne: a depth-map pixel spans pixel_size, so a surface
   * tilted by theta changes depth by up to pixel_size * tan(theta) across it. Clamped at
   * tan = 100 (cos ~ 0.01): steeper directions carry almost no cosine weight, and a lower
   * clamp let grazing directions shadow open planes (acne of ~1e-3). */
  float tan_theta = min(sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / cos_theta, 100.0);
  float bias = (1.5 * tan_theta + 0.5) * view_info.z;
  float depth = light_pos.z * 0.5 + 0.5;
  return (depth - bias <= texelFetch(depth_tex, px, 0).r) ? 1.0 : 0.0;
}
#endif

#ifdef MAX_DISTANCE
/* Max distance: the occluder nearest to `position` towards the light is the largest listed
 * depth in front of it by more than the slope-scaled bias (its own surface, rasterized at
 * the pixel centre, lies within that bias); view_info.w is the depth range in normalized
 * units, so depth differences times it are distances (orthographic view). */
float visible_from_layers(mat4 view_proj, vec4 view_info, vec3 position, float cos_theta)
{
  vec3 light_pos = (view_proj * vec4(position, 1.0)).xyz;
  ivec2 view_size = ivec2(view_info.xy);
  ivec2 px = ivec2(floor((light_pos.xy * 0.5 + 0.5) * view_info.xy));
  if (any(lessThan(px, ivec2(0))) || any(greaterThanEqual(px, view_size))) {
    return 1.0;
  }
  float tan_theta = min(sqrt(max(1.0 - cos_theta * cos_theta, 0.0)) / cos_theta, 100.0);
  float bias = (1.5 * tan_theta + 0.5) * view_info.z;
  float depth = light_pos.z * 0.5 + 0.5;
  int count = min(int(imageLoad(layer_count, px).r), LAYERS);
  float z_front = -1.0;
  for (int i = 0; i < count; i++) {
    float z = uintBitsToFloat(imageLoad(layer_depth, ivec3(px, i)).r);
    if (z < depth - bias && z > z_front) {
      z_front = z;
    }
  }
  return (z_front >= 0.0) ? occluder_visibility((depth - z_front) * view_info.w, max_distance) : 1.0;
}
#  define VISIBLE(depth_tex, k, cos_true) \
    visible_from_layers(views.view_proj[k], views.view_info[k], position.xyz, cos_true)
#else
#  define VISIBLE(depth_tex, k, cos_true) \
    visible_from(depth_tex, views.view_proj[k], views.view_info[k], position.xyz, cos_true)
#endif

/* Hemisphere weight of a light at cos_theta > 0 (times 1 / S, added in GATHER_VIEW). */
#ifdef UNIFORM_WEIGHTING
#  define VIEW_WEIGHT(cos_theta) 1.0
#else
#  define VIEW_WEIGHT(cos_theta) (cos_theta)
#endif

/* Adds one view's term to sum when the entry faces that light. With shading normals the
 * weight is about the shading normal and visibility is judged from the true surface; a
 * direction above the shading hemisphere but below the face (the terminator) counts as
 * occluded, as in Cycles' AO pass, which traces only directions above the geometric normal. */
#ifdef SHADING_NORMALS
#  define GATHER_VIEW(depth_tex, k) \
  { \
    float cos_theta = dot(normal, views.omega[k].xyz); \
    if (cos_theta > 0.0) { \
      float weight = VIEW_WEIGHT(cos_theta) * position.w; \
      float cos_true = dot(geometric, views.omega[k].xyz); \
      float visible = (cos_true > 0.0) ? VISIBLE(depth_tex, k, cos_true) : 0.0; \
      sum += vec2(weight * visible, weight); \
    } \
  }
#else
#  define GATHER_VIEW(depth_tex, k) \
  { \
    float cos_theta = dot(normal, views.omega[k].xyz); \
    if (cos_theta > 0.0) { \
      float weight = VIEW_WEIGHT(cos_theta) * position.w; \
      sum += vec2(weight * VISIBLE(depth_tex, k, cos_theta), weight); \
    } \
  }
#endif

void main()
{
  /* This dispatch covers entries first_entry .. entry_end - 1 (a run of normal bins that can
   * face one of its views, core/normal_bins.py), LIST_WIDTH per grid row. */
  int index = first_entry + int(gl_GlobalInvocationID.y) * LIST_WIDTH + int(gl_GlobalInvocationID.x);
  if (index >= entry_end) {
    return;
  }
  ivec2 slot = ivec2(index % LIST_WIDTH, index / LIST_WIDTH);
  vec4 position = imageLoad(entry_position, slot); /* xyz normalized world, w = 1 / S */
#ifdef SHADING_NORMALS
  vec4 normals = imageLoad(entry_normal, slot);
  vec3 normal = octahedral_decode(normals.xy);
  vec3 geometric = octahedral_decode(normals.zw);
#else
  vec3 normal = imageLoad(entry_normal, slot).xyz;
#endif
  vec2 sum = imageLoad(accum, slot).xy;
  vec2 before = sum;
  GATHER_VIEW(depth_tex0, 0)
#if VIEWS > 1
  GATHER_VIEW(depth_tex1, 1)
#endif
#if VIEWS > 2
  GATHER_VIEW(depth_tex2, 2)
#endif
#if VIEWS > 3
  GATHER_VIEW(depth_tex3, 3)
#endif
  if (sum != before) {
    imageStore(accum, slot, vec4(sum, 0.0, 0.0));
  }
}
