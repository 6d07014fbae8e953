/* Accelerations of fluid particles: symmetric pressure force (Monaghan 1992), viscosity (Monaghan
 * 2005's form, covering both the physical and the artificial part), gravity.
 * Boundary particles (mass Psi_b, Akinci et al. 2012) enter with their own summation density and
 * pressure (see density.cl), so the pressure force is exactly the gradient of the total internal
 * energy and the system stays conservative: a damped state settles. Akinci's one-sided term
 * -Psi_b p_i/rho_i^2 grad W is conservative too but carries only half the load, so a water column
 * sinks into the floor; mirroring (p_b = p_i) or hydrostatic extrapolation (Adami et al. 2012) is not
 * an energy gradient and pumped energy into particles at a tank's vertical edges. Both measured with
 * configs/hydrostatic-tank.json and `thaw validate hydrostatic`. */
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
    const float k = boundary ? visc_boundary : visc_fluid;
    const float vd = dot(vi.xyz - vel[j].xyz, d);
    /* -m_j (p_i/rho_i^2 + p_j/rho_j^2) grad W  +  k (m_j/rho_j) (v_ij . x_ij)/(r^2 + eps h^2) grad W */
    a += (pj.w * f) * (k * vd / (sj.x * (r2 + eps2)) - (dpi + sj.y)) * d;
  })
  accel[i] = (float4)(a + gravity.xyz, 0.0f);
}
