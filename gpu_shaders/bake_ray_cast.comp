/* Selected-to-Active projection on the GPU: the first hit of each ray on the high-poly
 * triangles, either side, within `reach` (core/bake/ray_grid.py's uniform grid, walked cell by
 * cell with a 3D DDA; the twin of mathutils' BVH ray cast in core/bake/projection.py).
 *
 * Everything is in cell units (world - grid lo) / cell side: cell (x, y, z) spans [x, x + 1)
 * and so on, and the grid's box is [0, dims]. One invocation per ray; ray r's data are entry r
 * of each list, read with gpu/list_inputs.py's macros (list textures or storage buffers).
 *
 * Output hit_out: (face as int bits, -1 for a miss; t; u; v): the hit is
 * (1 - u - v) v0 + u v1 + v v2 at origin + t * direction. */

/* Moller-Trumbore, both sides: (t, u, v) of the hit, t < 0 for none. A ray through a shared
 * edge may report both triangles (EDGE_SLACK keeps it from slipping between them). */
vec3 intersect(vec3 origin, vec3 dir, int face)
{
  vec3 v0 = LIST_VEC4(tri_corners, 3 * face).xyz;
  vec3 e1 = LIST_VEC4(tri_corners, 3 * face + 1).xyz;
  vec3 e2 = LIST_VEC4(tri_corners, 3 * face + 2).xyz;
  vec3 p = cross(dir, e2);
  float det = dot(e1, p);
  if (det == 0.0) {
    return vec3(-1.0);
  }
  float inv_det = 1.0 / det;
  vec3 s = origin - v0;
  float u = dot(s, p) * inv_det;
  vec3 q = cross(s, e1);
  float v = dot(dir, q) * inv_det;
  if (u < -EDGE_SLACK || v < -EDGE_SLACK || u + v > 1.0 + EDGE_SLACK) {
    return vec3(-1.0);
  }
  return vec3(dot(e2, q) * inv_det, u, v);
}

void main()
{
  int ray = first_ray + int(gl_GlobalInvocationID.y) * LIST_WIDTH + int(gl_GlobalInvocationID.x);
  if (ray >= ray_end) {
    return;
  }
  vec3 origin = LIST_VEC4(ray_origin, ray).xyz;
  vec3 dir = LIST_VEC4(ray_direction, ray).xyz;
  vec4 result = vec4(intBitsToFloat(-1), 0.0, 0.0, 0.0);
  vec3 box = vec3(dims);
  /* A zero component steps never: a huge but finite inverse keeps 0 * inf NaNs out. */
  vec3 safe = mix(dir, vec3(1e-30), lessThan(abs(dir), vec3(1e-30)));
  vec3 inv = 1.0 / safe;
  vec3 t_lo = (vec3(0.0) - origin) * inv;
  vec3 t_hi = (box - origin) * inv;
  vec3 t_near = min(t_lo, t_hi);
  vec3 t_far = max(t_lo, t_hi);
  float t_enter = max(max(max(t_near.x, t_near.y), t_near.z), 0.0);
  float t_exit = min(min(min(t_far.x, t_far.y), t_far.z), reach);
  if (dot(dir, dir) == 0.0 || t_enter > t_exit) {
    LIST_STORE(hit_out, ray, result);
    return;
  }
  ivec3 cell = clamp(ivec3(floor(origin + dir * t_enter)), ivec3(0), dims - 1);
  ivec3 step_dir = ivec3(greaterThanEqual(safe, vec3(0.0))) * 2 - 1;
  /* Ray parameter at which the ray leaves the current cell along each axis, and per cell. */
  vec3 next = (vec3(cell) + vec3(greaterThan(step_dir, ivec3(0))) - origin) * inv;
  vec3 delta = abs(inv);
  float best = t_exit;
  int best_face = -1;
  vec2 best_uv = vec2(0.0);
  for (int visited = 0; visited < dims.x + dims.y + dims.z; visited++) {
    int c = (cell.z * dims.y + cell.y) * dims.x + cell.x;
    int first = int(LIST_UINT(cell_start, c));
    int last = int(LIST_UINT(cell_start, c + 1));
    for (int k = first; k < last; k++) {
      int face = int(LIST_UINT(cell_triangles, k));
      vec3 hit = intersect(origin, dir, face);
      if (hit.x >= 0.0 && hit.x <= best && (hit.x < best || face < best_face || best_face < 0)) {
        best = hit.x;
        best_face = face;
        best_uv = hit.yz;
      }
    }
    float leave = min(min(next.x, next.y), next.z);
    /* A hit before the ray leaves this cell is the nearest: every triangle it can meet
     * earlier overlaps a cell already visited. */
    if ((best_face >= 0 && best <= leave) || leave > t_exit) {
      break;
    }
    if (next.x == leave) {
      cell.x += step_dir.x;
      next.x += delta.x;
    }
    else if (next.y == leave) {
      cell.y += step_dir.y;
      next.y += delta.y;
    }
    else {
      cell.z += step_dir.z;
      next.z += delta.z;
    }
    if (any(lessThan(cell, ivec3(0))) || any(greaterThanEqual(cell, dims))) {
      break;
    }
  }
  if (best_face >= 0) {
    result = vec4(intBitsToFloat(best_face), best, best_uv);
  }
  LIST_STORE(hit_out, ray, result);
}
