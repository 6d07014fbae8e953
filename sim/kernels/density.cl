/* Summation density rho_i = sum_j m_j W_ij over fluid and boundary neighbours (boundary m_j = Psi_j,
 * Akinci 2012 eq. 6), then the equation of state; boundary particles too, which gives the walls the
 * pressure the fluid presses on them with (see forces.cl). state_i = (rho, p / rho^2, is_boundary, p).
 * Candidates are read THAW_VW at a time (SIMD lanes: grid_common.h) from the structure-of-arrays copy
 * `soa` the reorder writes (x, y, z, m blocks of `stride` floats). Also writes the per-particle factors of the
 * forces pass's pair terms: derived = (k_j m_j / rho_j, m_j p_j / rho_j^2, solid ? m_j : 0) blocks,
 * k_j the viscosity coefficient of the particle's kind (fluid or boundary). */

kernel void density(global const float4* pos, global const float* soa, global const uchar* phase,
                    global const uchar* material, global const MaterialFlow* flow, global const uint* cell_start,
                    const Grid g, const DensityParams P, global float* density, global float4* state,
                    global float* derived) {
  const uint i = get_global_id(0);
  const uint n = P.n, stride = P.stride;
  if (i >= n) return;
  const float H = P.support;
  /* The particle's material's rest density and stiffness (fluid_params.h). */
  const MaterialFlow mf = flow[material[i]];
  const float rho0 = mf.rest_density, B = mf.stiffness;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H;
  const float inv_H = 1.0f / H;
  global const float* X = soa;
  global const float* Y = soa + stride;
  global const float* Z = soa + 2 * stride;
  global const float* M = soa + 3 * stride;
  floatV acc = (floatV)(0.0f);
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      const floatV dx = pi.x - vloadV(0, X + j);
      const floatV dy = pi.y - vloadV(0, Y + j);
      const floatV dz = pi.z - vloadV(0, Z + j);
      const floatV r2 = dx * dx + dy * dy + dz * dz;
      /* Lanes past the row's end, or outside the support, add nothing (a select, not a branch). */
      const intV in = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2);
      const floatV w = vloadV(0, M + j) * w_shape(sqrt(r2) * inv_H);
      acc += select((floatV)(0.0f), w, in);
    }
  }
  const float rho = THAW_SIGMA(H) * lanes_sum(acc);
#ifdef THAW_DFSPH
  /* DFSPH (sim/kernels/dfsph.cl) solves for the pressure after the forces pass: none here. */
  float p = 0.0f;
#elif defined(THAW_EOS_TAIT)
  /* Tait (Monaghan 1994; Becker & Teschner 2007): p = B ((rho/rho0)^gamma - 1). */
#ifdef THAW_GAMMA_7
  /* gamma = 7 (the usual choice) by multiplication: pocl's powr cost as much as the neighbour sum. */
  const float x = rho / rho0, x2 = x * x, x4 = x2 * x2;
  float p = B * (x4 * x2 * x - 1.0f);
#else
  float p = B * (powr(rho / rho0, P.gamma) - 1.0f);
#endif
#else
  /* Linear: p = c^2 (rho - rho0), B passed as c^2 * rho0. */
  float p = B * (rho / rho0 - 1.0f);
#endif
  /* No tension: clamping keeps free-surface particles from clumping (tensile instability). */
  p = fmax(p, 0.0f);
  const int boundary = THAW_IS_STATIC(phase[i]);
  const float dp = p / (rho * rho);
  density[i] = rho;
  state[i] = (float4)(rho, dp, boundary ? 1.0f : 0.0f, p);
  derived[i] = (boundary ? P.visc_boundary : mf.viscosity) * pi.w / rho;
  derived[stride + i] = pi.w * dp;
  derived[2 * stride + i] = phase[i] == THAW_PHASE_SOLID ? pi.w : 0.0f;
}
