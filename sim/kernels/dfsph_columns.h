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
#endif
