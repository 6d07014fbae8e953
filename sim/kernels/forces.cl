/* Accelerations of fluid particles: the symmetric pressure force (Monaghan 1992), viscosity (Monaghan 2005's
 * form, the physical and the artificial part), gravity, and the walls' push.
 * - Viscosity's pair term divides by rho_i rho_j / rho0 (Morris et al. 1997), so a pair's forces are equal
 *   and opposite where the densities differ and viscosity moves momentum without making it (rigid.cl's
 *   reaction on ice matches; docs/ARCHITECTURE.md, Numerics).
 * - Solid particles (walls, static solids; not ice) push a fluid particle closer than rep_r0 (0.95 spacings)
 *   away, a spring and dashpot as stiff as the ice contacts (rigid.cl) that never pulls:
 *   m_i m_b K max((r0 - r) / r - D (v_ij . x_ij) / r^2, 0) x_ij, K = c^2 / (dx^2 rho0 dx^3), D = dx / c,
 *   so a lone drop, too thin for pressure, rests on a wall instead of sinking into it.
 * - Boundary particles (mass Psi_b, Akinci et al. 2012) enter with their own summation density and pressure
 *   (density.cl): the pressure force is then the gradient of the total internal energy, and a damped state
 *   settles. Akinci's one-sided -Psi_b p_i / rho_i^2 grad W carries half the load; mirroring and Adami et
 *   al. 2012's extrapolation are not energy gradients (docs/ARCHITECTURE.md, Numerics).
 * Candidates are read THAW_VW at a time (SIMD lanes: grid_common.h) from the reorder's structure-of-arrays
 * copy (x, y, z, m, vx, vy, vz) and the per-particle factors the density pass wrote (k_j m_j / rho_j,
 * m_j p_j / rho_j^2, and m_j for solid particles). */

/* The boundary push's factor of x_ij (without m_b K): zero beyond r0, never negative. */
floatV repulsion(const floatV r, const floatV vd, const float r0, const float d) {
  /* An approximate reciprocal: the push needs no more, and a division per lane cost a third of the pass. */
  const floatV inv = native_recip(fmax(r, 1e-20f));
  const floatV f = fmax((r0 - r - d * vd * inv) * inv, 0.0f);
  return select((floatV)(0.0f), f, r < r0);
}

