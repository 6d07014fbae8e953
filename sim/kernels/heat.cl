/* Heat: conduction between all particles, the exposed surface's exchange with the ambient air and the
 * dryers, the tank walls' exchange with the outside, absorbed lamp photons, and the phase change that
 * follows from each particle's enthalpy (thermal_law.h). Built with thermal_law.h and dryer_model.h.
 *
 * Conduction is the pairwise form of Cleary & Monaghan (1999, eq. 9; Brookshaw 1985) with the harmonic
 * mean of the two conductivities, not the kernel Laplacian of Iwasaki et al. (2010) eq. 1, which is off by
 * 10-20 % in effective diffusivity on lattices and unstable on disordered particles (docs/VALIDATION-RESULTS.md, conduction):
 *   Q_i = 2 V_i sum_j V_j k_ij (T_i - T_j) (x_ij . grad W_ij) / (r_ij^2 + eta^2),
 *   k_ij = 2 k_i k_j / (k_i + k_j),
 * the heat flow into particle i [W]. Each pair's term is antisymmetric, so conduction conserves the total
 * enthalpy sum m_i h_i up to float rounding. */

/* Per particle: temperature, conductivity and volume, in the structure-of-arrays layout the neighbour
 * loop reads on lanes (thermal = T, k, V blocks of `stride` floats). Moving water takes its volume from
 * the summation density; static particles, and every particle when the flow is off, from rho0. */
/* THAW_MELT_SHIFT (substances that lower the melting point, sim/substance_stage.h): how far below its material's
 * melting point each particle melts and freezes [K], from the water it holds or, for ice, the water around it
 * (substance.cl); the law is thermal_law.h's thermal_temperature_lowered. */
#ifdef THAW_MELT_SHIFT
#define MELT_SHIFT(i) melt_shift[i]
#else
#define MELT_SHIFT(i) 0.0f
#endif

kernel void thermal_state(global const float4* pos, global const float* density, global const float2* enthalpy,
                          global const uchar* phase, global const uchar* material,
                          global const MaterialThermal* materials, global float* thermal, const HeatParams P,
                          global const float* melt_shift) {
  const uint i = get_global_id(0);
  const uint stride = P.stride, n = P.n, flow = P.flow;
  const float rho0 = P.rest_density;
  if (i >= n) return;
  const MaterialThermal m = materials[material[i]];
  const float2 e = enthalpy[i];
  const float h = e.x + e.y;
  const float rho = (flow && !THAW_IS_STATIC(phase[i])) ? density[i] : rho0;
#ifdef THAW_MELT_SHIFT
  const float d = m.latent > 0.0f ? MELT_SHIFT(i) : 0.0f;
  thermal[i] = thermal_temperature_lowered(h, m.latent, m.melt, m.c_solid, m.c_liquid, d);
  /* The front's conductivity (below) reads the liquid fraction as h / L: the same fraction under the
   * lowered law. */
  const float h_front = m.latent > 0.0f ? m.latent * thermal_liquid_fraction_lowered(h, m.latent, m.c_solid, m.c_liquid, d)
                                        : h;
#else
  thermal[i] = thermal_temperature(h, m.latent, m.melt, m.c_solid, m.c_liquid);
  const float h_front = h;
#endif
  /* A held particle is isothermal, as if it conducted without limit: the pair's harmonic mean then
   * tends to 2 k_j, the conductance of the neighbour's half of the path alone. With its own k instead,
   * a held wall took the resistance of a particle-wide layer (the front lagged about 0.4 spacings in
   * `thaw validate stefan`). 1e6 W/m/K is far above any real material and keeps the float sums finite. */
  thermal[stride + i] = (m.flags & THAW_MAT_HELD)
                            ? 1.0e6f
                            : thermal_conductivity(h_front, m.latent, m.k_solid, m.k_liquid, phase[i] == THAW_PHASE_ICE);
  thermal[2 * stride + i] = pos[i].w / rho;
}

#ifdef THAW_ADIABATIC
/* Adiabatic solids (materials' `adiabatic`): each particle takes the temperature and conductivity of the
 * fluid and ice around it, their Shepard average sum_j V_j W_ij X_j / sum_j V_j W_ij over non-solid
 * neighbours (as Adami et al. 2012 extrapolate a wall's pressure and velocity). Across the surface the
 * temperatures then nearly agree, so almost no heat crosses it (what does is booked as held: heat()),
 * while the fluid beside it sees a full neighbourhood at its own temperature, so it conducts along the
 * wall as in bulk: with conductivity 0 instead the particles within a kernel's reach of the floor and
 * ceiling of the cavity case conducted too little, and still air there read Nu 0.965 (res 20, Wendland
 * over 3 spacings) where a slab has 1. Runs after thermal_state, before heat; a particle with no such
 * neighbour conducts nothing (k 0). */
