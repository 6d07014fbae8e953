/* Substances dissolved in the water (issue 20, docs/SUBSTANCES.md): each water particle holds an amount
 * Q_i [kg] of each of up to four substances (THAW_NSUB), carried with it by the flow; between water
 * particles it diffuses by Fick's law, rho Dw/Dt = div(rho D grad w) for the mass fraction w = Q / m. Built
 * with sph_kernel.h, grid_common.h, sph_lanes.h, wrapped_walk.h, thermal_law.h, liquidus.h and
 * substance_params.h.
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
 * that holds them by their liquidus (liquidus.h: a measured table to the eutectic, or Blagden's dilute law),
 * and ice melts at the lowered point of the water around it (substance_ice): the heat pass reads the shift
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
#ifdef THAW_SURFACE
/* With surface-active substances, after the W blocks:
 *   AS      a surface particle's area a_i (water with more than P.min_area of it), 0 for every other
 *   NRM     a surface particle's 1 / sum_k M_k w(r_ik / H) over the carriers within its support (substance_norm)
 *   MOM     a surface particle's 2-D kernel moment sum_j a_j (-p_ij . grad W2_ij) / 2 over the surface
 *           particles j (substance_norm): 1 where the areas sample the surface evenly
 *   PX..PZ  its point on the surface, x_i + surface_depth n_i
 *   NX..NZ  its outward normal
 *   G+s     its surface excess Gamma_i = S_i / a_i of substance s [kg/m^2] (0 for bulk substances) */
#define SUB_AS (SUB_W + THAW_NSUB)
#define SUB_NRM (SUB_AS + 1)
#define SUB_MOM (SUB_AS + 2)
#define SUB_PX (SUB_AS + 3)
#define SUB_NX (SUB_AS + 6)
#define SUB_G (SUB_AS + 9)

/* The surface points' and normals' blocks, for SURFACE_PAIR. */
#define SURFACE_POINTS                                      \
  global const float* PX = sub + SUB_PX * stride;           \
  global const float* PY = sub + (SUB_PX + 1) * stride;     \
  global const float* PZ = sub + (SUB_PX + 2) * stride;     \
  global const float* NX = sub + SUB_NX * stride;           \
  global const float* NY = sub + (SUB_NX + 1) * stride;     \
  global const float* NZ = sub + (SUB_NX + 2) * stride;

/* Inside a walk, with point_i, normal_i and the PX.. and NX.. blocks in scope: p2, the squared distance
 * between the surface points of i and the lanes j.. along the surface, their offset less its part along the
 * pair's mean normal n_i + n_j. The surface points of a lattice's jagged outer layer lie up to half a spacing
 * off the surface; counted whole, that offset made the diffusion 17 % slow on a sphere (surface-diffusion),
 * as part of each pair's distance went across the surface, where nothing varies. The same operations on
 * both sides of every pair. */
#define SURFACE_PAIR(j)                                                                                    \
  const floatV ox = point_i.x - vloadV(0, PX + (j)), oy = point_i.y - vloadV(0, PY + (j)),                \
               oz = point_i.z - vloadV(0, PZ + (j));                                                      \
  const floatV nx = normal_i.x + vloadV(0, NX + (j)), ny = normal_i.y + vloadV(0, NY + (j)),              \
               nz = normal_i.z + vloadV(0, NZ + (j));                                                     \
  const floatV nn = nx * nx + ny * ny + nz * nz, on = ox * nx + oy * ny + oz * nz;                         \
  const floatV p2 = fmax(ox * ox + oy * oy + oz * oz - select((floatV)(0.0f), on * on / nn, nn > 0.0f), 0.0f);
#endif

#ifdef THAW_DEPOSIT
/* With coatings, after the blocks above:
 *   F     a solid or ice particle's face over its wet weight, face / max(sum_j M_j w(r_ij / H), wet_weight)
 *         over the carriers j within its support (substance_wet); 0 for every other particle and for a
 *         boundary particle no water touches
 *   R+s   its deposit per face Gamma_R = R / face of substance s [kg/m^2] (0 but for coatings) */
#ifdef THAW_SURFACE
#define SUB_F (SUB_G + THAW_NSUB)
#else
#define SUB_F (SUB_W + THAW_NSUB)
#endif
#define SUB_R (SUB_F + 1)
#endif

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

