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
  unsigned int stride; /* length of each structure-of-arrays block */
  unsigned int n;      /* particles */
  unsigned int flow;   /* 1: moving water takes its density from the density pass */
  unsigned int reject; /* bit s: water that freezes gives substance s up (its enters_ice is false) */
  /* Surface-active substances (THAW_SURFACE; Orthmann et al. 2013 sec. 5-6.2): */
  unsigned int surface; /* bit s: substance s is surface-active */
  float min_area;       /* water with less surface area than this is not on the surface [m^2] */
  /* Each one's Langmuir rates for a step of dt: k_a rho0 dt [kg/m^2 per unit mass fraction] and k_d dt */
  float adsorb0, adsorb1, adsorb2, adsorb3;
  float desorb0, desorb1, desorb2, desorb3;
  float inv_capacity0, inv_capacity1, inv_capacity2, inv_capacity3; /* 1 / Gamma_max; 0: no limit [m^2/kg] */
  /* 2 D_s dt sigma2 / H^4 [1/m^2]: the surface pair term's constant, x . grad W2 = sigma2 / H^4 grad_shape
   * r^2 */
  float glide0, glide1, glide2, glide3;
  float surface_depth; /* a surface particle's point on the surface lies this far along its normal [m] */
  float sigma2;        /* the kernel's 2-D normalisation times H^2: W2 = sigma2 / H^2 w_shape(r / H) */
  /* Coatings (THAW_DEPOSIT; Orthmann et al. 2013 sec. 6.3-6.4): */
  unsigned int coating;  /* bit s: substance s is a coating */
  unsigned int cleanser; /* 4 bits per substance s: the index of the substance that cleanses it; 15: none */
  float face;            /* a boundary particle's face, the spacing squared [m^2] */
  float wet_weight; /* the water weight sum_j M_j w(r / H) past which a boundary particle is wholly wet */
  /* Each one's rates for a step of dt: k_c rho0 dt [kg/m^2 per unit mass fraction] and k_r rho0 dt [1] */
  float coat0, coat1, coat2, coat3;
  float cleanse0, cleanse1, cleanse2, cleanse3;
  float inv_coat_capacity0, inv_coat_capacity1, inv_coat_capacity2, inv_coat_capacity3; /* 0: no limit */
  /* Surface tension (THAW_TENSION_LAW): 2 bits per substance s, its law (0 none, 1 Szyszkowski, 2 linear),
   * and each one's E / sigma0 */
  unsigned int tension_law;
  float tension0, tension1, tension2, tension3;
} SubstanceParams;

#ifndef __OPENCL_VERSION__
static_assert(sizeof(SubstanceParams) == 216, "SubstanceParams must match its OpenCL layout");
}  // namespace thaw::substance
#endif

#endif
