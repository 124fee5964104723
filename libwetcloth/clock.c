/* clock_gettime is POSIX, not C99: ask for it here, in this file only. */
#define _POSIX_C_SOURCE 199309L
#include "clock.h"

#include <time.h>

double wc_clock_seconds(void)
{
    struct timespec t;
    if (clock_gettime(CLOCK_MONOTONIC, &t) != 0) return 0.0;
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
