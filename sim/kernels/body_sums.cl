/* Per-body sums over the ice particles, for the rigid-body stage (Iwasaki et al. 2010, sec. 5 and 6: mass,
 * centre of mass, inertia, force and torque of each ice object). Deterministic without float atomics: the
 * particles are grouped by body with a stable counting sort, cut into fixed chunks of the grouped order,
 * summed per (chunk, body) piece, and the pieces of each body added in chunk order. Every sum is
 * compensated (Kahan), carried as (sum, correction) float pairs; the host adds the pair in double.
 *   body_histogram  particles per (tile, body)
 *   body_scan       per body: each tile's start within the body, and the body's count
 *   body_offsets    start of each body in the grouped order (one work-item)
 *   body_scatter    the grouped order: particle indices, ascending within each body
 *   body_pieces     compensated sums of each chunk's run of each body
 *   body_totals     each body's pieces in chunk order
 * hist is tile-major (hist[t * nbodies + b]) so tiles counting at once write separate cache lines. */

#define THAW_NO_BODY 0xffffffffu

/* bad[0]: smallest particle index with a body index >= nbodies other than THAW_NO_BODY; bad[1]: smallest
 * particle index with a material outside the mass-scale table. The atomics run only on these error
 * paths. */
kernel void body_histogram(global const uint* body, global uint* hist, volatile global uint* bad,
                           const uint n, const uint tile, const uint ntiles, const uint nbodies) {
  const uint t = get_global_id(0);
  if (t >= ntiles) return;
  global uint* h = hist + (size_t)t * nbodies;
  for (uint b = 0; b < nbodies; ++b) h[b] = 0;
  const uint e = min(n, (t + 1) * tile);
  for (uint i = t * tile; i < e; ++i) {
    const uint b = body[i];
    if (b < nbodies) {
      h[b] += 1;
    } else if (b != THAW_NO_BODY) {
      atomic_min(&bad[0], i);
    }
  }
}

kernel void body_scan(global uint* hist, global uint* count, const uint ntiles, const uint nbodies) {
  const uint b = get_global_id(0);
  if (b >= nbodies) return;
  uint s = 0;
  for (uint t = 0; t < ntiles; ++t) {
    const uint c = hist[(size_t)t * nbodies + b];
    hist[(size_t)t * nbodies + b] = s;
    s += c;
  }
  count[b] = s;
}

kernel void body_offsets(global const uint* count, global uint* offsets, const uint nbodies) {
  if (get_global_id(0) != 0) return;
  uint s = 0;
  for (uint b = 0; b < nbodies; ++b) {
    offsets[b] = s;
    s += count[b];
  }
  offsets[nbodies] = s;
}

kernel void body_scatter(global const uint* body, global uint* hist, global const uint* offsets,
                         global uint* order, const uint n, const uint tile, const uint ntiles,
                         const uint nbodies) {
  const uint t = get_global_id(0);
  if (t >= ntiles) return;
  global uint* h = hist + (size_t)t * nbodies;
  const uint e = min(n, (t + 1) * tile);
  for (uint i = t * tile; i < e; ++i) {
    const uint b = body[i];
    if (b < nbodies) order[offsets[b] + h[b]++] = i;
  }
}

void kahan_add(float16* sum, float16* comp, const float16 x) {
  const float16 y = x - *comp;
  const float16 t = *sum + y;
  *comp = (t - *sum) - y;
  *sum = t;
}

/* m, m r, m r r^T (xx, yy, zz, xy, xz, yz), f, r x f for r = x - ref. */
float16 body_terms(const float4 x, const float4 f, const float m, const float4 ref) {
  const float4 r = (float4)(x.xyz - ref.xyz, 0.0f);
  const float4 mr = m * r;
  const float4 f3 = (float4)(f.xyz, 0.0f);
  const float4 t = cross(r, f3);
  return (float16)(m, mr.x, mr.y, mr.z, mr.x * r.x, mr.y * r.y, mr.z * r.z, mr.x * r.y, mr.x * r.z,
                   mr.y * r.z, f.x, f.y, f.z, t.x, t.y, t.z);
}

/* The piece of body b within chunk c is pieces[c + b] (as (sum, correction) pairs): chunks and bodies both
 * run in grouped order, so c + b differs for any two non-empty pieces. */
kernel void body_pieces(global const uint* order, global const uint* offsets, global const uint* body,
                        global const float4* pos, global const uchar* material,
                        global const float* mass_scale, const uint materials, global const float4* force,
                        global const float4* ref, global float16* pieces, volatile global uint* bad,
                        const uint nbodies, const uint chunk) {
  const uint c = get_global_id(0);
  const uint total = offsets[nbodies];
  const uint b0 = c * chunk;
  if (b0 >= total) return;
  const uint e = min(total, b0 + chunk);
  uint cur = body[order[b0]];
  float4 r0 = ref[cur];
  float16 sum = 0.0f, comp = 0.0f;
  for (uint k = b0; k < e; ++k) {
    const uint i = order[k];
    const uint b = body[i];
    if (b != cur) {
      pieces[2 * (c + cur)] = sum;
      pieces[2 * (c + cur) + 1] = -comp;
      sum = 0.0f;
      comp = 0.0f;
      cur = b;
      r0 = ref[cur];
    }
    const uint mat = material[i];
    if (mat >= materials) atomic_min(&bad[1], i);
    const float4 x = pos[i];
    const float m = x.w * mass_scale[min(mat, materials - 1)];
    kahan_add(&sum, &comp, body_terms(x, force[i], m, r0));
  }
  pieces[2 * (c + cur)] = sum;
  pieces[2 * (c + cur) + 1] = -comp;
}

kernel void body_totals(global const float16* pieces, global const uint* offsets, global float16* out,
                        const uint nbodies, const uint chunk) {
  const uint b = get_global_id(0);
  if (b >= nbodies) return;
  const uint lo = offsets[b], hi = offsets[b + 1];
  float16 sum = 0.0f, comp = 0.0f;
  if (hi > lo) {
    for (uint c = lo / chunk; c <= (hi - 1) / chunk; ++c) {
      kahan_add(&sum, &comp, pieces[2 * (c + b)]);
      kahan_add(&sum, &comp, pieces[2 * (c + b) + 1]);
    }
  }
  out[2 * b] = sum;
  out[2 * b + 1] = -comp;
}
