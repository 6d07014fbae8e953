/* Summation density rho_i = sum_j m_j W_ij over fluid and boundary neighbours (boundary m_j = Psi_j,
 * Akinci 2012 eq. 6), then the equation of state; boundary particles too, which gives the walls the
 * pressure the fluid presses on them with (see forces.cl). state_i = (rho, p / rho^2, is_boundary, p).
 * Candidates are read THAW_VW at a time (SIMD lanes: grid_common.h) from the structure-of-arrays copy
 * `soa` the reorder writes (x, y, z, m blocks of `stride` floats). Also writes the per-particle factors of the
 * forces pass's pair terms: derived = (k_j m_j / rho_j, m_j p_j / rho_j^2, solid ? m_j : 0) blocks,
 * k_j the viscosity coefficient of the particle's kind (fluid or boundary). */

kernel void density(global const float4* pos, global const float* soa, global const uchar* phase,
                    global const uchar* material, global const MaterialFlow* flow, global const uint* cell_start,
                    const Grid g, const DensityParams P, global float* density, global float4* state,
                    global float* derived
#ifdef THAW_DFSPH
                    ,
                    global float* col, const uint min_neighbours
#endif
#ifdef THAW_NO_SLIP
                    ,
                    global float* ghost
#endif
) {
  const uint i = get_global_id(0);
  const uint n = P.n, stride = P.stride;
  if (i >= n) return;
  const float H = P.support;
  /* The particle's material's rest density and stiffness (fluid_params.h). */
  const MaterialFlow mf = flow[material[i]];
  const float4 pi = pos[i];
#ifdef THAW_MULTIPHASE
  /* The particle's own rest density m / V (dfsph_columns: the material's, or eq 7's for ideal-gas air). */
  const float rho0 = pi.w / col[COL_VOL * stride + i], B = mf.stiffness;
#else
  const float rho0 = mf.rest_density, B = mf.stiffness;
#endif
  const int4 c = grid_cell(g, pi);
  const float H2 = H * H;
  const float inv_H = 1.0f / H;
  global const float* X = soa;
  global const float* Y = soa + stride;
  global const float* Z = soa + 2 * stride;
  global const float* M = soa + 3 * stride;
  const int boundary = THAW_IS_STATIC(phase[i]);
  floatV acc = (floatV)(0.0f);
#ifdef THAW_DFSPH
  /* DFSPH's alpha (dfsph.cl) in the same visit: G = sum_j m_j grad W_ij over every neighbour, S = m_i
   * sum_j (fluid) m_j |grad W_ij|^2, the neighbour count; a boundary particle only learns whether fluid is
   * within reach (the fluid masses FM, written by dfsph_columns before this pass). */
  global const float* FM = col + COL_FM * stride;
#ifdef THAW_MULTIPHASE
  global const float* VOL = col + COL_VOL * stride;
#endif
  floatV gx = (floatV)(0.0f), gy = (floatV)(0.0f), gz = (floatV)(0.0f), s = (floatV)(0.0f);
  floatV count = (floatV)(0.0f);
#ifdef THAW_MULTIPHASE
  floatV hx = (floatV)(0.0f), hy = (floatV)(0.0f), hz = (floatV)(0.0f);
  floatV light = (floatV)(0.0f); /* sum_light V_j W_ij, for a heavy particle's COL_RHO */
  const int heavy = rho0 >= THAW_MP_SPLIT;
#endif
#endif
#ifdef THAW_NO_SLIP
  /* A boundary particle's Shepard average of the fluid's velocity around it (Adami et al. 2012 eq 22). */
  global const float* VX = soa + 4 * stride;
  global const float* VY = soa + 5 * stride;
  global const float* VZ = soa + 6 * stride;
  floatV fu = (floatV)(0.0f), fv = (floatV)(0.0f), fw = (floatV)(0.0f), fs = (floatV)(0.0f);
#endif
  FOR_EACH_NEIGHBOUR_ROW(g, cell_start, c, jb, je) {
    const float4 pr = THAW_ROW_POS(g, c, pi);
    for (uint j = jb; j < je; j += THAW_VW) {
      const floatV dx = pr.x - vloadV(0, X + j);
      const floatV dy = pr.y - vloadV(0, Y + j);
      const floatV dz = pr.z - vloadV(0, Z + j);
      const floatV r2 = dx * dx + dy * dy + dz * dz;
      /* Lanes past the row's end, or outside the support, add nothing (a select, not a branch). */
      const intV in = (THAW_LANE_IDS < (int)(je - j)) & (r2 < H2);
#ifdef THAW_MULTIPHASE
      /* Fluids of several rest densities (Hu & Adams 2006; Solenthaler & Pajarola 2008): each particle
       * counts its neighbours' rest volumes V_j (dfsph_columns), not their masses, and takes
       * rho_i = rho0_i sum_j V_j W_ij, so water next to air (830x lighter) is not read as under-dense nor
       * the air beside it as 400x over-dense. */
      const floatV m = vloadV(0, VOL + j);
#else
      const floatV m = vloadV(0, M + j);
#endif
      const floatV q = sqrt(r2) * inv_H;
      const floatV mw = m * w_shape(q);
      acc += select((floatV)(0.0f), mw, in);
#ifdef THAW_NO_SLIP
      if (boundary) {
        const intV ph = THAW_CAT(convert_int, THAW_VW)(THAW_CAT(vload, THAW_VW)(0, phase + j));
        const floatV wf =
            select((floatV)(0.0f), m * w_shape(q), in & ((ph == THAW_PHASE_WATER) | (ph == THAW_PHASE_AIR)));
        fu += wf * vloadV(0, VX + j);
        fv += wf * vloadV(0, VY + j);
        fw += wf * vloadV(0, VZ + j);
        fs += wf;
      }
#endif
#ifdef THAW_DFSPH
      const floatV fm = vloadV(0, FM + j);
      if (boundary) {
        count += select((floatV)(0.0f), fm, in);
      } else {
        const floatV gf = grad_shape(q); /* grad W = sigma/H^2 gf x_ij; the factor comes last */
        const floatV mg = m * gf;
        gx += select((floatV)(0.0f), mg * dx, in);
        gy += select((floatV)(0.0f), mg * dy, in);
        gz += select((floatV)(0.0f), mg * dz, in);
#ifdef THAW_MULTIPHASE
        /* pi_i's share of the pair pressure (dfsph.cl): c_ij = 2 rho0_j / (rho0_i + rho0_j), rho0_j = V_j / FM_j
         * for a fluid neighbour; for a boundary one 1, or 2 for the light fluid, whose walls mirror its own
         * pressure (dfsph_correct). */
        const floatV cb = (floatV)(rho0 < THAW_MP_SPLIT ? 2.0f : 1.0f);
#ifdef THAW_MP_SYMMETRIC /* solver.multiphase domaradzki_martyn: the pair's mean pressure */
        const floatV cw = select(cb, (floatV)(1.0f), fm > 0.0f);
#else
        const floatV cw = select(cb, 2.0f * m / (rho0 * fm + m), fm > 0.0f);
#endif
        hx += select((floatV)(0.0f), cw * mg * dx, in);
        hy += select((floatV)(0.0f), cw * mg * dy, in);
        hz += select((floatV)(0.0f), cw * mg * dz, in);
        if (heavy) /* a light neighbour: rho0_j = V_j / FM_j below the split */
          light += select((floatV)(0.0f), mw, in & (fm > 0.0f) & (fm * THAW_MP_SPLIT > m));
        s += select((floatV)(0.0f), cw * fm * gf * gf * r2, in);
#else
        s += select((floatV)(0.0f), fm * gf * gf * r2, in);
#endif
        count += select((floatV)(0.0f), (floatV)(1.0f), in);
      }
#endif
    }
  }
#ifdef THAW_MULTIPHASE
  const float rho = rho0 * THAW_SIGMA(H) * lanes_sum(acc);
#else
  const float rho = THAW_SIGMA(H) * lanes_sum(acc);
#endif
#ifdef THAW_NO_SLIP
  /* The velocity the forces pass's viscous term gives each particle (blocks of `stride` floats): a
   * boundary particle's ghost 2 v_w - v~ (eq 23: the fluid's velocity mirrored through the wall moving with
   * v_w, so that the wall's surface holds v_w), a fluid particle's own. */
  {
    float3 v = (float3)(VX[i], VY[i], VZ[i]);
    const float s = lanes_sum(fs);
    if (boundary && s > 0.0f) v = 2.0f * v - (float3)(lanes_sum(fu), lanes_sum(fv), lanes_sum(fw)) / s;
    ghost[i] = v.x;
    ghost[stride + i] = v.y;
    ghost[2 * stride + i] = v.z;
  }
#endif
#ifdef THAW_DFSPH
  /* alpha_i = rho_i / (|G_i|^2 + S_i) for both solves (Bender & Koschier 2015 eq 10; dfsph.cl has the
   * columns). A boundary particle's AD is -1 when fluid is within its support (the solves extrapolate a
   * pressure to it), else 0. */
  col[COL_ERR * stride + i] = 0.0f;
  if (boundary) {
    col[COL_AD * stride + i] = lanes_sum(count) > 0.0f ? -1.0f : 0.0f;
    col[COL_AV * stride + i] = 0.0f;
  } else {
    const float scale = THAW_SIGMA(H) * inv_H * inv_H;
    const float3 G = scale * (float3)(lanes_sum(gx), lanes_sum(gy), lanes_sum(gz));
    const float S = pi.w * scale * scale * lanes_sum(s);
#ifdef THAW_MULTIPHASE
    /* With rest volumes (dfsph.cl, multiphase): G_i = sum_j V_j grad W_ij, Gc_i = sum_j c_ij V_j grad W_ij,
     * S_i = sum_j (fluid) c_ij V_j / rho0_j |grad W_ij|^2, and a pressure pi_i alone changes D r_i / Dt by
     * -dt pi_i (Gc_i . G_i / rho0_i + V_i S_i). */
    const float3 Gc = scale * (float3)(lanes_sum(hx), lanes_sum(hy), lanes_sum(hz));
    const float d = dot(Gc, G) / rho0 + VOL[i] * S / pi.w;
    const float alpha = d > 0.0f ? 1.0f / d : 0.0f;
#else
    const float d = dot(G, G) + S;
    /* A particle without neighbours (d = 0) cannot be corrected by its own pressure: leave it alone. */
    const float alpha = d > 0.0f ? rho / d : 0.0f;
#endif
    col[COL_AD * stride + i] = alpha;
    col[COL_AV * stride + i] = lanes_sum(count) - 1.0f >= (float)min_neighbours ? alpha : 0.0f; /* -1: itself */
  }
#ifdef THAW_MULTIPHASE
  /* Boundary particles too: ice that melts this step is fluid in the density solve. */
  col[COL_RHO * stride + i] = rho - rho0 * THAW_SIGMA(H) * lanes_sum(light);
#endif
#endif
#ifdef THAW_DFSPH
  /* DFSPH (sim/kernels/dfsph.cl) solves for the pressure after the forces pass: none here. */
  float p = 0.0f;
#elif defined(THAW_EOS_TAIT)
  /* Tait (Monaghan 1994; Becker & Teschner 2007): p = B ((rho/rho0)^gamma - 1). */
#ifdef THAW_GAMMA_7
  /* gamma = 7 (the usual choice) by multiplication: pocl's powr cost as much as the neighbour sum. */
  const float x = rho / rho0, x2 = x * x, x4 = x2 * x2;
  float p = B * (x4 * x2 * x - 1.0f);
#else
  float p = B * (powr(rho / rho0, P.gamma) - 1.0f);
#endif
#else
  /* Linear: p = c^2 (rho - rho0), B passed as c^2 * rho0. */
  float p = B * (rho / rho0 - 1.0f);
#endif
  /* Clamped at zero: negative pressure would make free-surface particles clump (tensile instability).
   * Surface tension (tension.cl) is an explicit force, not a negative pressure, so the clamp leaves it whole;
   * its pull on the bulk is held by positive pressure (sim/tension_stage.h, cohesive_pressure). */
  p = fmax(p, 0.0f);
  const float dp = p / (rho * rho);
  density[i] = rho;
  state[i] = (float4)(rho, dp, boundary ? 1.0f : 0.0f, p);
#if defined(THAW_MULTIPHASE)
  /* Multiphase (forces.cl): a fluid particle's dynamic viscosity coefficient mu_j = k_j rho0_j, a boundary
   * particle's kinematic one negated (the pair takes it at the fluid's own density, as in one fluid), and
   * the volume m_j / rho_j, which the pair term weighs symmetrically (DFSPH: no pressure term there). */
#ifdef THAW_NO_SLIP
  derived[i] = boundary ? -mf.viscosity : mf.viscosity * mf.rest_density;
#else
  derived[i] = boundary ? -P.visc_boundary : mf.viscosity * mf.rest_density;
#endif
  derived[stride + i] = pi.w / rho;
#else
#ifdef THAW_NO_SLIP
  /* No-slip: a boundary pair takes the fluid's viscosity (the boundary material's row holds the fluid's). */
  derived[i] = mf.viscosity * pi.w / rho;
#else
  derived[i] = (boundary ? P.visc_boundary : mf.viscosity) * pi.w / rho;
#endif
  derived[stride + i] = pi.w * dp;
#endif
  derived[2 * stride + i] = phase[i] == THAW_PHASE_SOLID ? pi.w : 0.0f;
}
