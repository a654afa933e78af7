/* The cascades of the AO pass (std140; layout: hao_sampling.CASCADES_DTYPE, up to
 * MAX_CASCADES, a define from core/hao/cascades.py), finest first, each inside the next:
 * origin_voxel is the grid's corner (anchor-relative world) and voxel size, dims its voxels
 * and (w) pyramid levels, atlas.x its row in the grid texture; count.x how many are used. */
struct HaoCascades {
  vec4 origin_voxel[MAX_CASCADES];
  ivec4 dims[MAX_CASCADES];
  ivec4 atlas[MAX_CASCADES];
  ivec4 count;
};
