/* Example: one call of uvsym_induction_motor_luenberger_step with zero inputs; prints its last output. */
#include <stdio.h>
#include "uvsym_induction_motor.h"

int main(void) {
  int i;
  uvsym_induction_motor_real s[5] = {0};
  uvsym_induction_motor_real y[3] = {0};
  uvsym_induction_motor_real u[2] = {0};
  uvsym_induction_motor_real p[1] = {0};
  uvsym_induction_motor_real s_next[5];
  uvsym_induction_motor_real out[8];
  if (uvsym_induction_motor_luenberger_step(s, y, u, p, s_next, out)) return 1;
  for (i = 0; i < 8; ++i) printf("%g ", (double)out[i]);
  printf("\n");
  return 0;
}
