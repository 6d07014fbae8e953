/* Substances dissolved in the water (issue 20, docs/SUBSTANCES.md): each water particle holds an amount
 * Q_i [kg] of each of up to four substances (THAW_NSUB), carried with it by the flow; between water
 * particles it diffuses by Fick's law, rho Dw/Dt = div(rho D grad w) for the mass fraction w = Q / m. Built
 * with sph_kernel.h, grid_common.h, sph_lanes.h, wrapped_walk.h, thermal_law.h and substance_params.h.
 *
 * The pair term is Cleary & Monaghan's (1999, eq. 9; Brookshaw 1985), the form the heat pass conducts by
 * (heat.cl) and Orthmann et al. 2013 sec. 5 carry their bulk quantities with, with w in place of T and
 * rho D in place of k:
 *   dQ_i/dt = sum_j 2 V_i V_j K_ij (w_i - w_j) (x_ij . grad W_ij) / (r_ij^2 + eta^2),
 *   K_ij = D sqrt(rho_i rho_j),  so  V_i V_j K_ij = D m_i m_j / sqrt(rho_i rho_j) = D a_i a_j,  a = m / sqrt(rho):
 * the geometric mean of rho D, where the conduction pass takes the harmonic mean of k. Within one liquid the
 * densities differ by a percent at most, where the means agree to 1e-5; a product of per-particle numbers is
 * symmetric without a division in the pair loop: with the harmonic form the pass took 1.38 times the density
 * pass's time on 97k particles (bench/scenes/block.json, one substance), with this one 1.18-1.20 times.
 * Mass fractions rather than concentrations per volume: a uniform solution has no gradient of w where the
 * water's summation density falls short (at its free surface), and would have one of Q / V.
 *
 * Water that freezes (THAW_REJECT) gives up the substances that do not enter ice (their enters_ice false) to the
 * water within its support, each water particle j taking the share W_ij / sum_k W_ik; the ice keeps only the
 * round-off of that split. Substances with a molar mass (THAW_MELT_SHIFT) lower the melting point of the water
 * that holds them by K_f sum_s i_s b_s (Blagden's law with van 't Hoff's factor; b_s the molality), and ice
 * melts at the lowered point of the water around it (substance_ice): the heat pass reads the shift
 * (heat.cl, thermal_law.h).
 *
 * Conservation to round-off: each pair's transfer for the step, ((a_i a_j) G_ij) ((w_i - w_j) c), with
 * G_ij = grad_shape(q) r^2 / (r^2 + eta^2) and c = 2 D dt sigma / H^2, is computed by
 * i and by j from the same operands in the same order, so j's is exactly -i's; each particle adds its
 * transfers with a compensated sum (Knuth's two-sum, per lane, then over the lanes) into its amount, which
 * is itself a compensated pair (hi, lo). Contraction into fused multiply-adds would break both, so it is
 * off in this file. */
#pragma OPENCL FP_CONTRACT OFF

/* Per particle, in the structure-of-arrays layout the walks read on lanes (`sub`, blocks of `stride` floats):
 *   M    its mass for water; -1 for ice that gives substance up this step (substance_ice); 0 for every
 *        other particle, which takes no part
 *   A    M / sqrt(rho), rho its density: the density pass's for moving water, its material's rest density
 *        otherwise
 *   W+s  water: the mass fraction of substance s; ice that gives it up: its amount over the summed kernel
 *        weight of the water around it (each water particle takes this times its weight) */
#define SUB_M 0
#define SUB_A 1
#define SUB_W 2

float2 two_sum(float a, float b) {
  const float s = a + b;
  const float bp = s - a;
  return (float2)(s, (a - (s - bp)) + (b - bp));
}

/* (hi, lo) + d, the rounding error of hi + d kept in lo (as heat.cl's add_compensated). */
float2 add_to_pair(float2 e, float d) {
  const float2 s = two_sum(e.x, d);
  const float lo = e.y + s.y;
  const float hi = s.x + lo;
  return (float2)(hi, lo - (hi - s.x));
}

/* The lanes of (hi, lo) added in a fixed order, compensated: (sum, its error). */
float2 lanes_compensated(floatV hi, floatV lo) {
  float s = 0.0f, e = 0.0f;
  for (int l = 0; l < THAW_VW; ++l) {
    const float2 t = two_sum(s, ((float*)&hi)[l]);
    s = t.x;
    e += t.y + ((float*)&lo)[l];
  }
  return (float2)(s, e);
}

