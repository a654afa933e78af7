/* Image-space near-field AO (Shanmugam & Arikan, section 4) at the AO-map resolution.
 * Neighbours within the projected r_far are gathered from two layers (front faces, and the
 * nearest back faces), each pixel standing for a small patch of surface, reconstructed as a
 * sphere pushed back along -n and summed with equations 2 and 3.
 *
 * Two choices make the sum an estimate of the form factor rather than an arbitrary sum (the
 * numpy mirror is hao_addon/core/proxies/near_field.py, which documents them): a sample only counts
 * when its patch faces the receiver (a ray through a closed occluder enters once through a
 * facing patch, so the two layers do not count it twice), and its sphere's cross-section
 * equals the patch's area seen from the receiver; M random samples of the disk stand for all
 * its pixels, each sample's occlusion weighted by (disk pixels) / M. */

vec3 layer_normal_at(int layer, ivec2 q)
{
  return layer == 0 ? imageLoad(gbuf_normal, q).xyz : imageLoad(back_normal, q).xyz;
}

vec4 layer_position_at(int layer, ivec2 q)
{
  return layer == 0 ? imageLoad(gbuf_position, q) : imageLoad(back_position, q);
}

void main()
{
  ivec2 low = ivec2(gl_GlobalInvocationID.xy);
  ivec2 low_size = (full_size + scale - 1) / scale;
  if (any(greaterThanEqual(low, low_size))) {
    return;
  }
  vec4 p;
  ivec2 pick = pick_gbuffer_pixel(low, p);
  if (p.w < 1.0) {
    imageStore(ao_low, low, vec4(1.0));
    return;
  }
  vec3 n = imageLoad(gbuf_normal, pick).xyz;
  float w_p = dot(view_proj_row3, vec4(p.xyz, 1.0));
  float px_per_unit = proj_scale * 0.5 * float(full_size.y) / max(w_p, 1e-6);
  float radius_px = r_far * px_per_unit;
  /* Each sample stands for (disk pixels) / M pixels: its one-pixel sphere's occlusion is
   * weighted by that (weighting the occlusion, not inflating the sphere, keeps the estimate
   * unbiased: occlusion is not linear in a sphere's size). */
  float weight = max(3.141592653589793 * radius_px * radius_px / float(samples), 1.0);
  uvec3 h = pcg3d(uvec3(ivec3(floor(p.xyz / (0.125 * r_far)))) + uvec3(7u, 11u, 13u));
  vec2 jit = vec2(h.xy) * (1.0 / 4294967296.0);
  float occlusion = 0.0;
  for (int i = 0; i < samples; i++) {
    float rr = sqrt((float(i) + jit.y) / float(samples)) * radius_px;
    float phi = 6.283185307179586 * fract(float(i) * HAO_GOLDEN_FRACTION + jit.x);
    ivec2 q = pick + ivec2(floor(vec2(cos(phi), sin(phi)) * rr + 0.5));
    if (any(lessThan(q, ivec2(0))) || any(greaterThanEqual(q, full_size))) {
      continue;
    }
    for (int layer = 0; layer < 2; layer++) {
      vec4 qp = layer_position_at(layer, q);
      if (qp.w == 0.0) {
        continue;
      }
      vec3 nq = layer_normal_at(layer, q);
      vec3 v = p.xyz - qp.xyz;
      float d = length(v);
      float facing = dot(nq, v) / max(d, 1e-12);
      if (d > r_far || d < 1e-6 || facing <= 0.0) {
        continue;
      }
      float w_q = dot(view_proj_row3, vec4(qp.xyz, 1.0));
      float pixel_size = 2.0 * w_q / (proj_scale * float(full_size.y));
      vec3 to_eye = eye.w > 0.5 ? normalize(eye.xyz - qp.xyz) : eye.xyz;
      float patch_area = pixel_size * pixel_size / max(abs(dot(nq, to_eye)), 0.2);
      float r = sqrt(patch_area * facing / 3.141592653589793);
      vec3 pc = (qp.xyz - nq * r) - p.xyz;
      float dist = length(pc);
      float sin_t = min(r / max(dist, r), 1.0);
      float solid_angle = 6.283185307179586 * (1.0 - sqrt(max(1.0 - sin_t * sin_t, 0.0)));
      occlusion += weight * occlusion_weight(d, max_distance) * (dist > 0.0 ?
                                 min(solid_angle * max(dot(n, pc) / max(dist, 1e-12), 0.0) / 3.141592653589793, 1.0) :
                                 1.0);
    }
  }
  imageStore(ao_low, low, vec4(1.0 - min(occlusion, 1.0)));
}
