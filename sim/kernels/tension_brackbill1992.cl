/* Brackbill, Kothe & Zemach 1992's continuum surface force, f = sigma kappa n delta, on each surface
 * particle's share of the surface: a_i = v |grad c_i| scaled as the surface stage's brackbill1992 areas
 * (docs/SURFACE.md), so the force on a patch of surface is sigma kappa times its area and a still drop holds
 * Laplace's jump 2 sigma / R. The colour c counts water, ice and solids as inside, so a face against a wall
 * or ice carries no tension; the water holds to them by Akinci et al. 2013's adhesion. Taking the divergence
 * of the normals for kappa, as Brackbill et al. do, is too noisy on particles (docs/TENSION.md): kappa here
 * is the mean curvature of a quadric fitted by least squares to the surface points near the particle (as the
 * height functions of volume-of-fluid codes do on cells), the outer layer's particles moved out half a
 * spacing along their normals. */

/* Each water particle's colour gradient over the inside, grad c_i = sum_j v_j grad W_ij, and its outward
 * normal n_i = -grad c / |grad c|. A particle is on the outer layer where no
 * inside neighbour lies within 45 degrees of n_i above it (the cone of Marrone et al. 2010's free-surface
 * test); its surface point lies half a spacing out along n_i. The layer, not a threshold on the colour, marks
 * it: the equation of state holds the outer layer only once it is packed to the rest density, where its
 * colour is that of the bulk. */
kernel void tension_surface(global const float4* pos, global const uchar* phase, global const float* soa,
                            global const uint* cell_start, const Grid g, const TensionParams P,
                            global float* col) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_WATER) return;
  const uint stride = P.stride;
  const float4 pi = pos[i];
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  global const float* V = col + COL_V * stride;
  const float3 grad =
      THAW_SIGMA(H) * inv_H * inv_H * colour_gradient_sum(pi, c, g, cell_start, xs, V, H2, inv_H);
  const float g_len = length(grad);
  if (!(g_len > 0.0f)) return;
  const float3 n = -grad / g_len;
  col[(COL_NX + 0) * stride + i] = n.x;
  col[(COL_NX + 1) * stride + i] = n.y;
  col[(COL_NX + 2) * stride + i] = n.z;
  /* the cone: (x_j - x_i) . n > |x_j - x_i| cos 45 degrees, over inside neighbours within the support */
  int covered = 0;
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je && !covered; ++j) {
      if (!(V[j] > 0.0f)) continue;
      const float3 o = (float3)(xs.x[j] - pr.x, xs.y[j] - pr.y, xs.z[j] - pr.z);
      const float r2 = dot(o, o);
      const float up = dot(o, n);
      covered = r2 < H2 && up > 0.0f && up * up > 0.5f * r2;
    }
  }
  if (!covered) col[COL_BAND * stride + i] = 1.0f;
}

/* The rows of cells within THAW_FIT_REACH of cell c: the fit's and the average's patches reach past the
 * support (grid_common.h). */
#define FOR_EACH_FIT_ROW(g, cell_start, c, jb, je) FOR_EACH_ROW_WITHIN(g, cell_start, c, THAW_FIT_REACH, jb, je)

/* Outer-layer particle j's surface point less particle i's, each half a spacing out along its normal:
 * s_j - s_i = (x_j - x_i) + (dx / 2)(n_j - n_i), with pr as particle i's position that row sees (minimum
 * image). */
float3 surface_offset(const float4 pr, const uint j, const Positions xs, global const float* col,
                      const uint stride, const float3 ni, const float half_dx) {
  const float3 nj = (float3)(col[(COL_NX + 0) * stride + j], col[(COL_NX + 1) * stride + j],
                             col[(COL_NX + 2) * stride + j]);
  return (float3)(xs.x[j] - pr.x, xs.y[j] - pr.y, xs.z[j] - pr.z) + half_dx * (nj - ni);
}

/* kappa_i: the mean curvature at s_i of the quadric h = a u^2 + b u v + c v^2 + d u + e v + f fitted by
 * weighted least squares to the surface points s_j of the surface particles within fit_radius of s_i whose
 * normals lie within 60 degrees of n_i, in the frame (e1, e2, n_i), lengths in spacings; weights
 * 1 - (u^2 + v^2) / r_fit^2 (tangential distance), and 1e-3 beyond. kappa = -2 (a + c) / dx, positive where
 * the surface bulges out (a drop). Fewer than 8 points, or a singular fit: no curvature (OK = 0). */
