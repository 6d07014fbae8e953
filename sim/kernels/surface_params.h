/* The surface pass's scalar parameters (sim/surface_stage.h), shared verbatim by the host and surface.cl;
 * every member is 4 bytes, so both layouts agree (static_assert below). */
#ifndef THAW_SURFACE_PARAMS_H
#define THAW_SURFACE_PARAMS_H

#ifndef __OPENCL_VERSION__
namespace thaw::surface {
#endif

typedef struct {
  float support;                      /* kernel support H [m] */
  float volume;                       /* each particle's rest volume v = dx^3 [m^3] */
  float radius;                       /* Orthmann's d, the particle's radius dx / 2 [m] */
  float spacing;                      /* dx [m] */
  float period_x, period_y, period_z; /* domain length along each periodic axis, 0 elsewhere [m] */
  float colour_scale;                 /* brackbill1992: a flat face's area over sum_i v |grad c_i| under it */
  float min_neighbours; /* fewer neighbours than this: a singular neighbourhood (eq. 8's test) */
  float min_flatness;   /* det C / (tr C / 3)^3 below this: a flat one (eq. 8) */
  float rate;           /* Orthmann eq. 9's kappa in singular neighbourhoods */
  float full_colour;    /* sum_j v W_ij at or above this: a full neighbourhood (no eq. 8 walk) */
  unsigned int n;       /* particles */
  float rim_scale; /* brackbill1992, a sheet one particle thick: its rim's area over sum_i v |grad c_i| */
  unsigned int pad1, pad2;
} SurfaceParams;

#ifndef __OPENCL_VERSION__
static_assert(sizeof(SurfaceParams) == 64, "SurfaceParams must match its OpenCL layout");
}  // namespace thaw::surface
#endif

#endif
