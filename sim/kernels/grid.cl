/* Neighbour grid: cell keys (with domain clamping), a stable radix sort of the keys, a gather of
 * every per-particle buffer into sorted order, and the start of each cell's range. */

/* Key of each particle's cell; fluid particles outside the domain are put back on its face, their
 * outward velocity removed, and counted (never silently lost). */
/* Cell keys. A moving particle past a side of the domain is held at that side (its velocity out of the
 * domain removed, and counted in `clamped`), unless the side is open (bit 2a of open_faces for the lower
 * side of axis a, 2a + 1 for the upper): then it has left, and its key is `ncells`, past every cell, so
 * the sort moves it behind all the others where the solver removes it. */
/* Air dryers (-DTHAW_INTAKE; sim/emitters.h). Per blowing dryer k, four float4: (exit centre, (r + dx)^2),
 * (unit direction u, pipe length P), (mouth depth M, half the exit speed, k, (r + dx/2)^2), (exit speed,
 * body depth B, 0, 0). Along the axis s = (x - centre).u, across it the distance rho; only air particles:
 *   pipe  -P <= s < 0, rho < r + dx/2: the nozzle's own air, laid in discs at its back, moves out at
 *         the exit speed (pipe_drive sets it before each step's drift, so the discs reach the exit
 *         evenly spaced and with air behind them, as in a real nozzle); air there that does not move so
 *         came in from outside and is taken in (flag 2k + 1): left there (if it moved out at half the
 *         exit speed) the jet carried 7 % more momentum than the nozzle gave it;
 *   mouth 0 <= s < M, rho < r + dx/2: air slower than half the exit speed is taken in (2k + 1): the jet
 *         leaves into room air at the room's pressure (room air left there, the jet pushed it ahead,
 *         the pressure at the exit rose, and the jet carried 9 % more momentum than the nozzle gave it);
 *   body  the rest of -P - B <= s < 0, rho < r + dx: the dryer's housing, where it draws the room's air
 *         in (2k + 2), taken while the dryer owes particles (the host chooses, NeighbourGrid::build).
 * Each flagged particle is also listed, (index, flag), at an atomically counted slot of `list`, so the host
 * reads the few flagged rather than a byte per particle; it orders them by index (the slots' order
 * varies from run to run, the choice must not) and clears the flags of those it leaves (set_flags).
 * cell_keys removes those whose flag the host leaves nonzero. */
#ifdef THAW_INTAKE
kernel void intake_flags(global const float4* pos, global const float4* vel, global const uchar* phase,
                         global uchar* flag, global const float4* intake, const uint count, const uint n,
                         volatile global uint* listed, global uint2* list) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  uchar f = 0;
  if (phase[i] == THAW_PHASE_AIR) {
    const float4 p = pos[i];
    for (uint k = 0; k < count && f == 0; ++k) {
      const float4 a = intake[4 * k], b = intake[4 * k + 1], c = intake[4 * k + 2], e = intake[4 * k + 3];
      const float3 d = p.xyz - a.xyz;
      const float s = dot(d, b.xyz);
      if (s < -b.w - e.y || s >= c.x) continue;
      const float3 radial = d - s * b.xyz;
      const float r2 = dot(radial, radial);
      const uint dryer = (uint)c.z;
      if (s >= -b.w && r2 < c.w) {
        const float3 v = vel[i].xyz;
        const float3 off = v - e.x * b.xyz;
        if (s < 0.0f ? dot(off, off) > 1e-6f * e.x * e.x : dot(v, b.xyz) < c.y) f = (uchar)(2 * dryer + 1);
      } else if (s < 0.0f && r2 < a.w) {
        f = (uchar)(2 * dryer + 2);
      }
    }
  }
  flag[i] = f;
  if (f) list[atomic_inc(listed)] = (uint2)(i, f);
}

/* flag[list[j].x] = list[j].y for the host's m entries (its answer to intake_flags' list). */
kernel void set_flags(global uchar* flag, global const uint2* list, const uint m) {
  const uint j = get_global_id(0);
  if (j < m) flag[list[j].x] = (uchar)list[j].y;
}

/* The pipes' air moves out at the exit speed (see above): run before the drift. */
kernel void pipe_drive(global const float4* pos, global float4* vel, global const uchar* phase,
                       global const float4* intake, const uint count, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n || phase[i] != THAW_PHASE_AIR) return;
  const float4 p = pos[i];
  for (uint k = 0; k < count; ++k) {
    const float4 a = intake[4 * k], b = intake[4 * k + 1], c = intake[4 * k + 2], e = intake[4 * k + 3];
    const float3 d = p.xyz - a.xyz;
    const float s = dot(d, b.xyz);
    if (s < -b.w || s >= 0.0f) continue;
    const float3 radial = d - s * b.xyz;
    if (dot(radial, radial) >= c.w) continue;
    const float4 v = vel[i];
    vel[i] = (float4)(e.x * b.xyz, v.w);
    return;
  }
}
#define THAW_INTAKE_ARG , global const uchar *take
#else
#define THAW_INTAKE_ARG
#endif

