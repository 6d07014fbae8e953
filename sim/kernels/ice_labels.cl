/* Ice bodies: connected components of the ice particles (Iwasaki et al. 2010, sec. 6 and Fig. 4). Two ice
 * particles closer than the connection radius belong to one body; every ice particle's label converges to
 * the largest id in its body. The host (sim/ice_bodies.cpp) runs, on particles sorted by cell:
 *   label_slots       sorted index of each id, for the pointer jump
 *   ice_points        coordinates of the ice particles for the lanes of the walk
 *   ice_neighbours    each ice particle's ice neighbours within the radius; labels start as the own id
 *   propagate_labels  one Jacobi sweep of max propagation with pointer jumps (and hooks), until nothing
 *                     changes
 * The neighbour lists are built once per labelling (one grid walk, into rows of a fixed width the host
 * widens when a particle has more): each sweep then reads a few neighbours rather than walking the cells
 * again. */

/* The pair test, (dx dx + dy dy) + dz dz < r2, must give the same answer on the host (tests, reference
 * loops) as here: no fused multiply-add. */
#pragma OPENCL FP_CONTRACT OFF

#define THAW_NO_LABEL 0xffffffffu

/* Particles per work-item of a sweep (the host sets it): most are not ice and take a few instructions,
 * so one work-item each spent more in pocl's per-item overhead than in the work. */
#ifndef THAW_SWEEP_TILE
#define THAW_SWEEP_TILE 16
#endif

/* The ice particles' coordinates as x, y, z blocks of `stride` floats for the lanes of ice_neighbours; NaN
 * for other phases and the padding (up to THAW_VW - 1 past the last particle is read), so their distance
 * test fails without a phase test. A fourth block holds each particle's group as an int: its body before
 * this labelling (with use_group), or -1 (kNoBody's bits: in no body yet, or no groups given). */
kernel void ice_points(global const float4* pos, global const uchar* phase, global const uint* group,
                       const uint use_group, global float* points, const uint stride, const uint n) {
  const uint i = get_global_id(0);
  if (i >= stride) return;
  const bool ice = i < n && phase[i] == THAW_PHASE_ICE;
  const float4 p = ice ? pos[i] : (float4)(NAN);
  points[i] = p.x;
  points[stride + i] = p.y;
  points[2 * stride + i] = p.z;
  ((global int*)points)[3 * stride + i] = (ice && use_group) ? (int)group[i] : -1;
}

int lanes_sum_int4(int4 a) { return (a.x + a.y) + (a.z + a.w); }
int lanes_sum_int8(int8 a) { return lanes_sum_int4(a.lo + a.hi); }
int lanes_sum_int16(int16 a) { return lanes_sum_int8(a.lo + a.hi); }
#define lanes_sum_int THAW_CAT(lanes_sum_int, THAW_VW)

/* Each ice particle's ice neighbours within the radius and in a compatible group (the same one, or either
 * in none: two bodies that come to touch stay two, new ice joins what it touches), in the grid walk's
 * order, in its row of `width` slots (edges[i * width + k]); degree[i] is the full count, and a count
 * beyond the width is reported in overflow[0] (the largest; the atomic runs only then) so the host can
 * widen the rows and walk again. Candidates are tested THAW_VW at a time (SIMD lanes, grid_common.h); the
 * few hits are then written one by one. The labels start as the own id. */
