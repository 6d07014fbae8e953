/* The substance stage's scalar parameters as one struct, shared verbatim by the host
 * (sim/substance_stage.cpp) and substance.cl; every member is 4 bytes, so both layouts agree (static_assert
 * below). */
#ifndef THAW_SUBSTANCE_PARAMS_H
#define THAW_SUBSTANCE_PARAMS_H

#ifndef __OPENCL_VERSION__
namespace thaw::substance {
#endif

typedef struct {
  float support;                      /* kernel support H [m] */
  float eta2;                         /* 0.01 h^2, keeps the pair term finite at r -> 0 [m^2] */
  float period_x, period_y, period_z; /* domain length along each periodic axis, 0 elsewhere [m] */
  /* Each substance's 2 D dt [m^2] for a step of dt (the pair term's constant is this times sigma / H^2). */
  float step0, step1, step2, step3;
  /* Each substance's van 't Hoff factor over its molar mass, i / M [mol/kg]; 0 where it does not lower the
   * melting point. */
  float moles0, moles1, moles2, moles3;
  float max_shift;     /* the melting point is lowered by at most this [K] */
  unsigned int stride; /* length of each structure-of-arrays block */
  unsigned int n;      /* particles */
  unsigned int flow;   /* 1: moving water takes its density from the density pass */
  unsigned int reject; /* bit s: water that freezes gives substance s up (its enters_ice is false) */
  unsigned int pad0, pad1;
} SubstanceParams;

#ifndef __OPENCL_VERSION__
static_assert(sizeof(SubstanceParams) == 80, "SubstanceParams must match its OpenCL layout");
}  // namespace thaw::substance
#endif

#endif
