#include <math.h>
#include "uvsym_otter_ukf_mmae_casadi.h"
#include "uvsym_otter_ukf_mmae.h"

/* 1 when the n entries of v are all finite (not NaN, not infinite), else 0 */
static int uvsym_otter_ukf_mmae_all_finite(const uvsym_otter_ukf_mmae_real* v, int n) {
  int i;
  for (i = 0; i < n; ++i) if (!isfinite(v[i])) return 0;
  return 1;
}

int uvsym_otter_ukf_mmae_ukf_step(const uvsym_otter_ukf_mmae_real s[100], const uvsym_otter_ukf_mmae_real y[6], const uvsym_otter_ukf_mmae_real u[2], const uvsym_otter_ukf_mmae_real p[2], uvsym_otter_ukf_mmae_real s_next[100], uvsym_otter_ukf_mmae_real out[21]) {
  static casadi_int iw[uvsym_otter_ukf_mmae_casadi_ukf_step_SZ_IW > 0 ? uvsym_otter_ukf_mmae_casadi_ukf_step_SZ_IW : 1];
  static casadi_real w[uvsym_otter_ukf_mmae_casadi_ukf_step_SZ_W > 0 ? uvsym_otter_ukf_mmae_casadi_ukf_step_SZ_W : 1];
  const casadi_real* arg[uvsym_otter_ukf_mmae_casadi_ukf_step_SZ_ARG > 0 ? uvsym_otter_ukf_mmae_casadi_ukf_step_SZ_ARG : 1] = {s, y, u, p};
  casadi_real* res[uvsym_otter_ukf_mmae_casadi_ukf_step_SZ_RES > 0 ? uvsym_otter_ukf_mmae_casadi_ukf_step_SZ_RES : 1] = {s_next, out};
  if (!uvsym_otter_ukf_mmae_all_finite(s, 100)) return UVSYM_OTTER_UKF_MMAE_NONFINITE_INPUT;
  if (!uvsym_otter_ukf_mmae_all_finite(y, 6)) return UVSYM_OTTER_UKF_MMAE_NONFINITE_INPUT;
  if (!uvsym_otter_ukf_mmae_all_finite(u, 2)) return UVSYM_OTTER_UKF_MMAE_NONFINITE_INPUT;
  if (!uvsym_otter_ukf_mmae_all_finite(p, 2)) return UVSYM_OTTER_UKF_MMAE_NONFINITE_INPUT;
  if (uvsym_otter_ukf_mmae_casadi_ukf_step(arg, res, iw, w, 0)) return UVSYM_OTTER_UKF_MMAE_EVAL_FAILED;
  if (!uvsym_otter_ukf_mmae_all_finite(s_next, 100)) return UVSYM_OTTER_UKF_MMAE_NONFINITE_OUTPUT;
  if (!uvsym_otter_ukf_mmae_all_finite(out, 21)) return UVSYM_OTTER_UKF_MMAE_NONFINITE_OUTPUT;
  if (!(out[19] > 0)) return UVSYM_OTTER_UKF_MMAE_UNHEALTHY;  /* pd_margin */
  return UVSYM_OTTER_UKF_MMAE_OK;
}
