/* Ice that moves (Iwasaki et al. 2010 sec. 5): every connected piece of ice is a rigid body driven by the
 * forces on its particles. This file holds the per-particle parts: the force on each ice particle of a
 * free body (from the water, and contacts with solids and other bodies) and placing the particles where
 * their body has moved; the per-particle body and offset are declared fields, sorted with the rest
 * (sim/particle_store.h). The host (sim/rigid_ice.cpp) sums the forces per body and integrates them. */

#define THAW_NO_BODY 0xffffffffu

/* Per body, as the host uploads it each step (must match ClBody in sim/rigid_ice.cpp): centre of
 * mass, the rows of the rotation body -> world, velocity of the centre, angular velocity; w of `centre`
 * is 1 for a free body, 0 for a fixed one. */
typedef struct {
  float4 centre;
  float4 r0, r1, r2;
  float4 velocity;
  float4 omega;
} Body;

/* Contact model between an ice particle and a solid particle or an ice particle of another body
 * (Tanaka et al. 2007, as Iwasaki 2010 cites): a linear spring on the overlap of two spheres of
 * diameter `distance`, a dashpot on the normal approach speed, and Coulomb friction on the sliding
 * speed (regularised by a viscous law below the friction limit). Must match ClContact. */
typedef struct {
  float stiffness; /* k_n [N/m] */
  float damping;   /* c_n [N s/m] */
  float friction;  /* mu */
  float distance;  /* contact diameter [m] */
} Contact;

/* The force [N] on each ice particle of a free body (other particles get 0):
 * - from water neighbours, the exact opposite of what the forces pass (forces.cl) gives the water from
 *   this particle as a boundary particle, so momentum is exchanged, not made: pressure
 *   -m_b m_i (p_b / rho_b^2 + p_i / rho_i^2) grad W_bi and viscosity
 *   m_b (k_b m_i rho0 / (rho_b rho_i)) (v_bi . x_bi) / (r^2 + eps h^2) grad W_bi, k_b the boundary
 *   coefficient (forces.cl's viscous pair term);
 * - contacts with solid particles and ice particles of other bodies.
 * Gravity is added per body on the host, with the body's physical mass. */
kernel void rigid_forces(global const float4* pos, global const float4* vel, global const float4* state,
                         global const uchar* phase, global const uint* body, global const Body* bodies,
                         global const uint* cell_start, const Grid g, const float H, const float eps2,
                         const float visc_boundary, const float rho0, const Contact contact,
                         global float4* force, const uint n
#ifdef THAW_MULTIPHASE
                         ,
                         global const uchar* material, global const MaterialFlow* flow, global const float* col,
                         const uint stride
#endif
#ifdef THAW_TENSION_REACTION
                         ,
                         global const uchar* tension_material, global const float* adhesion
#endif
) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uint b = body[i];
  if (phase[i] != THAW_PHASE_ICE || b == THAW_NO_BODY || bodies[b].centre.w == 0.0f) {
    force[i] = (float4)(0.0f);
    return;
  }
  const float4 pi = pos[i];
  const float4 vi = vel[i];
  const float4 si = state[i];
  const float rho_i = si.x, dpi = si.y;
  const float H2 = H * H;
  const float d2 = contact.distance * contact.distance;
  const int4 c = grid_cell(g, pi);
  float3 f_fluid = (float3)(0.0f), f_contact = (float3)(0.0f);
#ifdef THAW_TENSION_REACTION
  /* The water's adhesion to this ice particle (tension.cl), taken back: Akinci et al. 2013 eq 6's
   * beta m_j Psi_b A(r) x_bj / r towards the water (Psi_b = pi.w, applied with f_fluid below), or Iwasaki's
   * k_b x_bj / r^2. */
  const float adhesion_b = adhesion[tension_material[i]];
