/* Occlusion of one sphere at the AO-map pixel's surface point, by the paper's equations 2
 * and 3 (A_psi / pi as a fraction of the cosine-weighted hemisphere), cut off beyond d_far,
 * weighted as core/proxies/sphere_ao.sphere_weight: the AO's distance falloff halfway into
 * the sphere, and with a near field (near_radius > 0) the sphere's share beyond its radius.
 * Multiplicative blending into the AO map: A *= 1 - occlusion. */

void main()
{
  ivec2 low = ivec2(gl_FragCoord.xy);
  vec4 p = imageLoad(low_position, low);
  if (p.w < 1.0) {
    discard;
  }
  vec3 pc = sphere_data.xyz - p.xyz;
  float dist = length(pc);
  if (dist > sphere_reach) {
    discard;
  }
  /* Inside the sphere the distance is clamped to r (see hao_addon/core/proxies/sphere_ao.py). */
  float r = sphere_data.w;
  float occlusion = 1.0;
  if (dist > 0.0) {
    vec3 n = imageLoad(low_normal, low).xyz;
    float sin_t = min(r / max(dist, r), 1.0);
    float solid_angle = 6.283185307179586 * (1.0 - sqrt(max(1.0 - sin_t * sin_t, 0.0)));
    occlusion = min(solid_angle * max(dot(n, pc) / dist, 0.0) / 3.141592653589793, 1.0);
  }
  occlusion *= occlusion_weight(max(dist - 0.5 * r, 0.0), max_distance);
  if (near_radius > 0.0) {
    occlusion *= clamp((dist + r - near_radius) / (2.0 * max(r, 1e-30)), 0.0, 1.0);
  }
  far_out = vec4(1.0 - occlusion);
}
