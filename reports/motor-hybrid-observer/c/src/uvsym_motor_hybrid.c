#include <math.h>
#include "uvsym_motor_hybrid_casadi.h"
#include "uvsym_motor_hybrid.h"

/* 1 when the n entries of v are all finite (not NaN, not infinite), else 0 */
static int uvsym_motor_hybrid_all_finite(const uvsym_motor_hybrid_real* v, int n) {
  int i;
  for (i = 0; i < n; ++i) if (!isfinite(v[i])) return 0;
  return 1;
}

int uvsym_motor_hybrid_detection_step(const uvsym_motor_hybrid_real s[5], const uvsym_motor_hybrid_real y[3], const uvsym_motor_hybrid_real u[2], const uvsym_motor_hybrid_real* p, uvsym_motor_hybrid_real s_next[5], uvsym_motor_hybrid_real out[8]) {
  static casadi_int iw[uvsym_motor_hybrid_casadi_detection_step_SZ_IW > 0 ? uvsym_motor_hybrid_casadi_detection_step_SZ_IW : 1];
  static casadi_real w[uvsym_motor_hybrid_casadi_detection_step_SZ_W > 0 ? uvsym_motor_hybrid_casadi_detection_step_SZ_W : 1];
  const casadi_real* arg[uvsym_motor_hybrid_casadi_detection_step_SZ_ARG > 0 ? uvsym_motor_hybrid_casadi_detection_step_SZ_ARG : 1] = {s, y, u, p};
  casadi_real* res[uvsym_motor_hybrid_casadi_detection_step_SZ_RES > 0 ? uvsym_motor_hybrid_casadi_detection_step_SZ_RES : 1] = {s_next, out};
  if (!uvsym_motor_hybrid_all_finite(s, 5)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (!uvsym_motor_hybrid_all_finite(y, 3)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (!uvsym_motor_hybrid_all_finite(u, 2)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (uvsym_motor_hybrid_casadi_detection_step(arg, res, iw, w, 0)) return UVSYM_MOTOR_HYBRID_EVAL_FAILED;
  if (!uvsym_motor_hybrid_all_finite(s_next, 5)) return UVSYM_MOTOR_HYBRID_NONFINITE_OUTPUT;
  if (!uvsym_motor_hybrid_all_finite(out, 8)) return UVSYM_MOTOR_HYBRID_NONFINITE_OUTPUT;
  return UVSYM_MOTOR_HYBRID_OK;
}

int uvsym_motor_hybrid_estimator_step(const uvsym_motor_hybrid_real s[6], const uvsym_motor_hybrid_real y[3], const uvsym_motor_hybrid_real u[2], const uvsym_motor_hybrid_real* p, uvsym_motor_hybrid_real s_next[6], uvsym_motor_hybrid_real out[9]) {
  static casadi_int iw[uvsym_motor_hybrid_casadi_estimator_step_SZ_IW > 0 ? uvsym_motor_hybrid_casadi_estimator_step_SZ_IW : 1];
  static casadi_real w[uvsym_motor_hybrid_casadi_estimator_step_SZ_W > 0 ? uvsym_motor_hybrid_casadi_estimator_step_SZ_W : 1];
  const casadi_real* arg[uvsym_motor_hybrid_casadi_estimator_step_SZ_ARG > 0 ? uvsym_motor_hybrid_casadi_estimator_step_SZ_ARG : 1] = {s, y, u, p};
  casadi_real* res[uvsym_motor_hybrid_casadi_estimator_step_SZ_RES > 0 ? uvsym_motor_hybrid_casadi_estimator_step_SZ_RES : 1] = {s_next, out};
  if (!uvsym_motor_hybrid_all_finite(s, 6)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (!uvsym_motor_hybrid_all_finite(y, 3)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (!uvsym_motor_hybrid_all_finite(u, 2)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (uvsym_motor_hybrid_casadi_estimator_step(arg, res, iw, w, 0)) return UVSYM_MOTOR_HYBRID_EVAL_FAILED;
  if (!uvsym_motor_hybrid_all_finite(s_next, 6)) return UVSYM_MOTOR_HYBRID_NONFINITE_OUTPUT;
  if (!uvsym_motor_hybrid_all_finite(out, 9)) return UVSYM_MOTOR_HYBRID_NONFINITE_OUTPUT;
  return UVSYM_MOTOR_HYBRID_OK;
}

int uvsym_motor_hybrid_baseline_step(const uvsym_motor_hybrid_real s[5], const uvsym_motor_hybrid_real y[3], const uvsym_motor_hybrid_real u[2], const uvsym_motor_hybrid_real* p, uvsym_motor_hybrid_real s_next[5], uvsym_motor_hybrid_real out[8]) {
  static casadi_int iw[uvsym_motor_hybrid_casadi_baseline_step_SZ_IW > 0 ? uvsym_motor_hybrid_casadi_baseline_step_SZ_IW : 1];
  static casadi_real w[uvsym_motor_hybrid_casadi_baseline_step_SZ_W > 0 ? uvsym_motor_hybrid_casadi_baseline_step_SZ_W : 1];
  const casadi_real* arg[uvsym_motor_hybrid_casadi_baseline_step_SZ_ARG > 0 ? uvsym_motor_hybrid_casadi_baseline_step_SZ_ARG : 1] = {s, y, u, p};
  casadi_real* res[uvsym_motor_hybrid_casadi_baseline_step_SZ_RES > 0 ? uvsym_motor_hybrid_casadi_baseline_step_SZ_RES : 1] = {s_next, out};
  if (!uvsym_motor_hybrid_all_finite(s, 5)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (!uvsym_motor_hybrid_all_finite(y, 3)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (!uvsym_motor_hybrid_all_finite(u, 2)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (uvsym_motor_hybrid_casadi_baseline_step(arg, res, iw, w, 0)) return UVSYM_MOTOR_HYBRID_EVAL_FAILED;
  if (!uvsym_motor_hybrid_all_finite(s_next, 5)) return UVSYM_MOTOR_HYBRID_NONFINITE_OUTPUT;
  if (!uvsym_motor_hybrid_all_finite(out, 8)) return UVSYM_MOTOR_HYBRID_NONFINITE_OUTPUT;
  return UVSYM_MOTOR_HYBRID_OK;
}

int uvsym_motor_hybrid_corrected_step(const uvsym_motor_hybrid_real s[6], const uvsym_motor_hybrid_real y[3], const uvsym_motor_hybrid_real u[2], const uvsym_motor_hybrid_real* p, uvsym_motor_hybrid_real s_next[6], uvsym_motor_hybrid_real out[9]) {
  static casadi_int iw[uvsym_motor_hybrid_casadi_corrected_step_SZ_IW > 0 ? uvsym_motor_hybrid_casadi_corrected_step_SZ_IW : 1];
  static casadi_real w[uvsym_motor_hybrid_casadi_corrected_step_SZ_W > 0 ? uvsym_motor_hybrid_casadi_corrected_step_SZ_W : 1];
  const casadi_real* arg[uvsym_motor_hybrid_casadi_corrected_step_SZ_ARG > 0 ? uvsym_motor_hybrid_casadi_corrected_step_SZ_ARG : 1] = {s, y, u, p};
  casadi_real* res[uvsym_motor_hybrid_casadi_corrected_step_SZ_RES > 0 ? uvsym_motor_hybrid_casadi_corrected_step_SZ_RES : 1] = {s_next, out};
  if (!uvsym_motor_hybrid_all_finite(s, 6)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (!uvsym_motor_hybrid_all_finite(y, 3)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (!uvsym_motor_hybrid_all_finite(u, 2)) return UVSYM_MOTOR_HYBRID_NONFINITE_INPUT;
  if (uvsym_motor_hybrid_casadi_corrected_step(arg, res, iw, w, 0)) return UVSYM_MOTOR_HYBRID_EVAL_FAILED;
  if (!uvsym_motor_hybrid_all_finite(s_next, 6)) return UVSYM_MOTOR_HYBRID_NONFINITE_OUTPUT;
  if (!uvsym_motor_hybrid_all_finite(out, 9)) return UVSYM_MOTOR_HYBRID_NONFINITE_OUTPUT;
  return UVSYM_MOTOR_HYBRID_OK;
}
