/* The heat pass's scalar parameters as one struct, shared verbatim by the host (sim/heat_stage.cpp) and
 * heat.cl; every member is 4 bytes, so both layouts agree (static_assert below). */
#ifndef THAW_HEAT_PARAMS_H
#define THAW_HEAT_PARAMS_H

#ifndef __OPENCL_VERSION__
namespace thaw::heat {
#endif

typedef struct {
  float support;             /* kernel support H [m] */
  float eta2;                /* 0.01 h^2, keeps the pair term finite at r -> 0 [m^2] */
  float period_x, period_y, period_z; /* domain length along each periodic axis, 0 elsewhere [m] */
  float exposed_r2;          /* squared radius within which a neighbour covers a face [m^2] */
  float face_area;           /* dx^2 [m^2] */
  float ambient_temperature; /* [°C] */
  float ambient_coefficient; /* h [W/m^2/K] */
  float dt_heat;             /* time_scale * dt [s] */
  unsigned int ndryers;      /* entries of the dryer table */
  unsigned int stride;       /* length of each structure-of-arrays block */
  unsigned int n;            /* particles */
  float rest_density;        /* rho0: the volume of static particles, and of all with the flow off */
  unsigned int flow;         /* 1: moving water takes its volume from its summation density */
  unsigned int face_material; /* THAW_AIR_FACES: the air material that relaxes near the sides */
  /* THAW_AIR_FACES (air.face_exchange_time): the sides air relaxes at (a periodic axis: +-1e30), how far
   * from them, the fraction 1 - exp(-dt_heat / tau) of the way to face_enthalpy it goes a step. */
  float face_min_x, face_min_y, face_min_z, face_max_x, face_max_y, face_max_z;
  float face_depth, face_fraction, face_enthalpy; /* [m], -, [J/kg] */
  unsigned int pad1;
} HeatParams;

#ifndef __OPENCL_VERSION__
static_assert(sizeof(HeatParams) == 104, "HeatParams must match its OpenCL layout");
}  // namespace thaw::heat
#endif

#endif
