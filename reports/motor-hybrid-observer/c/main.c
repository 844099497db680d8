/* Example: one call of uvsym_motor_hybrid_corrected_step on zero inputs (the observer set gives no example data: put yours here).
   Prints each output on one line: its name, then its entries (units: README.md, manifest.json). */
#include <stdio.h>
#include "uvsym_motor_hybrid.h"

int main(void) {
  int i, rc;
  static const uvsym_motor_hybrid_real s[6] = {0};
  static const uvsym_motor_hybrid_real y[3] = {0};
  static const uvsym_motor_hybrid_real u[2] = {0};
  const uvsym_motor_hybrid_real* p = NULL;
  uvsym_motor_hybrid_real s_next[6];
  uvsym_motor_hybrid_real out[9];
  rc = uvsym_motor_hybrid_corrected_step(s, y, u, p, s_next, out);
  if (rc != UVSYM_MOTOR_HYBRID_OK) {
    fprintf(stderr, "uvsym_motor_hybrid_corrected_step returned %d\n", rc);
    return 1;
  }
  printf("s_next");
  for (i = 0; i < 6; ++i) printf(" %.17g", (double)s_next[i]);
  printf("\n");
  printf("out");
  for (i = 0; i < 9; ++i) printf(" %.17g", (double)out[i]);
  printf("\n");
  return 0;
}
