/* Interfacial tension of water (sim/tension_stage.h): accelerations added to the forces pass's. Built with
 * sph_kernel.h, grid_common.h, sph_lanes.h and tension_params.h, with -DTHAW_TENSION_<model>: AKINCI2013 or
 * IWASAKI2010.
 * Water particles attract water particles; solids and ice (the boundary particles) hold water by
 * adhesion; air takes no part. The neighbour passes read a block of seven columns of stride floats, so
 * the candidates come THAW_VW at a time (grid_common.h):
 *   W: the cohesion weight (akinci2013: m_j; iwasaki2010: 1) of water particles, 0 for the rest;
 *   R: rho_j of water particles (1 for the rest);
 *   V: the volume m_j / rho_j of water particles, 0 for the rest;
 *   B: the adhesion weight (akinci2013: beta Psi_b; iwasaki2010: k of eq. 4) of boundary particles, 0 for
 *      the rest, beta or k per boundary material from `adhesion` (set from the contact angles);
 *   NX, NY, NZ: akinci2013's normals n_j (tension_normals), 0 where there are none. */

#define COL_W 0
#define COL_R 1
#define COL_V 2
#define COL_B 3
#define COL_NX 4

kernel void tension_columns(global const uchar* phase, global const uchar* material, global const float4* pos,
                            global const float* density, global const float* adhesion, const TensionParams P,
                            global float* col) {
  const uint i = get_global_id(0);
  const uint stride = P.stride;
  if (i >= stride) return;
  float w = 0.0f, r = 1.0f, v = 0.0f, b = 0.0f;
  if (i < P.n) {
    const uchar ph = phase[i];
    const float m = pos[i].w;
#ifdef THAW_TENSION_AKINCI2013
    const float weight = m;
#else
    const float weight = 1.0f;
#endif
    if (ph == THAW_PHASE_WATER) {
      w = weight;
      r = density[i];
      v = m / r;
    } else if (THAW_IS_STATIC(ph)) {
      b = adhesion[material[i]] * weight;
    }
  }
  col[COL_W * stride + i] = w;
  col[COL_R * stride + i] = r;
  col[COL_V * stride + i] = v;
  col[COL_B * stride + i] = b;
  col[(COL_NX + 0) * stride + i] = 0.0f;
  col[(COL_NX + 1) * stride + i] = 0.0f;
  col[(COL_NX + 2) * stride + i] = 0.0f;
}

/* A neighbour pass's start: particle i's position and cell, the support and the candidates' x, y, z. */
#define TENSION_START                        \
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H; \
  const float4 pi = pos[i];                  \
  const int4 c = grid_cell(g, pi);           \
  global const float* X = soa;               \
  global const float* Y = soa + stride;      \
  global const float* Z = soa + 2 * stride;

#ifdef THAW_TENSION_AKINCI2013
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
  TENSION_START
  global const float* V = col + COL_V * stride;
  floatV gx = (floatV)(0.0f), gy = (floatV)(0.0f), gz = (floatV)(0.0f);
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      const floatV dx = pr.x - vloadV(0, X + j), dy = pr.y - vloadV(0, Y + j), dz = pr.z - vloadV(0, Z + j);
      const floatV r2 = dx * dx + dy * dy + dz * dz;
      const intV in = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2);
      const floatV s = select((floatV)(0.0f), vloadV(0, V + j) * grad_shape(sqrt(r2) * inv_H), in);
      gx += s * dx;
      gy += s * dy;
      gz += s * dz;
    }
  }
  const float3 n = H * THAW_SIGMA(H) * inv_H * inv_H * (float3)(lanes_sum(gx), lanes_sum(gy), lanes_sum(gz));
  col[(COL_NX + 0) * stride + i] = n.x;
  col[(COL_NX + 1) * stride + i] = n.y;
  col[(COL_NX + 2) * stride + i] = n.z;
}
#endif

/* Each water particle's tension acceleration, added to the forces pass's:
 *   akinci2013 (eqs. 1, 2, 5, per unit mass of i): a_i = -gamma sum_j K_ij (m_j C(r) x_ij / r
 *     + (n_i - n_j)), K_ij = 2 rho0 / (rho_i + rho_j), over water neighbours;
 *   iwasaki2010 (eq. 4, over m_i): a_i = sum_j k (x_j - x_i) / |x_j - x_i|^2 / m_i, k = k_w for water
 *     neighbours and the boundary material's k for solids and ice;
 * and for akinci2013 the adhesion of its eq. 6, -sum_b beta Psi_b A(r) x_ib / r over
 * boundary neighbours b (solids and ice), built with -DTHAW_TENSION_ADHESION where the scene has any. */
kernel void tension_forces(global const float4* pos, global const uchar* phase, global const float* soa,
                           global const uint* cell_start, const Grid g, const TensionParams P,
                           global const float* col, global float4* accel) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_WATER) return;
  const uint stride = P.stride;
  TENSION_START
  global const float* W = col + COL_W * stride;
  global const float* B = col + COL_B * stride;
  const float rho_i = col[COL_R * stride + i];
  floatV ax = (floatV)(0.0f), ay = (floatV)(0.0f), az = (floatV)(0.0f);
#ifdef THAW_TENSION_AKINCI2013
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
#else
  const float inv_m = 1.0f / pi.w;
#endif
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      const floatV dx = pr.x - vloadV(0, X + j), dy = pr.y - vloadV(0, Y + j), dz = pr.z - vloadV(0, Z + j);
      const floatV r2 = dx * dx + dy * dy + dz * dz;
      /* i itself (r = 0) takes no part; lanes past the row may hold anything: masked after the products. */
      const intV in = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2) & (r2 > 1e-12f * H2);
#if defined(THAW_TENSION_ADHESION) || defined(THAW_TENSION_IWASAKI2010)
      const floatV b = vloadV(0, B + j);
#endif
#ifdef THAW_TENSION_IWASAKI2010
      const floatV s = -(P.cohesion * vloadV(0, W + j) + b) * inv_m / fmax(r2, 1e-30f);
      const floatV fx = s * dx, fy = s * dy, fz = s * dz;
#else
      /* approximate reciprocals: the shapes need no more, and divisions cost a third of the pass (forces.cl) */
      const floatV inv_r = native_rsqrt(fmax(r2, 1e-30f)), q = r2 * inv_r * inv_H;
      const floatV nx = vloadV(0, NX + j), ny = vloadV(0, NY + j), nz = vloadV(0, NZ + j);
      const floatV w = vloadV(0, W + j);
      const floatV k = two_rho0 * native_recip(rho_i + vloadV(0, R + j));
      /* eq. 1 along x_ij, per unit mass of i, and eq. 2 between water particles only */
#ifdef THAW_TENSION_ADHESION
      const floatV sa = -adhesion * b * THAW_AKINCI_ADHESION(q) * inv_r;
#else
      const floatV sa = (floatV)(0.0f);
#endif
      const floatV s = -cohesion * k * w * akinci_cohesion_shape(q) * inv_r + sa;
      const floatV kc = select((floatV)(0.0f), -curv * k, w > 0.0f);
      const floatV fx = s * dx + kc * (nix - nx), fy = s * dy + kc * (niy - ny), fz = s * dz + kc * (niz - nz);
#endif
      ax += select((floatV)(0.0f), fx, in);
      ay += select((floatV)(0.0f), fy, in);
      az += select((floatV)(0.0f), fz, in);
    }
  }
  accel[i] += (float4)(lanes_sum(ax), lanes_sum(ay), lanes_sum(az), 0.0f);
}
