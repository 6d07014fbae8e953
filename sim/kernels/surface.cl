/* Each ice and water particle's share of the surface it lies under (sim/surface_stage.h): its surface delta
 * delta_i [1/m], area a_i = v_i delta_i [m^2] (eq. 7 for orthmann2013), outward normal and Zhu & Bridson's
 * signed distance phi. Air is the outside; ice, water and solids are the inside (a face against a wall is
 * not exposed). Built with sph_kernel.h, grid_common.h, sph_lanes.h, wrapped_walk.h and surface_params.h, with
 * -DTHAW_AREA_<model> (ORTHMANN2013 or BRACKBILL1992). Every particle's rest volume is v = dx^3. */

/* The eigenvalues of a symmetric 3x3 matrix (a b c / b d e / c e f), ascending (Smith 1961). */
float3 symmetric_eigenvalues(float a, float b, float c, float d, float e, float f) {
  const float p1 = b * b + c * c + e * e;
  const float q = (a + d + f) / 3.0f;
  const float p2 = (a - q) * (a - q) + (d - q) * (d - q) + (f - q) * (f - q) + 2.0f * p1;
  if (p2 <= 1e-30f) return (float3)(q, q, q);
  const float p = sqrt(p2 / 6.0f);
  const float ia = (a - q) / p, id = (d - q) / p, iff = (f - q) / p, ib = b / p, ic = c / p, ie = e / p;
  const float r = 0.5f * (ia * (id * iff - ie * ie) - ib * (ib * iff - ie * ic) + ic * (ib * ie - id * ic));
  const float phi = acos(clamp(r, -1.0f, 1.0f)) / 3.0f;
  const float hi = q + 2.0f * p * cos(phi), lo = q + 2.0f * p * cos(phi + 2.0943951f);
  return (float3)(lo, 3.0f * q - hi - lo, hi);
}

/* Which particles are inside (ice, water, solids: 1) and which outside (air; and past n: 0), as floats in
 * a block padded like the structure-of-arrays copy, so the neighbour loops below read it on lanes. */
kernel void surface_inside(global const uchar* phase, global float* inside, const uint n, const uint stride) {
  const uint i = get_global_id(0);
  if (i >= stride) return;
  inside[i] = (i < n && phase[i] != THAW_PHASE_AIR) ? 1.0f : 0.0f;
}

/* One pass over the neighbours: the centre of mass m_i (eq. 3) and phi (eq. 2), the colour gradient
 * grad c_i = sum_j v_j grad W_ij, the covariance C_i (eq. 8) and the neighbour count; then the delta:
 *   orthmann2013: eq. 6's half-sided tent of phi, delta_max = 1/d where the neighbourhood is singular;
 *   brackbill1992: the colour gradient's |grad c_i| (Brackbill, Kothe & Zemach 1992's surface delta),
 *     scaled so a flat face on the scene's lattice sums to its area (surface_project then keeps only its part
 *     along the outer layer's normal, and only near the layer); where the neighbourhood is singular, a
 *     sheet's 2 / t (t its thickness from C's least eigenvalue: both faces) or, for a filament or a lone
 *     particle, the area of a sphere of its volume.
 * In singular neighbourhoods delta relaxes at eq. 9's rate from its last value (NaN: none yet). The sums
 * run on lanes (grid_common.h) with the kernel's normalisation factored out. delta_lanes: orthmann2013,
 * delta again, in a padded block for surface_area's lanes; brackbill1992, the layer marks surface_layer and
 * surface_project read (2 where singular, else 0), and layer_n the layer's normals in three padded blocks (x,
 * y, z; 0 off the layer) that surface_project reads on lanes. */