kernel void adiabatic_state(global const float4* pos, global const uchar* phase, global const uchar* material,
                            global const MaterialThermal* materials, global const float* soa,
                            global float* thermal, global const uint* cell_start, const Grid g,
                            const HeatParams P) {
  const uint i = get_global_id(0);
  if (i >= P.n || !(materials[material[i]].flags & THAW_MAT_ADIABATIC)) return;
  const uint stride = P.stride;
  const float H = P.support, H2 = H * H, inv_H = 1.0f / H;
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const Positions xs = soa_positions(soa, stride);
  /* thermal_state's blocks: each particle's T, k and V */
  global const float* TT = thermal;
  global const float* KK = thermal + stride;
  global const float* VV = thermal + 2 * stride;
  floatV st = (floatV)(0.0f), sk = (floatV)(0.0f), sw = (floatV)(0.0f);
  FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair o = pair_lanes_wrapped(xs, pi, period, j, je, H2);
      const intV ph = THAW_CAT(convert_int, THAW_VW)(THAW_CAT(vload, THAW_VW)(0, phase + j));
      const intV in = (THAW_LANE_IDS < (int)(je - j)) & (o.r2 < H2) & (ph != THAW_PHASE_SOLID);
      const floatV w = select((floatV)(0.0f), vloadV(0, VV + j) * w_shape(sqrt(o.r2) * inv_H), in);
      st += w * select((floatV)(0.0f), vloadV(0, TT + j), in);
      sk += w * select((floatV)(0.0f), vloadV(0, KK + j), in);
      sw += w;
    }
  }
  /* Its conductivity is stored negative: heat() pairs it with fluid and ice only, never with a solid (a
   * held wall beside it would otherwise heat it, and through it the count of held heat). */
  const float s = lanes_sum(sw);
  if (s > 0.0f) {
    thermal[i] = lanes_sum(st) / s;
    thermal[stride + i] = -lanes_sum(sk) / s;
  } else {
    thermal[stride + i] = 0.0f;
  }
}
#endif

/* Compensated add: (hi, lo) + d with the rounding error of hi + d kept in lo (Knuth's two-sum), so heat
 * increments far below one ulp of the enthalpy still add up. */
float2 add_compensated(float2 e, float d) {
  const float s = e.x + d;
  const float bp = s - e.x;
  const float err = (e.x - (s - bp)) + (d - bp);
  const float lo = e.y + err;
  const float hi = s + lo;
  return (float2)(hi, lo - (hi - s));
}

/* The area [m^2] of a particle's surface in contact with air (heat.exposed_area): the surface stage's areas
 * (sim/surface_stage.h), read from `area` with -DTHAW_SURFACE_AREA; otherwise Iwasaki et al. 2010 sec. 4's
 * count of the particles that cover it: dA = (6 - n_i) / 6 of the voxel's A = 6 dx^2, clamped at 0. */
float exposed_area_iwasaki2010(int neighbours, float face_area) {
  return face_area * (float)max(6 - neighbours, 0);
}

/* Source categories of the energy budget, blocks of `stride` floats in `budget` [J this step]. */
#define THAW_SRC_AMBIENT 0
#define THAW_SRC_LAMPS 1
#define THAW_SRC_DRYERS 2
#define THAW_SRC_WALLS 3
#define THAW_SRC_HELD 4
#define THAW_SRC_COUNT 5

/* One heat step of length dt_heat = time_scale * dt. exposed_r2: squared radius within which neighbours
 * cover a face (Iwasaki 2010: (6 - n_i) / 6 of the voxel's area A = 6 dx^2 is exposed); face_area = dx^2.
 * lamp_energy: each particle's absorbed photon energy this step [J], consumed (zeroed) here. */
