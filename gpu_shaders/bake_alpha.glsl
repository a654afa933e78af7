/* Alpha-aware occluders (core/bake/alpha.py): a fragment of an occluder that lets light
 * through is kept with probability alpha ('blend', alpha_clip < 0) or where alpha reaches
 * alpha_clip ('clip'). alpha_face: x = the face's constant alpha, y = its layer of alpha_tex
 * (-1: none); the texel is fetched as the reference reads it (nearest, repeating). The
 * uniform number comes from a hash of the pixel, the direction (alpha_seed) and the
 * fragment's depth, so two surfaces on one pixel are kept independently. */
float alpha_uniform(uvec3 v)
{
  return float(pcg3d(v).x >> 8u) * (1.0 / 16777216.0);
}

bool alpha_keeps()
{
  float a = alpha_face_v.x;
  if (alpha_face_v.y >= 0.0) {
    ivec2 size = textureSize(alpha_tex, 0).xy;
    ivec2 t = clamp(ivec2(floor(fract(alpha_uv_v) * vec2(size))), ivec2(0), size - 1);
    a *= texelFetch(alpha_tex, ivec3(t, int(alpha_face_v.y + 0.5)), 0).r;
  }
  if (alpha_clip >= 0.0) {
    return a >= alpha_clip;
  }
  uvec3 key = uvec3(uvec2(gl_FragCoord.xy), floatBitsToUint(gl_FragCoord.z) ^ (uint(alpha_seed) * 2654435769u));
  return alpha_uniform(key) < a;
}