kernel void surface_delta(global const float4* pos, global const uchar* phase, global const float* soa,
                          global const float* inside, global const uint* cell_start, const Grid g,
                          const SurfaceParams P, const uint stride, global float4* normal, global float* delta,
                          global float* delta_lanes, global float* area, global float* layer_n) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uchar ph = phase[i];
  if (ph != THAW_PHASE_WATER && ph != THAW_PHASE_ICE) {
    normal[i] = (float4)(0.0f);
    delta[i] = 0.0f;
    delta_lanes[i] = 0.0f;
    area[i] = 0.0f;
#ifdef THAW_AREA_BRACKBILL1992
    layer_n[i] = layer_n[stride + i] = layer_n[2 * stride + i] = 0.0f;
#endif
    return;
  }
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  const float v = P.volume, d = P.radius;
  floatV sw = (floatV)(0.0f), count = (floatV)(0.0f);
  floatV sx = (floatV)(0.0f), sy = (floatV)(0.0f), sz = (floatV)(0.0f);
  floatV gx = (floatV)(0.0f), gy = (floatV)(0.0f), gz = (floatV)(0.0f);
  FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair o = pair_lanes_wrapped(xs, pi, period, j, je, H2);
      const floatV q = sqrt(o.r2) * inv_H;
      const floatV on = select((floatV)(0.0f), vloadV(0, inside + j), o.in);
      const floatV w = on * w_shape(q);
      const floatV gr = on * grad_shape(q); /* grad_i W_ij = sigma / H^2 grad_shape(q) (x_i - x_j) */
      sw += w;
      count += on;
      /* x_j - x_i = -(ox, oy, oz) */
      sx -= w * o.dx;
      sy -= w * o.dy;
      sz -= w * o.dz;
      gx += gr * o.dx;
      gy += gr * o.dy;
      gz += gr * o.dz;
    }
  }
  const float inv = 1.0f / lanes_sum(sw);
  const float3 m = (float3)(lanes_sum(sx), lanes_sum(sy), lanes_sum(sz)) * inv; /* m_i - x_i (eq. 3) */
  const float phi = length(m) - d;                                              /* eq. 2 */
  const float3 grad = (v * THAW_SIGMA(H) * inv_H * inv_H) * (float3)(lanes_sum(gx), lanes_sum(gy), lanes_sum(gz));
  const float g_len = length(grad);
  const float3 n = g_len > 0.0f ? -grad / g_len : (float3)(0.0f);
  /* eq. 8's covariance about m_i, sum_j W (x_j - m)(x_j - m)^T / sum_j W, only where the neighbourhood lacks
   * particles (its colour below P.full_colour): a full one is neither sparse nor flat, and most particles are
   * full, so the second walk is skipped for them. */
  float3 lam = (float3)(1.0f);
  float3 across = (float3)(0.0f); /* the eigenvector of C's least eigenvalue: a sheet's normal */
  if (v * THAW_SIGMA(H) * lanes_sum(sw) < P.full_colour) {
    const float4 mi = (float4)(pi.x + m.x, pi.y + m.y, pi.z + m.z, 0.0f);
    floatV cxx = (floatV)(0.0f), cxy = (floatV)(0.0f), cxz = (floatV)(0.0f), cyy = (floatV)(0.0f),
           cyz = (floatV)(0.0f), czz = (floatV)(0.0f);
    FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
      for (uint j = jb; j < je; j += THAW_VW) {
        const Pair o = pair_lanes_wrapped(xs, pi, period, j, je, H2);
        const floatV w = select((floatV)(0.0f), vloadV(0, inside + j), o.in) * w_shape(sqrt(o.r2) * inv_H);
        /* x_j - m_i, with the same minimum image as x_j - x_i */
        const floatV ex = -o.dx - m.x, ey = -o.dy - m.y, ez = -o.dz - m.z;
        cxx += w * ex * ex;
        cxy += w * ex * ey;
        cxz += w * ex * ez;
        cyy += w * ey * ey;
        cyz += w * ey * ez;
        czz += w * ez * ez;
      }
    }
    const float a = lanes_sum(cxx) * inv, b = lanes_sum(cxy) * inv, e = lanes_sum(cxz) * inv,
                dd = lanes_sum(cyy) * inv, f = lanes_sum(cyz) * inv, k = lanes_sum(czz) * inv;
    lam = symmetric_eigenvalues(a, b, e, dd, f, k);
    /* (C - lam I) x = 0: x is across two of its rows; the longest of the three crosses */
    const float3 r0 = (float3)(a - lam.x, b, e), r1 = (float3)(b, dd - lam.x, f), r2 = (float3)(e, f, k - lam.x);
    const float3 x01 = cross(r0, r1), x02 = cross(r0, r2), x12 = cross(r1, r2);
    const float l01 = dot(x01, x01), l02 = dot(x02, x02), l12 = dot(x12, x12);
    const float3 best = l01 >= l02 && l01 >= l12 ? x01 : (l02 >= l12 ? x02 : x12);
    const float lb = length(best);
    if (lb > 0.0f) across = best / lb;
  }
  const float tr = max(lam.x + lam.y + lam.z, 1e-30f);
  const float flatness = 27.0f * max(lam.x, 0.0f) * max(lam.y, 0.0f) * max(lam.z, 0.0f) / (tr * tr * tr);
  const int singular = lanes_sum(count) < P.min_neighbours || flatness < P.min_flatness;