/* Moves what `from` holds for particle i into `to`'s pair for it, compensated, and empties `from`'s. */
void hand_over(global float2* from, global float2* to, const uint i) {
  const float2 held = from[i];
  if (held.x == 0.0f && held.y == 0.0f) return;
  to[i] = add_to_pair(add_to_pair(to[i], held.x), held.y);
  from[i] = (float2)(0.0f);
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

/* Inside a walk over candidates j..: the lanes' offsets and squared distance r2 from pi, along periodic axes
 * the minimum image's (xs: walk.h's positions). The same operations on both sides of every pair. Still a
 * macro here, unlike the other passes' pair_lanes_wrapped: through that function this file's passes gave
 * other bits (the build's -cl-mad-enable lets the compiler contract them differently), and they are kept bit
 * for bit. */
#define PAIR_LANES(pi, j, period)                                           \
  const floatV dx = nearest_image((pi).x - vloadV(0, xs.x + (j)), (period).x); \
  const floatV dy = nearest_image((pi).y - vloadV(0, xs.y + (j)), (period).y); \
  const floatV dz = nearest_image((pi).z - vloadV(0, xs.z + (j)), (period).z); \
  const floatV r2 = dx * dx + dy * dy + dz * dz;

/* A walk's compensated lanes (hi, lo) added into particle i's pair in q. */
void add_lanes(global float2* q, const uint i, floatV hi, floatV lo) {
  const float2 d = lanes_compensated(hi, lo);
  q[i] = add_to_pair(add_to_pair(q[i], d.x), d.y);
}

/* hi, lo += d on every lane, compensated (Knuth's two-sum). */
#define ACCUMULATE(hi, lo, d)                  \
  {                                            \
    const floatV t_ = (hi) + (d);              \
    const floatV bp_ = t_ - (hi);              \
    (lo) += ((hi) - (t_ - bp_)) + ((d) - bp_); \
    (hi) = t_;                                 \
  }

/* The melt shift d [K] that the solutes in a particle's melted part give it, consistent with that part:
 * d = D(q, f(h, d) m), with f the lowered law's liquid fraction at the particle's enthalpy h (thermal_law.h),
 * D the liquidus of a melt of that mass holding the amounts q (liquidus.h: each substance dissolved up to its
 * solubility, capped at the eutectic), m the physical mass and `l` = (L, c_solid, c_liquid). The melt grows
 * with d and D falls with the melt, so F(d) = D(q, f(d) m) - d falls, and bisection on [0, cap] finds its
 * one root; at the cap (D still above it there) the particle is at its eutectic, where what is left of its
 * melt freezes through as it loses heat. Taking f from last step's shift instead swung the shift of brine
 * frozen part-way from step to step (the map's slope is below -1). */
float own_shift(float h, float4 l, float m, const float* q, float kf, global const Liquidus* lq) {
  /* a melt of nothing is at the cap of what it holds: 0 where it holds nothing that lowers */
  const float cap = liquidus_drop(lq, THAW_NSUB, q, 0.0f, kf);
  if (cap <= 0.0f) return 0.0f;
  if (l.x <= 0.0f) return liquidus_drop(lq, THAW_NSUB, q, m, kf);
  if (liquidus_drop(lq, THAW_NSUB, q, thermal_liquid_fraction_lowered(h, l.x, l.y, l.z, cap) * m, kf) >= cap)
    return cap;
  /* 24 halvings take [0, cap] to a float's resolution at the cap (2^-24 of it). */
  float lo = 0.0f, hi = cap;
  for (int k = 0; k < 24; ++k) {
    const float d = 0.5f * (lo + hi);
    const float melt = thermal_liquid_fraction_lowered(h, l.x, l.y, l.z, d) * m;
    if (liquidus_drop(lq, THAW_NSUB, q, melt, kf) > d) lo = d;
    else hi = d;
  }
  return 0.5f * (lo + hi);
}

/* What particle i holds of each substance [kg] (its compensated pairs' sums). */
void held_amounts(global const float2* q[4], const uint i, float* held) {
  for (int s = 0; s < THAW_NSUB; ++s) held[s] = q[s][i].x + q[s][i].y;
}

/* M, A and w of every particle. With THAW_MELT_SHIFT, each water particle's melt shift, the liquidus of its
 * liquid part (own_shift; `liquidus` holds each substance's); `fluid` holds each material's rest density and
 * cryoscopic constant. With the ice
 * pass (THAW_MELT_SHIFT or THAW_REJECT), ice that is partly melted at its lowered melting point carries
 * substances too, in its melted part: M is that part's mass, its liquid fraction (from its enthalpy and last
 * step's shift; `law` holds each material's L, c_solid, c_liquid and physical over SPH mass) times its
 * physical mass. The melt in a partly melted particle then mixes with the brine around it, so the brine
 * dilutes as ice melts into it: with the melt kept fresh, brine-melting's column stayed at the undiluted
 * brine's liquidus. `shift` is the melt_shift field with THAW_MELT_SHIFT, untouched otherwise. */
kernel void substance_state(global const float4* pos, global const float* density, global const float2* enthalpy,
                            global const uchar* phase, global const uchar* material, global const float2* fluid,
                            global const float4* law, global const Liquidus* liquidus, global float* sub,
                            global float* shift, global float2* q0, global float2* q1, global float2* q2,
                            global float2* q3,
                            global const float* area, global const float4* normal, global float2* s0,
                            global float2* s1, global float2* s2, global float2* s3, global float2* d0,
                            global float2* d1, global float2* d2, global float2* d3, const SubstanceParams P) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uint stride = P.stride;
  const float m = pos[i].w;
  const uchar mi = material[i];
  const float2 f = fluid[mi];
  const int water = phase[i] == THAW_PHASE_WATER && m > 0.0f;
  global float2* q[4] = {q0, q1, q2, q3};
#ifdef THAW_SURFACE
  /* A particle off the surface (drawn under it, frozen, or never on it) hands what it holds on its surface to
   * its own bulk: Orthmann et al. sec. 6.1's "particles drawn under the surface transfer mass back", to the
   * one bulk particle that is certain to be there, itself, so nothing is lost. */
  global float2* sa[4] = {s0, s1, s2, s3};
  const float own_area = area[i];
  const int on_surface = water && own_area > P.min_area;
  for (int s = 0; s < THAW_NSUB; ++s)
    if (((P.surface >> s) & 1u) && !on_surface) hand_over(sa[s], q[s], i);
#endif
#ifdef THAW_DEPOSIT
  /* A deposit on ice that has melted goes into the particle's own water (sec. 6.4's deposit stays on the
   * rigid surface it stuck to; that surface is gone). */
  global float2* dep[4] = {d0, d1, d2, d3};
  const int boundary = THAW_IS_STATIC(phase[i]);
  for (int s = 0; s < THAW_NSUB; ++s)
    if (((P.coating >> s) & 1u) && !boundary) hand_over(dep[s], q[s], i);
#endif
  global const float2* qc[4] = {q0, q1, q2, q3};
  float held[THAW_NSUB];
  held_amounts(qc, i, held);
  float carried = water ? m : 0.0f;
#if defined(THAW_MELT_SHIFT) || defined(THAW_REJECT)
  const float4 l = law[mi];
  const float2 e = enthalpy[i];
  const float h = e.x + e.y;
#ifdef THAW_MELT_SHIFT
  /* Partly frozen water carries its solutes in its liquid part alone, and its shift is the liquidus of that
   * part (own_shift): as it freezes its solutes concentrate, which lowers its melting point and stops the
   * freezing (brine rejection), down to the eutectic. Counted over the whole particle, the brine beside
   * partly melted ice froze part-way at the liquidus of its undiluted start. */
  if (water) {
    const float d = own_shift(h, l, m * l.w, held, f.y, liquidus);
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
  /* What diffuses is what the melt dissolves; past its solubility the rest stays with the particle, undissolved
   * (liquidus.h), and dissolves as the melt grows or its brine thins. */
  for (int s = 0; s < THAW_NSUB; ++s)
    sub[(SUB_W + s) * stride + i] =
        carried > 0.0f ? liquidus_dissolved(liquidus + s, held[s], carried) / carried : 0.0f;
#ifdef THAW_SURFACE
  const int surface = on_surface && carried > 0.0f;
  sub[SUB_AS * stride + i] = surface ? own_area : 0.0f;
  const float3 n = normal[i].xyz;
  const float3 point = pos[i].xyz + (surface ? P.surface_depth : 0.0f) * n;
  sub[SUB_PX * stride + i] = point.x;
  sub[(SUB_PX + 1) * stride + i] = point.y;
  sub[(SUB_PX + 2) * stride + i] = point.z;
  sub[SUB_NX * stride + i] = n.x;
  sub[(SUB_NX + 1) * stride + i] = n.y;
  sub[(SUB_NX + 2) * stride + i] = n.z;
  for (int s = 0; s < THAW_NSUB; ++s) {
    const float2 a = sa[s][i];
    sub[(SUB_G + s) * stride + i] = surface && ((P.surface >> s) & 1u) ? (a.x + a.y) / own_area : 0.0f;
  }
#endif
#ifdef THAW_DEPOSIT
  for (int s = 0; s < THAW_NSUB; ++s) {
    const float2 a = dep[s][i];
    sub[(SUB_R + s) * stride + i] = boundary && ((P.coating >> s) & 1u) ? (a.x + a.y) / P.face : 0.0f;
  }
#endif
}

#ifdef THAW_SURFACE
/* Each surface particle's 1 / sum_j M_j w(r_ij / H) over the carriers j within its support (itself among
 * them): what its uptake from each carrier is weighted by, so the shares it takes sum to one (sec. 6.1's
 * V_j W_ij, Shepard-normalised: a surface particle's neighbourhood is cut off by the surface, and the
 * uptake k_a c a_i must not shrink with it). */
kernel void substance_norm(global const float4* pos, global const float* soa, global float* sub,
                           global const uint* cell_start, const Grid g, const SubstanceParams P) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uint stride = P.stride;
  if (!(sub[SUB_AS * stride + i] > 0.0f)) {
    sub[SUB_NRM * stride + i] = 0.0f;
    sub[SUB_MOM * stride + i] = 0.0f;
    return;
  }
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  const Positions xs = soa_positions(soa, stride);
  global const float* M = sub + SUB_M * stride; /* the carriers' masses */
  const float4 pi = pos[i];
  const int4 cell = grid_cell(g, pi);
  global const float* AS = sub + SUB_AS * stride;
  SURFACE_POINTS
  const float3 point_i = (float3)(PX[i], PY[i], PZ[i]), normal_i = (float3)(NX[i], NY[i], NZ[i]);
  floatV sw = (floatV)(0.0f), sm = (floatV)(0.0f);
  FOR_EACH_HEAT_RANGE(g, cell_start, cell, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      PAIR_LANES(pi, j, period)
      const floatV mj = vloadV(0, M + j);
      const intV in = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2);
      sw += select((floatV)(0.0f), mj * w_shape(sqrt(r2) * inv_H), in & (mj > 0.0f));
      const floatV area_j = vloadV(0, AS + j);
      SURFACE_PAIR(j)
      /* with the pair term's eta^2, so a field quadratic along the surface gets its Laplacian exactly */
      sm += select((floatV)(0.0f), area_j * (grad_shape(sqrt(p2) * inv_H) * p2 * p2 / (p2 + P.eta2)),
                   in & (area_j > 0.0f) & (p2 < H2));
    }
  }
  const float total = lanes_sum(sw);
  sub[SUB_NRM * stride + i] = total > 0.0f ? 1.0f / total : 0.0f;
  /* In 2-D the integral of -x . grad W2 over the plane is 2; x . grad W2 = sigma2 / H^4 grad_shape(q) r^2. */
  sub[SUB_MOM * stride + i] = -0.5f * P.sigma2 * (inv_H * inv_H) * (inv_H * inv_H) * lanes_sum(sm);
}
#endif

