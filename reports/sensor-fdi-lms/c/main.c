/* Example: one call of uvsym_sensor_fdi_lms_lms_step on zero inputs (the observer set gives no example data: put yours here).
   Prints each output on one line: its name, then its entries (units: README.md, manifest.json). */
#include <stdio.h>
#include "uvsym_sensor_fdi_lms.h"

int main(void) {
  int i, rc;
  static const uvsym_sensor_fdi_lms_real s[235] = {0};
  static const uvsym_sensor_fdi_lms_real y[1] = {0};
  static const uvsym_sensor_fdi_lms_real u[2] = {0};
  static const uvsym_sensor_fdi_lms_real p[3] = {0};
  uvsym_sensor_fdi_lms_real s_next[235];
  uvsym_sensor_fdi_lms_real out[10];
  rc = uvsym_sensor_fdi_lms_lms_step(s, y, u, p, s_next, out);
  if (rc != UVSYM_SENSOR_FDI_LMS_OK) {
    fprintf(stderr, "uvsym_sensor_fdi_lms_lms_step returned %d\n", rc);
    return 1;
  }
  printf("s_next");
  for (i = 0; i < 235; ++i) printf(" %.17g", (double)s_next[i]);
  printf("\n");
  printf("out");
  for (i = 0; i < 10; ++i) printf(" %.17g", (double)out[i]);
  printf("\n");
  return 0;
}
