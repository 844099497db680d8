/* Example: one call of uvsym_sensor_fdi_lms_lms_fir_step on zero inputs (the observer set gives no example data: put yours here).
   Prints each output on one line: its name, then its entries (units: README.md, manifest.json). */
#include <stdio.h>
#include "uvsym_sensor_fdi_lms.h"

int main(void) {
  int i, rc;
  static const uvsym_sensor_fdi_lms_real C[70] = {0};
  static const uvsym_sensor_fdi_lms_real U[70] = {0};
  static const uvsym_sensor_fdi_lms_real target[1] = {0};
  static const uvsym_sensor_fdi_lms_real u[1] = {0};
  static const uvsym_sensor_fdi_lms_real mu[1] = {0};
  uvsym_sensor_fdi_lms_real C_next[70];
  uvsym_sensor_fdi_lms_real U_next[70];
  uvsym_sensor_fdi_lms_real d[1];
  uvsym_sensor_fdi_lms_real e[1];
  rc = uvsym_sensor_fdi_lms_lms_fir_step(C, U, target, u, mu, C_next, U_next, d, e);
  if (rc != UVSYM_SENSOR_FDI_LMS_OK) {
    fprintf(stderr, "uvsym_sensor_fdi_lms_lms_fir_step returned %d\n", rc);
    return 1;
  }
  printf("C_next");
  for (i = 0; i < 70; ++i) printf(" %.17g", (double)C_next[i]);
  printf("\n");
  printf("U_next");
  for (i = 0; i < 70; ++i) printf(" %.17g", (double)U_next[i]);
  printf("\n");
  printf("d");
  for (i = 0; i < 1; ++i) printf(" %.17g", (double)d[i]);
  printf("\n");
  printf("e");
  for (i = 0; i < 1; ++i) printf(" %.17g", (double)e[i]);
  printf("\n");
  return 0;
}
