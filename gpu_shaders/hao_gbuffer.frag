void main()
{
  /* Viewport shading is two-sided: a back face is seen from behind, so its AO hemisphere
   * is the one facing the viewer. */
  vec3 n = normalize(world_nrm);
  gbuf_position = vec4(world_pos, receiver);
#ifdef BACK_LAYER
  /* Second layer (nearest back faces, for the near-field pass): the surface's own normal. */
  gbuf_normal = vec4(n, 0.0);
#else
  gbuf_normal = vec4(gl_FrontFacing ? n : -n, 0.0);
#endif
}
