/* A solute's phase diagram with water (issue 44, docs/SUBSTANCES.md "Salt's phase diagram"), shared verbatim
 * by the OpenCL kernels (substance.cl) and the host (scene loading, metrics, validation), so both sides
 * dissolve, lower and cap with the same arithmetic.
 *
 * Each substance has a liquidus: how far a melt holding it at mass fraction w (kg of it per kg of melt) lies
 * below the water's melting point. Either
 *   Blagden's law with van 't Hoff's factor, d = K_f i b, b = (Q / M) / m_water, the dilute law (`moles`
 *   = i / M); or
 *   a table of measured points (w_k, d_k) from (0, 0), its last point the eutectic (w_e, d_e) past which
 *   no melt stays liquid: between points the apparent slope d / w is interpolated linearly in w (for NaCl
 *   it is nearly linear where d itself curves: docs/SUBSTANCES.md), below the first point it is the first
 *   point's.
 * A melt dissolves each substance up to its solubility w_sat (kg per kg of melt); what exceeds that stays
 * undissolved, a solid amount carried by the particle, and dissolves as water comes (the split is
 * recomputed from the particle's amount and its melt every step). A melt cannot be colder than the
 * eutectic: the drop is capped at `cap`, T_m - T_e, and below the eutectic brine freezes through (the
 * lowered enthalpy law at the cap, thermal_law.h). */
#ifndef THAW_LIQUIDUS_H
#define THAW_LIQUIDUS_H

#ifdef __OPENCL_VERSION__
#define THAW_LQ_FN
#define THAW_LQ_REAL float
#define THAW_LQ_TABLE global const Liquidus*
#else
#define THAW_LQ_FN inline
#define THAW_LQ_REAL double
#define THAW_LQ_TABLE const Liquidus*
namespace thaw::thermal {
#endif

#define THAW_LIQUIDUS_POINTS 12

/* One substance's phase diagram with the water; every member is 4 bytes, so host and device layouts agree.
 * A substance that lowers nothing (a dye) has moles = points = cap = 0 and solubility 1e30. */
typedef struct {
  float solubility;              /* w_sat [kg per kg of melt]; 1e30: unlimited */
  float moles;                   /* Blagden: i / M [mol/kg]; 0 with a table */
  float cap;                     /* the largest drop [K]: the eutectic's T_m - T_e */
  int points;                    /* measured points after (0, 0); 0: Blagden's law */
  float w[THAW_LIQUIDUS_POINTS]; /* mass fraction in the melt, rising; w[points - 1] the eutectic's */
  float d[THAW_LIQUIDUS_POINTS]; /* the drop there [K], rising */
} Liquidus;

/* A table's drop at mass fraction w (the apparent slope d / w linear in w between points, the first point's
 * below it, the eutectic's drop past the last). */
THAW_LQ_FN THAW_LQ_REAL liquidus_table_drop(THAW_LQ_TABLE lq, THAW_LQ_REAL w) {
  if (w >= lq->w[lq->points - 1]) return lq->d[lq->points - 1];
  if (w <= lq->w[0]) return w * (lq->d[0] / lq->w[0]);
  int k = 1;
  while (w > lq->w[k]) ++k;
  const THAW_LQ_REAL w0 = lq->w[k - 1], w1 = lq->w[k];
  const THAW_LQ_REAL r0 = lq->d[k - 1] / w0, r1 = lq->d[k] / w1;
  return w * (r0 + (r1 - r0) * ((w - w0) / (w1 - w0)));
}

/* What a melt of mass `melt` [kg] (water and what it dissolves) dissolves of an amount q [kg]. */
THAW_LQ_FN THAW_LQ_REAL liquidus_dissolved(THAW_LQ_TABLE lq, THAW_LQ_REAL q, THAW_LQ_REAL melt) {
  const THAW_LQ_REAL most = melt > 0 ? lq->solubility * melt : 0;
  return q < most ? q : most;
}

/* The drop [K] of a melt of mass `melt` [kg] holding the amounts q[0..count) [kg] of the substances lq[..],
 * each dissolved up to its solubility, kf the water's cryoscopic constant [K kg/mol]: the table drops plus
 * Blagden's over the melt's water, capped at the largest cap of the substances it holds. A melt of nothing
 * that holds what lowers it is at that cap. */
THAW_LQ_FN THAW_LQ_REAL liquidus_drop(THAW_LQ_TABLE lq, int count, const THAW_LQ_REAL* q, THAW_LQ_REAL melt,
                                      THAW_LQ_REAL kf) {
  THAW_LQ_REAL cap = 0, dissolved = 0, table = 0, moles = 0;
  for (int s = 0; s < count; ++s) {
    if (!(q[s] > 0)) continue;
    const THAW_LQ_REAL held = liquidus_dissolved(lq + s, q[s], melt);
    dissolved += held;
    if (lq[s].cap <= 0) continue;
    cap = cap > lq[s].cap ? cap : lq[s].cap;
    if (lq[s].points > 0) {
      if (melt > 0) table += liquidus_table_drop(lq + s, held / melt);
    } else {
      moles += lq[s].moles * held;
    }
  }
  if (cap <= 0) return 0;
  if (!(melt > 0)) return cap;
  const THAW_LQ_REAL water = melt - dissolved;
  const THAW_LQ_REAL d = table + (moles > 0 ? (water > 0 ? kf * moles / water : cap) : 0);
  return d < cap ? d : cap;
}

#ifndef __OPENCL_VERSION__
static_assert(sizeof(Liquidus) == 16 + 8 * THAW_LIQUIDUS_POINTS, "Liquidus must match its OpenCL layout");
}  // namespace thaw::thermal
#endif
#undef THAW_LQ_FN
#undef THAW_LQ_REAL
#undef THAW_LQ_TABLE
#endif
