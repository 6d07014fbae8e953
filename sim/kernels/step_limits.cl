/* Per-tile maxima of |v|^2 and |a|^2 over moving particles, the fastest particle, and the first
 * non-finite one: the host finishes the reduction and chooses dt. Tiles are walked in order, so the
 * result is deterministic. out_f = (max v2, max a2); out_i = (argmax v2, first non-finite or ~0).
 * A non-finite position or velocity outranks a non-finite acceleration: the forces pass spreads one
 * particle's NaN into its neighbours' accelerations, and the message should name the culprit. The
 * rank is kept in the top bit (set: acceleration only). */
kernel void step_limits(global const float4* pos, global const float4* vel, global const float4* accel, global const uchar* phase,
                        global float2* out_f, global uint2* out_i, const uint n, const uint tile) {
  const uint t = get_global_id(0);
  const uint b = t * tile;
  if (b >= n) return;
  const uint e = min(n, b + tile);
  float vmax = 0.0f, amax = 0.0f;
  uint arg = b, bad = 0xffffffffu;
  for (uint i = b; i < e; ++i) {
    if (THAW_IS_STATIC(phase[i])) continue;
    const float v2 = dot(vel[i].xyz, vel[i].xyz);
    const float a2 = dot(accel[i].xyz, accel[i].xyz);
    const float x2 = dot(pos[i].xyz, pos[i].xyz);
    if (!isfinite(v2) || !isfinite(x2)) {
      bad = min(bad, i);
      continue;
    }
    if (!isfinite(a2)) {
      bad = min(bad, i | 0x80000000u);
      continue;
    }
    if (v2 > vmax) {
      vmax = v2;
      arg = i;
    }
    amax = fmax(amax, a2);
  }
  out_f[t] = (float2)(vmax, amax);
  out_i[t] = (uint2)(arg, bad);
}
