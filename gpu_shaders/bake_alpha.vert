/* Light-view positions of a batch that carries alpha (core/bake/alpha.py): gl_Position is
 * computed as bake_raster.vert and bake_depth_positions.vert compute it, so depths match the
 * passes that test against them. */
void main()
{
  alpha_uv_v = alpha_uv;
  alpha_face_v = alpha_face;
  gl_Position = view_proj * vec4(pos, 1.0);
}
