#include <math.h>

#include "buckling.h"
#include "test_util.h"

int main(void)
{
    double r[] = {1 - 1e-15, 1 - 1e-8, 0.5, 1e-9, 0};
    for (int i = 0; i < 5; ++i) {
        double t = wc_inverse_sinc(r[i]);
        double back = t == 0 ? 1.0 : sin(t) / t;
        printf("r=%.17g theta=%.17g sinc=%.17g\n", r[i], t, back);
        CHECK(fabs(back - r[i]) <= 4e-16, "r=%g", r[i]);
    }
    printf("phi(0)=%.17g phi(pi)=%.17g\n", wc_buckling_phi(0), wc_buckling_phi(3.141592653589793));
    return test_report("test_buckling");
}
