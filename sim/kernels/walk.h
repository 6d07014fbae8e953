/* A neighbour pass's view of a pair, as functions every neighbour kernel shares (after grid_common.h and
 * sph_lanes.h): the reorder's structure-of-arrays copy of the particles, and the lanes of candidates
 * j .. j + THAW_VW - 1 as particle i sees them. The walk over cells is grid_common.h's FOR_EACH_NEIGHBOUR_ROW
 * (wrapped_walk.h's FOR_EACH_HEAT_RANGE where x wraps too). */
#ifndef THAW_WALK_H
#define THAW_WALK_H

/* The reorder's structure-of-arrays copy (neighbour_grid.cpp): blocks of `stride` floats x, y, z, m (then
 * vx, vy, vz). */
typedef struct {
  global const float* x;
  global const float* y;
  global const float* z;
  global const float* m;
} Positions;

Positions soa_positions(global const float* soa, const uint stride) {
  Positions s;
  s.x = soa;
  s.y = soa + stride;
  s.z = soa + 2 * stride;
  s.m = soa + 3 * stride;
  return s;
}

/* The lanes j .. j + THAW_VW - 1 seen from a particle at p: the offsets x_i - x_j (dx, dy, dz), their
 * squared length r2, and which lanes are neighbours (`in`): candidates before the row's end je within the
 * support, r2 < H2. Lanes past je read padding (grid_common.h) and are masked out. */
typedef struct {
  floatV dx, dy, dz, r2;
  intV in;
} Pair;

/* The minimum image of an offset d along an axis of period L (L = 0: the axis does not wrap). Periodic
 * axes (-DTHAW_PERIODIC_X/Y/Z) are wrapped_walk.h's; without them no pass pays for the test. */
#if defined(THAW_PERIODIC_X) || defined(THAW_PERIODIC_Y) || defined(THAW_PERIODIC_Z)
floatV nearest_image(const floatV d, const float L) { return L > 0.0f ? d - L * rint(d / L) : d; }
#else
floatV nearest_image(const floatV d, const float L) { return d; }
#endif

Pair pair_lanes(const Positions s, const float4 p, const uint j, const uint je, const float H2) {
  Pair q;
  q.dx = p.x - vloadV(0, s.x + j);
  q.dy = p.y - vloadV(0, s.y + j);
  q.dz = p.z - vloadV(0, s.z + j);
  q.r2 = q.dx * q.dx + q.dy * q.dy + q.dz * q.dz;
  q.in = (THAW_LANE_IDS < (int)(je - j)) & (q.r2 < H2);
  return q;
}

/* The same along periodic axes (period.x, .y, .z: 0 where an axis does not wrap), each offset the nearest
 * image's. */
Pair pair_lanes_wrapped(const Positions s, const float4 p, const float4 period, const uint j, const uint je,
                        const float H2) {
  Pair q;
  q.dx = nearest_image(p.x - vloadV(0, s.x + j), period.x);
  q.dy = nearest_image(p.y - vloadV(0, s.y + j), period.y);
  q.dz = nearest_image(p.z - vloadV(0, s.z + j), period.z);
  q.r2 = q.dx * q.dx + q.dy * q.dy + q.dz * q.dz;
  q.in = (THAW_LANE_IDS < (int)(je - j)) & (q.r2 < H2);
  return q;
}

#endif