#ifdef THAW_DEPOSIT
/* What each grid cell holds, one work item per cell over its particles: CELL_CARRIER a carrier (M > 0),
 * CELL_STATIC a solid or ice particle; then (substance_cells_around) what the 27 cells around it hold. A
 * wall's inner layers, with no carrier in the cells around them, skip substance_wet's walk, and a carrier
 * with no solid or ice around it skips the walk of the exchange with them: the coating stage cost half again
 * on the benchmark block, whose walls outnumber its water, where no water touched a wall. */
#define CELL_CARRIER 1
#define CELL_STATIC 2
kernel void substance_cells(global const float* sub, global const uchar* phase, global const uint* cell_start,
                            global uchar* held_cells, const uint ncells, const SubstanceParams P) {
  const uint c = get_global_id(0);
  if (c >= ncells) return;
  global const float* M = sub + SUB_M * P.stride;
  uchar held = 0;
  for (uint j = cell_start[c]; j < cell_start[c + 1] && held != (CELL_CARRIER | CELL_STATIC); ++j)
    held |= (M[j] > 0.0f ? CELL_CARRIER : 0) | (THAW_IS_STATIC(phase[j]) ? CELL_STATIC : 0);
  held_cells[c] = held;
}

/* What the cells around `cell` (the 27 the walks visit, wrapped along periodic axes) hold together. */
uchar cells_around(const Grid g, const int4 cell, global const uchar* held) {
  uchar all = 0;
  for (int dz = -1; dz <= 1; ++dz)
    for (int dy = -1; dy <= 1; ++dy)
      for (int dx = -1; dx <= 1; ++dx) {
#ifdef THAW_PERIODIC
        const int c = heat_cell(g, cell, dz, dy, dx);
#else
        const int4 n = cell + (int4)(dx, dy, dz, 0);
        const int c = any(n.xyz < 0) || any(n.xyz >= (int3)(g.nx, g.ny, g.nz)) ? -1 : (int)grid_key(g, n);
#endif
        if (c >= 0) all |= held[c];
      }
  return all;
}

