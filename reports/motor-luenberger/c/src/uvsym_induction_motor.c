#include <math.h>
#include "uvsym_induction_motor_casadi.h"
#include "uvsym_induction_motor.h"

/* 1 when the n entries of v are all finite (not NaN, not infinite), else 0 */
static int uvsym_induction_motor_all_finite(const uvsym_induction_motor_real* v, int n) {
  int i;
  for (i = 0; i < n; ++i) if (!isfinite(v[i])) return 0;
  return 1;
}

int uvsym_induction_motor_luenberger_step(const uvsym_induction_motor_real s[5], const uvsym_induction_motor_real y[3], const uvsym_induction_motor_real u[2], const uvsym_induction_motor_real* p, uvsym_induction_motor_real s_next[5], uvsym_induction_motor_real out[8]) {
  static casadi_int iw[uvsym_induction_motor_casadi_luenberger_step_SZ_IW > 0 ? uvsym_induction_motor_casadi_luenberger_step_SZ_IW : 1];
  static casadi_real w[uvsym_induction_motor_casadi_luenberger_step_SZ_W > 0 ? uvsym_induction_motor_casadi_luenberger_step_SZ_W : 1];
  const casadi_real* arg[uvsym_induction_motor_casadi_luenberger_step_SZ_ARG > 0 ? uvsym_induction_motor_casadi_luenberger_step_SZ_ARG : 1] = {s, y, u, p};
  casadi_real* res[uvsym_induction_motor_casadi_luenberger_step_SZ_RES > 0 ? uvsym_induction_motor_casadi_luenberger_step_SZ_RES : 1] = {s_next, out};
  if (!uvsym_induction_motor_all_finite(s, 5)) return UVSYM_INDUCTION_MOTOR_NONFINITE_INPUT;
  if (!uvsym_induction_motor_all_finite(y, 3)) return UVSYM_INDUCTION_MOTOR_NONFINITE_INPUT;
  if (!uvsym_induction_motor_all_finite(u, 2)) return UVSYM_INDUCTION_MOTOR_NONFINITE_INPUT;
  if (uvsym_induction_motor_casadi_luenberger_step(arg, res, iw, w, 0)) return UVSYM_INDUCTION_MOTOR_EVAL_FAILED;
  if (!uvsym_induction_motor_all_finite(s_next, 5)) return UVSYM_INDUCTION_MOTOR_NONFINITE_OUTPUT;
  if (!uvsym_induction_motor_all_finite(out, 8)) return UVSYM_INDUCTION_MOTOR_NONFINITE_OUTPUT;
  return UVSYM_INDUCTION_MOTOR_OK;
}
