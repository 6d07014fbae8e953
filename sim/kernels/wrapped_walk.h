/* Neighbour walks that wrap along periodic axes, for the passes that run in the heat-only mode too (heat.cl,
 * surface.cl): FOR_EACH_HEAT_RANGE visits the cells around c one at a time, THAW_WRAP takes the minimum
 * image. Built after grid_common.h. */
#ifndef THAW_WRAPPED_WALK_H
#define THAW_WRAPPED_WALK_H

/* Neighbour rows around cell c. Along periodic axes (-DTHAW_PERIODIC_X/Y/Z: any axis in the heat-only mode, y
 * and z in a flowing scene) the grid
 * wraps and cells are visited one at a time, so that a wrapped x range needs no special case. */
#if defined(THAW_PERIODIC_X) || defined(THAW_PERIODIC_Y) || defined(THAW_PERIODIC_Z)
#define THAW_PERIODIC 1
#endif

#ifdef THAW_PERIODIC
int wrap_axis(int v, int n, int periodic) { return periodic ? (v + n) % n : v; }
#ifdef THAW_PERIODIC_X
#define THAW_PX 1
#else
#define THAW_PX 0
#endif
#ifdef THAW_PERIODIC_Y
#define THAW_PY 1
#else
#define THAW_PY 0
#endif
#ifdef THAW_PERIODIC_Z
#define THAW_PZ 1
#else
#define THAW_PZ 0
#endif
/* The cell (dz, dy, dx) around c with the periodic axes wrapped, or -1 where it lies outside the grid. */
int heat_cell(const Grid g, const int4 c, const int dz, const int dy, const int dx) {
  const int z = wrap_axis(c.z + dz, g.nz, THAW_PZ), y = wrap_axis(c.y + dy, g.ny, THAW_PY),
            x = wrap_axis(c.x + dx, g.nx, THAW_PX);
  return (z < 0 || z >= g.nz || y < 0 || y >= g.ny || x < 0 || x >= g.nx) ? -1 : (z * g.ny + y) * g.nx + x;
}
/* As FOR_EACH_NEIGHBOUR_ROW (grid_common.h), one cell at a time: the statement that follows sees [jb, je). */
#define FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je)                            \
  for (int dz_ = -1; dz_ <= 1; ++dz_)                                            \
    for (int dy_ = -1; dy_ <= 1; ++dy_)                                          \
      for (int dx_ = -1; dx_ <= 1; ++dx_)                                        \
        for (int cell_ = heat_cell(g, c, dz_, dy_, dx_); cell_ >= 0; cell_ = -1) \
          for (uint jb = (cell_start)[cell_], je = (cell_start)[cell_ + 1], once_ = 1; once_; once_ = 0)
#else
#define FOR_EACH_HEAT_RANGE FOR_EACH_NEIGHBOUR_ROW
#endif

/* Minimum image along periodic axes: period = domain lengths (0 where not periodic). */
#ifdef THAW_PERIODIC
#define THAW_WRAP(d, L) ((L) > 0.0f ? (d) - (L)*rint((d) / (L)) : (d))
#else
#define THAW_WRAP(d, L) (d)
#endif

#endif
