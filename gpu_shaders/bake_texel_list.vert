/* Texel list of the shadow-map gather: the target rasterized once in UV space, one fragment
 * per covered texel centre, carrying the surface point and its normals.
 * pos: normalized world position; uv: UV in [0, 1]; face: the corner's shading normal and
 * 1 / S (the face normal and 1 / S_f on flat faces); geometric: the face normal;
 * bin: the face's normal bin (core/bake/normal_bins.py), a small whole number. With the terminator
 * offset each corner also carries its whole face (corners and their shading normals) and its
 * barycentric unit vector, so the fragment computes Cycles' lift of its point. */
void main()
{
  world_pos = pos;
  face_data = face;
  geometric_normal = geometric;
  face_bin = int(bin + 0.5);
#ifdef TERMINATOR_OFFSET
  lift_v0 = tri_v0;
  lift_v1 = tri_v1;
  lift_v2 = tri_v2;
  lift_n0 = tri_n0;
  lift_n1 = tri_n1;
  lift_n2 = tri_n2;
  lift_bary = corner_bary;
#endif
  gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
