/* Example: one call of uvsym_induction_motor_luenberger_step on data from the fault-free motor experiment, 1000 steps of 0.0001 s from t = 0.5 s (row 0 of the package's example).
   Prints each output on one line: its name, then its entries (units: README.md, manifest.json). */
#include <stdio.h>
#include "uvsym_induction_motor.h"

int main(void) {
  int i, rc;
  static const uvsym_induction_motor_real s[5] = {0.011770831346064797, 30.070271785538704, 0.00045160434956889367, 0.27804477368840563,
    250.00121737829662};
  static const uvsym_induction_motor_real y[3] = {0.008484252354150196, 29.94674925715017, 249.99996234140758};
  static const uvsym_induction_motor_real u[2] = {143.23944878999998, 0.8999999999999999};
  const uvsym_induction_motor_real* p = NULL;
  uvsym_induction_motor_real s_next[5];
  uvsym_induction_motor_real out[8];
  rc = uvsym_induction_motor_luenberger_step(s, y, u, p, s_next, out);
  if (rc != UVSYM_INDUCTION_MOTOR_OK) {
    fprintf(stderr, "uvsym_induction_motor_luenberger_step returned %d\n", rc);
    return 1;
  }
  printf("s_next");
  for (i = 0; i < 5; ++i) printf(" %.17g", (double)s_next[i]);
  printf("\n");
  printf("out");
  for (i = 0; i < 8; ++i) printf(" %.17g", (double)out[i]);
  printf("\n");
  return 0;
}
