/* Each ice and water particle's share of the surface it lies under (sim/surface_stage.h): its surface delta
 * delta_i [1/m], area a_i = v_i delta_i [m^2] (eq. 7 for orthmann2013), outward normal and Zhu & Bridson's
 * signed distance phi. Air is the outside; ice, water and solids are the inside (a face against a wall is
 * not exposed). Built with sph_kernel.h, grid_common.h, wrapped_walk.h and surface_params.h, with
 * -DTHAW_AREA_<model> (ORTHMANN2013 or BRACKBILL1992). Every particle's rest volume is v = dx^3. */

#ifdef THAW_WENDLAND
#define SURFACE_W wendland_c2_w
#define SURFACE_GRAD wendland_c2_grad_factor
#else
#define SURFACE_W cubic_spline_w
#define SURFACE_GRAD cubic_spline_grad_factor
#endif

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

int surface_inside(uchar ph) { return ph != THAW_PHASE_AIR; }

/* One pass over the neighbours: the centre of mass m_i (eq. 3) and phi (eq. 2), the colour gradient
 * grad c_i = sum_j v_j grad W_ij, the covariance C_i (eq. 8) and the neighbour count; then the delta:
 *   orthmann2013: eq. 6's half-sided tent of phi, delta_max = 1/d where the neighbourhood is singular;
 *   brackbill1992: the colour gradient's |grad c_i| (Brackbill, Kothe & Zemach 1992's surface delta),
 *     scaled so a flat face on the scene's lattice sums to its area; where the neighbourhood is singular, a
 *     sheet's 2 / t (t its thickness from C's least eigenvalue: both faces) or, for a filament or a lone
 *     particle, the area of a sphere of its volume.
 * In singular neighbourhoods delta relaxes at eq. 9's rate from its last value (NaN: none yet). */
kernel void surface_delta(global const float4* pos, global const uchar* phase, global const float* soa,
                          global const uint* cell_start, const Grid g, const SurfaceParams P, const uint stride,
                          global float4* normal, global float* delta, global float* area) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uchar ph = phase[i];
  if (ph != THAW_PHASE_WATER && ph != THAW_PHASE_ICE) {
    normal[i] = (float4)(0.0f);
    delta[i] = 0.0f;
    area[i] = 0.0f;
    return;
  }
  const float H = P.support, H2 = H * H, v = P.volume, d = P.radius;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  global const float* X = soa;
  global const float* Y = soa + stride;
  global const float* Z = soa + 2 * stride;
  float sw = 0.0f, count = 0.0f;
  float3 sd = (float3)(0.0f), grad = (float3)(0.0f);
  float cxx = 0.0f, cxy = 0.0f, cxz = 0.0f, cyy = 0.0f, cyz = 0.0f, czz = 0.0f;
  FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je; ++j) {
      if (!surface_inside(phase[j])) continue;
      /* x_j - x_i, the minimum image along periodic axes */
      const float ex = -THAW_WRAP(pi.x - X[j], P.period_x), ey = -THAW_WRAP(pi.y - Y[j], P.period_y),
                  ez = -THAW_WRAP(pi.z - Z[j], P.period_z);
      const float r2 = ex * ex + ey * ey + ez * ez;
      if (r2 >= H2) continue;
      const float r = sqrt(r2);
      const float w = SURFACE_W(r, H);
      sw += w;
      count += 1.0f;
      sd += w * (float3)(ex, ey, ez);
      grad -= SURFACE_GRAD(r, H) * (float3)(ex, ey, ez); /* grad_i W_ij = W'(r) / r (x_i - x_j) */
      cxx += w * ex * ex;
      cxy += w * ex * ey;
      cxz += w * ex * ez;
      cyy += w * ey * ey;
      cyz += w * ey * ez;
      czz += w * ez * ez;
    }
  }
  const float3 m = sd / sw; /* m_i - x_i (eq. 3, equal volumes) */
  const float phi = length(m) - d; /* eq. 2 */
  grad *= v;
  const float g_len = length(grad);
  const float3 n = g_len > 0.0f ? -grad / g_len : (float3)(0.0f);
  /* eq. 8 about m_i: sum_j W (x_j - m)(x_j - m)^T / sum_j W = sum_j W e e^T / sum_j W - m m^T */
  const float inv = 1.0f / sw;
  const float3 lam = symmetric_eigenvalues(cxx * inv - m.x * m.x, cxy * inv - m.x * m.y, cxz * inv - m.x * m.z,
                                           cyy * inv - m.y * m.y, cyz * inv - m.y * m.z, czz * inv - m.z * m.z);
  const float tr = max(lam.x + lam.y + lam.z, 1e-30f);
  const float flatness = 27.0f * max(lam.x, 0.0f) * max(lam.y, 0.0f) * max(lam.z, 0.0f) / (tr * tr * tr);
  const int singular = count < P.min_neighbours || flatness < P.min_flatness;
#ifdef THAW_AREA_ORTHMANN2013
  /* eq. 6, and delta_max = 1/d in singular neighbourhoods (sec. 4.3) */
  const float target = singular ? 1.0f / d : (phi < 0.0f ? (1.0f + phi / d) / d : 0.0f);
#else
  float target = P.colour_scale * g_len;
  if (singular) {
    const float h = P.spacing;
    /* a filament or a lone particle: two directions without extent */
    const int line = max(lam.y, 0.0f) < 0.05f * h * h;
    /* a sheet of k layers dx apart has sum (z - mean)^2 / k = dx^2 (k^2 - 1) / 12 across it */
    const float t = h * sqrt(1.0f + 12.0f * max(lam.x, 0.0f) / (h * h));
    target = line ? 4.8359744f / h /* (36 pi)^(1/3) v^(2/3) / v */ : max(2.0f / t, target);
  }
#endif
  const float last = delta[i];
  const float di = (singular && !isnan(last)) ? (1.0f - P.rate) * last + P.rate * target : target; /* eq. 9 */
  delta[i] = di;
  normal[i] = (float4)(n, phi);
  area[i] = v * di; /* orthmann2013: replaced by eq. 7 in surface_area */
}

#ifdef THAW_AREA_ORTHMANN2013
/* Orthmann eq. 7 with the Shepard-corrected kernel (Bonet & Kulasegaram 2002):
 * a_i = v_i sum_j delta_j v_j W_ij / sum_l v_l W_il over the inside's particles. */
kernel void surface_area(global const float4* pos, global const uchar* phase, global const float* soa,
                         global const uint* cell_start, const Grid g, const SurfaceParams P, const uint stride,
                         global const float* delta, global float* area) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uchar ph = phase[i];
  if (ph != THAW_PHASE_WATER && ph != THAW_PHASE_ICE) return;
  const float H = P.support, H2 = H * H;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  global const float* X = soa;
  global const float* Y = soa + stride;
  global const float* Z = soa + 2 * stride;
  float sw = 0.0f, sdw = 0.0f;
  FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je; ++j) {
      if (!surface_inside(phase[j])) continue;
      const float ex = THAW_WRAP(pi.x - X[j], P.period_x), ey = THAW_WRAP(pi.y - Y[j], P.period_y),
                  ez = THAW_WRAP(pi.z - Z[j], P.period_z);
      const float r2 = ex * ex + ey * ey + ez * ez;
      if (r2 >= H2) continue;
      const float w = SURFACE_W(sqrt(r2), H);
      sw += w;
      sdw += w * delta[j];
    }
  }
  area[i] = P.volume * sdw / sw;
}
#endif
