/* The light views of one gather dispatch (std140, up to VIEWS_PER_DISPATCH = 4): view_proj
 * maps normalized world to the view's clip space, omega points towards the light, view_info is
 * (width, height, one pixel's extent in clip z units, unused). A uniform buffer, because four
 * views' push constants would pass the 128 bytes some backends guarantee. */
struct GatherViews {
  mat4 view_proj[4];
  vec4 omega[4];
  vec4 view_info[4];
};
