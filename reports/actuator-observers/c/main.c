/* Example: one call of uvsym_docking_auv_observers_actuator_observers_step on data from the shipped scenario docking_faults (docking_auv), 500 samples from t = 10 s, gains of its time constants (row 0 of the package's example).
   Prints each output on one line: its name, then its entries (units: README.md, manifest.json). */
#include <stdio.h>
#include "uvsym_docking_auv_observers.h"

int main(void) {
  int i, rc;
  static const uvsym_docking_auv_observers_real x[18] = {-281.3020957341389, -674.3072405778087, 0.48542835672139456, 0.0, -0.0863113053374886,
    -64.57253781758082, -328.62385668076195, 46.9705333375691, -0.46936432689196783,
    -0.4753702344387743, -6.694351556043066, -2.590495507669648, -276.3206773815991,
    43.37620892294744, -0.37982863295217084, -0.4753702344387743, -6.622723000891228,
    0.28496402402767984};
  static const uvsym_docking_auv_observers_real eta[6] = {-14.66021114758451, 5.318858088342745, 5.031216896629118, 0.025820751375353106,
    0.0005417510040974712, 0.5758741467352957};
  static const uvsym_docking_auv_observers_real nu[6] = {3.2159288998793407, -0.229458448100767, 0.0023286912798637974, 0.001341365567893832,
    0.001679435218699343, 0.08111395772480857};
  static const uvsym_docking_auv_observers_real tau_d[6] = {52.93262473585168, -3.6490964720924515, 0.08709144934004073, -0.0, 0.06967315947203259,
    2.9192771776739614};
  static const uvsym_docking_auv_observers_real K[18] = {0.052083333333333336, 13.333333333333334, 3.3333333333333335, 333.33333333333326,
    3.3333333333333335, 37.03703703703703, 3.3333333333333335, 3.3333333333333335,
    3.3333333333333335, 3.3333333333333335, 3.3333333333333335, 3.3333333333333335,
    3.3333333333333335, 3.3333333333333335, 3.3333333333333335, 3.3333333333333335,
    3.3333333333333335, 3.3333333333333335};
  static const uvsym_docking_auv_observers_real dt[1] = {0.01};
  uvsym_docking_auv_observers_real x_next[18];
  uvsym_docking_auv_observers_real f_hat[18];
  rc = uvsym_docking_auv_observers_actuator_observers_step(x, eta, nu, tau_d, K, dt, x_next, f_hat);
  if (rc != UVSYM_DOCKING_AUV_OBSERVERS_OK) {
    fprintf(stderr, "uvsym_docking_auv_observers_actuator_observers_step returned %d\n", rc);
    return 1;
  }
  printf("x_next");
  for (i = 0; i < 18; ++i) printf(" %.17g", (double)x_next[i]);
  printf("\n");
  printf("f_hat");
  for (i = 0; i < 18; ++i) printf(" %.17g", (double)f_hat[i]);
  printf("\n");
  return 0;
}
