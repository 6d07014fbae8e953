/* Divergence-free SPH (Bender & Koschier 2015, "Divergence-Free Smoothed Particle Hydrodynamics", and
 * 2017, "Divergence-Free SPH for Incompressible and Viscous Fluids", Algorithms 1-3): two Jacobi solves
 * per step on the fluid's velocities, one that makes the velocity field divergence-free (Dρ/Dt = 0) and
 * one that brings the predicted density back to the rest density. sim/dfsph_stage.cpp drives them.
 *
 * Notation (2017 eqs 9-12): the pressure force of pair ij is -m_i m_j (κ_i/ρ_i + κ_j/ρ_j) ∇W_ij, so κ_i/ρ_i
 * plays p_i/ρ_i² (p_i = κ_i ρ_i). Boundary particles (static solids and ice, Akinci et al. 2012: mass Ψ_b)
 * take part with a pressure extrapolated from the fluid next to them in every sweep (dfsph_extrapolate,
 * Adami et al. 2012 eq 27), so a pair with a wall carries the full load, as two fluid particles would.
 * The 2017 paper's one-sided coupling (κ_b = 0) carries half of it: water sank 0.37 spacings into the
 * floor and walls of the floating case (against 0.14 with WCSPH, whose walls have their own pressure),
 * which put the water's mass level 0.7 spacings above its surface (WCSPH: 0.4), and the hydrostatic
 * tank's mean speed stayed at 1.7e-3 sqrt(gH). With the extrapolation: the water's first layer 0.498
 * spacings above the floor, the level by mass and by surface within 0.15-0.35 spacings, the tank at
 * 0.85e-3. The one-sided coupling stays selectable for comparison (solver.boundary_pressure akinci2012:
 * no extrapolation). With ∇W_ij = gf(r) x_ij and
 *   G_i = Σ_j m_j ∇W_ij (fluid and boundary),  S_i = m_i Σ_{j fluid} m_j |∇W_ij|²,
 * a change κ_i of one particle alone changes its density by -dt² κ_i/ρ_i (|G_i|² + S_i), hence
 *   α_i = ρ_i / (|G_i|² + S_i)                                           (2015 eq 10, mixed masses)
 *   density solve:    κ_i = (ρ*_i - ρ0) α_i / dt²,  ρ*_i = ρ_i + dt Σ_j m_j (v_i - v_j)·∇W_ij   (eq 12)
 *   divergence solve: κ_i = (Dρ/Dt)_i α_i / dt                                               (eq 14)
 *   velocity update:  v_i -= dt Σ_j m_j (κ_i/ρ_i + κ_j/ρ_j) ∇W_ij                             (eq 9)
 * (the α of a fluid particle leaves out the boundary's answer to its own κ: Jacobi's diagonal, relaxed).
 * Only compression is corrected (ρ* and Dρ/Dt clamped at zero error from below): a free surface is not
 * pulled together. The divergence solve leaves particles with fewer than min_neighbours neighbours alone
 * (their density deficit is the surface's, not a flow's), as SPlisHSPlasH's implementation does.
 *
 * α is computed in the density pass's visit (density.cl, built with THAW_DFSPH), which saves a sweep.
 * Per-particle columns (blocks of `stride` floats in `col`, dfsph_columns.h; read on SIMD lanes like the
 * reorder's soa):
 *   FM    m_j for fluid particles, 0 for boundary ones
 *   KR    κ_j / ρ_j of the current iteration (boundary particles: extrapolated, dfsph_extrapolate)
 *   AD    α_j for the density solve, AV α_j for the divergence solve (0 where it is not solved); for a
 *         boundary particle AD is -1 when fluid is within its support (it is extrapolated to), else 0.
 *         Negative, so that ice melting between alpha and the density solve (the heat stage runs
 *         between them) is solved with α 0 that step: read as α 1 it took κ 10⁷ times too large and
 *         blew up the first meltwater of ice-on-plate
 *   ERR   this iteration's error: ρ* - ρ0 or Dρ/Dt (≥ 0; 0 for boundary particles)
 * and the saved field `kappa` (sim/dfsph_stage.cpp): the step's accumulated (Σ κ dt², Σ κ dt) of the two
 * solves, dt-free, which warm-start the next step's density solve (2017 §4.3; its divergence solve too
 * with solver.divergence_warm_start) and make a resumed run bitwise the same.
 *
 * Fluids of several rest densities (THAW_MULTIPHASE: air beside water, 1:830): the mass-weighted sums
 * above read a water particle next to air as under-dense and the air beside it as hundreds of times
 * over-dense. Multiphase builds use the number-density form of Hu & Adams 2006 (also Solenthaler &
 * Pajarola 2008) with rest volumes V = m / ρ0 (column VOL): each particle's constraint is its own
 * r_i = ρ_i / ρ0_i = Σ_j V_j W_ij = 1, whatever its neighbours weigh. The pressure of a pair is Hu & Adams
 * 2006's inter-particle pressure, weighted by the other's density, 2 p_ij = c_ij π_i + (2 - c_ij) π_j with
 * c_ij = 2 ρ0_j / (ρ0_i + ρ0_j) (π_i + π_j between fluids of one density; solver.multiphase
 * domaradzki_martyn, THAW_MP_SYMMETRIC, keeps the plain sum), and F_ij = -V_i V_j 2 p_ij ∇W_ij, so
 *   a_i = -(1/ρ0_i) Σ_j V_j 2 p_ij ∇W_ij,  D r_i/Dt = Σ_j V_j (v_i - v_j)·∇W_ij,
 *   α_i = 1 / (Gc_i·G_i/ρ0_i + V_i S_i),  G_i = Σ_j V_j ∇W_ij,  Gc_i = Σ_j c_ij V_j ∇W_ij,
 *   S_i = Σ_{j fluid} c_ij V_j/ρ0_j |∇W_ij|²  (density.cl),
 *   density solve π_i = (r*_i - 1)⁺ α_i / dt², divergence solve π_i = (D r/Dt)⁺_i α_i / dt.
 * KR then holds the pressure π itself, the errors are fractions (of each particle's own ρ0), FM holds
 * V/ρ0 for fluid particles, and `kappa` accumulates π dt² and π dt. THAW_MP_SPLIT (a rest density
 * between the fluids') tells the light fluid from the heavy one for the walls (dfsph_extrapolate,
 * dfsph_correct). The weighted system is not symmetric and Jacobi is not sure to converge on it: see
 * docs/VALIDATION-RESULTS.md (air-water) for where it holds. */

