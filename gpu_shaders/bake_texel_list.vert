/* Texel list of the shadow-map gather: the target rasterized once in UV space, one fragment
 * per covered texel centre, carrying the surface point and its normals.
 * pos: normalized world position; uv: UV in [0, 1]; face: the corner's shading normal and
 * 1 / S (the face normal and 1 / S_f on flat faces); geometric: the face normal;
 * bin: the face's normal bin (core/bake/normal_bins.py), a small whole number; tri_v0..2 and
 * corner_bary: the whole face and the corner's barycentric unit vector, so the fragment puts
 * its point inside the face (SAMPLE_INSET). With the terminator offset each corner also
 * carries its face's shading normals, so the fragment computes Cycles' lift of its point. */
void main()
{
  world_pos = pos;
  face_data = face;
  geometric_normal = geometric;
  face_bin = int(bin + 0.5);
  face_v0 = tri_v0;
  face_v1 = tri_v1;
  face_v2 = tri_v2;
  face_bary = corner_bary;
#ifdef TERMINATOR_OFFSET
  lift_n0 = tri_n0;
  lift_n1 = tri_n1;
  lift_n2 = tri_n2;
#endif
  gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
