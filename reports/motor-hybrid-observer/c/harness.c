/* Test harness: each record on stdin is a function index then its inputs, all as text;
   prints that function's return code, then its outputs, on one line. Used to compare C with Python. */
#include <stdio.h>
#include "uvsym_motor_hybrid.h"

int main(void) {
  int index;
  double v;
  int i;
  while (scanf("%d", &index) == 1) {
    switch (index) {
    case 0: {
      uvsym_motor_hybrid_real in0[5]; uvsym_motor_hybrid_real in1[3]; uvsym_motor_hybrid_real in2[2]; uvsym_motor_hybrid_real in3[1]; uvsym_motor_hybrid_real out0[5]; uvsym_motor_hybrid_real out1[8];
      for (i = 0; i < 5; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 3; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 2; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 0; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_motor_hybrid_real)v;
      printf("%d", uvsym_motor_hybrid_detection_step(in0, in1, in2, in3, out0, out1));
      for (i = 0; i < 5; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 8; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 1: {
      uvsym_motor_hybrid_real in0[6]; uvsym_motor_hybrid_real in1[3]; uvsym_motor_hybrid_real in2[2]; uvsym_motor_hybrid_real in3[1]; uvsym_motor_hybrid_real out0[6]; uvsym_motor_hybrid_real out1[9];
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 3; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 2; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 0; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_motor_hybrid_real)v;
      printf("%d", uvsym_motor_hybrid_estimator_step(in0, in1, in2, in3, out0, out1));
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 9; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 2: {
      uvsym_motor_hybrid_real in0[5]; uvsym_motor_hybrid_real in1[3]; uvsym_motor_hybrid_real in2[2]; uvsym_motor_hybrid_real in3[1]; uvsym_motor_hybrid_real out0[5]; uvsym_motor_hybrid_real out1[8];
      for (i = 0; i < 5; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 3; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 2; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 0; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_motor_hybrid_real)v;
      printf("%d", uvsym_motor_hybrid_baseline_step(in0, in1, in2, in3, out0, out1));
      for (i = 0; i < 5; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 8; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 3: {
      uvsym_motor_hybrid_real in0[6]; uvsym_motor_hybrid_real in1[3]; uvsym_motor_hybrid_real in2[2]; uvsym_motor_hybrid_real in3[1]; uvsym_motor_hybrid_real out0[6]; uvsym_motor_hybrid_real out1[9];
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 3; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 2; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_motor_hybrid_real)v;
      for (i = 0; i < 0; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_motor_hybrid_real)v;
      printf("%d", uvsym_motor_hybrid_corrected_step(in0, in1, in2, in3, out0, out1));
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 9; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    default:
      return 3;
    }
    printf("\n");
  }
  return 0;
}