#ifdef THAW_AREA_ORTHMANN2013
  /* eq. 6, and delta_max = 1/d in singular neighbourhoods (sec. 4.3) */
  const float target = singular ? 1.0f / d : (phi < 0.0f ? (1.0f + phi / d) / d : 0.0f);
#else
  float target = P.colour_scale * g_len;
  if (singular) {
    const float h = P.spacing;
    /* a filament or a lone particle: two directions without extent */
    const int line = max(lam.y, 0.0f) < 0.05f * h * h;
    /* a sheet of k layers dx apart has sum (z - mean)^2 / k = dx^2 (k^2 - 1) / 12 across it: its faces; where
     * flat, the colour gradient along it is its rim, scaled to the rim's area (t high) as a flat face's is */
    const float t = h * sqrt(1.0f + 12.0f * max(lam.x, 0.0f) / (h * h));
    const int flat = flatness < P.min_flatness;
    const float across_g = dot(grad, across);
    const float along = flat ? length(grad - across_g * across) : 0.0f;
    const float face = flat ? P.colour_scale * fabs(across_g) : target;
    target = line ? 4.8359744f / h /* (36 pi)^(1/3) v^(2/3) / v */ : max(2.0f / t, face) + (t / h) * P.rim_scale * along;
  }
#endif
  const float last = delta[i];
  const float di = (singular && !isnan(last)) ? (1.0f - P.rate) * last + P.rate * target : target; /* eq. 9 */
  delta[i] = di;
#ifdef THAW_AREA_ORTHMANN2013
  delta_lanes[i] = di;
#else
  delta_lanes[i] = singular ? 2.0f : 0.0f; /* surface_layer's marks: 2, singular (kept as it is) */
  const float3 ln = singular ? n : (float3)(0.0f); /* the layer's normals, for surface_project's lanes */
  layer_n[i] = ln.x;
  layer_n[stride + i] = ln.y;
  layer_n[2 * stride + i] = ln.z;
#endif
  normal[i] = (float4)(n, phi);
  area[i] = v * di; /* orthmann2013: replaced by eq. 7 in surface_area */
}

#ifdef THAW_AREA_ORTHMANN2013
/* Orthmann eq. 7 with the Shepard-corrected kernel (Bonet & Kulasegaram 2002):
 * a_i = v_i sum_j delta_j v_j W_ij / sum_l v_l W_il over the inside's particles. */
kernel void surface_area(global const float4* pos, global const uchar* phase, global const float* soa,
                         global const float* inside, global const uint* cell_start, const Grid g,
                         const SurfaceParams P, const uint stride, global const float* delta_lanes,
                         global float* area) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uchar ph = phase[i];
  if (ph != THAW_PHASE_WATER && ph != THAW_PHASE_ICE) return;
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  floatV sw = (floatV)(0.0f), sdw = (floatV)(0.0f);
  FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair o = pair_lanes_wrapped(xs, pi, period, j, je, H2);
      const floatV w = select((floatV)(0.0f), vloadV(0, inside + j), o.in) * w_shape(sqrt(o.r2) * inv_H);
      sw += w;
      sdw += w * vloadV(0, delta_lanes + j);
    }
  }
  area[i] = P.volume * lanes_sum(sdw) / lanes_sum(sw);
}
#endif

#ifdef THAW_AREA_BRACKBILL1992
/* The least area, in spacings squared, of a particle surface_layer tests: a flat face's outer layer carries
 * about 0.6 of its share, and below this the test only finds the bulk covered (in `default` at 0.3 s, 0.1 and
 * 0.2 gave the same heat to 1e-4, and halved the stage's time against no threshold). */
