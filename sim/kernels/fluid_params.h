/* The fluid passes' parameters, shared verbatim by the host (sim/fluid_stage.cpp) and density.cl,
 * forces.cl; every member is 4 bytes, so both layouts agree (static_asserts below).
 *
 * MaterialFlow: one entry per scene material, indexed by a particle's material. A fluid's entry holds its
 * own rest density, EOS stiffness and viscosity coefficient; a boundary material's (solid, ice) holds
 * those of the fluid it bounds, since its particles carry rho0 V of that fluid (Akinci et al. 2012). */
#ifndef THAW_FLUID_PARAMS_H
#define THAW_FLUID_PARAMS_H

#ifndef __OPENCL_VERSION__
namespace thaw::fluid {
#endif

typedef struct {
  float rest_density; /* rho0 [kg/m^3] */
  float stiffness;    /* Tait B = rho0 c^2 / gamma, or rho0 c^2 for the linear EOS [Pa] */
  float viscosity;    /* the pair term's coefficient 2(d+2) nu + alpha c h [m^2/s] (Monaghan 2005) */
  float sound_speed;  /* c [m/s] */
  /* The body force per unit mass is g (gravity - expansion (T - T0)): water 1 and 0; Boussinesq air 0 and
   * beta (its weight left to a hydrostatic pressure; sim/scene.h, Buoyancy). T = h * inv_specific_heat
   * (a material without phase change, thermal_law.h), read only in builds with THAW_BUOYANCY. */
  float gravity;
  float expansion;             /* beta [1/K] */
  float reference_temperature; /* T0 [°C] */
  float inv_specific_heat;     /* 1 / c [kg K/J] */
  float push;                  /* 1: the walls' short-range push acts on it (forces.cl); 0: not (air) */
  /* Domaradzki & Martyn's artificial buoyancy (eq 8), air.artificial_buoyancy: an upward acceleration
   * sigma / (T_max - T) [m/s^2], with T_max - T no less than 1 K; sigma 0: off. */
  float artificial_buoyancy; /* sigma [K m/s^2] */
  float max_temperature;     /* T_max [°C] */
  /* Domaradzki & Martyn's eq 7 (air.buoyancy ideal_gas, builds with THAW_IDEAL_GAS): the particle's rest
   * density rest_density (1 + theta reference_temperature) / (1 + theta T), T from its enthalpy as above
   * (dfsph_columns); 0: its rest density is rest_density. */
  float theta; /* [1/K] */
} MaterialFlow;

typedef struct {
  float support;           /* kernel support H [m] */
  float gamma;             /* Tait exponent */
  float visc_boundary;     /* alpha_b c h against boundary particles [m^2/s] */
  unsigned int stride;     /* length of each structure-of-arrays block */
  unsigned int n;          /* particles */
  unsigned int pad0, pad1, pad2;
} DensityParams;

typedef struct {
  float support;                      /* kernel support H [m] */
  float eps2;                         /* 0.01 h^2 [m^2] */
  float gravity_x, gravity_y, gravity_z; /* [m/s^2] */
  float rep_k;                        /* boundary push stiffness per pair mass [1/(kg s^2)] */
  float rep_r0;                       /* its range [m] */
  float rep_d;                        /* its damping time [s] */
  unsigned int stride;
  unsigned int n;
  unsigned int pad0, pad1;
} ForcesParams;

#ifndef __OPENCL_VERSION__
static_assert(sizeof(MaterialFlow) == 48, "MaterialFlow must match its OpenCL layout");
static_assert(sizeof(DensityParams) == 32, "DensityParams must match its OpenCL layout");
static_assert(sizeof(ForcesParams) == 48, "ForcesParams must match its OpenCL layout");
}  // namespace thaw::fluid
#endif

#endif
