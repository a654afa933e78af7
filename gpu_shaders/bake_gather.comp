/* Shadow-map gather (the comparison of McGraw & Sowers' Table 1): every texel-list entry is
 * tested against the depth maps of the directions of one dispatch (GATHER_ALL_VIEWS: up to
 * GATHER_MAX_VIEWS, bake_gather.py; a slot with omega = 0 is padding and adds nothing) and adds the
 * estimator's term of (w, V, omega) for each (bake_estimator.glsl; for AO (V w, w)),
 * w = weight(omega . n) times the entry's scale (1 / S where the plan knows it; each entry's
 * sums are divided by its own weight sum on read-back, estimators.texel_sums). Loading an entry and its running sums once for
 * several directions is what batching saves (llvmpipe: the loads and the store cost more
 * than the tests). Each invocation owns its entry, so the float sums need no atomics; they
 * are added one direction at a time in direction order, the same arithmetic as one
 * direction per dispatch, and the same on every run. */

/* Receiver-plane depth test: where `position` looks up view k's depth map, and the depth its
 * own plane (normal plane_normal) has at that pixel's centre, minus DEPTH_BIAS_PIXELS of
 * depth and slope_slack pixels' worth of the plane's slope (bake_gather.py). The depth map holds the nearest surface at pixel centres, up to 0.71 pixel beside the
 * receiver; comparing it with the receiver's own plane extrapolated there, instead of
 * with the receiver's depth, needs no slope-scaled bias. That bias (1.5 tan(theta) + 0.5
 * pixels) ignored every occluder within that distance along the ray, up to 150 pixels at
 * grazing angles, which strongly bent shading normals weigh in: +0.004 brighter than Cycles
 * and the ray-traced reference on Spot with custom normals. Returns (pixel, depth), pixel.x
 * < 0 outside the view. */
/* The receiver in view k: `at` its pixel coordinates, `depth` its depth (z / 2 + 1 / 2), and
 * `slope` how its plane's depth changes per pixel: plane_slope.xy * m.xy / m.z, m the plane
 * normal through the view's linear part (core/bake/views.OrthoView.plane_slope: for an
 * orthographic view, S R with R a rotation, the clip-space normal is S^-2 m; the view_proj
 * entries are loaded for the position already, so this costs no further loads). */
void receiver_plane(int k, vec3 position, vec3 plane_normal, out vec2 at, out float depth, out vec2 slope)
{
  vec3 light_pos = (views.view_proj[k] * vec4(position, 1.0)).xyz;
  at = (light_pos.xy * 0.5 + 0.5) * views.view_info[k].xy;
  vec3 m = mat3(views.view_proj[k]) * plane_normal;
  float mz = (m.z < 0.0) ? min(m.z, -1e-12) : max(m.z, 1e-12);
  slope = views.plane_slope[k].xy * m.xy / mz;
  depth = light_pos.z * 0.5 + 0.5;
}

/* What a depth stored at pixel px must lie nearer the light than to occlude the receiver:
 * its plane there, or its own depth where that is nearer (where the plane runs away from the
 * light towards the pixel centre, a surface between the two depths, such as a wall at the
 * receiver's foot seen at a grazing angle, is beside the ray, not on it), less the bias. */
float occluding_depth(int k, vec2 px, vec2 at, float depth, vec2 slope, float slope_slack)
{
  float plane_depth = depth + dot(slope, px + 0.5 - at);
  float slack = DEPTH_BIAS_PIXELS * views.view_info[k].z + slope_slack * length(slope);
  return min(plane_depth, depth) - slack;
}

vec3 plane_lookup(int k, vec3 position, vec3 plane_normal, float slope_slack)
{
  vec2 at, slope;
  float depth;
  receiver_plane(k, position, plane_normal, at, depth, slope);
  /* Of a cropped view, its depth map holds the pixels of the window alone (views.window). */
  vec2 px = floor(at);
  if (any(lessThan(px, views.window[k].xy)) || any(greaterThanEqual(px, views.window[k].xy + views.window[k].zw))) {
    return vec3(-1.0);
  }
  return vec3(px, occluding_depth(k, px, at, depth, slope, slope_slack));
}

/* The depth of the receiver's plane at the centre of the pixel `position` falls in. */
float receiver_plane_depth(int k, vec3 position, vec3 plane_normal)
{
  vec2 at, slope;
  float depth;
  receiver_plane(k, position, plane_normal, at, depth, slope);
  return depth + dot(slope, floor(at) + 0.5 - at);
}