kernel void tension_curvature(global const float4* pos, global const uchar* phase, global const float* soa,
                              global const uint* cell_start, const Grid g, const TensionParams P,
                              global float* col) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_WATER) return;
  const uint stride = P.stride;
  global const float* BAND = col + COL_BAND * stride;
  if (!(BAND[i] > 0.0f)) return;
  const float4 pi = pos[i];
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  const float3 ni = (float3)(col[(COL_NX + 0) * stride + i], col[(COL_NX + 1) * stride + i],
                             col[(COL_NX + 2) * stride + i]);
  const float half_dx = 0.5f * P.spacing;
  /* a tangent frame: e1 across the axis n_i leans least towards */
  const float3 ax = fabs(ni.x) < 0.6f ? (float3)(1.0f, 0.0f, 0.0f) : (float3)(0.0f, 1.0f, 0.0f);
  const float3 e1 = normalize(cross(ni, ax)), e2 = cross(ni, e1);
  const float inv_dx = 1.0f / P.spacing, rf2 = P.fit_radius * P.fit_radius;
  const float rf2_dx = rf2 * inv_dx * inv_dx;
  float m[21], rhs[6];
  for (int k = 0; k < 21; ++k) m[k] = 0.0f;
  for (int k = 0; k < 6; ++k) rhs[k] = 0.0f;
  int count = 0;
  float density = 0.0f; /* the layer's points per area around s_i: sum_j W_2D(tangential distance) */
  const float h2d = H * inv_dx; /* the 2-D kernel's support, in spacings */
  global const float* NX = col + (COL_NX + 0) * stride;
  global const float* NY = col + (COL_NX + 1) * stride;
  global const float* NZ = col + (COL_NX + 2) * stride;
  FOR_EACH_FIT_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; ++j) {
      if (!(BAND[j] > 0.0f)) continue;
      if (NX[j] * ni.x + NY[j] * ni.y + NZ[j] * ni.z <= 0.5f) continue;
      const float3 o = surface_offset(pr, j, xs, col, stride, ni, half_dx);
      if (dot(o, o) >= rf2) continue;
      const float u = dot(o, e1) * inv_dx, v = dot(o, e2) * inv_dx, h = dot(o, ni) * inv_dx;
      const float w = fmax(1.0f - (u * u + v * v) / rf2_dx, 0.0f) + 1e-3f;
      const float q = sqrt(u * u + v * v) / h2d;
      const float qa = 1.0f - q;
      density += q < 0.5f ? 6.0f * q * q * (q - 1.0f) + 1.0f : (q < 1.0f ? 2.0f * qa * qa * qa : 0.0f);
      const float b[6] = {u * u, u * v, v * v, u, v, 1.0f};
      int k = 0;
      for (int r = 0; r < 6; ++r) {
        for (int s = r; s < 6; ++s) m[k++] += w * b[r] * b[s];
        rhs[r] += w * b[r] * h;
      }
      ++count;
    }
  }
  if (count < 8) return;
  /* The normal equations (symmetric positive semi-definite) by Gaussian elimination with partial pivoting. */
  float a[6][7];
  {
    int k = 0;
    for (int r = 0; r < 6; ++r)
      for (int s = r; s < 6; ++s) {
        a[r][s] = m[k];
        a[s][r] = m[k];
        ++k;
      }
    for (int r = 0; r < 6; ++r) a[r][6] = rhs[r];
  }
  const float scale = a[5][5]; /* the sum of the weights */
  for (int p = 0; p < 6; ++p) {
    int best = p;
    for (int r = p + 1; r < 6; ++r)
      if (fabs(a[r][p]) > fabs(a[best][p])) best = r;
    if (!(fabs(a[best][p]) > 1e-6f * scale)) return;
    if (best != p)
      for (int s = p; s < 7; ++s) {
        const float t = a[p][s];
        a[p][s] = a[best][s];
        a[best][s] = t;
      }
    for (int r = p + 1; r < 6; ++r) {
      const float f = a[r][p] / a[p][p];
      for (int s = p; s < 7; ++s) a[r][s] -= f * a[p][s];
    }
  }
  float x[6];
  for (int r = 5; r >= 0; --r) {
    float t = a[r][6];
    for (int s = r + 1; s < 6; ++s) t -= a[r][s] * x[s];
    x[r] = t / a[r][r];
  }
  /* A surface curved tighter than a sphere of two spacings' radius is not resolved by the particles: such
   * fits come from stray particles and broken patches, whose kicks would spray the water. */
  col[COL_K * stride + i] = -2.0f * (x[0] + x[2]) * inv_dx;
  col[COL_OK * stride + i] = 1.0f;
  /* its share of the surface: the inverse of the layer's 2-D SPH density (the cubic spline in 2-D on support
   * H, normalised by its sum over a square lattice of spacing dx: P.layer_area, so a flat face of the lattice
   * gives dx^2 a particle) */
  col[COL_A * stride + i] = P.layer_area / density;
}