kernel void ice_neighbours(global const float* points, const uint stride, global const uint* id,
                           global const uint* cell_start, const Grid g, const float radius, const uint width,
                           global uint* edges, global uint* degree, volatile global uint* overflow,
                           global uint* label, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  global const float* X = points;
  global const float* Y = points + stride;
  global const float* Z = points + 2 * stride;
  global const int* G = (global const int*)(points + 3 * stride);
  const float4 p = (float4)(X[i], Y[i], Z[i], 0.0f);
  const int gi = G[i];
  const intV any_group = (intV)(gi == -1 ? -1 : 0);
  const float r2 = radius * radius;
  uint count = 0;
  const bool ice = !isnan(p.x);
  if (ice) {
    /* Only the cells that reach within the radius along each axis: a neighbour's coordinates lie in
     * [p - radius, p + radius], and rounding and the cell index are monotone, so its cell lies between
     * these two (clamped to the grid as every particle's cell is). On a lattice with cells of 2 spacings
     * and a radius of 1.5, that is 8 cells of the 27 FOR_EACH_NEIGHBOUR_ROW would visit. */
    const int4 lo = grid_cell(g, p - (float4)(radius));
    const int4 hi = grid_cell(g, p + (float4)(radius));
    global uint* row = edges + (size_t)i * width;
    for (int z = lo.z; z <= hi.z; ++z)
      for (int y = lo.y; y <= hi.y; ++y) {
        const int cells = (z * g.ny + y) * g.nx;
        const uint jb = cell_start[cells + lo.x];
        const uint je = cell_start[cells + hi.x + 1];
        for (uint j = jb; j < je; j += THAW_VW) {
          const floatV dx = p.x - vloadV(0, X + j);
          const floatV dy = p.y - vloadV(0, Y + j);
          const floatV dz = p.z - vloadV(0, Z + j);
          const floatV d2 = dx * dx + dy * dy + dz * dz;
          const intV lane = THAW_LANE_IDS;
          const intV gj = vloadV(0, G + j);
          const intV hit = (d2 < r2) & (lane < (int)(je - j)) & (lane != (int)(i - j)) &
                           (any_group | (gj == (intV)(gi)) | (gj == (intV)(-1)));
          /* The hits as bits (distinct bits: the sum is their union), taken lowest first. */
          uint bits = lanes_sum_int(select((intV)(0), (intV)(1) << lane, hit));
          while (bits) {
            const uint l = 31u - clz(bits & (0u - bits));
            bits &= bits - 1u;
            if (count < width) row[count] = j + l;
            ++count;
          }
        }
      }
    if (count > width) atomic_max(overflow, count);
  }
  degree[i] = count;
  label[i] = ice ? id[i] : THAW_NO_LABEL;
}

/* slot_of[id] = sorted index. Ids at or above the capacity are reported in bad[0] (the smallest such
 * particle index; the atomic runs only on that error path). */
kernel void label_slots(global const uint* id, global uint* slot_of, const uint capacity,
                        volatile global uint* bad, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uint k = id[i];
  if (k < capacity) {
    slot_of[k] = i;
  } else {
    atomic_min(bad, i);
  }
}

/* One sweep (Fig. 4b, c): the largest of the particle's own label, its ice neighbours' labels and (with
 * `hook`) what was hooked onto it in the last sweep; then up to `jumps` pointer jumps: the particle whose
 * id is that label belongs to the same body, so its label is a candidate too (Iwasaki take one jump;
 * following the pointer while it rises roughly multiplies the distance a label travels per sweep by
 * jumps + 1). Hooking (Shiloach & Vishkin 1982): a particle whose label rose hands the new label to the
 * particle its old label names, for everyone whose jump lands there next sweep. Hooks meet in hook_out by
 * atomic_max (only where that particle is another one and lags: the plain reads first skip most), whose
 * final value is the same whatever order they come in; hook_in, last sweep's, is not written in this one.
 * With label_in read only (Jacobi), the sweep count and the result do not depend on the order work-items
 * run in. changed[0] is set (a plain store: every writer writes 1) when a label rose. Each work-item
 * sweeps THAW_SWEEP_TILE consecutive particles. */
kernel void propagate_labels(global const uint* degree, global const uint* edges, const uint width,
                             global const uint* slot_of, global const uint* label_in, global uint* label_out,
                             const uint jumps, const uint hook, global const uint* hook_in,
                             volatile global uint* hook_out, global uint* changed, const uint n) {
  const uint b = get_global_id(0) * THAW_SWEEP_TILE;
  if (b >= n) return;
  const uint e = min(n, b + THAW_SWEEP_TILE);
  uint rose = 0;
  for (uint i = b; i < e; ++i) {
    const uint own = label_in[i];
    uint l = own;
    if (own != THAW_NO_LABEL) {
      if (hook) l = max(l, hook_in[i]);
      global const uint* row = edges + (size_t)i * width;
      const uint d = degree[i];
      for (uint k = 0; k < d; ++k) l = max(l, label_in[row[k]]);
      for (uint h = 0; h < jumps; ++h) {
        const uint m = label_in[slot_of[l]];
        if (m <= l) break;
        l = m;
      }
      if (l != own) {
        rose = 1u;
        if (hook) {
          const uint r = slot_of[own];
          if (r != i && label_in[r] < l && hook_out[r] < l) atomic_max(&hook_out[r], l);
        }
      }
    }
    label_out[i] = l;
  }
  if (rose) changed[0] = 1u;
}
