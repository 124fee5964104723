/* What the benchmark programs share: a wall clock, a fail-fast status
 * check, and the thesis' solid. */
#ifndef WC_BENCH_UTIL_H
#define WC_BENCH_UTIL_H

#include "wetcloth.h"

/// Seconds on a monotonic clock.
double bench_now(void);

/// Exits with a message naming `what` (and the world's last error) unless s is WC_OK.
void bench_check(wc_status s, const wc_world *w, const char *what);

/// Adds the thesis' solid as a mesh collider: a UV sphere of radius 0.3 m at
/// the origin, 16 segments x 8 rings = 114 vertices, 224 triangles.
void bench_add_thesis_sphere(wc_world *w);

#endif
