/* Test harness: each record on stdin is a function index then its inputs, all as text;
   prints that function's return code, then its outputs, on one line. Used to compare C with Python. */
#include <stdio.h>
#include "uvsym_otter_ukf_mmae.h"

int main(void) {
  int index;
  double v;
  int i;
  while (scanf("%d", &index) == 1) {
    switch (index) {
    case 0: {
      uvsym_otter_ukf_mmae_real in0[100]; uvsym_otter_ukf_mmae_real in1[6]; uvsym_otter_ukf_mmae_real in2[2]; uvsym_otter_ukf_mmae_real in3[2]; uvsym_otter_ukf_mmae_real out0[100]; uvsym_otter_ukf_mmae_real out1[21];
      for (i = 0; i < 100; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_otter_ukf_mmae_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_otter_ukf_mmae_real)v;
      for (i = 0; i < 2; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_otter_ukf_mmae_real)v;
      for (i = 0; i < 2; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_otter_ukf_mmae_real)v;
      printf("%d", uvsym_otter_ukf_mmae_ukf_step(in0, in1, in2, in3, out0, out1));
      for (i = 0; i < 100; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 21; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    default:
      return 3;
    }
    printf("\n");
  }
  return 0;
}
