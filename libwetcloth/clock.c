/* clock_gettime is POSIX, not C99: ask for it here, in this file only.
 * Windows has no clock_gettime in its C runtime (MinGW's comes from
 * libwinpthread): there the performance counter is read instead. */
#define _POSIX_C_SOURCE 199309L
#include "clock.h"

#ifdef _WIN32
#define WIN32_LEAN_AND_MEAN
#include <windows.h>

double wci_clock_seconds(void)
{
    LARGE_INTEGER frequency, count;
    if (!QueryPerformanceFrequency(&frequency) || !QueryPerformanceCounter(&count)) return 0.0;
    return (double)count.QuadPart / (double)frequency.QuadPart;
}
#else
#include <time.h>

double wci_clock_seconds(void)
{
    struct timespec t;
    if (clock_gettime(CLOCK_MONOTONIC, &t) != 0) return 0.0;
    return (double)t.tv_sec + 1e-9 * (double)t.tv_nsec;
}
#endif