#endif
  FOR_EACH_NEIGHBOUR(g, cell_start, c, j) {
    if (j == i) continue;
    const float3 x = pi.xyz - pos[j].xyz;
    const float r2 = dot(x, x);
    if (r2 >= H2) continue;
    const uchar pj = phase[j];
    if (pj == THAW_PHASE_WATER || pj == THAW_PHASE_AIR) {
      const float4 sj = state[j];
      const float mj = pos[j].w;
      const float vd = dot(vi.xyz - vel[j].xyz, x);
#ifdef THAW_MULTIPHASE
      /* Fluids of several densities: the reaction of dfsph_correct's pressure -V_b V_j (p_b + p_j) grad W,
       * with the solve's rest volume V_j (column VOL: eq 7's, by temperature, for ideal-gas air; not the
       * material row's) and V_b = Psi_b / rho0; the light fluid (air) pushed with its own pressure for the
       * boundary's (dfsph_correct's mirror, p_b = p_j), the heavy one with the boundary's. The viscosity is
       * forces.cl's boundary pair, at the material row's density as that pass takes it. The sum is
       * multiplied by m_b = Psi_b below. */
      const float vol_j = col[COL_VOL * stride + j];
      const float pb = mj < THAW_MP_SPLIT * vol_j ? sj.w : si.w; /* rho0_j = m_j / V_j */
      const float rho0_row = flow[material[j]].rest_density;
      const float s = visc_boundary * mj * (rho0_row / (rho_i * sj.x)) * vd / (r2 + eps2) -
                      (vol_j / rho0) * (pb + sj.w);
#else
      const float s = visc_boundary * mj * (rho0 / (rho_i * sj.x)) * vd / (r2 + eps2) - mj * (dpi + sj.y);
#endif
      f_fluid += s * KERNEL_GRAD(sqrt(r2), H) * x;
#ifdef THAW_TENSION_REACTION
      if (pj == THAW_PHASE_WATER) {
        const float r = sqrt(r2);
#ifdef THAW_TENSION_AKINCI2013
        const float q = r / H;
        f_fluid -= adhesion_b * mj * 0.007f / (H * H * H) * THAW_AKINCI_ADHESION(q) / fmax(r, 1e-12f) * x;
#else
        f_contact -= adhesion_b / fmax(r2, 1e-24f) * x;
#endif
      }
#endif
    } else if (r2 < d2 && (pj == THAW_PHASE_SOLID || (pj == THAW_PHASE_ICE && body[j] != b))) {
      const float r = sqrt(r2);
      const float3 normal = x / fmax(r, 1e-12f);
      const float3 dv = vi.xyz - vel[j].xyz;
      const float vn = dot(dv, normal);
      /* A contact pushes, never pulls: the dashpot may only lower the spring's push to zero. */
      const float fn = fmax(contact.stiffness * (contact.distance - r) - contact.damping * vn, 0.0f);
      const float3 vt = dv - vn * normal;
      const float st = length(vt);
      const float ft = fmin(contact.friction * fn, contact.damping * st);
      f_contact += fn * normal - (st > 0.0f ? ft / st : 0.0f) * vt;
    }
  }
  force[i] = (float4)(pi.w * f_fluid + f_contact, 0.0f);
}

/* Moves each ice particle of a free body with its body: x = c + R r0, v = V + omega x (R r0), r0 its
 * offset in the body frame. A particle that is no longer ice (it melted this step) leaves its body and
 * moves on as water with the velocity it had. */
kernel void rigid_place(global float4* pos, global float4* vel, global const uchar* phase, global uint* body,
                        global const float4* offset, global const Body* bodies, const uint n) {
  const uint i = get_global_id(0);
  if (i >= n) return;
  const uint b = body[i];
  if (b == THAW_NO_BODY) return;
  if (phase[i] != THAW_PHASE_ICE) {
    body[i] = THAW_NO_BODY;
    return;
  }
  const Body B = bodies[b];
  if (B.centre.w == 0.0f) return;
  const float3 o = offset[i].xyz;
  const float3 r = (float3)(dot(B.r0.xyz, o), dot(B.r1.xyz, o), dot(B.r2.xyz, o));
  pos[i] = (float4)(B.centre.xyz + r, pos[i].w);
  vel[i] = (float4)(B.velocity.xyz + cross(B.omega.xyz, r), 0.0f);
}
