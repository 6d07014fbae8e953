/* Summation density rho_i = sum_j m_j W_ij over fluid and boundary neighbours (boundary m_j = Psi_j,
 * Akinci 2012 eq. 6), then the equation of state; boundary particles too, which gives the walls the
 * pressure the fluid presses on them with (see forces.cl). state_i = (rho, p / rho^2, is_boundary, p). */
kernel void density(global const float4* pos, global const uchar* phase, global const uint* cell_start,
                    const Grid g, const float H, const float rho0, const float B, const float gamma_eos,
                    global float* density, global float4* state, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H;
  float rho = 0.0f;
  FOR_EACH_NEIGHBOUR(g, cell_start, c, {
    const float4 pj = pos[j];
    const float3 d = pi.xyz - pj.xyz;
    const float r2 = dot(d, d);
    /* Most candidates lie outside the support: reject them before the square root. */
    if (r2 < H2) rho += pj.w * KERNEL_W(sqrt(r2), H);
  })
#ifdef THAW_EOS_TAIT
  /* Tait (Monaghan 1994; Becker & Teschner 2007): p = B ((rho/rho0)^gamma - 1). */
  float p = B * (powr(rho / rho0, gamma_eos) - 1.0f);
#else
  /* Linear: p = c^2 (rho - rho0), B passed as c^2 * rho0. */
  float p = B * (rho / rho0 - 1.0f);
#endif
  /* No tension: clamping keeps free-surface particles from clumping (tensile instability). */
  p = fmax(p, 0.0f);
  density[i] = rho;
  state[i] = (float4)(rho, p / (rho * rho), phase[i] == THAW_PHASE_SOLID ? 1.0f : 0.0f, p);
}
