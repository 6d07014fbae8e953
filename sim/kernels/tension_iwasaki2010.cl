/* Iwasaki et al. 2010's interfacial tension (tension.model iwasaki2010; after tension.cl): eq. 4 over m_i,
 *   a_i = sum_j k (x_j - x_i) / |x_j - x_i|^2 / m_i,
 * k = k_w (P.cohesion) for water neighbours and the boundary material's k (B, set from the contact angles)
 * for solids and ice. */
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
#ifdef THAW_TENSION_LOWERED
  global const float* S = col + COL_S * stride;
  const float s_i = S[i];
#endif
  floatV ax = (floatV)(0.0f), ay = (floatV)(0.0f), az = (floatV)(0.0f);
  const float inv_m = 1.0f / pi.w;
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      /* i itself (r = 0) takes no part; lanes past the row may hold anything: masked after the products. */
      const Pair o = pair_lanes(xs, pr, j, je, H2);
      const intV in = o.in & (o.r2 > 1e-12f * H2);
      const floatV b = vloadV(0, B + j);
#ifdef THAW_TENSION_LOWERED
      /* The pair's cohesion by the mean of the two tensions: symmetric, so the pair forces still move no
       * momentum, and a water particle pulls less where a surfactant lowered its tension. */
      const floatV pair_s = 0.5f * (s_i + vloadV(0, S + j));
#else
      const floatV pair_s = (floatV)(1.0f);
#endif
      const floatV s = -(P.cohesion * vloadV(0, W + j) * pair_s + b) * inv_m / fmax(o.r2, 1e-30f);
      const floatV fx = s * o.dx, fy = s * o.dy, fz = s * o.dz;
      ax += select((floatV)(0.0f), fx, in);
      ay += select((floatV)(0.0f), fy, in);
      az += select((floatV)(0.0f), fz, in);
    }
  }
  accel[i] += (float4)(lanes_sum(ax), lanes_sum(ay), lanes_sum(az), 0.0f);
}
