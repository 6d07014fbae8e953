/* Interfacial tension of water (sim/tension_stage.h): accelerations added to the forces pass's. What the
 * models share; each model's passes are in its own file after this one (tension_akinci2013.cl,
 * tension_iwasaki2010.cl, tension_brackbill1992.cl), built with -DTHAW_TENSION_<model> (and, for
 * brackbill1992, -DTHAW_FIT_REACH, the cells the fit's patch reaches).
 * Water particles attract water particles; solids and ice (the boundary particles) hold water by
 * adhesion; air takes no part. The neighbour passes read a block of seven columns of stride floats, so
 * the candidates come THAW_VW at a time (grid_common.h):
 *   W: the cohesion weight (akinci2013: m_j; iwasaki2010: 1) of water particles, 0 for the rest;
 *   R: rho_j of water particles (1 for the rest);
 *   V: the volume m_j / rho_j of water particles, 0 for the rest;
 *   B: the adhesion weight (akinci2013: beta Psi_b; iwasaki2010: k of eq. 4) of boundary particles, 0 for
 *      the rest, beta or k per boundary material from `adhesion` (set from the contact angles);
 *   NX, NY, NZ: akinci2013's normals n_j (tension_normals), brackbill1992's unit normals (outward), 0 where
 *      there are none;
 * and for brackbill1992 (tension_surface, tension_curvature, tension_smooth), where V is instead the colour's
 * rest volume dx^3 of every inside particle (water, ice, solids; air: 0):
 *   A: an outer-layer particle's share of the surface area (0 elsewhere);
 *   K, K2: the curvature, fitted and averaged (two columns to average from one into the other);
 *   OK: 1 where the fit held;
 *   BAND: 1 on the outer layer (tension_surface), whose surface points are fitted. */

#define COL_W 0
#define COL_R 1
#define COL_V 2
#define COL_B 3
#define COL_NX 4
#define COL_A 7
#define COL_K 8
#define COL_K2 9
#define COL_OK 10
#define COL_BAND 11
/* With -DTHAW_TENSION_LOWERED (surface-active substances that lower the tension; the substance stage's
 * tension_ratio field, substance.cl), after the block above:
 *   S: each water particle's tension over the scene's, sigma_i / sigma0 (1 off the surface) */
#ifdef THAW_TENSION_BRACKBILL1992
#define COL_S 12
#else
#define COL_S 7
#endif

kernel void tension_columns(global const uchar* phase, global const uchar* material, global const float4* pos,
                            global const float* density, global const float* adhesion, const TensionParams P,
                            global float* col, global const float* ratio) {
  const uint i = get_global_id(0);
  const uint stride = P.stride;
  if (i >= stride) return;
  float w = 0.0f, r = 1.0f, v = 0.0f, b = 0.0f;
  if (i < P.n) {
    const uchar ph = phase[i];
    const float m = pos[i].w;
#if defined(THAW_TENSION_AKINCI2013) || defined(THAW_TENSION_BRACKBILL1992)
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
#ifdef THAW_TENSION_BRACKBILL1992
    v = ph == THAW_PHASE_AIR ? 0.0f : P.volume;
#endif
  }
  col[COL_W * stride + i] = w;
  col[COL_R * stride + i] = r;
  col[COL_V * stride + i] = v;
  col[COL_B * stride + i] = b;
  col[(COL_NX + 0) * stride + i] = 0.0f;
  col[(COL_NX + 1) * stride + i] = 0.0f;
  col[(COL_NX + 2) * stride + i] = 0.0f;
#ifdef THAW_TENSION_BRACKBILL1992
  for (int k = COL_A; k <= COL_BAND; ++k) col[k * stride + i] = 0.0f;
#endif
#ifdef THAW_TENSION_LOWERED
  col[COL_S * stride + i] = i < P.n ? ratio[i] : 1.0f;
#endif
}

/* sum_j V_j grad_shape(r / H) (x_i - x_j) over the neighbours within H, on lanes: the colour gradient
 * sum_j V_j grad W_ij less the kernel's sigma / H^2 (akinci2013's normals, brackbill1992's). */
float3 colour_gradient_sum(const float4 pi, const int4 c, const Grid g, global const uint* cell_start,
                           const Positions xs, global const float* V, const float H2, const float inv_H) {
  floatV gx = (floatV)(0.0f), gy = (floatV)(0.0f), gz = (floatV)(0.0f);
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair o = pair_lanes(xs, pr, j, je, H2);
      const floatV s = select((floatV)(0.0f), vloadV(0, V + j) * grad_shape(sqrt(o.r2) * inv_H), o.in);
      gx += s * o.dx;
      gy += s * o.dy;
      gz += s * o.dz;
    }
  }
  return (float3)(lanes_sum(gx), lanes_sum(gy), lanes_sum(gz));
}