#ifndef MAX_DISTANCE
/* Visibility of `position` (on a plane of normal plane_normal) from view k. */
float visible_from(sampler2D depth_tex, int k, vec3 position, vec3 plane_normal, float slope_slack)
{
  vec3 lookup = plane_lookup(k, position, plane_normal, slope_slack);
  if (lookup.x < 0.0) {
    return 1.0;
  }
  /* A cleared pixel (depth 1) holds no surface, even where the extrapolated plane passes the
   * far end of the view's depth range. */
  float stored = texelFetch(depth_tex, ivec2(lookup.xy), 0).r;
#ifdef ALPHA_TAPS
  /* Occluders that let light through are kept per pixel at random (core/bake/alpha.py): the
   * mean of this pixel and its three neighbours towards the receiver's point, each tested at
   * its own centre on the receiver's plane, draws four times for the noise of one. */
  vec2 at, slope;
  float depth;
  receiver_plane(k, position, plane_normal, at, depth, slope);
  vec2 toward = sign(at - (lookup.xy + 0.5));
  float seen = (lookup.z <= stored || stored >= 1.0) ? 1.0 : 0.0;
  for (int t = 1; t < 4; t++) {
    vec2 px = clamp(lookup.xy + vec2(float(t & 1), float(t >> 1)) * toward, views.window[k].xy,
                    views.window[k].xy + views.window[k].zw - 1.0);
    float tap = texelFetch(depth_tex, ivec2(px), 0).r;
    seen += (occluding_depth(k, px, at, depth, slope, slope_slack) <= tap || tap >= 1.0) ? 1.0 : 0.0;
  }
  return 0.25 * seen;
#else
  return (lookup.z <= stored || stored >= 1.0) ? 1.0 : 0.0;
#endif
}
#endif

#ifdef MAX_DISTANCE
/* Max distance: the occluder nearest to `position` towards the light is the largest listed
 * depth in front of its own plane at the pixel centre (plane_lookup); view_info.w is the
 * depth range in normalized units, so depth differences times it are distances
 * (orthographic view). */
float visible_from_layers(int k, vec3 position, vec3 plane_normal, float slope_slack)
{
  vec3 lookup = plane_lookup(k, position, plane_normal, slope_slack);
  if (lookup.x < 0.0) {
    return 1.0;
  }
  ivec2 px = ivec2(lookup.xy);
  int count = min(int(imageLoad(layer_count, px).r), LAYERS);
  float depth = (views.view_proj[k] * vec4(position, 1.0)).z * 0.5 + 0.5;
  /* min_distance: nearer occluders are passed by. Measured from the receiver's plane at the
   * pixel centre, where the listed depths are (a ray there is as long as the receiver's). */
  float from_depth = receiver_plane_depth(k, position, plane_normal) - min_distance / views.view_info[k].w;
  float z_front = -1.0;
  for (int i = 0; i < count; i++) {
    float z = uintBitsToFloat(imageLoad(layer_depth, ivec3(px, i)).r);
    if (z < lookup.z && z > z_front && z <= from_depth) {
      z_front = z;
    }
  }
  return (z_front >= 0.0) ? occluder_visibility((depth - z_front) * views.view_info[k].w, max_distance) : 1.0;
}
#  define VISIBLE_AT(depth_tex, k, origin, plane_normal, slope_slack) \
    visible_from_layers(k, origin, plane_normal, slope_slack)
#else
#  define VISIBLE_AT(depth_tex, k, origin, plane_normal, slope_slack) \
    visible_from(depth_tex, k, origin, plane_normal, slope_slack)
#endif
#define VISIBLE(depth_tex, k, plane_normal) VISIBLE_AT(depth_tex, k, position.xyz, plane_normal, SLOPE_BIAS_PIXELS)

/* Hemisphere weight of a light at cos_theta > 0 (times the entry's scale, added in GATHER_VIEW). */
#ifdef UNIFORM_WEIGHTING
#  define HEMISPHERE_WEIGHT(cos_theta) 1.0
#else
#  define HEMISPHERE_WEIGHT(cos_theta) (cos_theta)
#endif
#ifdef SPREAD_COS /* outside the spread cone: weighs nothing */
#  define VIEW_WEIGHT(cos_theta) (HEMISPHERE_WEIGHT(cos_theta) * step(SPREAD_COS, (cos_theta)))
#else
#  define VIEW_WEIGHT(cos_theta) HEMISPHERE_WEIGHT(cos_theta)
#endif

