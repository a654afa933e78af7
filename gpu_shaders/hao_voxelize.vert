/* Voxelization: the triangle is projected along its dominant axis (surface pass) or along z
 * (solid pass) onto a plane of voxel columns, one pixel per column.
 * pos: world position; axis: dominant normal axis of the triangle (0, 1, 2). */
void main()
{
  vec3 g = (pos - grid_origin.xyz) / grid_origin.w;
#ifdef SOLID
  int a = 2;
#else
  int a = int(axis + 0.5);
#endif
  vec3 s = (a == 0) ? g.yzx : ((a == 1) ? g.zxy : g.xyz); /* (u, v, depth) */
  grid_pos = g;
  axis_id = a;
  gl_Position = vec4(s.xy / plane_size * 2.0 - 1.0, 0.5, 1.0);
}
