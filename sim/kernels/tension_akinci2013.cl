/* Akinci et al. 2013's cohesion, curvature and adhesion (tension.model akinci2013; after tension.cl). */
/* Akinci et al. 2013 eq. 3's C(r) = 32 / (pi H^3) c(q) on lanes, q = r / H (tension_params.h has it on the
 * host): attraction past H/2, repulsion close in. */
floatV akinci_cohesion_shape(const floatV q) {
  const floatV a = (1.0f - q) * (1.0f - q) * (1.0f - q) * q * q * q;
  return select(select(2.0f * a - 1.0f / 64.0f, a, q > 0.5f), (floatV)(0.0f), q > 1.0f);
}

/* Akinci et al. 2013 eq. 4: n_i = H sum_j (m_j / rho_j) grad W_ij over water neighbours, dimensionless and
 * about H |grad c| long at the surface, pointing into the water as SPlisHSPlasH's implementation has it
 * (grad W_ij = grad_shape x_ij points from i towards j). Solids, ice and air are outside, so the water's face
 * against a plate has tension too, which the adhesion offsets (docs/TENSION.md). */
kernel void tension_normals(global const float4* pos, global const uchar* phase, global const float* soa,
                            global const uint* cell_start, const Grid g, const TensionParams P,
                            global float* col) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_WATER) return;
  const uint stride = P.stride;
  const float4 pi = pos[i];
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  const float3 n = H * THAW_SIGMA(H) * inv_H * inv_H *
                   colour_gradient_sum(pi, c, g, cell_start, xs, col + COL_V * stride, H2, inv_H);
  col[(COL_NX + 0) * stride + i] = n.x;
  col[(COL_NX + 1) * stride + i] = n.y;
  col[(COL_NX + 2) * stride + i] = n.z;
}

/* Each water particle's tension acceleration, added to the forces pass's (eqs. 1, 2, 5, per unit mass of i):
 *   a_i = -gamma sum_j K_ij (m_j C(r) x_ij / r + (n_i - n_j)), K_ij = 2 rho0 / (rho_i + rho_j),
 * over water neighbours, and the adhesion of eq. 6, -sum_b beta Psi_b A(r) x_ib / r over boundary
 * neighbours b (solids and ice), built with -DTHAW_TENSION_ADHESION where the scene has any. */
kernel void tension_forces(global const float4* pos, global const uchar* phase, global const float* soa,
                           global const uint* cell_start, const Grid g, const TensionParams P,
                           global const float* col, global float4* accel) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_WATER) return;
  const uint stride = P.stride;
  const float4 pi = pos[i];
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  global const float* W = col + COL_W * stride;
  global const float* B = col + COL_B * stride;
  const float rho_i = col[COL_R * stride + i];
#ifdef THAW_TENSION_LOWERED
  global const float* S = col + COL_S * stride;
  const float s_i = S[i];
#endif
  floatV ax = (floatV)(0.0f), ay = (floatV)(0.0f), az = (floatV)(0.0f);
  global const float* NX = col + (COL_NX + 0) * stride;
  global const float* NY = col + (COL_NX + 1) * stride;
  global const float* NZ = col + (COL_NX + 2) * stride;
  const float nix = NX[i], niy = NY[i], niz = NZ[i];
#ifdef THAW_TENSION_ADHESION
  const float adhesion = 0.007f / (H * H * H);
#endif
  global const float* R = col + COL_R * stride;
  const float cohesion = P.cohesion * 32.0f / (THAW_PI_F * H * H * H), curv = P.cohesion * P.curvature;
  const float two_rho0 = 2.0f * P.rest_density;
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      /* i itself (r = 0) takes no part; lanes past the row may hold anything: masked after the products. */
      const Pair o = pair_lanes(xs, pr, j, je, H2);
      const intV in = o.in & (o.r2 > 1e-12f * H2);
#ifdef THAW_TENSION_ADHESION
      const floatV b = vloadV(0, B + j);
#endif
#ifdef THAW_TENSION_LOWERED
      /* The pair's cohesion by the mean of the two tensions: symmetric, so the pair forces still move no
       * momentum, and a water particle pulls less where a surfactant lowered its tension. */
      const floatV pair_s = 0.5f * (s_i + vloadV(0, S + j));
#else
      const floatV pair_s = (floatV)(1.0f);
#endif
      /* approximate reciprocals: the shapes need no more, and divisions cost a third of the pass (forces.cl) */
      const floatV inv_r = native_rsqrt(fmax(o.r2, 1e-30f)), q = o.r2 * inv_r * inv_H;
      const floatV nx = vloadV(0, NX + j), ny = vloadV(0, NY + j), nz = vloadV(0, NZ + j);
      const floatV w = vloadV(0, W + j);
      const floatV k = two_rho0 * native_recip(rho_i + vloadV(0, R + j));
      /* eq. 1 along x_ij, per unit mass of i, and eq. 2 between water particles only */
#ifdef THAW_TENSION_ADHESION
      const floatV sa = -adhesion * b * THAW_AKINCI_ADHESION(q) * inv_r;
#else
      const floatV sa = (floatV)(0.0f);
#endif
      const floatV s = -cohesion * k * w * pair_s * akinci_cohesion_shape(q) * inv_r + sa;
      const floatV kc = select((floatV)(0.0f), -curv * k * pair_s, w > 0.0f);
      const floatV fx = s * o.dx + kc * (nix - nx), fy = s * o.dy + kc * (niy - ny),
                   fz = s * o.dz + kc * (niz - nz);
      ax += select((floatV)(0.0f), fx, in);
      ay += select((floatV)(0.0f), fy, in);
      az += select((floatV)(0.0f), fz, in);
    }
  }
  accel[i] += (float4)(lanes_sum(ax), lanes_sum(ay), lanes_sum(az), 0.0f);
}