kernel void substance_cells_around(global const uchar* held, global uchar* around, const Grid g, const uint ncells) {
  const uint c = get_global_id(0);
  if (c >= ncells) return;
  const int x = (int)(c % (uint)g.nx), y = (int)(c / (uint)g.nx % (uint)g.ny), z = (int)(c / ((uint)g.nx * (uint)g.ny));
  around[c] = cells_around(g, (int4)(x, y, z, 0), held);
}

/* Each solid or ice particle's F = face / max(sum_j M_j w(r_ij / H), wet_weight) over the other carriers j
 * within its support: its uptake from each carrier is weighted by M_j w(r_ij / H) F, so the shares sum to
 * its face where water fills the wet share of its kernel volume (substance_stage.h's kWetFraction) and to
 * less where less water touches it; no water, no uptake. */
kernel void substance_wet(global const float4* pos, global const uchar* phase, global const float* soa,
                          global float* sub, global const uint* cell_start, const Grid g, const SubstanceParams P,
                          global const uchar* around) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uint stride = P.stride;
  if (!THAW_IS_STATIC(phase[i]) || !(around[grid_key(g, grid_cell(g, pos[i]))] & CELL_CARRIER)) {
    sub[SUB_F * stride + i] = 0.0f;
    return;
  }
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  const Positions xs = soa_positions(soa, stride);
  global const float* M = sub + SUB_M * stride; /* the carriers' masses */
  const float4 pi = pos[i];
  const int4 cell = grid_cell(g, pi);
  floatV sw = (floatV)(0.0f);
  FOR_EACH_HEAT_RANGE(g, cell_start, cell, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      PAIR_LANES(pi, j, period)
      const floatV mj = vloadV(0, M + j);
      const intV carrier = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2) & (r2 > 0.0f) & (mj > 0.0f);
      sw += select((floatV)(0.0f), mj * w_shape(sqrt(r2) * inv_H), carrier);
    }
  }
  const float total = lanes_sum(sw);
  sub[SUB_F * stride + i] = total > 0.0f ? P.face / fmax(total, P.wet_weight) : 0.0f;
}
#endif

