/* The gather's depth maps: positions only (a batch of the light-facing bins' faces,
 * core/bake/normal_bins.FaceBins). The scatter's pre-pass keeps bake_raster.vert, the vertex
 * shader of its splat pass, whose depths it must reproduce bit for bit. */
void main()
{
  gl_Position = view_proj * vec4(pos, 1.0);
}
