/* Multiplies the AO onto the image under it: black with alpha (1 - AO) * strength, blended
 * over, gives colour * (1 - alpha). gl_FragDepth is the G-buffer depth, so with a LESS_EQUAL
 * test against the viewport's depth buffer the AO never darkens something Blender drew in
 * front of the surface it belongs to. */
void main()
{
  ivec2 px = ivec2(gl_FragCoord.xy) - region_offset;
  float ao = texelFetch(ao_tex, px, 0).r;
  float depth = texelFetch(depth_tex, px, 0).r;
  if (depth >= 1.0 || ao >= 1.0) {
    discard;
  }
  gl_FragDepth = depth;
  frag_color = vec4(0.0, 0.0, 0.0, (1.0 - ao) * strength);
}
