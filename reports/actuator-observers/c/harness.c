/* Test harness: each record on stdin is a function index then its inputs, all as text;
   prints that function's return code, then its outputs, on one line. Used to compare C with Python. */
#include <stdio.h>
#include "uvsym_docking_auv_observers.h"

int main(void) {
  int index;
  double v;
  int i;
  while (scanf("%d", &index) == 1) {
    switch (index) {
    case 0: {
      uvsym_docking_auv_observers_real in0[6]; uvsym_docking_auv_observers_real in1[6]; uvsym_docking_auv_observers_real in2[6]; uvsym_docking_auv_observers_real in3[6]; uvsym_docking_auv_observers_real in4[6]; uvsym_docking_auv_observers_real out0[6]; uvsym_docking_auv_observers_real out1[6];
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in4[i] = (uvsym_docking_auv_observers_real)v;
      printf("%d", uvsym_docking_auv_observers_proportional_observer(in0, in1, in2, in3, in4, out0, out1));
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 1: {
      uvsym_docking_auv_observers_real in0[6]; uvsym_docking_auv_observers_real in1[6]; uvsym_docking_auv_observers_real in2[6]; uvsym_docking_auv_observers_real in3[6]; uvsym_docking_auv_observers_real in4[6]; uvsym_docking_auv_observers_real in5[1]; uvsym_docking_auv_observers_real out0[6]; uvsym_docking_auv_observers_real out1[6];
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in4[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 1; ++i) if (scanf("%lf", &v) != 1) return 1; else in5[i] = (uvsym_docking_auv_observers_real)v;
      printf("%d", uvsym_docking_auv_observers_proportional_step(in0, in1, in2, in3, in4, in5, out0, out1));
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 2: {
      uvsym_docking_auv_observers_real in0[6]; uvsym_docking_auv_observers_real in1[6]; uvsym_docking_auv_observers_real in2[6]; uvsym_docking_auv_observers_real in3[6]; uvsym_docking_auv_observers_real in4[6]; uvsym_docking_auv_observers_real out0[6]; uvsym_docking_auv_observers_real out1[6];
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in4[i] = (uvsym_docking_auv_observers_real)v;
      printf("%d", uvsym_docking_auv_observers_bias_observer(in0, in1, in2, in3, in4, out0, out1));
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 3: {
      uvsym_docking_auv_observers_real in0[6]; uvsym_docking_auv_observers_real in1[6]; uvsym_docking_auv_observers_real in2[6]; uvsym_docking_auv_observers_real in3[6]; uvsym_docking_auv_observers_real in4[6]; uvsym_docking_auv_observers_real in5[1]; uvsym_docking_auv_observers_real out0[6]; uvsym_docking_auv_observers_real out1[6];
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in4[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 1; ++i) if (scanf("%lf", &v) != 1) return 1; else in5[i] = (uvsym_docking_auv_observers_real)v;
      printf("%d", uvsym_docking_auv_observers_bias_step(in0, in1, in2, in3, in4, in5, out0, out1));
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 4: {
      uvsym_docking_auv_observers_real in0[6]; uvsym_docking_auv_observers_real in1[6]; uvsym_docking_auv_observers_real in2[6]; uvsym_docking_auv_observers_real in3[6]; uvsym_docking_auv_observers_real in4[6]; uvsym_docking_auv_observers_real out0[6]; uvsym_docking_auv_observers_real out1[6];
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in4[i] = (uvsym_docking_auv_observers_real)v;
      printf("%d", uvsym_docking_auv_observers_constant_observer(in0, in1, in2, in3, in4, out0, out1));
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 5: {
      uvsym_docking_auv_observers_real in0[6]; uvsym_docking_auv_observers_real in1[6]; uvsym_docking_auv_observers_real in2[6]; uvsym_docking_auv_observers_real in3[6]; uvsym_docking_auv_observers_real in4[6]; uvsym_docking_auv_observers_real in5[1]; uvsym_docking_auv_observers_real out0[6]; uvsym_docking_auv_observers_real out1[6];
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in4[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 1; ++i) if (scanf("%lf", &v) != 1) return 1; else in5[i] = (uvsym_docking_auv_observers_real)v;
      printf("%d", uvsym_docking_auv_observers_constant_step(in0, in1, in2, in3, in4, in5, out0, out1));
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 6; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 6: {
      uvsym_docking_auv_observers_real in0[18]; uvsym_docking_auv_observers_real in1[6]; uvsym_docking_auv_observers_real in2[6]; uvsym_docking_auv_observers_real in3[6]; uvsym_docking_auv_observers_real in4[18]; uvsym_docking_auv_observers_real in5[1]; uvsym_docking_auv_observers_real out0[18]; uvsym_docking_auv_observers_real out1[18];
      for (i = 0; i < 18; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 6; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 18; ++i) if (scanf("%lf", &v) != 1) return 1; else in4[i] = (uvsym_docking_auv_observers_real)v;
      for (i = 0; i < 1; ++i) if (scanf("%lf", &v) != 1) return 1; else in5[i] = (uvsym_docking_auv_observers_real)v;
      printf("%d", uvsym_docking_auv_observers_actuator_observers_step(in0, in1, in2, in3, in4, in5, out0, out1));
      for (i = 0; i < 18; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 18; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    default:
      return 3;
    }
    printf("\n");
  }
  return 0;
}