/* Room air through open sides (-DTHAW_ROOM_AIR; sim/emitters.h). A site is listed (at an atomically
 * counted slot; the host orders them) when no particle is within sqrt(gap2) of it, and the air around
 * it, by its kernel-weighted mean velocity, is not leaving through the site's side (outward normal
 * site_out[s]). That velocity goes to site_vel (zero where no particle moves): the room's air comes in
 * as the air beside it moves, so a stream through an open side stays whole. Measured on a box whose air
 * left through one side at up to 1 m/s (tests/sim/air_test.cpp, AirLeavesThroughOpenSides...): with a
 * gap of 0.95 dx its air kept the rise g t exactly and the box held 87-100 % of its particles (a whole
 * layer comes in at once). Laid at rest, it held 53 %; with a gap of 0.8 dx and also where air leaves,
 * 47 %: the new air blocked the outflow; with a fill criterion (the sum of W at the site below the
 * lattice's), the layers came in early, their pressure pushed them back, and it held 60-75 %. Run at the
 * end of a step on the step's grid with the positions the drift left: a particle moves far less than a
 * cell in a step, so the cells around a site still hold every particle near it. */
#ifdef THAW_ROOM_AIR
kernel void empty_sites(global const float4* pos, global const float4* vel, global const uchar* phase,
                        global const uint* cell_start, const Grid g, global const float4* sites,
                        global const float4* site_out, const uint count, const float gap2, const float H,
                        volatile global uint* listed, global uint* list, global float4* site_vel) {
  const uint s = get_global_id(0);
  if (s >= count) return;
  const float4 x = sites[s];
  const int4 c = grid_cell(g, x);
  float sw = 0.0f;
  float3 sv = (float3)(0.0f);
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 xs = THAW_ROW_POS(g, c, x);
    for (uint j = jb; j < je; ++j) {
      const float3 d = xs.xyz - pos[j].xyz;
      const float r2 = dot(d, d);
      if (r2 < gap2) return;
      if (r2 < H * H && !THAW_IS_STATIC(phase[j])) {
        const float w = KERNEL_W(sqrt(r2), H);
        sw += w;
        sv += w * vel[j].xyz;
      }
    }
  }
  const float3 v = sw > 0.0f ? sv / sw : (float3)(0.0f);
  if (dot(v, site_out[s].xyz) > 0.0f) return;
  site_vel[s] = (float4)(v, 0.0f);
  list[atomic_inc(listed)] = s;
}
#endif

kernel void cell_keys(global float4* pos, global float4* vel, global const uchar* phase, global uint* keys,
                      global uint* order, volatile global uint* clamped, const Grid g,
                      const KeysParams P THAW_INTAKE_ARG) {
  const uint i = get_global_id(0);
  const uint n = P.n, open_faces = P.open_faces, ncells = P.ncells;
  const float4 dmin = P.dmin, dmax = P.dmax;
  if (i >= n) return;
  float4 p = pos[i];
  order[i] = i;
#ifdef THAW_INTAKE
  if (P.intakes && take[i]) {
    keys[i] = ncells;
    return;
  }
#endif
  if (!THAW_IS_STATIC(phase[i])) {
#if THAW_WY || THAW_WZ
    /* Along a periodic axis a particle that left through one side comes back through the other. */
    const float4 span = dmax - dmin;
    float4 w = p;
    /* (Rounding can land a particle just below the lower side on the upper one: kept inside.) */
    if (THAW_WY) w.y = fmin(p.y - span.y * floor((p.y - dmin.y) / span.y), dmax.y);
    if (THAW_WZ) w.z = fmin(p.z - span.z * floor((p.z - dmin.z) / span.z), dmax.z);
    if (w.y != p.y || w.z != p.z) {
      pos[i] = w;
      p = w;
    }
#endif
    const int4 below = isless(p, dmin);
    const int4 above = isgreater(p, dmax);
    if (any(below.xyz) || any(above.xyz)) {
      const uint out = (below.x ? 1u : 0u) | (above.x ? 2u : 0u) | (below.y ? 4u : 0u) | (above.y ? 8u : 0u) |
                       (below.z ? 16u : 0u) | (above.z ? 32u : 0u);
      if (out & open_faces) {
        keys[i] = ncells;
        return;
      }
      float4 v = vel[i];
      v = select(v, fmax(v, 0.0f), below);
      v = select(v, fmin(v, 0.0f), above);
      vel[i] = (float4)(v.xyz, 0.0f);
      pos[i] = (float4)(clamp(p.xyz, dmin.xyz, dmax.xyz), p.w);
      p = pos[i];
      atomic_inc(clamped);
    }
  }
  keys[i] = grid_key(g, grid_cell(g, p));
}

