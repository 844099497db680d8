/* Example: one call of uvsym_otter_ukf_mmae_ukf_step on data from the shipped scenario otter_thruster_faults, every 10th step of the ukf bank (601 of 6001, both thruster faults) (row 0 of the package's example).
   Prints each output on one line: its name, then its entries (units: README.md, manifest.json). */
#include <stdio.h>
#include "uvsym_otter_ukf_mmae.h"

int main(void) {
  int i, rc;
  static const uvsym_otter_ukf_mmae_real s[100] = {0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0025,
    0.0, 0.0, 0.0, 0.01, 0.0, 0.0, 0.01, 0.0, 0.0025, 0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 1.0, 0.25, 0.0,
    0.0, 0.0, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0025, 0.0, 0.0, 0.0, 0.0, 0.01, 0.0,
    0.0, 0.0, 0.01, 0.0, 0.0, 0.0025, 0.0, 0.04, 0.0, 0.0, 0.0, 1.5, 0.0, 0.0, 1.0, 0.25, 0.0, 0.0,
    0.0, 0.0, 0.0, 0.0, 0.25, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0025, 0.0, 0.0, 0.0, 0.0, 0.01, 0.0, 0.0,
    0.0, 0.01, 0.0, 0.0, 0.0025, 0.0, 0.04, -0.020202707317519466, -4.605170185988091,
    -4.605170185988091};
  static const uvsym_otter_ukf_mmae_real y[6] = {-0.032589557630584486, -0.008735864616288858, 0.0058230339698691885, 1.5131829549966451,
    -0.03282794589169293, -1.8211424601761922e-05};
  static const uvsym_otter_ukf_mmae_real u[2] = {58.84820433605038, 56.16514868683566};
  static const uvsym_otter_ukf_mmae_real p[2] = {0.0, 0.0};
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
