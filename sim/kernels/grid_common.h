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
/* Particles the fluid passes do not move: static solids, and ice (rigid ice moves its own particles:
 * sim/rigid_ice.h). The fluid solver sees both as boundary particles. */
#define THAW_IS_STATIC(ph) ((ph) == THAW_PHASE_SOLID || (ph) == THAW_PHASE_ICE)

/* Must match ClGrid in sim/cl_grid.h. */
typedef struct {
  float4 origin;    /* grid minimum corner; w unused */
  float4 inv_cell;  /* 1 / cell size along x, y, z (cubes, except along periodic axes); w unused */
  int nx, ny, nz;
} Grid;

/* The cell-key pass's parameters. Must match ClKeysParams in sim/cl_grid.h. */
typedef struct {
  float4 dmin, dmax;  /* the domain; w unused */
  uint open_faces;    /* sides water leaves through: bit 2a lower, 2a + 1 upper side of axis a */
  uint ncells;        /* the key of a particle that left */
  uint n;             /* particles */
  uint intakes;       /* -DTHAW_INTAKE: nonzero when some take[i] marks air an air dryer takes in (grid.cl) */
} KeysParams;

int4 grid_cell(const Grid g, float4 p) {
  const int4 c = convert_int4_rtn((p - g.origin) * g.inv_cell);
  return clamp(c, (int4)(0), (int4)(g.nx - 1, g.ny - 1, g.nz - 1, 0));
}

uint grid_key(const Grid g, int4 c) { return (uint)((c.z * g.ny + c.y) * g.nx + c.x); }

/* Periodic y and z axes (solver.periodic; -DTHAW_ROW_WRAP_Y/Z): the grid wraps there, its cells divide
 * the domain's length exactly (sim/neighbour_grid.cpp) and the scene guarantees at least three of them,
 * so no row is visited twice. Rows stay contiguous along x, which never wraps in a flowing scene. */
#ifdef THAW_ROW_WRAP_Y
#define THAW_WY 1
#else
#define THAW_WY 0
#endif
#ifdef THAW_ROW_WRAP_Z
#define THAW_WZ 1
#else
#define THAW_WZ 0
#endif

/* The first cell of row (dz, dy) around cell c, or -1 where that row lies outside the grid. */
int neighbour_row(const Grid g, const int4 c, const int dz, const int dy) {
  int z = c.z + dz, y = c.y + dy;
  if (THAW_WZ) z = (z + g.nz) % g.nz;
  if (THAW_WY) y = (y + g.ny) % g.ny;
  return (z < 0 || z >= g.nz || y < 0 || y >= g.ny) ? -1 : (z * g.ny + y) * g.nx;
}

/* What a particle's position p becomes for the neighbours in row (dz, dy) around its cell c: moved by a
 * period where the row wrapped, so that p - x_j is the nearest image's offset (minimum image). */
float4 row_image(const Grid g, const int4 c, const int dz, const int dy, const float4 p) {
  float4 q = p;
  if (THAW_WY) {
    const int y = c.y + dy;
    const float L = (float)g.ny / g.inv_cell.y;
    q.y += y < 0 ? L : (y >= g.ny ? -L : 0.0f);
  }
  if (THAW_WZ) {
    const int z = c.z + dz;
    const float L = (float)g.nz / g.inv_cell.z;
    q.z += z < 0 ? L : (z >= g.nz ? -L : 0.0f);
  }
  return q;
}

/* Inside FOR_EACH_NEIGHBOUR_ROW: p as the current row's neighbours see it (row_image); p itself where no
 * axis wraps. */
#if THAW_WY || THAW_WZ
#define THAW_ROW_POS(g, c, p) row_image(g, c, dz_, dy_, p)
#else
#define THAW_ROW_POS(g, c, p) (p)
#endif

/* Visits the (2 THAW_REACH + 1)^2 rows of cells around cell c; the statement that follows it sees each
 * row's contiguous range [jb, je) of sorted particles:
 *     FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) { ... }
 * (a `continue` in it goes on to the next row). Written as nested for statements, not as a macro that
 * takes the body: OpenCL C has no variadic macros, and NVIDIA's compiler refuses them. Kept
 * deliberately simple: the walk's per-row cost is a large part of a pass (measured: trimming rows to
 * the cells that can hold a neighbour visits a quarter fewer candidates but made the density pass
 * slower; see docs/BENCHMARKS.md). */
#define FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) \
  FOR_EACH_ROW_WITHIN(g, cell_start, c, THAW_REACH, jb, je)

/* The same over the rows within `reach` cells of c (a pass whose patch reaches past the support). */
#define FOR_EACH_ROW_WITHIN(g, cell_start, c, reach, jb, je)                                 \
  for (int dz_ = -(reach); dz_ <= (reach); ++dz_)                                            \
    for (int dy_ = -(reach); dy_ <= (reach); ++dy_)                                          \
      for (int row_ = neighbour_row(g, c, dz_, dy_); row_ >= 0; row_ = -1)                   \
        for (uint jb = (cell_start)[row_ + max((c).x - (reach), 0)],                         \
                  je = (cell_start)[row_ + min((c).x + (reach), (g).nx - 1) + 1], once_ = 1; \
             once_; once_ = 0)

/* SIMD lanes over neighbour candidates: the neighbour passes (density.cl, forces.cl) read THAW_VW
 * consecutive sorted particles at a time (float4/8/16) from structure-of-arrays copies, with per-lane
 * masks, so pocl emits vector code for their inner loops (it vectorizes across work-items only in
 * loops without inner loops). Accumulating lane-wise changes only the summation order: each lane sums
 * its own candidates in order and the lanes are added in a fixed tree (lanes_sum), so results stay
 * deterministic. Loads may run up to THAW_VW - 1 elements past a row's end (and the last particle:
 * the arrays are padded). */
#ifndef THAW_VW
#define THAW_VW 8
#endif
#define THAW_CAT_(a, b) a##b
#define THAW_CAT(a, b) THAW_CAT_(a, b)
#define floatV THAW_CAT(float, THAW_VW)
#define intV THAW_CAT(int, THAW_VW)
#define vloadV THAW_CAT(vload, THAW_VW)
#if THAW_VW == 4
#define THAW_LANE_IDS ((int4)(0, 1, 2, 3))
#elif THAW_VW == 8
#define THAW_LANE_IDS ((int8)(0, 1, 2, 3, 4, 5, 6, 7))
#elif THAW_VW == 16
#define THAW_LANE_IDS ((int16)(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15))
#else
#error "THAW_VW must be 4, 8 or 16"
#endif

float lanes_sum4(float4 a) { return (a.x + a.y) + (a.z + a.w); }
float lanes_sum8(float8 a) { return lanes_sum4(a.lo + a.hi); }
float lanes_sum16(float16 a) { return lanes_sum8(a.lo + a.hi); }
#define lanes_sum THAW_CAT(lanes_sum, THAW_VW)

/* Visits every particle j in the cells within THAW_REACH of cell c; the statement that follows it sees
 * j:  FOR_EACH_NEIGHBOUR(g, cell_start, c, j) { ... } */
#define FOR_EACH_NEIGHBOUR(g, cell_start, c, j) \
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb_, je_) for (uint j = jb_; j < je_; ++j)

#endif