kernel void heat(global float4* pos, global float4* vel, global float2* enthalpy, global uchar* phase,
                 global uchar* material, global const MaterialThermal* materials, global const float* soa,
                 global const float* thermal, global const uint* cell_start, const Grid g, const HeatParams P,
                 global const DryerJet* dryers, global float* lamp_energy, global float* budget,
                 global uint* phase_changed, global const float* area, global const float* melt_shift) {
  const float H = P.support, eta2 = P.eta2, exposed_r2 = P.exposed_r2, face_area = P.face_area;
  const float ambient_temperature = P.ambient_temperature, ambient_coefficient = P.ambient_coefficient;
  const float dt_heat = P.dt_heat;
  const uint stride = P.stride, n = P.n, ndryers = P.ndryers;
  const float4 period = (float4)(P.period_x, P.period_y, P.period_z, 0.0f);
  const uint i = get_global_id(0);
  if (i >= n) return;
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H;
  const float inv_H = 1.0f / H;
  const Positions xs = soa_positions(soa, stride);
  /* thermal_state's blocks: each particle's T, k and V */
  global const float* TT = thermal;
  global const float* KK = thermal + stride;
  global const float* VV = thermal + 2 * stride;
  const float Ti = TT[i];
#ifdef THAW_ADIABATIC
  /* Adiabatic particles (k < 0, adiabatic_state) pair with fluid and ice only. */
  const float ki = fabs(KK[i]);
  const int i_adiabatic = KK[i] < 0.0f, i_solid = phase[i] == THAW_PHASE_SOLID;
#else
  const float ki = KK[i];
#endif
  floatV acc = (floatV)(0.0f);
  intV covered = (intV)(0);
  FOR_EACH_HEAT_RANGE(g, cell_start, c, jb, je) {
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair o = pair_lanes_wrapped(xs, pi, period, j, je, H2);
      const intV lane = THAW_LANE_IDS < (int)(je - j);
#ifdef THAW_ADIABATIC
      const floatV kraw = vloadV(0, KK + j);
      const floatV kj = fabs(kraw);
      const intV solid_j = THAW_CAT(convert_int, THAW_VW)(THAW_CAT(vload, THAW_VW)(0, phase + j)) == THAW_PHASE_SOLID;
      const intV in =
          lane & (o.r2 < H2) & ~((i_adiabatic ? solid_j : (intV)(0)) | (i_solid ? (kraw < 0.0f) : (intV)(0)));
#else
      const intV in = lane & (o.r2 < H2);
      const floatV kj = vloadV(0, KK + j);
#endif
      /* Harmonic mean; two insulators (k = 0) exchange nothing. */
      const floatV kij = 2.0f * ki * kj / fmax(ki + kj, 1e-30f);
      const floatV term = vloadV(0, VV + j) * kij * (Ti - vloadV(0, TT + j)) *
                          grad_shape(sqrt(o.r2) * inv_H) * o.r2 / (o.r2 + eta2);
      acc += select((floatV)(0.0f), term, in);
#if (defined(THAW_AMBIENT) || defined(THAW_DRYERS)) && !defined(THAW_SURFACE_AREA)
      covered += select((intV)(0), (intV)(1), lane & (o.r2 < exposed_r2));
#endif
    }
  }
  /* x . grad W = sigma / H^2 grad_shape(q) r^2 (sph_lanes.h). */
  const float Vi = VV[i];
  const float q_conduction = 2.0f * Vi * THAW_SIGMA(H) * inv_H * inv_H * lanes_sum(acc);
#if (defined(THAW_AMBIENT) || defined(THAW_DRYERS)) && !defined(THAW_SURFACE_AREA)
  int neighbours = -1; /* the particle itself is in its own range */
  for (int l = 0; l < THAW_VW; ++l) neighbours += ((int*)&covered)[l];
#endif

  const uchar mi = material[i];
  const MaterialThermal m = materials[mi];
  /* Each source is compiled in only when the scene has it (Solver: THAW_AMBIENT with an ambient
   * coefficient above 0, THAW_DRYERS with dryers, THAW_WALL_HEAT with walls that exchange heat with the
   * outside, THAW_LAMPS with lamps), so a scene without them tests no flag per particle. */
  float q_ambient = 0.0f, q_dryers = 0.0f, q_walls = 0.0f;
#if defined(THAW_AMBIENT) || defined(THAW_DRYERS)
#ifdef THAW_SURFACE_AREA
  const float exposed = (m.flags & THAW_MAT_AIR_EXCHANGE) ? area[i] : 0.0f;
#else
  const float exposed = (m.flags & THAW_MAT_AIR_EXCHANGE) ? exposed_area_iwasaki2010(neighbours, face_area) : 0.0f;
#endif
  if (exposed > 0.0f) {
#ifdef THAW_AMBIENT
    q_ambient = ambient_coefficient * (ambient_temperature - Ti) * exposed;
#endif
#ifdef THAW_DRYERS
    for (uint d = 0; d < ndryers; ++d) {
      const float2 air = dryer_air(dryers[d], pi.x, pi.y, pi.z, ambient_temperature);
      q_dryers += air.x * (air.y - Ti) * exposed;
    }
#endif
  }
#endif
#ifdef THAW_WALL_HEAT
  if (m.flags & THAW_MAT_WALL_HEAT) q_walls = m.wall_coefficient * (m.wall_temperature - Ti);
#endif
#ifdef THAW_LAMPS
  const float e_lamps = lamp_energy[i];
  lamp_energy[i] = 0.0f;
#else
  const float e_lamps = 0.0f;
#endif

  const float mass = pi.w * m.thermal_mass_scale;
  float e_faces = 0.0f;
