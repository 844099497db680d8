#include "uvsym_docking_auv_observers.h"

int uvsym_proportional_observer(const uvsym_real x[6], const uvsym_real eta[6], const uvsym_real nu[6], const uvsym_real tau_d[6], const uvsym_real K[6], uvsym_real x_dot[6], uvsym_real f_hat[6]) {
  static casadi_int iw[proportional_observer_SZ_IW > 0 ? proportional_observer_SZ_IW : 1];
  static casadi_real w[proportional_observer_SZ_W > 0 ? proportional_observer_SZ_W : 1];
  const casadi_real* arg[proportional_observer_SZ_ARG > 0 ? proportional_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[proportional_observer_SZ_RES > 0 ? proportional_observer_SZ_RES : 1] = {x_dot, f_hat};
  return proportional_observer(arg, res, iw, w, 0);
}

int uvsym_proportional_step(const uvsym_real x[6], const uvsym_real eta[6], const uvsym_real nu[6], const uvsym_real tau_d[6], const uvsym_real K[6], const uvsym_real dt[1], uvsym_real x_next[6], uvsym_real f_hat[6]) {
  static casadi_int iw[proportional_step_SZ_IW > 0 ? proportional_step_SZ_IW : 1];
  static casadi_real w[proportional_step_SZ_W > 0 ? proportional_step_SZ_W : 1];
  const casadi_real* arg[proportional_step_SZ_ARG > 0 ? proportional_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[proportional_step_SZ_RES > 0 ? proportional_step_SZ_RES : 1] = {x_next, f_hat};
  return proportional_step(arg, res, iw, w, 0);
}

int uvsym_bias_observer(const uvsym_real x[6], const uvsym_real eta[6], const uvsym_real nu[6], const uvsym_real tau_d[6], const uvsym_real K[6], uvsym_real x_dot[6], uvsym_real f_hat[6]) {
  static casadi_int iw[bias_observer_SZ_IW > 0 ? bias_observer_SZ_IW : 1];
  static casadi_real w[bias_observer_SZ_W > 0 ? bias_observer_SZ_W : 1];
  const casadi_real* arg[bias_observer_SZ_ARG > 0 ? bias_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[bias_observer_SZ_RES > 0 ? bias_observer_SZ_RES : 1] = {x_dot, f_hat};
  return bias_observer(arg, res, iw, w, 0);
}

int uvsym_bias_step(const uvsym_real x[6], const uvsym_real eta[6], const uvsym_real nu[6], const uvsym_real tau_d[6], const uvsym_real K[6], const uvsym_real dt[1], uvsym_real x_next[6], uvsym_real f_hat[6]) {
  static casadi_int iw[bias_step_SZ_IW > 0 ? bias_step_SZ_IW : 1];
  static casadi_real w[bias_step_SZ_W > 0 ? bias_step_SZ_W : 1];
  const casadi_real* arg[bias_step_SZ_ARG > 0 ? bias_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[bias_step_SZ_RES > 0 ? bias_step_SZ_RES : 1] = {x_next, f_hat};
  return bias_step(arg, res, iw, w, 0);
}

int uvsym_constant_observer(const uvsym_real x[6], const uvsym_real eta[6], const uvsym_real nu[6], const uvsym_real tau_d[6], const uvsym_real K[6], uvsym_real x_dot[6], uvsym_real f_hat[6]) {
  static casadi_int iw[constant_observer_SZ_IW > 0 ? constant_observer_SZ_IW : 1];
  static casadi_real w[constant_observer_SZ_W > 0 ? constant_observer_SZ_W : 1];
  const casadi_real* arg[constant_observer_SZ_ARG > 0 ? constant_observer_SZ_ARG : 1] = {x, eta, nu, tau_d, K};
  casadi_real* res[constant_observer_SZ_RES > 0 ? constant_observer_SZ_RES : 1] = {x_dot, f_hat};
  return constant_observer(arg, res, iw, w, 0);
}

int uvsym_constant_step(const uvsym_real x[6], const uvsym_real eta[6], const uvsym_real nu[6], const uvsym_real tau_d[6], const uvsym_real K[6], const uvsym_real dt[1], uvsym_real x_next[6], uvsym_real f_hat[6]) {
  static casadi_int iw[constant_step_SZ_IW > 0 ? constant_step_SZ_IW : 1];
  static casadi_real w[constant_step_SZ_W > 0 ? constant_step_SZ_W : 1];
  const casadi_real* arg[constant_step_SZ_ARG > 0 ? constant_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[constant_step_SZ_RES > 0 ? constant_step_SZ_RES : 1] = {x_next, f_hat};
  return constant_step(arg, res, iw, w, 0);
}

int uvsym_actuator_observers_step(const uvsym_real x[18], const uvsym_real eta[6], const uvsym_real nu[6], const uvsym_real tau_d[6], const uvsym_real K[18], const uvsym_real dt[1], uvsym_real x_next[18], uvsym_real f_hat[18]) {
  static casadi_int iw[actuator_observers_step_SZ_IW > 0 ? actuator_observers_step_SZ_IW : 1];
  static casadi_real w[actuator_observers_step_SZ_W > 0 ? actuator_observers_step_SZ_W : 1];
  const casadi_real* arg[actuator_observers_step_SZ_ARG > 0 ? actuator_observers_step_SZ_ARG : 1] = {x, eta, nu, tau_d, K, dt};
  casadi_real* res[actuator_observers_step_SZ_RES > 0 ? actuator_observers_step_SZ_RES : 1] = {x_next, f_hat};
  return actuator_observers_step(arg, res, iw, w, 0);
}
