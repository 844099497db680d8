#include <math.h>
#include "uvsym_docking_auv_observers_casadi.h"
#include "uvsym_docking_auv_observers.h"

/* 1 when the n entries of v are all finite (not NaN, not infinite), else 0 */
static int uvsym_docking_auv_observers_all_finite(const uvsym_docking_auv_observers_real* v, int n) {
  int i;
  for (i = 0; i < n; ++i) if (!isfinite(v[i])) return 0;
  return 1;
}

int uvsym_docking_auv_observers_proportional_observer(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], uvsym_docking_auv_observers_real x_dot[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_proportional_observer_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_proportional_observer_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_proportional_observer_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_proportional_observer_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_proportional_observer_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_proportional_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[uvsym_docking_auv_observers_casadi_proportional_observer_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_proportional_observer_SZ_RES : 1] = {x_dot, f_hat};
  if (!uvsym_docking_auv_observers_all_finite(x, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(eta, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(nu, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(tau_d, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(K, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (uvsym_docking_auv_observers_casadi_proportional_observer(arg, res, iw, w, 0)) return UVSYM_DOCKING_AUV_OBSERVERS_EVAL_FAILED;
  if (!uvsym_docking_auv_observers_all_finite(x_dot, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  if (!uvsym_docking_auv_observers_all_finite(f_hat, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  return UVSYM_DOCKING_AUV_OBSERVERS_OK;
}

int uvsym_docking_auv_observers_proportional_step(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], const uvsym_docking_auv_observers_real dt[1], uvsym_docking_auv_observers_real x_next[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_proportional_step_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_proportional_step_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_proportional_step_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_proportional_step_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_proportional_step_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_proportional_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[uvsym_docking_auv_observers_casadi_proportional_step_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_proportional_step_SZ_RES : 1] = {x_next, f_hat};
  if (!uvsym_docking_auv_observers_all_finite(x, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(eta, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(nu, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(tau_d, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(K, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(dt, 1)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (uvsym_docking_auv_observers_casadi_proportional_step(arg, res, iw, w, 0)) return UVSYM_DOCKING_AUV_OBSERVERS_EVAL_FAILED;
  if (!uvsym_docking_auv_observers_all_finite(x_next, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  if (!uvsym_docking_auv_observers_all_finite(f_hat, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  return UVSYM_DOCKING_AUV_OBSERVERS_OK;
}

int uvsym_docking_auv_observers_bias_observer(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], uvsym_docking_auv_observers_real x_dot[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_bias_observer_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_bias_observer_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_bias_observer_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_bias_observer_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_bias_observer_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_bias_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[uvsym_docking_auv_observers_casadi_bias_observer_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_bias_observer_SZ_RES : 1] = {x_dot, f_hat};
  if (!uvsym_docking_auv_observers_all_finite(x, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(eta, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(nu, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(tau_d, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(K, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (uvsym_docking_auv_observers_casadi_bias_observer(arg, res, iw, w, 0)) return UVSYM_DOCKING_AUV_OBSERVERS_EVAL_FAILED;
  if (!uvsym_docking_auv_observers_all_finite(x_dot, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  if (!uvsym_docking_auv_observers_all_finite(f_hat, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  return UVSYM_DOCKING_AUV_OBSERVERS_OK;
}

int uvsym_docking_auv_observers_bias_step(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], const uvsym_docking_auv_observers_real dt[1], uvsym_docking_auv_observers_real x_next[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_bias_step_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_bias_step_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_bias_step_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_bias_step_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_bias_step_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_bias_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[uvsym_docking_auv_observers_casadi_bias_step_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_bias_step_SZ_RES : 1] = {x_next, f_hat};
  if (!uvsym_docking_auv_observers_all_finite(x, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(eta, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(nu, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(tau_d, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(K, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(dt, 1)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (uvsym_docking_auv_observers_casadi_bias_step(arg, res, iw, w, 0)) return UVSYM_DOCKING_AUV_OBSERVERS_EVAL_FAILED;
  if (!uvsym_docking_auv_observers_all_finite(x_next, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  if (!uvsym_docking_auv_observers_all_finite(f_hat, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  return UVSYM_DOCKING_AUV_OBSERVERS_OK;
}

int uvsym_docking_auv_observers_constant_observer(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], uvsym_docking_auv_observers_real x_dot[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_constant_observer_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_constant_observer_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_constant_observer_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_constant_observer_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_constant_observer_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_constant_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[uvsym_docking_auv_observers_casadi_constant_observer_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_constant_observer_SZ_RES : 1] = {x_dot, f_hat};
  if (!uvsym_docking_auv_observers_all_finite(x, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(eta, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(nu, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(tau_d, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(K, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (uvsym_docking_auv_observers_casadi_constant_observer(arg, res, iw, w, 0)) return UVSYM_DOCKING_AUV_OBSERVERS_EVAL_FAILED;
  if (!uvsym_docking_auv_observers_all_finite(x_dot, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  if (!uvsym_docking_auv_observers_all_finite(f_hat, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  return UVSYM_DOCKING_AUV_OBSERVERS_OK;
}

int uvsym_docking_auv_observers_constant_step(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], const uvsym_docking_auv_observers_real dt[1], uvsym_docking_auv_observers_real x_next[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_constant_step_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_constant_step_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_constant_step_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_constant_step_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_constant_step_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_constant_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[uvsym_docking_auv_observers_casadi_constant_step_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_constant_step_SZ_RES : 1] = {x_next, f_hat};
  if (!uvsym_docking_auv_observers_all_finite(x, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(eta, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(nu, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(tau_d, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(K, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(dt, 1)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (uvsym_docking_auv_observers_casadi_constant_step(arg, res, iw, w, 0)) return UVSYM_DOCKING_AUV_OBSERVERS_EVAL_FAILED;
  if (!uvsym_docking_auv_observers_all_finite(x_next, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  if (!uvsym_docking_auv_observers_all_finite(f_hat, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  return UVSYM_DOCKING_AUV_OBSERVERS_OK;
}

int uvsym_docking_auv_observers_actuator_observers_step(const uvsym_docking_auv_observers_real x[18], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[18], const uvsym_docking_auv_observers_real dt[1], uvsym_docking_auv_observers_real x_next[18], uvsym_docking_auv_observers_real f_hat[18]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_RES : 1] = {x_next, f_hat};
  if (!uvsym_docking_auv_observers_all_finite(x, 18)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(eta, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(nu, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(tau_d, 6)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(K, 18)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (!uvsym_docking_auv_observers_all_finite(dt, 1)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_INPUT;
  if (uvsym_docking_auv_observers_casadi_actuator_observers_step(arg, res, iw, w, 0)) return UVSYM_DOCKING_AUV_OBSERVERS_EVAL_FAILED;
  if (!uvsym_docking_auv_observers_all_finite(x_next, 18)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  if (!uvsym_docking_auv_observers_all_finite(f_hat, 18)) return UVSYM_DOCKING_AUV_OBSERVERS_NONFINITE_OUTPUT;
  return UVSYM_DOCKING_AUV_OBSERVERS_OK;
}