#ifdef THAW_AIR_FACES
  /* Domaradzki & Martyn sec. 7 (Fig. 6): air near the sides exchanges its temperature with the ambient,
   * as if the room went on past them: the exact step of dh/dt = (h_a - h) / tau. */
  if (mi == P.face_material) {
    const float d = fmin(fmin(fmin(pi.x - P.face_min_x, P.face_max_x - pi.x), fmin(pi.y - P.face_min_y, P.face_max_y - pi.y)),
                         fmin(pi.z - P.face_min_z, P.face_max_z - pi.z));
    if (d < P.face_depth) {
      const float2 h = enthalpy[i];
      e_faces = mass * ((P.face_enthalpy - h.x) - h.y) * P.face_fraction;
    }
  }
#endif
  const float e_ambient = q_ambient * dt_heat + e_faces, e_dryers = q_dryers * dt_heat, e_walls = q_walls * dt_heat;
  const float e_total = (q_conduction + q_ambient + q_dryers + q_walls) * dt_heat + e_lamps + e_faces;
  float2 e = add_compensated(enthalpy[i], e_total / mass);
  float e_held = 0.0f;
#ifdef THAW_ADIABATIC
  if (m.flags & THAW_MAT_ADIABATIC) {
    /* An ideal insulator keeps its enthalpy: what its mirrored temperature exchanged is booked as held. */
    e_held = -e_total;
    e = enthalpy[i];
  }
#endif
  if (m.flags & THAW_MAT_HELD) {
    /* A thermostat: whatever heat the particle gained or lost, it is put back at its temperature. */
    e_held = mass * ((m.held_enthalpy - e.x) - e.y);
    e = (float2)(m.held_enthalpy, 0.0f);
  }
  enthalpy[i] = e;

  /* Phase change once the latent heat is complete (Iwasaki 2010 sec. 4): the particle keeps its enthalpy
   * and its physical mass; its SPH mass follows its new material's scale. */
  const float h = e.x + e.y;
  const uchar ph = phase[i];
  int to = -1;
  const float shift = MELT_SHIFT(i);
  if ((m.flags & THAW_MAT_MELTS) && ph == THAW_PHASE_ICE && h >= thermal_liquid_limit(m.latent, m.c_liquid, shift))
    to = THAW_PHASE_WATER;
  if ((m.flags & THAW_MAT_FREEZES) && ph == THAW_PHASE_WATER && h <= thermal_solid_limit(m.c_solid, shift))
    to = THAW_PHASE_ICE;
  if (to >= 0) {
    const MaterialThermal other = materials[m.partner];
    phase[i] = (uchar)to;
    material[i] = (uchar)m.partner;
    pos[i] = (float4)(pi.xyz, mass / other.thermal_mass_scale);
    /* Melted ice flows on with the velocity its body gave it; frozen water stands still until a body
     * adopts it (sim/rigid_ice.h). */
    if (to == THAW_PHASE_ICE) vel[i] = (float4)(0.0f);
    /* Every work-item that writes stores the same value: no atomic needed. */
    *phase_changed = 1u;
  }

  budget[THAW_SRC_AMBIENT * stride + i] = e_ambient;
  budget[THAW_SRC_LAMPS * stride + i] = e_lamps;
  budget[THAW_SRC_DRYERS * stride + i] = e_dryers;
  budget[THAW_SRC_WALLS * stride + i] = e_walls;
  budget[THAW_SRC_HELD * stride + i] = e_held;
}

/* Turns one lamp's photon hits into energy: lamp_energy[i] += hits[i] * photon_energy; hits cleared. */
kernel void absorb_photons(global uint* hits, global float* lamp_energy, const float photon_energy, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uint k = hits[i];
  if (k) {
    lamp_energy[i] += (float)k * photon_energy;
    hits[i] = 0;
  }
}

/* Per-tile sums of the budget's categories (compensated, walked in order: deterministic), and the first
 * particle whose enthalpy is not finite (~0 if none). out = THAW_SRC_COUNT floats per tile. */
kernel void heat_budget(global const float* budget, global const float2* enthalpy, const uint stride,
                        global float* out, global uint* bad, const uint n, const uint tile) {
  const uint t = get_global_id(0);
  const uint b = t * tile;
  if (b >= n) return;
  const uint e = min(n, b + tile);
  uint first_bad = 0xffffffffu;
  for (uint i = b; i < e; ++i) {
    const float2 h = enthalpy[i];
    if (!isfinite(h.x + h.y)) {
      first_bad = i;
      break;
    }
  }
  bad[t] = first_bad;
  for (int k = 0; k < THAW_SRC_COUNT; ++k) {
    float sum = 0.0f, comp = 0.0f;
    for (uint i = b; i < e; ++i) {
      const float y = budget[k * stride + i] - comp;
      const float s = sum + y;
      comp = (s - sum) - y;
      sum = s;
    }
    out[t * THAW_SRC_COUNT + k] = sum;
  }
}
