/* Akinci et al. 2012, eq. 4-5: a boundary particle's volume V_b = 1 / sum_k W_bk over boundary
 * neighbours, so densely sampled walls do not over-count. Its "mass" seen by fluid is Psi_b = rho0 V_b. */
kernel void boundary_psi(global const float4* pos, global const uchar* phase, global const uint* cell_start,
                         const Grid g, const float H, const float rho0, global float* psi, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  if (phase[i] != THAW_PHASE_SOLID) {
    psi[i] = pos[i].w;
    return;
  }
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  float sum = 0.0f;
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; ++j)
      if (phase[j] == THAW_PHASE_SOLID) sum += KERNEL_W(fast_length(pr.xyz - pos[j].xyz), H);
  }
  psi[i] = rho0 / sum;
}

kernel void set_mass(global float4* pos, global const float* mass, const uint n) {
  const uint i = get_global_id(0);
  if (i < n) pos[i].w = mass[i];
}