/* The fitted curvatures averaged over the layer's particles within smooth_radius whose fits held and whose
 * normals lie within 60 degrees of n_i, weighted by their areas and 1 - r^2 / r_s^2: from column `from` into
 * column `to`. */
kernel void tension_smooth(global const float4* pos, global const uchar* phase, global const float* soa,
                           global const uint* cell_start, const Grid g, const TensionParams P,
                           global float* col, const int into_k2) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_WATER) return;
  const uint stride = P.stride;
  global const float* OK = col + COL_OK * stride;
  global const float* A = col + COL_A * stride;
  if (!(OK[i] > 0.0f)) return;
  const float4 pi = pos[i];
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  const int from = into_k2 ? COL_K : COL_K2, to = into_k2 ? COL_K2 : COL_K;
  global const float* K = col + from * stride;
  global const float* NX = col + (COL_NX + 0) * stride;
  global const float* NY = col + (COL_NX + 1) * stride;
  global const float* NZ = col + (COL_NX + 2) * stride;
  const float3 ni = (float3)(NX[i], NY[i], NZ[i]);
  const float rs2 = P.smooth_radius * P.smooth_radius;
  float sw = 0.0f, sk = 0.0f;
  FOR_EACH_FIT_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; ++j) {
      if (!(OK[j] > 0.0f)) continue;
      if (NX[j] * ni.x + NY[j] * ni.y + NZ[j] * ni.z <= 0.5f) continue;
      const float3 o = (float3)(xs.x[j] - pr.x, xs.y[j] - pr.y, xs.z[j] - pr.z);
      const float r2 = dot(o, o);
      if (r2 >= rs2) continue;
      const float w = A[j] * (1.0f - r2 / rs2);
      sw += w;
      sk += w * K[j];
    }
  }
  col[to * stride + i] = sk / sw; /* i itself is among them */
}

/* Each water particle's tension acceleration, added to the forces pass's:
 *   akinci2013 (eqs. 1, 2, 5, per unit mass of i): a_i = -gamma sum_j K_ij (m_j C(r) x_ij / r
 *     + (n_i - n_j)), K_ij = 2 rho0 / (rho_i + rho_j), over water neighbours;
 *   iwasaki2010 (eq. 4, over m_i): a_i = sum_j k (x_j - x_i) / |x_j - x_i|^2 / m_i, k = k_w for water
 *     neighbours and the boundary material's k for solids and ice;
 * and for akinci2013 the adhesion of its eq. 6, -sum_b beta Psi_b A(r) x_ib / r over
 * boundary neighbours b (solids and ice), built with -DTHAW_TENSION_ADHESION where the scene has any. */
/* brackbill1992 (per unit mass of i): a_i = -sigma kappa_i a_i n_i / m_i, and where the scene
 * has solids or ice Akinci et al. 2013's adhesion, as akinci2013 has it. */
kernel void tension_forces(global const float4* pos, global const uchar* phase, global const float* soa,
                           global const uint* cell_start, const Grid g, const TensionParams P,
                           global const float* col, global float4* accel) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_WATER) return;
  const uint stride = P.stride;
  const float4 pi = pos[i];
  const float3 n = (float3)(col[(COL_NX + 0) * stride + i], col[(COL_NX + 1) * stride + i],
                            col[(COL_NX + 2) * stride + i]);
  /* 0 off the outer layer and where the fit failed (A and K are 0 there) */
#ifdef THAW_TENSION_LOWERED
  const float s_i = col[COL_S * stride + i];
#else
  const float s_i = 1.0f;
#endif
  const float area_i = col[COL_A * stride + i];
  float3 a = -(P.sigma * s_i) * col[COL_K * stride + i] * area_i / pi.w * n;