/* Inside a walk over candidates j..: the lanes' squared distance r2 from pi, along periodic axes the minimum
 * image's (X, Y, Z: the reorder's position blocks). The same operations on both sides of every pair. */
#define PAIR_LANES(pi, j, period)                                          \
  const floatV dx = THAW_WRAP((pi).x - vloadV(0, X + (j)), (period).x); \
  const floatV dy = THAW_WRAP((pi).y - vloadV(0, Y + (j)), (period).y); \
  const floatV dz = THAW_WRAP((pi).z - vloadV(0, Z + (j)), (period).z); \
  const floatV r2 = dx * dx + dy * dy + dz * dz;

/* hi, lo += d on every lane, compensated (Knuth's two-sum). */
#define ACCUMULATE(hi, lo, d)                  \
  {                                            \
    const floatV t_ = (hi) + (d);              \
    const floatV bp_ = t_ - (hi);              \
    (lo) += ((hi) - (t_ - bp_)) + ((d) - bp_); \
    (hi) = t_;                                 \
  }

/* The melt shift d [K] that the solutes in a particle's melted part give it, consistent with that part:
 * d = K_f n / (f(h, d) m - Q), with f the lowered law's liquid fraction at the particle's enthalpy h
 * (thermal_law.h), Kn = K_f n (n the moles of dissolved particles), Q the kg dissolved and m the physical
 * mass; `l` = (L, c_solid, c_liquid). F(d) = d (f(d) m - Q) - Kn is negative while the melt cannot hold the
 * solutes and rises with d after, so bisection on [0, dmax] finds its one root. Taking f from last step's
 * shift instead swung the shift of brine frozen part-way from step to step (the map's slope is below -1). */
float own_shift(float h, float4 l, float m, float Q, float Kn, float dmax) {
  if (Kn <= 0.0f) return 0.0f;
  if (l.x <= 0.0f) return m > Q ? fmin(Kn / (m - Q), dmax) : dmax;
  float lo = 0.0f, hi = dmax;
  if (dmax * (thermal_liquid_fraction_lowered(h, l.x, l.y, l.z, dmax) * m - Q) < Kn) return dmax;
  for (int k = 0; k < 32; ++k) {
    const float d = 0.5f * (lo + hi);
    if (d * (thermal_liquid_fraction_lowered(h, l.x, l.y, l.z, d) * m - Q) < Kn) lo = d;
    else hi = d;
  }
  return 0.5f * (lo + hi);
}

/* What particle i holds: (kg of substances, moles of the particles they make in solution, i / M each). */
float2 solutes(global const float2* q[4], const uint i, const SubstanceParams P) {
  const float moles[4] = {P.moles0, P.moles1, P.moles2, P.moles3};
  float2 held = (float2)(0.0f);
  for (int s = 0; s < THAW_NSUB; ++s) {
    const float amount = q[s][i].x + q[s][i].y;
    held += (float2)(amount, moles[s] * amount);
  }
  return held;
}

/* M, A and w of every particle. With THAW_MELT_SHIFT, each water particle's melt shift, the molality of its
 * liquid part (own_shift); `fluid` holds each material's rest density and cryoscopic constant. With the ice
 * pass (THAW_MELT_SHIFT or THAW_REJECT), ice that is partly melted at its lowered melting point carries
 * substances too, in its melted part: M is that part's mass, its liquid fraction (from its enthalpy and last
 * step's shift; `law` holds each material's L, c_solid, c_liquid and physical over SPH mass) times its
 * physical mass. The melt in a partly melted particle then mixes with the brine around it, so the brine
 * dilutes as ice melts into it: with the melt kept fresh, brine-melting's column stayed at the undiluted
 * brine's liquidus. `shift` is the melt_shift field with THAW_MELT_SHIFT, untouched otherwise. */
kernel void substance_state(global const float4* pos, global const float* density, global const float2* enthalpy,
                            global const uchar* phase, global const uchar* material, global const float2* fluid,
                            global const float4* law, global float* sub, global float* shift,
                            global const float2* q0, global const float2* q1, global const float2* q2,
                            global const float2* q3, const SubstanceParams P) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uint stride = P.stride;
  const float m = pos[i].w;
  const uchar mi = material[i];
  const float2 f = fluid[mi];
  const int water = phase[i] == THAW_PHASE_WATER && m > 0.0f;
  global const float2* q[4] = {q0, q1, q2, q3};
  const float2 held = solutes(q, i, P);
  const float dissolved = held.x, particles = held.y;
  float carried = water ? m : 0.0f;
#if defined(THAW_MELT_SHIFT) || defined(THAW_REJECT)
  const float4 l = law[mi];
  const float2 e = enthalpy[i];
  const float h = e.x + e.y;
