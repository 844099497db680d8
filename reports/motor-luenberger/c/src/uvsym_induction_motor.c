#include "uvsym_induction_motor.h"

int uvsym_induction_motor_luenberger_step(const uvsym_induction_motor_real s[5], const uvsym_induction_motor_real y[3], const uvsym_induction_motor_real u[2], const uvsym_induction_motor_real* p, uvsym_induction_motor_real s_next[5], uvsym_induction_motor_real out[8]) {
  static casadi_int iw[uvsym_induction_motor_casadi_luenberger_step_SZ_IW > 0 ? uvsym_induction_motor_casadi_luenberger_step_SZ_IW : 1];
  static casadi_real w[uvsym_induction_motor_casadi_luenberger_step_SZ_W > 0 ? uvsym_induction_motor_casadi_luenberger_step_SZ_W : 1];
  const casadi_real* arg[uvsym_induction_motor_casadi_luenberger_step_SZ_ARG > 0 ? uvsym_induction_motor_casadi_luenberger_step_SZ_ARG : 1] = {s, y, u, p};
  casadi_real* res[uvsym_induction_motor_casadi_luenberger_step_SZ_RES > 0 ? uvsym_induction_motor_casadi_luenberger_step_SZ_RES : 1] = {s_next, out};
  return uvsym_induction_motor_casadi_luenberger_step(arg, res, iw, w, 0);
}
