#include <math.h>
#include "uvsym_sensor_fdi_lms_casadi.h"
#include "uvsym_sensor_fdi_lms.h"

/* 1 when the n entries of v are all finite (not NaN, not infinite), else 0 */
static int uvsym_sensor_fdi_lms_all_finite(const uvsym_sensor_fdi_lms_real* v, int n) {
  int i;
  for (i = 0; i < n; ++i) if (!isfinite(v[i])) return 0;
  return 1;
}

int uvsym_sensor_fdi_lms_lms_step(const uvsym_sensor_fdi_lms_real s[235], const uvsym_sensor_fdi_lms_real y[1], const uvsym_sensor_fdi_lms_real u[2], const uvsym_sensor_fdi_lms_real p[3], uvsym_sensor_fdi_lms_real s_next[235], uvsym_sensor_fdi_lms_real out[10]) {
  static casadi_int iw[uvsym_sensor_fdi_lms_casadi_lms_step_SZ_IW > 0 ? uvsym_sensor_fdi_lms_casadi_lms_step_SZ_IW : 1];
  static casadi_real w[uvsym_sensor_fdi_lms_casadi_lms_step_SZ_W > 0 ? uvsym_sensor_fdi_lms_casadi_lms_step_SZ_W : 1];
  const casadi_real* arg[uvsym_sensor_fdi_lms_casadi_lms_step_SZ_ARG > 0 ? uvsym_sensor_fdi_lms_casadi_lms_step_SZ_ARG : 1] = {s, y, u, p};
  casadi_real* res[uvsym_sensor_fdi_lms_casadi_lms_step_SZ_RES > 0 ? uvsym_sensor_fdi_lms_casadi_lms_step_SZ_RES : 1] = {s_next, out};
  if (!uvsym_sensor_fdi_lms_all_finite(s, 235)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(y, 1)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(u, 2)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(p, 3)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (uvsym_sensor_fdi_lms_casadi_lms_step(arg, res, iw, w, 0)) return UVSYM_SENSOR_FDI_LMS_EVAL_FAILED;
  if (!uvsym_sensor_fdi_lms_all_finite(s_next, 235)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_OUTPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(out, 10)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_OUTPUT;
  return UVSYM_SENSOR_FDI_LMS_OK;
}

int uvsym_sensor_fdi_lms_lms_fir_step(const uvsym_sensor_fdi_lms_real C[70], const uvsym_sensor_fdi_lms_real U[70], const uvsym_sensor_fdi_lms_real target[1], const uvsym_sensor_fdi_lms_real u[1], const uvsym_sensor_fdi_lms_real mu[1], uvsym_sensor_fdi_lms_real C_next[70], uvsym_sensor_fdi_lms_real U_next[70], uvsym_sensor_fdi_lms_real d[1], uvsym_sensor_fdi_lms_real e[1]) {
  static casadi_int iw[uvsym_sensor_fdi_lms_casadi_lms_fir_step_SZ_IW > 0 ? uvsym_sensor_fdi_lms_casadi_lms_fir_step_SZ_IW : 1];
  static casadi_real w[uvsym_sensor_fdi_lms_casadi_lms_fir_step_SZ_W > 0 ? uvsym_sensor_fdi_lms_casadi_lms_fir_step_SZ_W : 1];
  const casadi_real* arg[uvsym_sensor_fdi_lms_casadi_lms_fir_step_SZ_ARG > 0 ? uvsym_sensor_fdi_lms_casadi_lms_fir_step_SZ_ARG : 1] = {C, U, target, u, mu};
  casadi_real* res[uvsym_sensor_fdi_lms_casadi_lms_fir_step_SZ_RES > 0 ? uvsym_sensor_fdi_lms_casadi_lms_fir_step_SZ_RES : 1] = {C_next, U_next, d, e};
  if (!uvsym_sensor_fdi_lms_all_finite(C, 70)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(U, 70)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(target, 1)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(u, 1)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(mu, 1)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_INPUT;
  if (uvsym_sensor_fdi_lms_casadi_lms_fir_step(arg, res, iw, w, 0)) return UVSYM_SENSOR_FDI_LMS_EVAL_FAILED;
  if (!uvsym_sensor_fdi_lms_all_finite(C_next, 70)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_OUTPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(U_next, 70)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_OUTPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(d, 1)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_OUTPUT;
  if (!uvsym_sensor_fdi_lms_all_finite(e, 1)) return UVSYM_SENSOR_FDI_LMS_NONFINITE_OUTPUT;
  return UVSYM_SENSOR_FDI_LMS_OK;
}
