/* Visibility of a receiver whose nearest occluder towards the light lies at distance t, for a
 * bake with a max distance (the numpy twin: hao_addon/core/kernels.occlusion_weight). Shared
 * by the scatter's splat and the gather's layered test. */
float occluder_visibility(float t, float max_distance)
{
  float x = clamp(t / max_distance, 0.0, 1.0);
#ifdef WENDLAND_FALLOFF
  /* Hybrid AO paper, equation 3. */
  return 1.0 - pow(1.0 - x, 4.0) * (4.0 * x + 1.0);
#else
  return (t < max_distance) ? 0.0 : 1.0;
#endif
}
