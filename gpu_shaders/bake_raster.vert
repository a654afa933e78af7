/* Light-view raster shared by the depth pre-pass and the splat pass (one vertex shader, so
 * both passes compute bit-identical depths for the same triangle).
 * pos: normalized world position; uv: UV in [0, 1]; face: xyz = unit face normal,
 * w = 1 / S_f (the face's exact normalizer) for target faces and 0 for occluders; with
 * shading normals the corner's normal and 1 / S (plan.target_corners); above: the fraction of
 * S above the face (plan.target_above). */
void main()
{
  uv_texel = uv * tex_size;
  face_data = face;
  above_fraction = above;
  gl_Position = view_proj * vec4(pos, 1.0);
}
