/* Thermal photons (Iwasaki et al. 2010, sec. 4 and 6): a lamp emits photons in a cosine-weighted
 * (Lambertian) distribution; each one walks a voxel grid by 3D-DDA (Amanatides & Woo 1987) until it
 * reaches a voxel holding an ice or solid particle, which absorbs it, or leaves the grid. Counts are
 * integer atomics, so the result does not depend on the order work-items run in. Needs grid_common.h
 * (THAW_PHASE_*) before it. */

/* Must match ClVoxelGrid in sim/photons.cpp. Voxel (i, j, k) covers origin + cell [i, i+1) x [j, j+1) x
 * [k, k+1); voxels are keyed x-fastest. */
typedef struct {
  float4 origin; /* w unused */
  float cell;
  int nx, ny, nz;
} VoxelGrid;

/* Keeps the random streams of this simulator apart from any other use of the same hash. */
#define THAW_PHOTON_KEY 0x7a3d1c5bu

kernel void clear_occupancy(global int* occ, const uint ncells) {
  const uint c = get_global_id(0);
  if (c < ncells) occ[c] = -1;
}

/* Each voxel holding absorbing particles keeps the largest of their indices: atomic_max gives the
 * same winner whatever the order. */
kernel void mark_occupancy(global const float4* pos, global const uchar* phase, const VoxelGrid vg, global int* occ,
                           const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uchar ph = phase[i];
  if (ph != THAW_PHASE_ICE && ph != THAW_PHASE_SOLID) return;
  const float3 q = (pos[i].xyz - vg.origin.xyz) / vg.cell;
  /* Written so that NaN positions fail too. */
  if (!(q.x >= 0.0f && q.y >= 0.0f && q.z >= 0.0f && q.x < (float)vg.nx && q.y < (float)vg.ny &&
        q.z < (float)vg.nz))
    return;
  const int3 c = min(convert_int3_rtn(q), (int3)(vg.nx - 1, vg.ny - 1, vg.nz - 1));
  atomic_max(&occ[(c.z * vg.ny + c.y) * vg.nx + c.x], (int)i);
}

/* PCG-style 4D hash (Jarzynski & Olano 2020, "Hash functions for GPU rendering"): a bijection of
 * uint4, so distinct counters give distinct outputs; two rounds decorrelate neighbouring counters. */
uint4 pcg4d(uint4 v) {
  v = v * 1664525u + 1013904223u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  v ^= v >> 16u;
  v.x += v.y * v.w;
  v.y += v.z * v.x;
  v.z += v.x * v.y;
  v.w += v.y * v.z;
  return v;
}

/* Four uniform numbers in [0, 1) for photon k of a lamp in one step; nothing is kept between steps. */
float4 photon_uniforms(uint k, uint lamp, uint step_lo, uint step_hi) {
  const uint4 h = pcg4d(pcg4d((uint4)(k, lamp, step_lo, step_hi ^ THAW_PHOTON_KEY)));
  return convert_float4(h >> 8u) * 0x1.0p-24f;
}

/* The slab of one axis of the grid box [0, n] in voxel units, intersected into [t0, t1]; false when a
 * ray parallel to the slab lies outside it. */
bool clip_slab(float p, float d, float n, float* t0, float* t1) {
  if (d == 0.0f) return p >= 0.0f && p < n;
  const float ta = (0.0f - p) / d, tb = (n - p) / d;
  *t0 = fmax(*t0, fmin(ta, tb));
  *t1 = fmin(*t1, fmax(ta, tb));
  return true;
}

/* The particle owning the first occupied voxel along the ray o + t d, t >= 0, or -1 when the ray
 * leaves the grid (or never enters it). d need not be unit length. */
