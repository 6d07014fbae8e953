/* The DFSPH solver's per-particle columns (blocks of `stride` floats in one buffer; sim/kernels/dfsph.cl
 * says what each holds), shared by dfsph.cl and the density pass that computes alpha (density.cl). */
#ifndef THAW_DFSPH_COLUMNS_H
#define THAW_DFSPH_COLUMNS_H
#define COL_FM 0
#define COL_KR 1
#define COL_AD 2
#define COL_AV 3
#define COL_ERR 4
#endif
