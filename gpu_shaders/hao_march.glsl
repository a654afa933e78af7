/* The AO pass's voxel marches (hao_ao.comp), in grid units of the cascade being marched
 * (voxels of side 1 from its grid's corner). Numpy twins: core/hao/ao_pattern.py
 * (march_reference, dda_first_hits). Each cascade's grid sits in the texture `grid` at row
 * cascades.atlas[k].x as the atlas of its occupancy pyramid (core/hao/voxel_grid.py): level
 * L, cells of 2^L voxels, at x offset the finer levels' widths summed; bits along z. */

ivec3 cascade_dims;
int cascade_row;
int cascade_levels;

void use_cascade(int k)
{
  cascade_dims = cascades.dims[k].xyz;
  cascade_levels = cascades.dims[k].w;
  cascade_row = cascades.atlas[k].x;
}

/* Cells of `level` per axis. */
ivec3 level_cells(int level)
{
  return (cascade_dims + (1 << level) - 1) >> level;
}

bool cell_occupied(int offset, ivec3 cells, ivec3 c)
{
  if (any(lessThan(c, ivec3(0))) || any(greaterThanEqual(c, cells))) {
    return false;
  }
  uint word = imageLoad(grid, ivec3(offset + c.x, c.y + cascade_row, c.z >> 5)).r;
  return ((word >> uint(c.z & 31)) & 1u) != 0u;
}

/* Hierarchical 3D-DDA in the current cascade, from the surface point o along unit d, over
 * t in [t_begin, t_limit): the parameter where the ray reaches the first occupied voxel
 * whose centre lies more than HAO_SELF_SLAB voxels above o's tangent plane (normal n), or -1.
 * The slab holds every voxel the receiver's own surface marks near o (their centres lie
 * within sqrt(3)/2 of it), so the ray can start on the surface instead of SELF_OFFSET voxels
 * off it, inside whatever else is that close. The hit distance is the voxel centre's along
 * the ray (a surface runs through a voxel's middle on average), never before its entry.
 * Where a coarse cell is empty the ray jumps to its exit; where it is occupied it descends,
 * and only an occupied voxel of level 0 ends the ray, so no occupied voxel on the path is
 * stepped over (cells are looked up a nudge of MARCH_NUDGE voxels past each boundary, which
 * only misses voxels a ray clips by less). Leaving a cell into another parent climbs one
 * level. Each loop spends one step of `budget`; t_left is where the ray left the grid's box
 * (or stopped). */
float march_hierarchical(vec3 o, vec3 n, vec3 d, float t_begin, float t_limit, inout int budget, out float t_left)
{
  vec3 dir = vec3(abs(d.x) < 1e-12 ? 1e-12 : d.x, abs(d.y) < 1e-12 ? 1e-12 : d.y, abs(d.z) < 1e-12 ? 1e-12 : d.z);
  vec3 inv = 1.0 / dir;
  vec3 t0 = -o * inv;
  vec3 t1 = (vec3(cascade_dims) - o) * inv;
  vec3 t_near = min(t0, t1);
  vec3 t_far = max(t0, t1);
  float t = max(max(max(t_near.x, t_near.y), t_near.z), t_begin);
  float t_end = min(min(min(t_far.x, t_far.y), t_far.z), t_limit);
  t_left = t_end;
  vec3 toward = step(vec3(0.0), dir); /* 1 where the ray runs towards + */
  ivec3 toward_cell = ivec3(toward);
  int level = 0;
  int offset = 0;
  ivec3 cells = cascade_dims;
  float side = 1.0;
  float inside = 0.0;   /* length of the current run of occupied voxels on the ray */
  float run_hit = 0.0;  /* the hit distance of the run's first voxel */
  while (budget > 0) {
    if (t >= t_end) {
      return -1.0;
    }
    budget--;
    ivec3 c = ivec3(floor((o + d * (t + MARCH_NUDGE)) * (1.0 / side)));
    if (cell_occupied(offset, cells, c)) {
      if (level > 0) {
        level--;
        side *= 0.5;
        cells = level_cells(level);
        offset -= cells.x;
        continue;
      }
      vec3 centre = vec3(c) + 0.5 - o;
      if (dot(centre, n) > HAO_SELF_SLAB) {
        vec3 t_out = ((vec3(c) + toward) - o) * inv;
        float chord = min(min(t_out.x, t_out.y), t_out.z) - t;
        run_hit = (inside > 0.0) ? run_hit : max(t, dot(centre, d));
        inside += chord;
        if (inside >= HAO_MIN_CHORD) {
          return run_hit;
        }
      }
      else {
        inside = 0.0;
      }
    }
    else {
      inside = 0.0;
    }
    vec3 t_exit = ((vec3(c) + toward) * side - o) * inv;
    float t_next = min(min(t_exit.x, t_exit.y), t_exit.z);
    /* The ray leaves its parent cell where it leaves through a face on an odd/even side. */
    bvec3 exits = equal(t_exit, vec3(t_next));
    bvec3 parent_face = equal(c & 1, toward_cell);
    bool leaves_parent = (exits.x && parent_face.x) || (exits.y && parent_face.y) || (exits.z && parent_face.z);
    if (inside == 0.0 && level + 1 < cascade_levels && leaves_parent) {
      offset += cells.x;
      level++;
      side *= 2.0;
      cells = level_cells(level);
    }
    t = max(t_next, t + MARCH_NUDGE);
  }
  t_left = t;
  return -1.0;
}

/* The paper's march in the current cascade: `steps` samples at t_j = reach (j + jitter) /
 * steps; the first occupied one ends the ray (returns its t, or -1). */
float march_fixed(vec3 o, vec3 d, float reach, int steps, float jitter)
{
  for (int j = 0; j < steps; j++) {
    float t = (float(j) + jitter) / float(steps) * reach;
    if (cell_occupied(0, cascade_dims, ivec3(floor(o + d * t)))) {
      return t;
    }
  }
  return -1.0;
}