/* Relaxed Jacobi (solver.pressure_relaxation, as IISPH's omega = 0.5, Ihmsen et al. 2014): each sweep
 * applies omega of the kappa that would zero a particle's own error. Unrelaxed (omega = 1), neighbours
 * that all correct the same compression at once overshoot and leave the water under-dense at its surface
 * (docs/ARCHITECTURE.md, Numerics, has the floating case's figures). */
#ifndef THAW_OMEGA
#define THAW_OMEGA 0.5f
#endif
#ifndef THAW_DFSPH_LATTICE
#define THAW_DFSPH_LATTICE 1.0f
#endif

/* FM: who is fluid, as the lanes of the other passes (and the density pass's alpha) read it; run after the
 * grid's sort, before the density pass. */
#ifdef THAW_IDEAL_GAS
/* Eq 7's rest density of particle i at its temperature (theta > 0: ideal-gas air; fluid_params.h), before
 * the closed domain's pressure factor (dfsph_gas_volume). */
float ideal_gas_rest_density(global const MaterialFlow* flow, const uchar m, const float2 h) {
  const float T = (h.x + h.y) * flow[m].inv_specific_heat;
  return flow[m].rest_density * (1.0f + flow[m].theta * flow[m].reference_temperature) /
         fmax(1.0f + flow[m].theta * T, 0.1f);
}

/* Per tile: the rest volume sum_i m_i / rho0(T_i) of the ideal-gas air at the room's pressure, and its
 * particle count (deterministic, unlike atomics); sim/dfsph_stage.cpp makes the closed domain's pressure
 * factor of it. */
