/* Symplectic Euler (kick, then drift with the new velocity); static solids do not move.
 * damping_factor = 1 / (1 + zeta dt) relaxes velocities while a state settles; 1 in ordinary runs. */
kernel void integrate(global float4* pos, global float4* vel, global const float4* accel,
                      global const uchar* phase, const float dt, const float damping_factor, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n || THAW_IS_STATIC(phase[i])) return;
  const float3 v = (vel[i].xyz + accel[i].xyz * dt) * damping_factor;
  vel[i] = (float4)(v, 0.0f);
  pos[i] = (float4)(pos[i].xyz + v * dt, pos[i].w);
}
