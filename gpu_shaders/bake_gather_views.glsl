/* The light views of one gather dispatch (std140, up to GATHER_MAX_VIEWS, a define from
 * bake_gather.py whose GATHER_VIEWS_DTYPE is this block's layout): view_proj maps normalized
 * world to the view's clip space, plane_slope.xy turns the image of a plane's normal under it
 * into the plane's depth change per pixel (core/bake/views.OrthoView.plane_slope), omega
 * points towards the light, view_info is (width, height, one pixel's extent in depth units,
 * the depth range in normalized units). A uniform buffer, because four views' push
 * constants would pass the 128 bytes some backends guarantee. */
struct GatherViews {
  mat4 view_proj[GATHER_MAX_VIEWS];
  vec4 plane_slope[GATHER_MAX_VIEWS];
  vec4 omega[GATHER_MAX_VIEWS];
  vec4 view_info[GATHER_MAX_VIEWS];
};