kernel void dfsph_gas_volume(global const float4* pos, global const uchar* material, global const MaterialFlow* flow,
                             global const float2* enthalpy, global float2* sums, const uint n, const uint tile) {
  const uint t = get_global_id(0);
  if (t >= (n + tile - 1) / tile) return;
  const uint b = t * tile, e = min(b + tile, n);
  float volume = 0.0f, count = 0.0f;
  for (uint i = b; i < e; ++i) {
    if (!(flow[material[i]].theta > 0.0f)) continue;
    volume += pos[i].w / ideal_gas_rest_density(flow, material[i], enthalpy[i]);
    count += 1.0f;
  }
  sums[t] = (float2)(volume, count);
}
#endif

kernel void dfsph_columns(global const float4* pos, global const uchar* phase, global const uchar* material,
                          global const MaterialFlow* flow, global float* col, const uint stride, const uint n
#ifdef THAW_IDEAL_GAS
                          ,
                          global const float2* enthalpy, const float gas_volume_factor
#endif
) {
  const uint i = get_global_id(0);
  if (i >= n) return;
#ifdef THAW_MULTIPHASE
  float rho0 = flow[material[i]].rest_density;
#ifdef THAW_IDEAL_GAS
  /* Domaradzki & Martyn eq 7, rho0(T) = rho0(0 °C) / (1 + theta T), with the material's density that at
   * T0 (fluid_params.h; theta 0 for every material but ideal-gas air). The constraint Σ V_j W_ij = 1 then
   * makes room for warm air's larger rest volume (the expansion Boussinesq leaves out), and the pressure
   * moves it by 1/rho0_i (dfsph_correct: its inertia); its weight less the reference air's is the forces
   * pass's (fluid_stage.cpp). In a closed domain every volume is scaled by gas_volume_factor, the room's
   * pressure over the domain's (dfsph_gas_volume; 1 where a side is open). Written here, after the sort,
   * so every pass of the step reads one V. */
  if (flow[material[i]].theta > 0.0f)
    rho0 = ideal_gas_rest_density(flow, material[i], enthalpy[i]) / gas_volume_factor;
#endif
  const float v = pos[i].w / rho0;
  col[COL_VOL * stride + i] = v;
  col[COL_FM * stride + i] = THAW_IS_STATIC(phase[i]) ? 0.0f : v / rho0;
#else
  col[COL_FM * stride + i] = THAW_IS_STATIC(phase[i]) ? 0.0f : pos[i].w;
#endif
  col[COL_KR * stride + i] = 0.0f;
}

/* Σ_j m_j (v_i - v_j)·∇W_ij over every neighbour (boundary particles move with their body or not at all).
 * Multiphase builds: Σ_j V_j (v_i - v_j)·∇W_ij, and with `heavy` (a water particle) over its heavy and
 * boundary neighbours only; its density (COL_RHO, from the density pass) likewise leaves its light (air)
 * neighbours' share out: water's constraint leaves the air out, as at a free surface. Counted in (the
 * number-density form's own choice), air pressed against water raised the water's density, whose pressure
 * moves only water (the pair weight c_ij is 2 rho0_air / (rho0_w + rho0_air) on it at the interface): a
 * 1.2 cm drop in an 8 m/s jet flung its surface particles off at 6 m/s within a few milliseconds, and the
 * jet lifted free ice cubes out of a glass of water. The air still counts the water in its own constraint,
 * and its pressure pushes the water at the interface (dfsph_correct). */
float density_rate(const float4 pi, const float3 vi, global const float* soa, global const float* col,
                   global const uint* cell_start, const Grid g, const float H, const uint stride, const int heavy) {
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H, inv_H = 1.0f / H;
  const Positions xs = soa_positions(soa, stride);
  global const float* VX = soa + 4 * stride;
  global const float* VY = soa + 5 * stride;
  global const float* VZ = soa + 6 * stride;
  floatV acc = (floatV)(0.0f);
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair q = pair_lanes(xs, pr, j, je, H2);
      const floatV vd = (vi.x - vloadV(0, VX + j)) * q.dx + (vi.y - vloadV(0, VY + j)) * q.dy +
                        (vi.z - vloadV(0, VZ + j)) * q.dz;
#ifdef THAW_MULTIPHASE
      const floatV vj = vloadV(0, col + COL_VOL * stride + j);
      intV skip = (intV)(0);
      if (heavy) { /* the air's rows (most of them) read no more than one fluid's */
        const floatV fmj = vloadV(0, col + COL_FM * stride + j);
        skip = (fmj > 0.0f) & (fmj * THAW_MP_SPLIT > vj); /* rho0_j = V_j / FM_j < split */
      }
      acc += select((floatV)(0.0f), vj * grad_shape(sqrt(q.r2) * inv_H) * vd, q.in & ~skip);
#else
      acc += select((floatV)(0.0f), vloadV(0, xs.m + j) * grad_shape(sqrt(q.r2) * inv_H) * vd, q.in);
#endif
    }
  }
  return THAW_SIGMA(H) * inv_H * inv_H * lanes_sum(acc);
}