#ifdef THAW_TENSION_LOWERED
  /* Marangoni's stress: a surface whose tension varies pulls along itself toward the higher tension, the
   * surface gradient of sigma on the particle's area (the CSF's tangential part; Brackbill et al. 1992
   * eq. 30). The gradient is fitted by weighted least squares to sigma_j - sigma_i over the outer layer's
   * particles in the support, on the tangent plane of n_i, so a linear sigma gives its slope exactly. */
  if (area_i > 0.0f) {
    const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
    const int4 c = grid_cell(g, pi);
    const Positions xs = soa_positions(soa, stride);
    global const float* A = col + COL_A * stride;
    global const float* S = col + COL_S * stride;
    const float3 e = fabs(n.x) < 0.6f ? (float3)(1.0f, 0.0f, 0.0f) : (float3)(0.0f, 1.0f, 0.0f);
    const float3 t1 = normalize(cross(n, e)), t2 = cross(n, t1);
    floatV s11 = (floatV)(0.0f), s12 = (floatV)(0.0f), s22 = (floatV)(0.0f), b1 = (floatV)(0.0f),
           b2 = (floatV)(0.0f);
    FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
      const float4 pr = THAW_ROW_POS(g, c, pi);
      for (uint j = jb; j < je; j += THAW_VW) {
        /* x_j - x_i: the fit's offsets point from i to its neighbours */
        const floatV dx = vloadV(0, xs.x + j) - pr.x, dy = vloadV(0, xs.y + j) - pr.y,
                     dz = vloadV(0, xs.z + j) - pr.z;
        const floatV r2 = dx * dx + dy * dy + dz * dz;
        const floatV area_j = vloadV(0, A + j);
        const intV in = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2) & (r2 > 1e-12f * H2) & (area_j > 0.0f);
        const floatV w = select((floatV)(0.0f), area_j * w_shape(sqrt(r2) * inv_H), in);
        const floatV d1 = dx * t1.x + dy * t1.y + dz * t1.z, d2 = dx * t2.x + dy * t2.y + dz * t2.z;
        const floatV ds = select((floatV)(0.0f), vloadV(0, S + j) - s_i, in);
        s11 += w * d1 * d1;
        s12 += w * d1 * d2;
        s22 += w * d2 * d2;
        b1 += w * ds * d1;
        b2 += w * ds * d2;
      }
    }
    const float m11 = lanes_sum(s11), m12 = lanes_sum(s12), m22 = lanes_sum(s22);
    const float det = m11 * m22 - m12 * m12;
    /* Fewer than two independent directions (a lone surface particle): no gradient. */
    if (det > 1e-6f * (m11 + m22) * (m11 + m22)) {
      const float v1 = lanes_sum(b1), v2 = lanes_sum(b2);
      const float g1 = (m22 * v1 - m12 * v2) / det, g2 = (m11 * v2 - m12 * v1) / det;
      a += (P.sigma * area_i / pi.w) * (g1 * t1 + g2 * t2);
    }
  }
#endif
#ifdef THAW_TENSION_ADHESION
  {
    const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
    const int4 c = grid_cell(g, pi);
    const Positions xs = soa_positions(soa, stride);
    global const float* B = col + COL_B * stride;
    const float adhesion = 0.007f / (H * H * H);
    floatV ax = (floatV)(0.0f), ay = (floatV)(0.0f), az = (floatV)(0.0f);
    FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
      const float4 pr = THAW_ROW_POS(g, c, pi);
      for (uint j = jb; j < je; j += THAW_VW) {
        const Pair o = pair_lanes(xs, pr, j, je, H2);
        const intV in = o.in & (o.r2 > 1e-12f * H2);
        const floatV inv_r = native_rsqrt(fmax(o.r2, 1e-30f)), q = o.r2 * inv_r * inv_H;
        const floatV s = -adhesion * vloadV(0, B + j) * THAW_AKINCI_ADHESION(q) * inv_r;
        ax += select((floatV)(0.0f), s * o.dx, in);
        ay += select((floatV)(0.0f), s * o.dy, in);
        az += select((floatV)(0.0f), s * o.dz, in);
      }
    }
    a += (float3)(lanes_sum(ax), lanes_sum(ay), lanes_sum(az));
  }
#endif
  accel[i] += (float4)(a, 0.0f);
}
