/* Texel list of the shadow-map gather: the target rasterized once in UV space, one fragment
 * per covered texel centre, carrying the surface point and its normals.
 * pos: normalized world position; uv: UV in [0, 1]; face: the corner's shading normal and
 * 1 / S (the face normal and 1 / S_f on flat faces); geometric: the face normal;
 * bin: the face's normal bin (core/normal_bins.py), a small whole number. */
void main()
{
  world_pos = pos;
  face_data = face;
  geometric_normal = geometric;
  face_bin = int(bin + 0.5);
  gl_Position = vec4(uv * 2.0 - 1.0, 0.0, 1.0);
}