#ifdef THAW_MELT_SHIFT
  /* Partly frozen water carries its solutes in its liquid part alone, and its shift is the molality of that
   * part (own_shift): as it freezes its solutes concentrate, which lowers its melting point and stops the
   * freezing (brine rejection). Counted over the whole particle, the brine beside partly melted ice froze
   * part-way at the liquidus of its undiluted start. */
  if (water) {
    const float d = own_shift(h, l, m * l.w, dissolved, f.y * particles, P.max_shift);
    shift[i] = d;
    if (l.x > 0.0f) carried = thermal_liquid_fraction_lowered(h, l.x, l.y, l.z, d) * m * l.w;
  }
#endif
  /* Ice partly melted carries what its melt holds, at last step's shift (the ice pass renews it). */
#ifdef THAW_MELT_SHIFT
  const float ice_shift = shift[i];
#else
  const float ice_shift = 0.0f;
#endif
  if (phase[i] == THAW_PHASE_ICE && m > 0.0f && l.x > 0.0f)
    carried = thermal_liquid_fraction_lowered(h, l.x, l.y, l.z, ice_shift) * m * l.w;
#endif
#ifdef THAW_MELT_SHIFT
  if (!water && phase[i] != THAW_PHASE_ICE) shift[i] = 0.0f;
#endif
  const float rho = water && P.flow ? density[i] : f.x;
  sub[SUB_M * stride + i] = carried;
  sub[SUB_A * stride + i] = carried / sqrt(rho > 0.0f ? rho : f.x);
  for (int s = 0; s < THAW_NSUB; ++s) {
    const float2 a = q[s][i];
    sub[(SUB_W + s) * stride + i] = carried > 0.0f ? (a.x + a.y) / carried : 0.0f;
  }
}

#if defined(THAW_MELT_SHIFT) || defined(THAW_REJECT)
/* Ice: its melt shift, the kernel-weighted mean of the water's around it (the liquidus of the brine it
 * touches), and with THAW_REJECT what ice frozen through gives up this step: M = -1 and w = amount / the
 * summed weight of the carriers within its support, for each substance that does not enter ice and that it
 * holds. */
kernel void substance_ice(global const float4* pos, global const uchar* phase, global const uchar* material,
                          global const float2* fluid, global const float4* law, global const float2* enthalpy,
                          global const float* soa,
                          global float* sub, global float* shift, global const uint* cell_start, const Grid g,
                          global const float2* q0, global const float2* q1, global const float2* q2,
                          global const float2* q3, const SubstanceParams P) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_ICE) return;
  const uint stride = P.stride;
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  global const float* X = soa;
  global const float* Y = soa + stride;
  global const float* Z = soa + 2 * stride;
  global const float* M = sub + SUB_M * stride;
  const float4 pi = pos[i];
  const int4 cell = grid_cell(g, pi);
  floatV sw = (floatV)(0.0f), sww = (floatV)(0.0f), sd = (floatV)(0.0f);
  FOR_EACH_HEAT_RANGE(g, cell_start, cell, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      PAIR_LANES(pi, j, period)
      const intV near = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2);
      /* Carriers (water, and ice partly melted) take its shares; water alone sets its shift (the partly
       * melted ice's own shifts are being renewed by this pass). */
      const intV carrier = near & (vloadV(0, M + j) > 0.0f);
      const intV water =
          carrier & (THAW_CAT(convert_int, THAW_VW)(THAW_CAT(vload, THAW_VW)(0, phase + j)) == THAW_PHASE_WATER);
      const floatV wsh = w_shape(sqrt(r2) * inv_H);
      sw += select((floatV)(0.0f), wsh, carrier);
#ifdef THAW_MELT_SHIFT
      const floatV ww = select((floatV)(0.0f), wsh, water);
      sww += ww;
      sd += ww * select((floatV)(0.0f), vloadV(0, shift + j), water);
#endif
    }
  }
  /* What it gives each carrier is its amount / weight times their pair's weight; the split closes to
   * round-off whatever order weight was summed in, since giver and taker compute the same products. */
  const float weight = lanes_sum(sw);
