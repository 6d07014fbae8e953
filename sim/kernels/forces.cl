/* Accelerations of fluid particles: symmetric pressure force (Monaghan 1992), viscosity (Monaghan
 * 2005's form, covering both the physical and the artificial part), gravity. Boundary particles
 * (Akinci 2012, mass Psi_b) take the fluid particle's pressure extrapolated hydrostatically,
 * p_b = p_i + rho_i g.(x_b - x_i) (Adami, Hu & Adams 2012 eq. 27, per pair), with rho_b = rho_i. Plain
 * mirroring (p_b = p_i) gives wall particles no vertical pressure gradient, so fluid beside a wall
 * lacks support, sinks along it and drives a circulation (measured in configs/hydrostatic-tank.json). */
kernel void forces(global const float4* pos, global const float4* vel, global const float4* state,
                   global const uchar* phase, global const uint* cell_start, const Grid g, const float H,
                   const float4 gravity, const float visc_fluid, const float visc_boundary, const float eps2,
                   global float4* accel, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  if (phase[i] == THAW_PHASE_SOLID) {
    accel[i] = (float4)(0.0f);
    return;
  }
  const float4 pi = pos[i];
  const float4 vi = vel[i];
  const float dpi = state[i].y;
  const float inv_rho_i = 1.0f / state[i].x;
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H;
  float3 a = (float3)(0.0f);
  FOR_EACH_NEIGHBOUR(g, cell_start, c, {
    const float4 pj = pos[j];
    const float3 d = pi.xyz - pj.xyz;
    const float r2 = dot(d, d);
    if (r2 >= H2) continue;
    const float4 sj = state[j];
    const float f = KERNEL_GRAD(sqrt(r2), H);
    const int boundary = sj.z > 0.5f;
    const float dpj = boundary ? fmax(0.0f, dpi - dot(gravity.xyz, d) * inv_rho_i) : sj.y;
    const float k = boundary ? visc_boundary : visc_fluid;
    const float vd = dot(vi.xyz - vel[j].xyz, d);
    /* -m_j (p_i/rho_i^2 + p_j/rho_j^2) grad W  +  k (m_j/rho_j) (v_ij . x_ij)/(r^2 + eps h^2) grad W */
    a += (pj.w * f) * (k * vd / (sj.x * (r2 + eps2)) - (dpi + dpj)) * d;
  })
  accel[i] = (float4)(a + gravity.xyz, 0.0f);
}