kernel void forces(global const float4* pos, global const float4* vel, global const float* soa,
                   global const float* derived, global const float4* state, global const uchar* phase,
                   global const uchar* material, global const MaterialFlow* flow, global const uint* cell_start,
                   const Grid g, const ForcesParams P, global float4* accel
#ifdef THAW_BUOYANCY
                   ,
                   global const float2* enthalpy
#endif
#ifdef THAW_NO_SLIP
                   ,
                   global const float* ghost
#endif
) {
  const uint i = get_global_id(0);
  const uint n = P.n, stride = P.stride;
  if (i >= n) return;
  const float H = P.support, eps2 = P.eps2, rep_k = P.rep_k, rep_r0 = P.rep_r0, rep_d = P.rep_d;
  const float4 gravity = (float4)(P.gravity_x, P.gravity_y, P.gravity_z, 0.0f);
  if (THAW_IS_STATIC(phase[i])) {
    accel[i] = (float4)(0.0f);
    return;
  }
  const float4 pi = pos[i];
  const float4 vi = vel[i];
  const float dpi = state[i].y;
  const MaterialFlow mf = flow[material[i]];
  const float visc_i = mf.rest_density / state[i].x; /* the viscous pair term's rho0 / rho_i */
#ifdef THAW_MULTIPHASE
  const float mu_i = derived[i], rho0_i = mf.rest_density, inv_rho_i = 1.0f / state[i].x;
#endif
  /* Body force per unit mass (fluid_params.h): gravity, or Boussinesq air's buoyancy. */
#ifdef THAW_BUOYANCY
  const float2 h = enthalpy[i];
  const float T = (h.x + h.y) * mf.inv_specific_heat;
  const float body = mf.gravity - mf.expansion * (T - mf.reference_temperature);
  /* Domaradzki & Martyn eq 8: F_b = sigma / (T_max - T_i) v_up, per unit mass here, v_up against gravity
   * (+z without it); T_max - T held at 1 K or more, where the paper's form has its pole. */
  const float glen = length(gravity.xyz);
  const float3 up = glen > 0.0f ? -gravity.xyz / glen : (float3)(0.0f, 0.0f, 1.0f);
  const float3 artificial = mf.artificial_buoyancy / fmax(mf.max_temperature - T, 1.0f) * up;
#else
  const float body = mf.gravity;
  const float3 artificial = (float3)(0.0f);
#endif
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H;
  const float inv_H = 1.0f / H;
  global const float* X = soa;
  global const float* Y = soa + stride;
  global const float* Z = soa + 2 * stride;
  global const float* M = soa + 3 * stride;
#ifdef THAW_NO_SLIP
  /* Boundary particles with their ghost velocities (density.cl), fluid ones with their own. */
  global const float* VX = ghost;
  global const float* VY = ghost + stride;
  global const float* VZ = ghost + 2 * stride;
#else
  global const float* VX = soa + 4 * stride;
  global const float* VY = soa + 5 * stride;
  global const float* VZ = soa + 6 * stride;
#endif
  global const float* KV = derived;
  global const float* MP = derived + stride;
  global const float* RB = derived + 2 * stride; /* m_j for solid particles, 0 for the rest */
  const float scale = THAW_SIGMA(H) * inv_H * inv_H;
  const float rep = mf.push * rep_k / scale; /* the sum below is scaled by `scale` at the end */
  floatV ax = (floatV)(0.0f), ay = (floatV)(0.0f), az = (floatV)(0.0f);
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      const floatV dx = pr.x - vloadV(0, X + j);
      const floatV dy = pr.y - vloadV(0, Y + j);
      const floatV dz = pr.z - vloadV(0, Z + j);
      const floatV r2 = dx * dx + dy * dy + dz * dz;
      const intV in = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2);
      const floatV vd = (vi.x - vloadV(0, VX + j)) * dx + (vi.y - vloadV(0, VY + j)) * dy +
                        (vi.z - vloadV(0, VZ + j)) * dz;
      /* -m_j (p_i/rho_i^2 + p_j/rho_j^2) grad W
       *   + k (m_j/rho_j) (rho0/rho_i) (v_ij . x_ij)/(r^2 + eps h^2) grad W,
       * grad W = grad_factor x_ij with grad_factor = sigma / H^2 grad_shape(q). */
      const floatV r = sqrt(r2);
#ifdef THAW_MULTIPHASE
      /* Fluids of several densities (DFSPH: the pressure is dfsph.cl's): the viscous pair force
       * mu_ij V_i V_j (v_ij . x_ij)/(r^2 + eps h^2) grad W, equal and opposite whatever the two weigh,
       * with mu_ij the harmonic mean of the two dynamic coefficients (Hu & Adams 2006: the interface
       * takes the weaker fluid's shear, as a continuous stress would), or with
       * THAW_VISC_ARITHMETIC_MEAN their average (Domaradzki & Martyn eq 5, selectable by name); a
       * boundary neighbour's coefficient is kinematic (negative in KV) and taken at the fluid's density. */
      const floatV kv = vloadV(0, KV + j);
#ifdef THAW_VISC_ARITHMETIC_MEAN
      const floatV mean = 0.5f * (mu_i + kv);
#else
      const floatV mean = 2.0f * mu_i * kv / fmax(mu_i + kv, 1e-30f);
#endif
      const floatV mu = select(mean, -kv * rho0_i, kv < 0.0f);
      const floatV s = grad_shape(r * inv_H) * (mu * vloadV(0, MP + j) * (inv_rho_i * vd) / (r2 + eps2)) +
                       rep * vloadV(0, RB + j) * repulsion(r, vd, rep_r0, rep_d);
#else
      const floatV s =
          grad_shape(r * inv_H) *
              (vloadV(0, KV + j) * (visc_i * vd) / (r2 + eps2) - (vloadV(0, M + j) * dpi + vloadV(0, MP + j))) +
          rep * vloadV(0, RB + j) * repulsion(r, vd, rep_r0, rep_d);
#endif
      /* Masked after the products: lanes past the row may hold any particle's (even non-finite) data. */
      ax += select((floatV)(0.0f), s * dx, in);
      ay += select((floatV)(0.0f), s * dy, in);
      az += select((floatV)(0.0f), s * dz, in);
    }
  }
  const float3 a = scale * (float3)(lanes_sum(ax), lanes_sum(ay), lanes_sum(az));
  accel[i] = (float4)(a + body * gravity.xyz + artificial, 0.0f);
}