#ifdef THAW_MELT_SHIFT
  const float water_weight = lanes_sum(sww);
  const float around = water_weight > 0.0f ? lanes_sum(sd) / water_weight : 0.0f;
  /* Or its own, where it holds what lowers it (salt dropped on dry ice): the molality of its melted part, the
   * cap while it has none, so it melts until its melt holds the salt as brine at its own liquidus. `fluid`
   * gives ice the cryoscopic constant of the water it melts into. */
  global const float2* qs[4] = {q0, q1, q2, q3};
  const float2 held = solutes(qs, i, P);
  const float4 l = law[material[i]];
  const float2 e = enthalpy[i];
  const float own = own_shift(e.x + e.y, l, pi.w * l.w, held.x, fluid[material[i]].y * held.y, P.max_shift);
  shift[i] = fmax(around, own);
#endif
#ifdef THAW_REJECT
  /* Ice partly melted carries what its melt holds (substance_state gave it its w); frozen through, it gives it
   * up. */
  if (M[i] != 0.0f || weight <= 0.0f) return;
  global const float2* q[4] = {q0, q1, q2, q3};
  int gives = 0;
  for (int s = 0; s < THAW_NSUB; ++s) {
    const float2 a = q[s][i];
    const float amount = a.x + a.y;
    const int out = ((P.reject >> s) & 1u) && amount > 0.0f;
    sub[(SUB_W + s) * stride + i] = out ? amount / weight : 0.0f;
    gives |= out;
  }
  if (gives) sub[SUB_M * stride + i] = -1.0f;
#endif
}
#endif

/* One step: each water particle's amounts change by its pairs' diffusive transfers, plus (THAW_REJECT) what
 * the giving ice around it hands it; giving ice loses what it hands out. */
kernel void substance_diffuse(global const float4* pos, global const float* soa, global const float* sub,
                              global const uint* cell_start, const Grid g, const SubstanceParams P,
                              global float2* q0, global float2* q1, global float2* q2, global float2* q3) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uint stride = P.stride;
  global const float* M = sub + SUB_M * stride;
  global const float* A = sub + SUB_A * stride;
  const float mi = M[i];
  if (mi == 0.0f) return;
  const int giving = mi < 0.0f;
  const float ai = A[i];
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H, eta2 = P.eta2;
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  const float unit = THAW_SIGMA(H) * inv_H * inv_H; /* x . grad W = sigma / H^2 grad_shape(q) r^2 */
  const float c[4] = {P.step0 * unit, P.step1 * unit, P.step2 * unit, P.step3 * unit};
  global const float* X = soa;
  global const float* Y = soa + stride;
  global const float* Z = soa + 2 * stride;
  const float4 pi = pos[i];
  const int4 cell = grid_cell(g, pi);
  float wi[THAW_NSUB];
  floatV hi[THAW_NSUB], lo[THAW_NSUB];
  for (int s = 0; s < THAW_NSUB; ++s) {
    wi[s] = sub[(SUB_W + s) * stride + i];
    hi[s] = (floatV)(0.0f);
    lo[s] = (floatV)(0.0f);
  }
  FOR_EACH_HEAT_RANGE(g, cell_start, cell, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      PAIR_LANES(pi, j, period)
      const intV in = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2);
      const floatV mj = vloadV(0, M + j);
      const floatV qr = sqrt(r2) * inv_H;
      if (!giving) {
        /* Symmetric in i and j operand by operand (the header); 0 for lanes out of range or not water. */
        const floatV pair = select((floatV)(0.0f), (ai * vloadV(0, A + j)) * (grad_shape(qr) * r2 / (r2 + eta2)),
                                   in & (mj > 0.0f));
        for (int s = 0; s < THAW_NSUB; ++s) {
          const floatV d = pair * ((wi[s] - vloadV(0, sub + (SUB_W + s) * stride + j)) * c[s]);
          ACCUMULATE(hi[s], lo[s], d)
        }
      }
#ifdef THAW_REJECT
      /* Ice gives to water: the giver's amount per weight times the pair's weight, computed alike on both
       * sides. */
      const intV handed = in & (giving ? (mj > 0.0f) : (mj < 0.0f));
      /* Givers are rare (water froze through last step): most water skips this for every candidate. */
      if (any(handed)) {
        const floatV w = select((floatV)(0.0f), w_shape(qr), handed);
        for (int s = 0; s < THAW_NSUB; ++s) {
          const floatV d = giving ? -(wi[s] * w) : vloadV(0, sub + (SUB_W + s) * stride + j) * w;
          ACCUMULATE(hi[s], lo[s], d)
        }
      }
#endif
    }
  }
  global float2* q[4] = {q0, q1, q2, q3};
  for (int s = 0; s < THAW_NSUB; ++s) {
    const float2 d = lanes_compensated(hi[s], lo[s]);
    q[s][i] = add_to_pair(add_to_pair(q[s][i], d.x), d.y);
  }
}
