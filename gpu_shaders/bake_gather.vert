/* Shadow-map baseline (the comparison of McGraw & Sowers' Table 1): the target is
 * rasterized in UV space, one fragment per texel centre, carrying its light-view position. */
void main()
{
  vec2 uv_texel = uv * tex_size;
  light_pos = (view_proj * vec4(pos, 1.0)).xyz;
  face_data = face;
  gl_Position = vec4(uv_texel / tex_size * 2.0 - 1.0, 0.0, 1.0);
}
