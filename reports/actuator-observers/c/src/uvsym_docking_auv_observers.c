#include "uvsym_docking_auv_observers.h"

int uvsym_docking_auv_observers_proportional_observer(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], uvsym_docking_auv_observers_real x_dot[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_proportional_observer_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_proportional_observer_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_proportional_observer_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_proportional_observer_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_proportional_observer_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_proportional_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[uvsym_docking_auv_observers_casadi_proportional_observer_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_proportional_observer_SZ_RES : 1] = {x_dot, f_hat};
  return uvsym_docking_auv_observers_casadi_proportional_observer(arg, res, iw, w, 0);
}

int uvsym_docking_auv_observers_proportional_step(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], const uvsym_docking_auv_observers_real dt[1], uvsym_docking_auv_observers_real x_next[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_proportional_step_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_proportional_step_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_proportional_step_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_proportional_step_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_proportional_step_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_proportional_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[uvsym_docking_auv_observers_casadi_proportional_step_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_proportional_step_SZ_RES : 1] = {x_next, f_hat};
  return uvsym_docking_auv_observers_casadi_proportional_step(arg, res, iw, w, 0);
}

int uvsym_docking_auv_observers_bias_observer(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], uvsym_docking_auv_observers_real x_dot[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_bias_observer_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_bias_observer_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_bias_observer_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_bias_observer_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_bias_observer_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_bias_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[uvsym_docking_auv_observers_casadi_bias_observer_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_bias_observer_SZ_RES : 1] = {x_dot, f_hat};
  return uvsym_docking_auv_observers_casadi_bias_observer(arg, res, iw, w, 0);
}

int uvsym_docking_auv_observers_bias_step(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], const uvsym_docking_auv_observers_real dt[1], uvsym_docking_auv_observers_real x_next[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_bias_step_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_bias_step_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_bias_step_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_bias_step_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_bias_step_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_bias_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[uvsym_docking_auv_observers_casadi_bias_step_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_bias_step_SZ_RES : 1] = {x_next, f_hat};
  return uvsym_docking_auv_observers_casadi_bias_step(arg, res, iw, w, 0);
}

int uvsym_docking_auv_observers_constant_observer(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], uvsym_docking_auv_observers_real x_dot[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_constant_observer_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_constant_observer_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_constant_observer_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_constant_observer_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_constant_observer_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_constant_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[uvsym_docking_auv_observers_casadi_constant_observer_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_constant_observer_SZ_RES : 1] = {x_dot, f_hat};
  return uvsym_docking_auv_observers_casadi_constant_observer(arg, res, iw, w, 0);
}

int uvsym_docking_auv_observers_constant_step(const uvsym_docking_auv_observers_real x[6], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[6], const uvsym_docking_auv_observers_real dt[1], uvsym_docking_auv_observers_real x_next[6], uvsym_docking_auv_observers_real f_hat[6]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_constant_step_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_constant_step_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_constant_step_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_constant_step_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_constant_step_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_constant_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[uvsym_docking_auv_observers_casadi_constant_step_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_constant_step_SZ_RES : 1] = {x_next, f_hat};
  return uvsym_docking_auv_observers_casadi_constant_step(arg, res, iw, w, 0);
}

int uvsym_docking_auv_observers_actuator_observers_step(const uvsym_docking_auv_observers_real x[18], const uvsym_docking_auv_observers_real eta[6], const uvsym_docking_auv_observers_real nu[6], const uvsym_docking_auv_observers_real tau_d[6], const uvsym_docking_auv_observers_real K[18], const uvsym_docking_auv_observers_real dt[1], uvsym_docking_auv_observers_real x_next[18], uvsym_docking_auv_observers_real f_hat[18]) {
  static casadi_int iw[uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_IW > 0 ? uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_IW : 1];
  static casadi_real w[uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_W > 0 ? uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_W : 1];
  const casadi_real* arg[uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_ARG > 0 ? uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_RES > 0 ? uvsym_docking_auv_observers_casadi_actuator_observers_step_SZ_RES : 1] = {x_next, f_hat};
  return uvsym_docking_auv_observers_casadi_actuator_observers_step(arg, res, iw, w, 0);
}
