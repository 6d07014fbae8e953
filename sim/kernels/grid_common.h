/* Uniform grid shared by every stage that visits neighbours. Cells are cubes of the kernel support
 * radius divided by THAW_REACH, keyed x-fastest, so the 2 THAW_REACH + 1 cells of one (y, z) row around
 * a particle are one contiguous range of the sorted particles. cell_start has ncells + 1 entries. */
#ifndef THAW_REACH
#define THAW_REACH 1
#endif
#ifndef THAW_GRID_COMMON_H
#define THAW_GRID_COMMON_H

/* Must match thaw::Phase (sim/particles.h). */
#define THAW_PHASE_WATER 0
#define THAW_PHASE_ICE 1
#define THAW_PHASE_SOLID 2
#define THAW_PHASE_AIR 3

typedef struct {
  float4 origin;   /* grid minimum corner; w unused */
  float inv_cell;  /* 1 / cell size */
  int nx, ny, nz;
} Grid;

int4 grid_cell(const Grid g, float4 p) {
  const int4 c = convert_int4_rtn((p - g.origin) * g.inv_cell);
  return clamp(c, (int4)(0), (int4)(g.nx - 1, g.ny - 1, g.nz - 1, 0));
}

uint grid_key(const Grid g, int4 c) { return (uint)((c.z * g.ny + c.y) * g.nx + c.x); }

/* Visits every particle j in the cells within THAW_REACH of cell c; BODY sees j. */
#define FOR_EACH_NEIGHBOUR(g, cell_start, c, BODY)                                   \
  for (int dz_ = -THAW_REACH; dz_ <= THAW_REACH; ++dz_) {                            \
    const int z_ = (c).z + dz_;                                                      \
    if (z_ < 0 || z_ >= (g).nz) continue;                                            \
    for (int dy_ = -THAW_REACH; dy_ <= THAW_REACH; ++dy_) {                          \
      const int y_ = (c).y + dy_;                                                    \
      if (y_ < 0 || y_ >= (g).ny) continue;                                          \
      const int row_ = (z_ * (g).ny + y_) * (g).nx;                                  \
      const uint jb_ = (cell_start)[row_ + max((c).x - THAW_REACH, 0)];              \
      const uint je_ = (cell_start)[row_ + min((c).x + THAW_REACH, (g).nx - 1) + 1]; \
      for (uint j = jb_; j < je_; ++j) { BODY }                                      \
    }                                                                                \
  }

#endif
