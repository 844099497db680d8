/* Test harness: each record on stdin is a function index then its inputs, all as text;
   prints that function's return code, then its outputs, on one line. Used to compare C with Python. */
#include <stdio.h>
#include "uvsym_sensor_fdi_lms.h"

int main(void) {
  int index;
  double v;
  int i;
  while (scanf("%d", &index) == 1) {
    switch (index) {
    case 0: {
      uvsym_sensor_fdi_lms_real in0[235]; uvsym_sensor_fdi_lms_real in1[1]; uvsym_sensor_fdi_lms_real in2[2]; uvsym_sensor_fdi_lms_real in3[3]; uvsym_sensor_fdi_lms_real out0[235]; uvsym_sensor_fdi_lms_real out1[10];
      for (i = 0; i < 235; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_sensor_fdi_lms_real)v;
      for (i = 0; i < 1; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_sensor_fdi_lms_real)v;
      for (i = 0; i < 2; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_sensor_fdi_lms_real)v;
      for (i = 0; i < 3; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_sensor_fdi_lms_real)v;
      printf("%d", uvsym_sensor_fdi_lms_lms_step(in0, in1, in2, in3, out0, out1));
      for (i = 0; i < 235; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 10; ++i) printf(" %.17g", (double)out1[i]);
      break;
    }
    case 1: {
      uvsym_sensor_fdi_lms_real in0[70]; uvsym_sensor_fdi_lms_real in1[70]; uvsym_sensor_fdi_lms_real in2[1]; uvsym_sensor_fdi_lms_real in3[1]; uvsym_sensor_fdi_lms_real in4[1]; uvsym_sensor_fdi_lms_real out0[70]; uvsym_sensor_fdi_lms_real out1[70]; uvsym_sensor_fdi_lms_real out2[1]; uvsym_sensor_fdi_lms_real out3[1];
      for (i = 0; i < 70; ++i) if (scanf("%lf", &v) != 1) return 1; else in0[i] = (uvsym_sensor_fdi_lms_real)v;
      for (i = 0; i < 70; ++i) if (scanf("%lf", &v) != 1) return 1; else in1[i] = (uvsym_sensor_fdi_lms_real)v;
      for (i = 0; i < 1; ++i) if (scanf("%lf", &v) != 1) return 1; else in2[i] = (uvsym_sensor_fdi_lms_real)v;
      for (i = 0; i < 1; ++i) if (scanf("%lf", &v) != 1) return 1; else in3[i] = (uvsym_sensor_fdi_lms_real)v;
      for (i = 0; i < 1; ++i) if (scanf("%lf", &v) != 1) return 1; else in4[i] = (uvsym_sensor_fdi_lms_real)v;
      printf("%d", uvsym_sensor_fdi_lms_lms_fir_step(in0, in1, in2, in3, in4, out0, out1, out2, out3));
      for (i = 0; i < 70; ++i) printf(" %.17g", (double)out0[i]);
      for (i = 0; i < 70; ++i) printf(" %.17g", (double)out1[i]);
      for (i = 0; i < 1; ++i) printf(" %.17g", (double)out2[i]);
      for (i = 0; i < 1; ++i) printf(" %.17g", (double)out3[i]);
      break;
    }
    default:
      return 3;
    }
    printf("\n");
  }
  return 0;
}