int photon_first_hit(const VoxelGrid vg, global const int* occ, float3 o, float3 d) {
  if (d.x == 0.0f && d.y == 0.0f && d.z == 0.0f) return -1;
  const float3 p = (o - vg.origin.xyz) / vg.cell; /* voxel units */
  float t0 = 0.0f, t1 = INFINITY;
  if (!clip_slab(p.x, d.x, (float)vg.nx, &t0, &t1) || !clip_slab(p.y, d.y, (float)vg.ny, &t0, &t1) ||
      !clip_slab(p.z, d.z, (float)vg.nz, &t0, &t1) || !(t0 < t1))
    return -1;

  /* The entry voxel; clamping puts a point rounded onto the far face back inside. */
  const int3 last = (int3)(vg.nx - 1, vg.ny - 1, vg.nz - 1);
  int3 c = clamp(convert_int3_sat_rtn(p + t0 * d), (int3)(0), last);
  const int3 step = (int3)(d.x > 0.0f ? 1 : -1, d.y > 0.0f ? 1 : -1, d.z > 0.0f ? 1 : -1);
  const float3 inv = (float3)(1.0f) / d; /* +-inf on axes the ray never crosses */
  /* The next voxel face along each axis, offset from c (1 ahead when moving up, 0 when moving down). */
  const float3 ahead = (float3)(d.x > 0.0f, d.y > 0.0f, d.z > 0.0f);
  /* Parameters of the next face crossings, recomputed from p after each step (no drift from adding
   * t_delta); axes with d = 0 never cross. */
  float3 tmax = (convert_float3(c) + ahead - p) * inv;
  if (d.x == 0.0f) tmax.x = INFINITY;
  if (d.y == 0.0f) tmax.y = INFINITY;
  if (d.z == 0.0f) tmax.z = INFINITY;

  const int limit = vg.nx + vg.ny + vg.nz + 3;
  for (int s = 0; s < limit; ++s) {
    const int hit = occ[(c.z * vg.ny + c.y) * vg.nx + c.x];
    if (hit >= 0) return hit;
    if (tmax.x <= tmax.y && tmax.x <= tmax.z) {
      c.x += step.x;
      if (c.x < 0 || c.x > last.x) return -1;
      tmax.x = ((float)c.x + ahead.x - p.x) * inv.x;
    } else if (tmax.y <= tmax.z) {
      c.y += step.y;
      if (c.y < 0 || c.y > last.y) return -1;
      tmax.y = ((float)c.y + ahead.y - p.y) * inv.y;
    } else {
      c.z += step.z;
      if (c.z < 0 || c.z > last.z) return -1;
      tmax.z = ((float)c.z + ahead.z - p.z) * inv.z;
    }
  }
  return -1;
}

/* An orthonormal basis (t, b, n) around unit n (Duff et al. 2017, "Building an orthonormal basis,
 * revisited"), continuous except across n.z = 0. */
void basis_around(float3 n, float3* t, float3* b) {
  const float s = n.z >= 0.0f ? 1.0f : -1.0f;
  const float a = -1.0f / (s + n.z);
  const float c = n.x * n.y * a;
  *t = (float3)(1.0f + s * n.x * n.x * a, s * c, -s * n.x);
  *b = (float3)(c, s + n.y * n.y * a, -n.y);
}

/* One work-item per photon of one lamp (rectangle centre c, unit normal n on the emitting side, edge
 * half-vectors u and v). Absorbed photons add one to hits[particle] and to *absorbed. */
kernel void trace_photons(const VoxelGrid vg, global const int* occ, const float4 centre, const float4 normal,
                          const float4 half_u, const float4 half_v, const uint photons, const uint step_lo,
                          const uint step_hi, const uint lamp, global uint* hits, global uint* absorbed) {
  local uint group_absorbed;
  const uint k = get_global_id(0);
  if (get_local_id(0) == 0) group_absorbed = 0;
  barrier(CLK_LOCAL_MEM_FENCE);

  if (k < photons) {
    const float4 r = photon_uniforms(k, lamp, step_lo, step_hi);
    const float3 o = centre.xyz + (2.0f * r.x - 1.0f) * half_u.xyz + (2.0f * r.y - 1.0f) * half_v.xyz;
    /* Cosine-weighted hemisphere (Malley's method): a uniform point on the unit disc lifted onto it. */
    const float rad = sqrt(r.z), phi = 2.0f * M_PI_F * r.w;
    float3 t, b;
    basis_around(normal.xyz, &t, &b);
    const float3 d = rad * cos(phi) * t + rad * sin(phi) * b + sqrt(1.0f - r.z) * normal.xyz;
    const int hit = photon_first_hit(vg, occ, o, d);
    if (hit >= 0) {
      atomic_inc(&hits[hit]);
      atomic_inc(&group_absorbed);
    }
  }

  barrier(CLK_LOCAL_MEM_FENCE);
  if (get_local_id(0) == 0 && group_absorbed > 0) atomic_add(absorbed, group_absorbed);
}