/* One Jacobi sweep's first half: each fluid particle's error and κ, from the velocities as they are.
 * density_mode 1: the density solve (dt this step's); 0: the divergence solve. */
kernel void dfsph_error(global const float4* pos, global const float* soa, global const float* density,
                        global const uchar* phase, global const uchar* material, global const MaterialFlow* flow,
                        global float* col, global const uint* cell_start, const Grid g, const float H,
                        const float dt, const int density_mode, const uint stride, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  if (THAW_IS_STATIC(phase[i])) return; /* their KR and ERR stay 0 (dfsph_columns, density.cl) */
  const float4 pi = pos[i];
  const float3 vi = (float3)(soa[4 * stride + i], soa[5 * stride + i], soa[6 * stride + i]);
#ifdef THAW_MULTIPHASE
  const int heavy = pi.w > THAW_MP_SPLIT * col[COL_VOL * stride + i];
  const float rate = density_rate(pi, vi, soa, col, cell_start, g, H, stride, heavy);
  const float rho = col[COL_RHO * stride + i]; /* water's without the air's share (density_rate) */
#else
  const float rate = density_rate(pi, vi, soa, col, cell_start, g, H, stride, 0);
  const float rho = density[i];
#endif
  float err, k;
  if (density_mode) {
    /* The density a resting lattice of this water sums to (THAW_DFSPH_LATTICE, from sph::lattice_sum in
     * sph_kernel.h), so water sampled on the scene's lattice starts at rest, one lattice volume per
     * particle. Against rho0 itself, Wendland C2 over 3 spacings (lattice sum 1.003) made the density
     * solve expand all water by 0.3 % in its first step: 70 mm of warm water in ice-bunny rose at
     * 0.17 m/s on average, and after 0.1 s its top 5 spacings were still under-dense (717-881 kg/m^3;
     * now 895 in the top one, then 1002-1003), and Iwasaki's neighbour count gave the air 6,875 exposed
     * faces of water (now 994; WCSPH 963), so the water lost 8x the heat to the air that WCSPH's did. */
#ifdef THAW_MULTIPHASE
    /* Fractions of the particle's own rest density (the header), compression only as in one fluid
     * (Domaradzki & Martyn's eq 6 clamps the interface so too). Correcting expansion as well where the
     * neighbourhood is full blew the air-over-water tank up within 50 steps: the Jacobi sweeps then
     * pull the water's top layer into the air and back. In ideal-gas air alone (the cavity, Ra 1e3, res
     * 20) it diverged in the first step, the mean error doubling every sweep: relaxed Jacobi with this
     * diagonal holds only while the clamp cuts its overshoot off. */
    err = fmax(rho * col[COL_VOL * stride + i] / pi.w + dt * rate - THAW_DFSPH_LATTICE, 0.0f); /* rho / rho0_i */
#else
    const float rho0 = flow[material[i]].rest_density * THAW_DFSPH_LATTICE;
    err = fmax(rho + dt * rate - rho0, 0.0f);
#endif
    k = err * fmax(col[COL_AD * stride + i], 0.0f) / (dt * dt); /* a boundary's flag, if it melted: 0 */
  } else {
    const float a = col[COL_AV * stride + i];
    err = a > 0.0f ? fmax(rate, 0.0f) : 0.0f;
    k = err * a / dt;
  }
  k *= THAW_OMEGA; /* relaxed Jacobi */
#ifdef THAW_MULTIPHASE
  col[COL_KR * stride + i] = k; /* the pressure π */
#else
  col[COL_KR * stride + i] = k / rho;
#endif
  col[COL_ERR * stride + i] = err; /* ≥ 0: both solves correct compression only */
}

