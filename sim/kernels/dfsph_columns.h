/* The DFSPH solver's per-particle columns (blocks of `stride` floats in one buffer; sim/kernels/dfsph.cl
 * says what each holds), shared by dfsph.cl and the density pass that computes alpha (density.cl). */
#ifndef THAW_DFSPH_COLUMNS_H
#define THAW_DFSPH_COLUMNS_H
#define COL_FM 0
#define COL_KR 1
#define COL_AD 2
#define COL_AV 3
#define COL_ERR 4
/* Multiphase builds (THAW_MULTIPHASE) only: each particle's rest volume V = m / rho0 of its material's row
 * (a boundary particle's Psi / rho0 of the fluid it bounds: Akinci's volume). */
#define COL_VOL 5
/* Multiphase builds only: the density each particle's constraint reads (dfsph_error). The summation density,
 * but a heavy particle's (water's) without its light (air) neighbours' share, rho0_i sum_light V_j W_ij:
 * water's constraint leaves the air out (dfsph.cl, density_rate). Written once a step by the density pass,
 * which sums the share with the density, rather than in every sweep. */
#define COL_RHO 6
#endif
