void main()
{
  /* Viewport shading is two-sided: a back face is seen from behind, so its AO hemisphere
   * is the one facing the viewer. */
  vec3 n = normalize(world_nrm);
  gbuf_position = vec4(world_pos, receiver);
  gbuf_normal = vec4(gl_FrontFacing ? n : -n, 0.0);
}
