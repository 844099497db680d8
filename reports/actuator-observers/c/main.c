/* Example: one call of uvsym_docking_auv_observers_actuator_observers_step with zero inputs; prints its last output. */
#include <stdio.h>
#include "uvsym_docking_auv_observers.h"

int main(void) {
  int i;
  uvsym_docking_auv_observers_real x[18] = {0};
  uvsym_docking_auv_observers_real eta[6] = {0};
  uvsym_docking_auv_observers_real nu[6] = {0};
  uvsym_docking_auv_observers_real tau_d[6] = {0};
  uvsym_docking_auv_observers_real K[18] = {0};
  uvsym_docking_auv_observers_real dt[1] = {0};
  uvsym_docking_auv_observers_real x_next[18];
  uvsym_docking_auv_observers_real f_hat[18];
  if (uvsym_docking_auv_observers_actuator_observers_step(x, eta, nu, tau_d, K, dt, x_next, f_hat)) return 1;
  for (i = 0; i < 18; ++i) printf("%g ", (double)f_hat[i]);
  printf("\n");
  return 0;
}
