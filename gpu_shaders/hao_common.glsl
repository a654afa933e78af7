/* Shared by the Hybrid Ambient Occlusion passes; mirrored in hao_addon/core/hao/ao_pattern.py
 * and hao_addon/core/hao/bilateral.py, which the tests compare against. HAO_GOLDEN_FRACTION and
 * HAO_SELF_OFFSET are defines from ao_pattern.GLSL_DEFINES (one value for both sides). */

/* Wendland C2 kernel, HAO paper equation 3: w(t, h) = (1 - t/h)^4 (4 t/h + 1) on [0, h]. */
float wendland(float t, float h)
{
  float x = clamp(t / h, 0.0, 1.0);
  float y = 1.0 - x;
  return y * y * y * y * (4.0 * x + 1.0);
}

/* The AO's distance falloff at distance t (numpy twin: core/kernels.occlusion_weight):
 * Wendland with WENDLAND_FALLOFF defined, else a step at d_max; d_max <= 0 is unlimited
 * distance, where every hit occludes fully. */
float occlusion_weight(float t, float d_max)
{
  if (d_max <= 0.0) {
    return 1.0;
  }
#ifdef WENDLAND_FALLOFF
  return wendland(t, d_max);
#else
  return (t < d_max) ? 1.0 : 0.0;
#endif
}

/* Branchless orthonormal basis around n (Duff et al. 2017). */
void tangent_frame(vec3 n, out vec3 t, out vec3 s)
{
  float sgn = n.z >= 0.0 ? 1.0 : -1.0;
  float a = -1.0 / (sgn + n.z);
  float b = n.x * n.y * a;
  t = vec3(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x);
  s = vec3(b, sgn + n.y * n.y * a, -n.y);
}
