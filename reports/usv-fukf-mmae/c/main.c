/* Example: one call of uvsym_otter_ukf_mmae_ukf_step on zero inputs (the observer set gives no example data: put yours here).
   Prints each output on one line: its name, then its entries (units: README.md, manifest.json). */
#include <stdio.h>
#include "uvsym_otter_ukf_mmae.h"

int main(void) {
  int i, rc;
  static const uvsym_otter_ukf_mmae_real s[100] = {0};
  static const uvsym_otter_ukf_mmae_real y[6] = {0};
  static const uvsym_otter_ukf_mmae_real u[2] = {0};
  static const uvsym_otter_ukf_mmae_real p[2] = {0};
  uvsym_otter_ukf_mmae_real s_next[100];
  uvsym_otter_ukf_mmae_real out[21];
  rc = uvsym_otter_ukf_mmae_ukf_step(s, y, u, p, s_next, out);
  if (rc != UVSYM_OTTER_UKF_MMAE_OK) {
    fprintf(stderr, "uvsym_otter_ukf_mmae_ukf_step returned %d\n", rc);
    return 1;
  }
  printf("s_next");
  for (i = 0; i < 100; ++i) printf(" %.17g", (double)s_next[i]);
  printf("\n");
  printf("out");
  for (i = 0; i < 21; ++i) printf(" %.17g", (double)out[i]);
  printf("\n");
  return 0;
}