/* A boundary particle's KR from the fluid around it (Adami et al. 2012, eq 27, the wall's acceleration
 * left out): p_b = Σ_f m_f W_bf (p_f + ρ_f g·(x_b - x_f)) / Σ_f m_f W_bf, p_f = KR_f ρ_f², KR_b = p_b / ρ_b²
 * with ρ_b the density the fluid's equation of state gives p_b (Adami's eq 28), which for an
 * incompressible fluid is its rest density ρ0, not the boundary particle's summed density, which runs
 * below ρ0 where the boundary's own neighbourhood is thin (a body's edges and waterline) and overloads
 * bodies there. The gravity term is a pressure, not an increment: it enters once a step, with the density
 * solve's warm start (`hydrostatic` 1), where the solve meets gravity; later sweeps extrapolate the
 * increments alone. It gives the boundary layer the pressure at its own depth rather than that of the
 * fluid a spacing below it. (docs/ARCHITECTURE.md, Numerics, has what each choice measured.) */
kernel void dfsph_extrapolate(global const float4* pos, global const float* soa, global const float* density,
                              global const uchar* phase, global float* col, global const uint* cell_start,
                              const Grid g, const float H, const float4 gravity, const int hydrostatic,
                              const float rest_density, const uint stride, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  if (!THAW_IS_STATIC(phase[i]) || col[COL_AD * stride + i] >= 0.0f) return; /* flagged -1 by density.cl */
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H, inv_H = 1.0f / H;
  const Positions xs = soa_positions(soa, stride);
  global const float* FM = col + COL_FM * stride;
  global const float* KR = col + COL_KR * stride;
  floatV num = (floatV)(0.0f), den = (floatV)(0.0f);
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair q = pair_lanes(xs, pr, j, je, H2);
#ifdef THAW_MULTIPHASE
      /* Shepard weights V_f W_bf over the heavy fluid only, KR the pressure itself: the light fluid
       * (air) takes its own pressure for a wall's (dfsph_correct), and the water's wall pressure is not
       * lowered by the air's beside it. rho0_j = V_j / FM_j. */
      const floatV vj = vloadV(0, col + COL_VOL * stride + j), fmj = vloadV(0, FM + j);
      const floatV w = select((floatV)(0.0f), vj, (fmj > 0.0f) & (fmj * THAW_MP_SPLIT <= vj)) *
                       w_shape(sqrt(q.r2) * inv_H);
      const floatV rho_j = vloadV(0, density + j);
      floatV p = vloadV(0, KR + j);
      if (hydrostatic) p += rho_j * (gravity.x * q.dx + gravity.y * q.dy + gravity.z * q.dz);
      num += select((floatV)(0.0f), w * p, q.in);
      den += select((floatV)(0.0f), w, q.in);
#else
      const floatV w = vloadV(0, FM + j) * w_shape(sqrt(q.r2) * inv_H); /* 0 for boundary neighbours */
      const floatV rho_j = vloadV(0, density + j);
      floatV p = vloadV(0, KR + j) * rho_j * rho_j;
      if (hydrostatic) p += rho_j * (gravity.x * q.dx + gravity.y * q.dy + gravity.z * q.dz);
      num += select((floatV)(0.0f), w * p, q.in);
      den += select((floatV)(0.0f), w, q.in);
#endif
    }
  }
  const float d = lanes_sum(den);
  /* No suction: a wall above the water (the gravity term below zero) pushes nothing. */
#ifdef THAW_MULTIPHASE
  col[COL_KR * stride + i] = d > 0.0f ? fmax(lanes_sum(num) / d, 0.0f) : 0.0f;
#else
  col[COL_KR * stride + i] = d > 0.0f ? fmax(lanes_sum(num) / d, 0.0f) / (rest_density * rest_density) : 0.0f;
#endif
}

/* The warm start (2017 §4.3): `share` of last step's accumulated κ of this solve as this iteration's KR
 * (sim/dfsph_stage.cpp says which share and when); the accumulator starts again from zero, and
 * dfsph_correct adds back what it applies (share 0: nothing is applied, the solve starts from zero). */