#if defined(THAW_MELT_SHIFT) || defined(THAW_REJECT)
/* Ice: its melt shift, the kernel-weighted mean of the water's around it (the liquidus of the brine it
 * touches), and with THAW_REJECT what ice frozen through gives up this step: M = -1 and w = amount / the
 * summed weight of the carriers within its support, for each substance that does not enter ice and that it
 * holds. */
kernel void substance_ice(global const float4* pos, global const uchar* phase, global const uchar* material,
                          global const float2* fluid, global const float4* law,
                          global const Liquidus* liquidus, global const float2* enthalpy, global const float* soa,
                          global float* sub, global float* shift, global const uint* cell_start, const Grid g,
                          global const float2* q0, global const float2* q1, global const float2* q2,
                          global const float2* q3, const SubstanceParams P) {
  const uint i = get_global_id(0);
  if (i >= P.n || phase[i] != THAW_PHASE_ICE) return;
  const uint stride = P.stride;
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  const Positions xs = soa_positions(soa, stride);
  global const float* M = sub + SUB_M * stride; /* the carriers' masses */
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
  /* Or its own, where it holds what lowers it (salt dropped on dry ice): the liquidus of its melted part, the
   * eutectic while it has none, so it melts until its melt holds the salt as brine at its own liquidus (ice
   * and salt, a freezing mixture, cool towards the eutectic). `fluid` gives ice the cryoscopic constant of
   * the water it melts into. */
  global const float2* qs[4] = {q0, q1, q2, q3};
  float held[THAW_NSUB];
  held_amounts(qs, i, held);
  const float4 l = law[material[i]];
  const float2 e = enthalpy[i];
  const float own = own_shift(e.x + e.y, l, pi.w * l.w, held, fluid[material[i]].y, liquidus);
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

/* The amount a surface particle (area a, 1 / its weights' sum nrm, surface excess g) takes from a carrier of
 * weight wgt = M w(r / H) and mass fraction wb over one step, for substance s: Orthmann et al. 2013 sec. 6.1's
 * Langmuir-Hinshelwood flux,
 *   Gamma_{i<-j} = a_i (M_j w_ij / sum_k M_k w_ik) [k_a c_j (1 - Gamma_i / Gamma_max) - k_d Gamma_i] dt,
 * with c_j = rho0 w_j and the weights normalised (sec. 6.1 weights by V_j W_ij), so a well-mixed bulk gives
 * sum_j Gamma_{i<-j} = a_i (k_a c - k_d Gamma_i) dt exactly. Eq. 10: the carrier loses what the surface takes.
 * Both sides evaluate this one expression from the same operands, so the two amounts are equal to the bit. */
#define ADSORBED(a, nrm, g, wgt, wb, s) \
  ((a) * ((nrm) * (wgt)) * ((adsorb[s] * (wb)) * fmax(1.0f - (g) * inv_capacity[s], 0.0f) - desorb[s] * (g)))

/* The amount a boundary particle (F = face / its wet weight, deposit per face G) takes from a carrier of weight
 * wgt = M w(r / H), mass fractions wc of coating s and wd of its cleanser, over one step: Orthmann et al. 2013
 * sec. 6.4's coating, Gamma^r = -sigma_r S_i (V_i + V_k) W_ik / 2, as a deposition velocity k_c onto the
 * boundary's face up to its capacity, less sec. 6.3's cleansing, sigma_r S_i R_k (V_i + V_k) W_ik / 2, as
 * k_r c_D Gamma_R back into the water,
 *   R_{k<-j} = face (M_j w_kj / sum_i M_i w_ki) [k_c c_j (1 - Gamma_R,k / Gamma_R,max) - k_r c_D,j Gamma_R,k] dt,
 * c = rho0 w; a boundary wholly wet takes face (k_c c - k_r c_D Gamma_R) dt from well-mixed water. The
 * paper's S_i is the coating's and the detergent's amount on the free surface; here the water touching the
 * boundary carries both in its bulk, as water that wets a plate does. Both sides evaluate this one
 * expression from the same operands, so the two amounts are equal to the bit. */
#define DEPOSITED(f, wgt, wc, wd, g, s)                                                            \
  ((f) * (wgt) * ((coat[s] * (wc)) * fmax(1.0f - (g) * inv_coat_capacity[s], 0.0f) - (cleanse[s] * (wd)) * (g)))

/* substance_diffuse's candidates j..j+THAW_VW: offsets and r2 (PAIR_LANES), which lanes are within the support
 * (`in`), their carried masses mj and r / H (qr). */
#define DIFFUSE_LANES(j)                                              \
  PAIR_LANES(pi, j, period)                                           \
  const intV in = (THAW_LANE_IDS < (int)(je - (j))) & (r2 < H2);      \
  const floatV mj = vloadV(0, M + (j));                               \
  const floatV qr = sqrt(r2) * inv_H;

/* One step: each water particle's amounts change by its pairs' diffusive transfers, plus (THAW_REJECT) what
 * the giving ice around it hands it; giving ice loses what it hands out. With THAW_SURFACE, surface-active
 * substances also move between the surface and the bulk (eq. 10, ADSORBED) and along the surface between
 * surface particles (eq. 11): Cleary & Monaghan's pair term in 2-D on the particles' points on the surface,
 *   dS_i/dt = sum_j 2 D_s a_i a_j (Gamma_i - Gamma_j) (p_ij . grad W2_ij) / (|p_ij|^2 + eta^2),
 * W2 the kernel's 2-D form (the same shape with sigma_2), symmetric in i and j term by term as eq. 11 asks,
 * where sec. 6.2's (a_i V_i + a_j V_j) is not a surface integral's weight. */
kernel void substance_diffuse(global const float4* pos, global const float* soa, global const float* sub,
                              global const uint* cell_start, const Grid g, const SubstanceParams P,
                              global float2* q0, global float2* q1, global float2* q2, global float2* q3,
                              global float2* s0, global float2* s1, global float2* s2, global float2* s3,
                              global float2* d0, global float2* d1, global float2* d2, global float2* d3,
                              global float* tension_ratio, global const uchar* around) {
  const uint i = get_global_id(0);
  if (i >= P.n) return;
  const uint stride = P.stride;
  const float mi = sub[SUB_M * stride + i];
#ifdef THAW_DEPOSIT
  /* A boundary particle that water touches takes part for its deposits. */
  const float f_i = sub[SUB_F * stride + i];
  if (mi == 0.0f && !(f_i > 0.0f)) return;
#else
  if (mi == 0.0f) return;
#endif
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  const Positions xs = soa_positions(soa, stride);
  global const float* M = sub + SUB_M * stride; /* the carriers' masses */
  const float4 pi = pos[i];
  const int4 cell = grid_cell(g, pi);
  global const float* A = sub + SUB_A * stride;
  const int giving = mi < 0.0f;
  const float ai = A[i], eta2 = P.eta2;
  const float unit = THAW_SIGMA(H) * inv_H * inv_H; /* x . grad W = sigma / H^2 grad_shape(q) r^2 */
  const float c[4] = {P.step0 * unit, P.step1 * unit, P.step2 * unit, P.step3 * unit};
  float wi[THAW_NSUB];
  floatV hi[THAW_NSUB], lo[THAW_NSUB];
  for (int s = 0; s < THAW_NSUB; ++s) {
    wi[s] = sub[(SUB_W + s) * stride + i];
    hi[s] = (floatV)(0.0f);
    lo[s] = (floatV)(0.0f);
  }
#ifdef THAW_SURFACE
  global const float* AS = sub + SUB_AS * stride;
  global const float* NRM = sub + SUB_NRM * stride;
  SURFACE_POINTS
  const float adsorb[4] = {P.adsorb0, P.adsorb1, P.adsorb2, P.adsorb3};
  const float desorb[4] = {P.desorb0, P.desorb1, P.desorb2, P.desorb3};
  const float inv_capacity[4] = {P.inv_capacity0, P.inv_capacity1, P.inv_capacity2, P.inv_capacity3};
  const float glide[4] = {P.glide0, P.glide1, P.glide2, P.glide3};
  global const float* MOM = sub + SUB_MOM * stride;
  const float area_i = AS[i], nrm_i = NRM[i], mom_i = MOM[i];
  const float3 point_i = (float3)(PX[i], PY[i], PZ[i]), normal_i = (float3)(NX[i], NY[i], NZ[i]);
  float gi[THAW_NSUB];
  floatV shi[THAW_NSUB], slo[THAW_NSUB];
  for (int s = 0; s < THAW_NSUB; ++s) {
    gi[s] = sub[(SUB_G + s) * stride + i];
    shi[s] = (floatV)(0.0f);
    slo[s] = (floatV)(0.0f);
  }
#endif
#ifdef THAW_DEPOSIT
  global const float* F = sub + SUB_F * stride;
  const float coat[4] = {P.coat0, P.coat1, P.coat2, P.coat3};
  const float cleanse[4] = {P.cleanse0, P.cleanse1, P.cleanse2, P.cleanse3};
  const float inv_coat_capacity[4] = {P.inv_coat_capacity0, P.inv_coat_capacity1, P.inv_coat_capacity2,
                                      P.inv_coat_capacity3};
  /* A carrier gives to wet boundary particles only where a solid or ice particle is in the cells around. */
  const int near_static = mi > 0.0f && (around[grid_key(g, grid_cell(g, pos[i]))] & CELL_STATIC);
  float ri[THAW_NSUB];
  uint by[THAW_NSUB]; /* each coating's cleanser, 15 for none */
  floatV dhi[THAW_NSUB], dlo[THAW_NSUB];
  for (int s = 0; s < THAW_NSUB; ++s) {
    ri[s] = sub[(SUB_R + s) * stride + i];
    by[s] = (P.cleanser >> (4 * s)) & 15u;
    dhi[s] = (floatV)(0.0f);
    dlo[s] = (floatV)(0.0f);
  }
#endif
  FOR_EACH_HEAT_RANGE(g, cell_start, cell, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      DIFFUSE_LANES(j)
      if (mi > 0.0f) {
        /* Symmetric in i and j operand by operand (the header); 0 for lanes out of range or not water. */
        const floatV pair = select((floatV)(0.0f), (ai * vloadV(0, A + j)) * (grad_shape(qr) * r2 / (r2 + eta2)),
                                   in & (mj > 0.0f));
        for (int s = 0; s < THAW_NSUB; ++s) {
          const floatV d = pair * ((wi[s] - vloadV(0, sub + (SUB_W + s) * stride + j)) * c[s]);
          ACCUMULATE(hi[s], lo[s], d)
        }
#ifdef THAW_SURFACE
        const floatV area_j = vloadV(0, AS + j);
        const intV surface_j = in & (area_j > 0.0f);
        if (area_i > 0.0f) {
          /* i on the surface takes from the carriers around it (itself among them) ... */
          const floatV wgt = select((floatV)(0.0f), mj * w_shape(qr), in & (mj > 0.0f));
          /* ... and exchanges along the surface with the surface particles, on their points on it. */
          SURFACE_PAIR(j)
          /* Renormalised by the pair's mean moment 2 / (MOM_i + MOM_j), symmetric: where the areas sample
           * the surface unevenly (a lattice sphere's jagged outer layer), the plain sum misses the Laplacian
           * by the moment's shortfall (measured on surface-diffusion: 31-38 % too slow without it). */
          const floatV mom_j = vloadV(0, MOM + j);
          const floatV glide_pair = select(
              (floatV)(0.0f),
              (area_i * area_j) * (grad_shape(sqrt(p2) * inv_H) * p2 / (p2 + eta2)) * (2.0f / (mom_i + mom_j)),
              surface_j & (p2 < H2) & (mom_i + mom_j > 0.0f));
          for (int s = 0; s < THAW_NSUB; ++s) {
            if (!((P.surface >> s) & 1u)) continue;
            const floatV w_j = vloadV(0, sub + (SUB_W + s) * stride + j);
            const floatV taken = ADSORBED(area_i, nrm_i, gi[s], wgt, w_j, s);
            ACCUMULATE(shi[s], slo[s], taken)
            const floatV glided = glide_pair * ((gi[s] - vloadV(0, sub + (SUB_G + s) * stride + j)) * glide[s]);
            ACCUMULATE(shi[s], slo[s], glided)
          }
        }
        /* i as a carrier gives to the surface particles around it (itself among them, when on the surface). */
        if (any(surface_j)) {
          const floatV wgt = select((floatV)(0.0f), mi * w_shape(qr), surface_j);
          const floatV nrm_j = vloadV(0, NRM + j);
          for (int s = 0; s < THAW_NSUB; ++s) {
            if (!((P.surface >> s) & 1u)) continue;
            const floatV g_j = vloadV(0, sub + (SUB_G + s) * stride + j);
            const floatV given = -ADSORBED(area_j, nrm_j, g_j, wgt, wi[s], s);
            ACCUMULATE(hi[s], lo[s], given)
          }
        }
#endif
      }
#ifdef THAW_REJECT
      /* Ice gives to water: the giver's amount per weight times the pair's weight, computed alike on both
       * sides (a boundary particle that only holds deposits, M 0, neither gives nor takes). */
      const intV handed = in & (giving ? (mj > 0.0f) : (mj < 0.0f)) & (intV)(mi != 0.0f ? -1 : 0);
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
#ifdef THAW_DEPOSIT
  /* The exchange with solids and ice, in a walk of its own for the particles next to them: in the walk above
   * its branches, though never taken, slowed every carrier's walk by a third on pocl. */
  if (near_static || f_i > 0.0f) {
    FOR_EACH_HEAT_RANGE(g, cell_start, cell, jb, je) {
      for (uint j = jb; j < je; j += THAW_VW) {
        DIFFUSE_LANES(j)
        /* i a carrier gives to the wet boundary particles around it (not itself: partly melted ice is both) ... */
        if (near_static) {
          const floatV f_j = vloadV(0, F + j);
          const intV wet_j = in & (f_j > 0.0f) & (r2 > 0.0f);
          if (any(wet_j)) {
            const floatV wgt = select((floatV)(0.0f), mi * w_shape(qr), wet_j);
            for (int s = 0; s < THAW_NSUB; ++s) {
              if (!((P.coating >> s) & 1u)) continue;
              const float wd = by[s] < THAW_NSUB ? wi[by[s]] : 0.0f;
              const floatV g_j = vloadV(0, sub + (SUB_R + s) * stride + j);
              const floatV given = -DEPOSITED(f_j, wgt, wi[s], wd, g_j, s);
              ACCUMULATE(hi[s], lo[s], given)
            }
          }
        }
        /* ... and i a wet boundary particle takes from the carriers around it. */
        if (f_i > 0.0f) {
          const intV carrier = in & (mj > 0.0f) & (r2 > 0.0f);
          if (any(carrier)) {
            const floatV wgt = select((floatV)(0.0f), mj * w_shape(qr), carrier);
            for (int s = 0; s < THAW_NSUB; ++s) {
              if (!((P.coating >> s) & 1u)) continue;
              const floatV wc = vloadV(0, sub + (SUB_W + s) * stride + j);
              const floatV wd = by[s] < THAW_NSUB ? vloadV(0, sub + (SUB_W + by[s]) * stride + j) : (floatV)(0.0f);
              const floatV taken = DEPOSITED(f_i, wgt, wc, wd, ri[s], s);
              ACCUMULATE(dhi[s], dlo[s], taken)
            }
          }
        }
      }
    }
  }
#endif
  global float2* q[4] = {q0, q1, q2, q3};
  if (mi != 0.0f)
    for (int s = 0; s < THAW_NSUB; ++s) add_lanes(q[s], i, hi[s], lo[s]);
#ifdef THAW_DEPOSIT
  global float2* dep[4] = {d0, d1, d2, d3};
  if (f_i > 0.0f)
    for (int s = 0; s < THAW_NSUB; ++s)
      if ((P.coating >> s) & 1u) add_lanes(dep[s], i, dhi[s], dlo[s]);
#endif
#ifdef THAW_SURFACE
  global float2* sa[4] = {s0, s1, s2, s3};
  if (area_i > 0.0f)
    for (int s = 0; s < THAW_NSUB; ++s)
      if ((P.surface >> s) & 1u) add_lanes(sa[s], i, shi[s], slo[s]);
#endif
#ifdef THAW_TENSION_LAW
  /* Each water particle's surface tension over the scene's, from the surface excess it now holds: each
   * substance with a law lowers it by Szyszkowski's E ln(1 - Gamma / Gamma_max) (the equation of state of a
   * Langmuir monolayer; theta is kept below 0.999, where it is already 6.9 E down) or linearly by
   * E Gamma / Gamma_max, the sum floored at 0. 1 off the surface. The tension pass reads it next step. */
  if (mi > 0.0f) {
    const float drop[4] = {P.tension0, P.tension1, P.tension2, P.tension3};
    float ratio = 1.0f;
    if (area_i > 0.0f)
      for (int s = 0; s < THAW_NSUB; ++s) {
        const uint law = (P.tension_law >> (2 * s)) & 3u;
        if (law == 0u) continue;
        const float2 held = sa[s][i];
        const float theta = clamp((held.x + held.y) / area_i * inv_capacity[s], 0.0f, 0.999f);
        ratio += law == 1u ? drop[s] * log(1.0f - theta) : -drop[s] * theta;
      }
    tension_ratio[i] = fmax(ratio, 0.0f);
  }
#endif
}