/* Adds one view's term to sum when the entry faces that light. With shading normals the
 * weight is about the shading normal and visibility is judged from the true surface; a
 * direction above the shading hemisphere but below the face (the terminator) counts as
 * occluded: its ray would enter the surface, as in Cycles' AO pass. With Cycles' terminator
 * offset (core/bake/terminator.py) grazing and below-face directions are tested from the
 * lifted point instead: above the face with the face's plane (parallel, through the lifted
 * point); below it with the tangent plane of the smooth surface the lift reached, without
 * slope slack, since the facet it rose from, now between it and the light, may occlude it
 * (measured against Cycles' default on Spot with custom normals: bias -0.0000; with no plane
 * -0.0006, with the slope slack +0.0005). */
#ifdef TERMINATOR_OFFSET
/* One lookup per view whichever case applies: llvmpipe runs both sides of a branch its lanes
 * disagree on, so two calls would cost two lookups. */
#  define TERMINATOR_VISIBLE(depth_tex, k, cos_theta, cos_true) \
    float amount = lift_amount(cos_theta, cos_true, terminator_offset); \
    bool above = cos_true > 0.0; \
    float visible = 0.0; \
    if (above || amount * lift_length > MIN_LIFT) { \
      visible = VISIBLE_AT(depth_tex, k, position.xyz + lift * amount, above ? geometric : normal, \
                           above ? SLOPE_BIAS_PIXELS : 0.0); \
    }
#else
#  define TERMINATOR_VISIBLE(depth_tex, k, cos_theta, cos_true) \
    float visible = (cos_true > 0.0) ? VISIBLE(depth_tex, k, geometric) : 0.0;
#endif
#ifdef DIFFERENCE
/* A re-bake by difference (hao_addon/rebake_difference.py): a view of the scene before the
 * edit (omega.w < 0) takes its lit weight off and adds no weight, so the sums are N after
 * minus N before, and W after (ambient occlusion's two sums alone). */
#  define VIEW_TERM(k, term) ((views.omega[k].w < 0.0) ? vec2(-(term).x, 0.0) : (term))
#else
#  define VIEW_TERM(k, term) (term)
#endif
#ifdef SHADING_NORMALS
#  define GATHER_VIEW(depth_tex, k) \
  { \
    float cos_theta = dot(normal, views.omega[k].xyz); \
    if (cos_theta > 0.0) { \
      float weight = VIEW_WEIGHT(cos_theta) * position.w; \
      float cos_true = dot(geometric, views.omega[k].xyz); \
      TERMINATOR_VISIBLE(depth_tex, k, cos_theta, cos_true) \
      sum += VIEW_TERM(k, ESTIMATOR_TERM(weight, visible, views.omega[k].xyz)); \
    } \
  }
#else
#  define GATHER_VIEW(depth_tex, k) \
  { \
    float cos_theta = dot(normal, views.omega[k].xyz); \
    if (cos_theta > 0.0) { \
      float weight = VIEW_WEIGHT(cos_theta) * position.w; \
      sum += VIEW_TERM(k, ESTIMATOR_TERM(weight, VISIBLE(depth_tex, k, normal), views.omega[k].xyz)); \
    } \
  }
#endif

void main()
{
  /* This dispatch covers entries first_entry .. entry_end - 1 (a run of normal bins that can
   * face one of its views, core/bake/normal_bins.py), LIST_WIDTH per grid row. */
  int index = first_entry + int(gl_GlobalInvocationID.y) * LIST_WIDTH + int(gl_GlobalInvocationID.x);
  if (index >= entry_end) {
    return;
  }
  ivec2 slot = ivec2(index % LIST_WIDTH, index / LIST_WIDTH);
  vec4 position = imageLoad(entry_position, slot); /* xyz normalized world, w = the weight scale */
#ifdef SHADING_NORMALS
  vec4 normals = imageLoad(entry_normal, slot);
  vec3 normal = octahedral_decode(normals.xy);
  vec3 geometric = octahedral_decode(normals.zw);
#  ifdef TERMINATOR_OFFSET
  vec3 lift = imageLoad(entry_lift, slot).xyz;
  float lift_length = length(lift);
#  endif
#else
  vec3 normal = imageLoad(entry_normal, slot).xyz;
#endif
  EstimatorSums sum = ESTIMATOR_LOAD(accum, slot);
  EstimatorSums before = sum;
  GATHER_ALL_VIEWS
  if (sum != before) {
    ESTIMATOR_STORE(accum, slot, sum);
  }
}