#define THAW_LAYER_MIN_AREA 0.1f

/* brackbill1992's outer layer: a water or ice particle whose neighbourhood is not singular is on it where no
 * inside neighbour lies within 45 degrees of its outward normal (the cone of Marrone et al. 2010's
 * free-surface test): layer 1. Particles already marked singular (2) stay so. Inside disordered water the
 * colour gradient is noise and its normal random, but some neighbour always lies in that cone: on lattices
 * jittered by up to 0.25 spacing no bulk particle passed (numpy, docs/SURFACE.md). */
kernel void surface_layer(global const float4* pos, global const uchar* phase, global const float* soa,
                          global const float* inside, global const uint* cell_start, const Grid g,
                          const SurfaceParams P, const uint stride, global const float4* normal,
                          global float* layer, global float* layer_n, global const float* area) {
  const uint i = get_global_id(0);
  if (i >= P.n || layer[i] != 0.0f) return;
  const uchar ph = phase[i];
  if (ph != THAW_PHASE_WATER && ph != THAW_PHASE_ICE) return;
  const float3 n = normal[i].xyz;
  if (!(dot(n, n) > 0.0f) || !(area[i] > THAW_LAYER_MIN_AREA * P.spacing * P.spacing)) return;
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  int covered = 0;
  FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je && !covered; ++j) {
      if (!(inside[j] > 0.0f) || j == i) continue;
      const float3 o = (float3)(THAW_WRAP(xs.x[j] - pi.x, P.period_x), THAW_WRAP(xs.y[j] - pi.y, P.period_y),
                                THAW_WRAP(xs.z[j] - pi.z, P.period_z));
      const float r2 = dot(o, o), up = dot(o, n);
      covered = r2 < H2 && up > 0.0f && up * up > 0.5f * r2;
    }
  }
  if (covered) return;
  layer[i] = 1.0f;
  layer_n[i] = n.x;
  layer_n[stride + i] = n.y;
  layer_n[2 * stride + i] = n.z;
}

/* brackbill1992's areas where the neighbourhood is not singular: the colour gradient's component along the
 * outer layer's normal there, a_i = v s max(-grad c_i . nbar_i, 0), with nbar_i the mean of the normals of
 * the layer's particles within the support (weights 1 - r / H, i itself among them if it is on the layer),
 * and 0 where none is that near. Both cut the colour gradient's noise inside disordered water, which is not
 * surface: the gate removes it away from the surface, the projection its random directions near it. On an
 * exact lattice every particle with a colour gradient lies within a support of the layer, so the sum there
 * moves only by the projection (numpy: spheres of 10 and 20 spacings, -1.5 to -1.8 %). */
kernel void surface_project(global const float4* pos, global const uchar* phase, global const float* soa,
                            global const uint* cell_start, const Grid g, const SurfaceParams P,
                            const uint stride, global const float4* normal, global const float* layer,
                            global const float* layer_n, global float* delta, global float* area) {
  const uint i = get_global_id(0);
  if (i >= P.n || layer[i] > 1.5f) return;
  const uchar ph = phase[i];
  if (ph != THAW_PHASE_WATER && ph != THAW_PHASE_ICE) return;
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  global const float* LX = layer_n;
  global const float* LY = layer_n + stride;
  global const float* LZ = layer_n + 2 * stride;
  floatV nx = (floatV)(0.0f), ny = (floatV)(0.0f), nz = (floatV)(0.0f);
  FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair o = pair_lanes_wrapped(xs, pi, period, j, je, H2);
      const floatV w = select((floatV)(0.0f), 1.0f - sqrt(o.r2) * inv_H, o.in);
      nx += w * vloadV(0, LX + j);
      ny += w * vloadV(0, LY + j);
      nz += w * vloadV(0, LZ + j);
    }
  }
  const float3 nbar = (float3)(lanes_sum(nx), lanes_sum(ny), lanes_sum(nz));
  const float len = length(nbar);
  const float cosine = len > 0.0f ? fmax(dot(normal[i].xyz, nbar) / len, 0.0f) : 0.0f;
  const float di = delta[i] * cosine; /* delta = s |grad c_i| here, and grad c_i = -|grad c_i| n_i */
  delta[i] = di;
  area[i] = P.volume * di;
}
#endif