kernel void dfsph_warm(global const float* density, global const uchar* phase, global float* col,
                       global float2* kappa, const float dt, const int density_mode, const float share,
                       const uint stride, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  float2 acc = kappa[i];
  if (THAW_IS_STATIC(phase[i])) { /* extrapolated next (dfsph_extrapolate); it books what it applies */
    col[COL_KR * stride + i] = 0.0f;
    if (density_mode)
      acc.x = 0.0f;
    else
      acc.y = 0.0f;
    kappa[i] = acc;
    return;
  }
  const float k = share * (density_mode ? acc.x / (dt * dt) : acc.y / dt);
#ifdef THAW_MULTIPHASE
  col[COL_KR * stride + i] = k; /* π */
#else
  col[COL_KR * stride + i] = k / density[i];
#endif
  if (density_mode)
    acc.x = 0.0f;
  else
    acc.y = 0.0f;
  kappa[i] = acc;
}

/* Adds the κ a sweep applied to particle i's accumulator: κ dt² (density_mode) or κ dt. */
void book_kappa(global float2* kappa, const uint i, const float k, const float dt, const int density_mode) {
  float2 acc = kappa[i];
  if (density_mode)
    acc.x += k * dt * dt;
  else
    acc.y += k * dt;
  kappa[i] = acc;
}

/* The second half: v_i -= dt Σ_j m_j (KR_i + KR_j) ∇W_ij, written to vel and to the soa copy the lanes
 * read. Boundary neighbours enter with their extrapolated KR and their Ψ. The κ applied is booked
 * (book_kappa), by boundary particles too. */
kernel void dfsph_correct(global float4* vel, global float* soa, global const uchar* phase, global const float* col,
                          global const float4* pos, global const float* density, global float2* kappa,
                          global const uint* cell_start, const Grid g, const float H, const float dt,
                          const int density_mode, const uint stride, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  global const float* KR = col + COL_KR * stride;
  const float kri = KR[i];
  if (THAW_IS_STATIC(phase[i])) {
    /* A boundary particle does not move: it books the κ its fluid neighbours applied with it (their
     * pressure force from it; rigid ice takes the reaction through dfsph_pressure's state). */
#ifdef THAW_MULTIPHASE
    book_kappa(kappa, i, kri, dt, density_mode);
#else
    book_kappa(kappa, i, kri * density[i], dt, density_mode);
#endif
    return;
  }
  const float4 pi = pos[i];
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H, inv_H = 1.0f / H;
  const Positions xs = soa_positions(soa, stride);
#ifdef THAW_MULTIPHASE
  global const float* FM = col + COL_FM * stride;
  const float rho0_i = pi.w / col[COL_VOL * stride + i];
  /* A boundary neighbour's pressure: the light fluid (air) takes its own for the wall's (pressure
   * mirroring, p_b = p_i, the full load; not boundary_pressure akinci2012's one-sided half), since the
   * wall's extrapolated pressure is the water's beside it and blows the air off the wall at the
   * interface; the heavy fluid takes the wall's (dfsph_extrapolate). density.cl counts the mirror twice
   * in the light fluid's alpha. */
  const int light_i = rho0_i < THAW_MP_SPLIT;
#endif
  floatV ax = (floatV)(0.0f), ay = (floatV)(0.0f), az = (floatV)(0.0f);
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      const Pair q = pair_lanes(xs, pr, j, je, H2);
#ifdef THAW_MULTIPHASE
      /* The pair's pressure weighted by the other's rest density (Hu & Adams 2006's inter-particle pressure):
       * 2 p_ij = c_ij pi_i + (2 - c_ij) pi_j, c_ij = 2 rho0_j / (rho0_i + rho0_j); between fluids of one
       * density pi_i + pi_j, and at air beside water almost 2 pi_air on both sides, so the water's pressure
       * does not push the light air and the interface holds one pressure. Boundary neighbours: c = 1. */
      const floatV vj = vloadV(0, col + COL_VOL * stride + j), fmj = vloadV(0, FM + j);
#ifdef THAW_MP_SYMMETRIC /* solver.multiphase domaradzki_martyn: the pair's mean pressure */
      const floatV cw = (floatV)(1.0f);
#else
      const floatV cw = select((floatV)(1.0f), 2.0f * vj / (rho0_i * fmj + vj), fmj > 0.0f);
#endif
      const floatV krj = vloadV(0, KR + j);
      const floatV pj = light_i ? select((floatV)(kri), krj, fmj > 0.0f) : krj;
      const floatV t = vj * (cw * kri + (2.0f - cw) * pj) * grad_shape(sqrt(q.r2) * inv_H);
#else
      const floatV t = vloadV(0, xs.m + j) * (kri + vloadV(0, KR + j)) * grad_shape(sqrt(q.r2) * inv_H);
#endif
      ax += select((floatV)(0.0f), t * q.dx, q.in);
      ay += select((floatV)(0.0f), t * q.dy, q.in);
      az += select((floatV)(0.0f), t * q.dz, q.in);
    }
  }
