/* What the benchmark programs share: a wall clock, a fail-fast status
 * check, the thesis' solid, and a cloth resting on a plate. */
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

/// A size x size cloth of link length 1/63 m (so the same stable step at
/// every size) lying on a ground plate, every particle in contact, after 20
/// warm-up steps of *out_dt = the stable step. Exits on failure.
wc_world *bench_resting_world(int size, int self_collision, int threads, double *out_dt);

/// Exits unless at least half the cloth's particles touch a collider in the
/// last step (the resting scene's cloth must lie on its plate).
void bench_check_resting(const wc_world *w, int size);

#endif
