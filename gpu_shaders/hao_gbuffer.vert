/* G-buffer: world position and normal of the visible surface of every evaluated mesh.
 * pos, nrm: world-space corner position and normal; flags: 1 = AO receiver, 0.5 = object
 * with a baked AO map (HAO skips its pixels, it still occludes). */
void main()
{
  world_pos = pos;
  world_nrm = nrm;
  receiver = flags;
  gl_Position = view_proj * vec4(pos, 1.0);
}