#ifdef THAW_MULTIPHASE
  const float mass_scale = col[COL_VOL * stride + i] / pi.w; /* 1 / rho0_i */
  const float kb = kri;
#else
  const float mass_scale = 1.0f;
  const float kb = kri * density[i];
#endif
  const float3 dv = -dt * mass_scale * THAW_SIGMA(H) * inv_H * inv_H *
                    (float3)(lanes_sum(ax), lanes_sum(ay), lanes_sum(az));
  const float3 v = vel[i].xyz + dv;
  vel[i] = (float4)(v, 0.0f);
  soa[4 * stride + i] = v.x;
  soa[5 * stride + i] = v.y;
  soa[6 * stride + i] = v.z;
  book_kappa(kappa, i, kb, dt, density_mode);
}

/* Per tile: the sum of the errors over fluid particles, and their count (deterministic, unlike atomics). */
kernel void dfsph_error_sum(global const float* col, global const uchar* phase, global float2* sums,
                            const uint stride, const uint n, const uint tile) {
  const uint t = get_global_id(0);
  if (t >= (n + tile - 1) / tile) return;
  const uint b = t * tile, e = min(b + tile, n);
  float sum = 0.0f, count = 0.0f;
  for (uint i = b; i < e; ++i) {
    if (THAW_IS_STATIC(phase[i])) continue;
    sum += col[COL_ERR * stride + i];
    count += 1.0f;
  }
  sums[t] = (float2)(sum, count);
}

/* v += dt a (the non-pressure forces), before the density solve; soa too. */
kernel void dfsph_predict(global float4* vel, global float* soa, global const float4* accel, global const uchar* phase,
                          const float dt, const float damping_factor, const uint stride, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n || THAW_IS_STATIC(phase[i])) return;
  const float3 v = (vel[i].xyz + accel[i].xyz * dt) * damping_factor;
  vel[i] = (float4)(v, 0.0f);
  soa[4 * stride + i] = v.x;
  soa[5 * stride + i] = v.y;
  soa[6 * stride + i] = v.z;
}

/* x += dt v with the corrected velocities. */
kernel void dfsph_drift(global float4* pos, global const float4* vel, global const uchar* phase, const float dt,
                        const uint n) {
  const uint i = get_global_id(0);
  if (i >= n || THAW_IS_STATIC(phase[i])) return;
  pos[i] = (float4)(pos[i].xyz + vel[i].xyz * dt, pos[i].w);
}

/* The step's pressure as the rest of the solver reads it (state = (ρ, p/ρ², is_boundary, p), as density.cl
 * writes it for WCSPH): the two solves' impulses over this step's dt, dp = (Σκ dt + Σκ dt² / dt) / (dt ρ),
 * so rigid ice (rigid.cl) takes exactly the reaction of what the fluid received from its particles
 * (a boundary particle's accumulated κ is what its neighbours applied with it). */
kernel void dfsph_pressure(global const float* density, global const uchar* phase, global const float2* kappa,
                           global float4* state, const float dt, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const float rho = density[i];
  const float2 acc = kappa[i];
#ifdef THAW_MULTIPHASE
  /* The accumulators hold π dt² and π dt: p = Σπ, and p / ρ² as WCSPH's state has it. */
  const float dp = dt > 0.0f ? (acc.y + acc.x / dt) / (dt * rho * rho) : 0.0f;
#else
  const float dp = dt > 0.0f ? (acc.y + acc.x / dt) / (dt * rho) : 0.0f;
#endif
  state[i] = (float4)(rho, dp, THAW_IS_STATIC(phase[i]) ? 1.0f : 0.0f, dp * rho * rho);
}