/* Radix sort, THAW_RADIX_BITS bits a pass (as many as the cell keys need, spread evenly over the
 * fewest passes of at most 11 bits: the host chooses). Each work-item owns one tile of consecutive
 * particles and walks it in order, so the sort is stable and deterministic without atomics
 * (rank-based scatter). hist is digit-major: hist[d * ntiles + t]. */
#ifndef THAW_RADIX_BITS
#define THAW_RADIX_BITS 8
#endif
#define THAW_RADIX_BUCKETS (1u << THAW_RADIX_BITS)
#define THAW_RADIX_MASK (THAW_RADIX_BUCKETS - 1u)

kernel void radix_histogram(global const uint* keys, global uint* hist, const uint shift, const uint n,
                            const uint tile, const uint ntiles) {
  const uint t = get_global_id(0);
  if (t >= ntiles) return;
  for (uint d = 0; d < THAW_RADIX_BUCKETS; ++d) hist[d * ntiles + t] = 0;
  const uint e = min(n, (t + 1) * tile);
  for (uint i = t * tile; i < e; ++i) hist[((keys[i] >> shift) & THAW_RADIX_MASK) * ntiles + t] += 1;
}

/* Exclusive scan of `count` consecutive counts in place, starting from `sum`; returns the sum past them. */
uint scan_counts(global uint* row, const uint count, uint sum) {
  for (uint k = 0; k < count; ++k) {
    const uint c = row[k];
    row[k] = sum;
    sum += c;
  }
  return sum;
}

/* Exclusive scan of each digit's row of tile counts (hist[d * ntiles + t]), the row totals to totals[d],
 * in chunks of THAW_SCAN_CHUNK tiles, so that a GPU's thousands of tiles are not one work-item per digit
 * walking all of them (a long chain of dependent loads): (1) each (digit, chunk) counts its chunk, (2)
 * each digit scans its chunks' counts, (3) each (digit, chunk) scans its tiles from its chunk's offset.
 * Integer sums: the result is the serial scan's, bit for bit. A CPU's 32 tiles are one chunk. */
#ifndef THAW_SCAN_CHUNK
#define THAW_SCAN_CHUNK 32
#endif
kernel void radix_chunk_counts(global const uint* hist, global uint* chunks, const uint ntiles,
                               const uint nchunks) {
  const uint k = get_global_id(0);
  if (k >= THAW_RADIX_BUCKETS * nchunks) return;
  const uint d = k / nchunks, c = k % nchunks;
  const uint e = min(ntiles, (c + 1) * THAW_SCAN_CHUNK);
  uint sum = 0;
  for (uint t = c * THAW_SCAN_CHUNK; t < e; ++t) sum += hist[d * ntiles + t];
  chunks[k] = sum;
}

kernel void radix_scan_chunks(global uint* chunks, global uint* totals, const uint nchunks) {
  const uint d = get_global_id(0);
  if (d >= THAW_RADIX_BUCKETS) return;
  totals[d] = scan_counts(chunks + (size_t)d * nchunks, nchunks, 0u);
}

kernel void radix_scan_tiles(global uint* hist, global const uint* chunks, const uint ntiles, const uint nchunks) {
  const uint k = get_global_id(0);
  if (k >= THAW_RADIX_BUCKETS * nchunks) return;
  const uint d = k / nchunks, c = k % nchunks;
  const uint b = c * THAW_SCAN_CHUNK, e = min(ntiles, b + THAW_SCAN_CHUNK);
  scan_counts(hist + (size_t)d * ntiles + b, e - b, chunks[k]);
}

kernel void radix_scatter(global const uint* keys_in, global const uint* vals_in, global uint* keys_out,
                          global uint* vals_out, global uint* hist, global const uint* totals,
                          const uint shift, const uint n, const uint tile, const uint ntiles) {
  const uint t = get_global_id(0);
  if (t >= ntiles) return;
  uint base[THAW_RADIX_BUCKETS];
  uint sum = 0;
  for (uint d = 0; d < THAW_RADIX_BUCKETS; ++d) {
    base[d] = sum + hist[d * ntiles + t];
    sum += totals[d];
  }
  const uint e = min(n, (t + 1) * tile);
  for (uint i = t * tile; i < e; ++i) {
    const uint k = keys_in[i];
    const uint d = (k >> shift) & THAW_RADIX_MASK;
    const uint dst = base[d]++;
    keys_out[dst] = k;
    vals_out[dst] = vals_in[i];
  }
}

/* cell_start[k] = first sorted particle with key >= k; every entry written exactly once. */
kernel void cell_starts(global const uint* keys, global uint* cell_start, const uint n, const uint ncells) {
  const uint i = get_global_id(0);
  if (i > n) return;
  const uint lo = i == 0 ? 0u : keys[i - 1] + 1u;
  const uint hi = i == n ? ncells : keys[i];
  for (uint k = lo; k <= hi; ++k) cell_start[k] = i;
}
