/* A failed step leaves no trace ("a failing step keeps the last
 * good state"), for each integrator.
 *
 * Two twin worlds, A and B, get the same calls: a soaked, self-colliding
 * cloth pinned at one corner falls onto the thesis' sphere beside a box,
 * frame after frame. Between frames A also gets steps that fail with
 * WC_ERROR_NON_FINITE: every particle thrown at 1e308 m/s for a 10 s step,
 * and one particle moved to 1e300 m so that its links' forces overflow.
 * Each injection is undone through the API (the velocities or positions
 * read before it are set back), and B makes the same set-back calls, so the
 * twins differ only in the failed steps. After each one A must equal B
 * bitwise: positions, velocities, wetness, contacts and their normals,
 * stuck flags, time. And since hidden state (the integrators' buffers, the
 * collision caches, the contact history) must not differ either, the twins
 * then run on and must still be equal at the end.
 *
 * A step whose collisions would tear the cloth is refused the same way and
 * taken again as two half steps (step_guard.h). With every step made to
 * count as tearing (the world's tear ratio at 0), an advance of n steps
 * refuses each one and its halves down to the last halving, 7 refusals per
 * step, and must give the bits of an advance of 8n steps that refused
 * nothing: the refused steps leave no trace either.
 *
 * The out-of-memory failures, which come in every phase of a step, are
 * test_oom's; this test covers the failures a step finds in its numbers. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "scenes.h"
#include "step_guard.h"
#include "test_util.h"
#include "wetcloth.h"
#include "world.h"

#define SIDE 8
#define N (SIDE * SIDE)
#define FRAME (1.0 / 240.0)

static const char *const NAME[] = {"verlet", "xpbd", "implicit"};

/* Everything a user can read of the cloth, for a bitwise comparison. */
typedef struct snapshot {
    double x[3 * N], v[3 * N], wet[N], normal[3 * N];
    uint8_t contact[N], stuck[N];
    double time;
} snapshot;

static void take(wc_world *w, snapshot *s)
{
    memset(s, 0, sizeof *s);
    CHECK(wc_cloth_get_positions(w, 0, s->x, N) == WC_OK, "positions");
    CHECK(wc_cloth_get_velocities(w, 0, s->v, N) == WC_OK, "velocities");
    CHECK(wc_cloth_get_wetness(w, 0, s->wet, N) == WC_OK, "wetness");
    CHECK(wc_cloth_get_contacts(w, 0, s->contact, s->normal, N) == WC_OK, "contacts");
    CHECK(wc_cloth_get_stuck(w, 0, s->stuck, N) == WC_OK, "stuck");
    s->time = wc_world_time(w);
}

static int same(const snapshot *a, const snapshot *b)
{
    return memcmp(a, b, sizeof *a) == 0;
}

static wc_world *twin(wc_integrator integrator)
{
    wc_world_def def = wc_world_def_default();
    def.thread_count = 1;
    def.integrator = integrator;
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(&def, &w, &msg) != WC_OK) {
        fprintf(stderr, "world: %s\n", msg.text);
        exit(1);
    }
    scene_add_thesis_sphere(w, 0.3);
    wc_convex_collider_def box = wc_convex_collider_def_default();
    box.shape = WC_SHAPE_BOX;
    box.position[0] = 0.35;
    box.position[2] = 0.1;
    box.half_extents[0] = box.half_extents[1] = box.half_extents[2] = 0.1;
    int32_t id;
    CHECK(wc_world_add_convex_collider(w, &box, &id) == WC_OK, "box: %s", wc_world_last_error(w));
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = SIDE;
    g.size_u = g.size_v = 0.7;
    g.center[0] = 0.1;
    g.center[2] = 0.31;
    g.self_collision = 1;
    g.wetness = 1.0;
    CHECK(wc_world_add_grid_cloth(w, &g, &id) == WC_OK, "cloth: %s", wc_world_last_error(w));
    int32_t corner = 0;
    CHECK(wc_cloth_pin(w, 0, &corner, 1) == WC_OK, "pin: %s", wc_world_last_error(w));
    return w;
}

static void frames(wc_world *a, wc_world *b, int count, const char *name)
{
    for (int f = 0; f < count; ++f) {
        CHECK(wc_world_advance(a, FRAME, 0) == WC_OK, "%s A: %s", name, wc_world_last_error(a));
        CHECK(wc_world_advance(b, FRAME, 0) == WC_OK, "%s B: %s", name, wc_world_last_error(b));
    }
}

/* The failing step must say so, with a message, and change nothing. */
static void expect_failure(wc_world *a, wc_status got, const snapshot *before, const char *what,
                           const char *name)
{
    CHECK(got == WC_ERROR_NON_FINITE, "%s, %s: status %s, expected %s", name, what,
          wc_status_name(got), wc_status_name(WC_ERROR_NON_FINITE));
    CHECK(wc_world_last_error(a)[0] != '\0', "%s, %s: no message", name, what);
    snapshot after;
    take(a, &after);
    CHECK(same(before, &after), "%s, %s: the failed step changed the cloth", name, what);
}

/* Every particle at 1e308 m/s for a 10 s step: the positions overflow in
 * the integration. */
static void fail_by_speed(wc_world *a, wc_world *b, const char *name)
{
    static double v[3 * N], fast[3 * N];
    CHECK(wc_cloth_get_velocities(a, 0, v, N) == WC_OK, "velocities");
    for (int i = 0; i < 3 * N; ++i) fast[i] = i % 3 == 2 ? -1e308 : 1e308;
    CHECK(wc_cloth_set_velocities(a, 0, fast, N) == WC_OK, "%s: %s", name, wc_world_last_error(a));
    snapshot before;
    take(a, &before);
    expect_failure(a, wc_world_step(a, 10.0), &before, "1e308 m/s for 10 s", name);
    CHECK(wc_cloth_set_velocities(a, 0, v, N) == WC_OK, "%s: %s", name, wc_world_last_error(a));
    CHECK(wc_cloth_get_velocities(b, 0, v, N) == WC_OK, "velocities");
    CHECK(wc_cloth_set_velocities(b, 0, v, N) == WC_OK, "%s: %s", name, wc_world_last_error(b));
}

/* One particle at 1e300 m: its links' squared lengths overflow in the
 * forces. wc_cloth_set_positions zeroes velocities, so both twins set
 * positions and velocities back. */
static void fail_by_distance(wc_world *a, wc_world *b, const char *name)
{
    static double x[3 * N], v[3 * N], far[3 * N];
    wc_world *w[2] = {a, b};
    CHECK(wc_cloth_get_positions(a, 0, x, N) == WC_OK, "positions");
    CHECK(wc_cloth_get_velocities(a, 0, v, N) == WC_OK, "velocities");
    memcpy(far, x, sizeof far);
    far[3 * (N / 2) + 2] = 1e300;
    CHECK(wc_cloth_set_positions(a, 0, far, N) == WC_OK, "%s: %s", name, wc_world_last_error(a));
    snapshot before;
    take(a, &before);
    expect_failure(a, wc_world_step(a, 1e-4), &before, "a particle at 1e300 m", name);
    /* A's positions are still `far`: both twins take B's state */
    CHECK(wc_cloth_get_positions(b, 0, x, N) == WC_OK, "positions");
    CHECK(wc_cloth_get_velocities(b, 0, v, N) == WC_OK, "velocities");
    for (int k = 0; k < 2; ++k) {
        CHECK(wc_cloth_set_positions(w[k], 0, x, N) == WC_OK, "%s: %s", name,
              wc_world_last_error(w[k]));
        CHECK(wc_cloth_set_velocities(w[k], 0, v, N) == WC_OK, "%s: %s", name,
              wc_world_last_error(w[k]));
    }
}

static void compare(wc_world *a, wc_world *b, const char *when, const char *name)
{
    snapshot sa, sb;
    take(a, &sa);
    take(b, &sb);
    CHECK(same(&sa, &sb), "%s: after %s the twins differ", name, when);
}

static void run(wc_integrator integrator)
{
    const char *name = NAME[integrator];
    wc_world *a = twin(integrator), *b = twin(integrator);
    frames(a, b, 24, name);
    snapshot s;
    take(a, &s);
    int touching = 0;
    for (int i = 0; i < N; ++i) touching += s.contact[i] != 0;
    CHECK(touching > 0, "%s: the cloth should touch the sphere by now", name);
    fail_by_speed(a, b, name);
    compare(a, b, "a step that overflowed in the integration", name);
    frames(a, b, 6, name);
    fail_by_distance(a, b, name);
    compare(a, b, "a step whose forces overflowed", name);
    frames(a, b, 12, name);
    compare(a, b, "the frames after the failed steps", name);
    printf("%s: %d particles touching at the first failure; failed steps left no trace\n", name,
           touching);
    wc_world_destroy(a);
    wc_world_destroy(b);
}

/* The tear criterion on one link of a 3 x 3 cloth, its second particle
 * moved along it: at the start (x) to `from`, at the end (nx) to `to`
 * times its rest length. */
static int32_t tears_at(wc_world *w, double from, double to)
{
    wc_cloth *c = w->cloths[0];
    const wc_link_set *l = &c->topology.stretch;
    int32_t a = l->a[0], b = l->b[0];
    double *pos[3] = {c->x, c->y, c->z}, *end[3] = {c->nx, c->ny, c->nz}, d[3];
    double len = 0.0;
    for (int k = 0; k < 3; ++k) d[k] = pos[k][b] - pos[k][a], len += d[k] * d[k];
    len = sqrt(len);
    static double keep[3][N];
    for (int k = 0; k < 3; ++k) memcpy(keep[k], pos[k], (size_t)c->particle_count * sizeof(double));
    for (int k = 0; k < 3; ++k) {
        pos[k][b] = pos[k][a] + d[k] / len * from * l->rest[0];
        memcpy(end[k], pos[k], (size_t)c->particle_count * sizeof(double));
        end[k][b] = pos[k][a] + d[k] / len * to * l->rest[0];
    }
    int32_t e = wci_step_tears(c, WC_TEAR_RATIO, WC_TEAR_GROWTH, 2);
    for (int k = 0; k < 3; ++k) memcpy(pos[k], keep[k], (size_t)c->particle_count * sizeof(double));
    return e;
}

static void tear_criterion(void)
{
    wc_world *w = scene_world(1);
    wc_grid_cloth_def g = wc_grid_cloth_def_default();
    g.count_u = g.count_v = 3;
    int32_t cl;
    CHECK(wc_world_add_grid_cloth(w, &g, &cl) == WC_OK, "%s", wc_world_last_error(w));
    CHECK(tears_at(w, 1.0, 1.6) == 0, "1.0 to 1.6 times the rest length in a step must tear");
    CHECK(tears_at(w, 1.0, 1.45) < 0, "1.0 to 1.45 (under the ratio) must not tear");
    CHECK(tears_at(w, 1.2, 1.6) < 0, "1.2 to 1.6 (growth under a half) must not tear");
    CHECK(tears_at(w, 1.6, 3.0) == 0, "1.6 to 3.0 in a step must tear");
    CHECK(tears_at(w, 1.0, 1.0) < 0, "a link at rest must not tear");
    wc_world_destroy(w);
}

/* Twin A refuses every step down to the last halving; twin B takes the
 * steps A ends with, 8 times as many, and refuses none. n is a power of two
 * (the pins' fractions and the steps then halve exactly) at which A's
 * first, refused, steps are within the stable step (Verlet's guard would
 * fail them otherwise). */
static void refused_steps(wc_integrator integrator)
{
    const char *name = NAME[integrator];
    wc_world *a = twin(integrator), *b = twin(integrator);
    a->tear_ratio = 0.0, a->tear_growth = -INFINITY;
    int32_t n = 1;
    while (FRAME / n > 0.9 * wc_world_stable_dt(a)) n *= 2;
    int32_t halvings = (1 << WC_TEAR_HALVINGS) - 1, wrong_count = 0;
    for (int f = 0; f < 30; ++f) {
        CHECK(wc_world_advance(a, FRAME, n) == WC_OK, "%s A: %s", name, wc_world_last_error(a));
        CHECK(wc_world_advance(b, FRAME, 8 * n) == WC_OK, "%s B: %s", name, wc_world_last_error(b));
        wrong_count += wc_world_get_stats(a).halved_steps != halvings * n ||
                       wc_world_get_stats(b).halved_steps != 0;
    }
    CHECK(wrong_count == 0, "%s: %d frames where A did not halve %d times per step or B halved",
          name, wrong_count, (int)halvings);
    snapshot s;
    take(a, &s);
    int touching = 0;
    for (int i = 0; i < N; ++i) touching += s.contact[i] != 0;
    CHECK(touching > 0, "%s: the cloth should touch the sphere by now", name);
    compare(a, b, "30 frames of steps refused and halved", name);
    printf("%s: %d steps per frame each refused %d times, %d particles touching: the bits of %d "
           "steps per frame\n", name, (int)n, (int)halvings, touching, (int)(8 * n));
    wc_world_destroy(a);
    wc_world_destroy(b);
}

int main(void)
{
    run(WC_INTEGRATOR_VERLET);
    run(WC_INTEGRATOR_XPBD);
    run(WC_INTEGRATOR_IMPLICIT);
    tear_criterion();
    refused_steps(WC_INTEGRATOR_VERLET);
    refused_steps(WC_INTEGRATOR_XPBD);
    refused_steps(WC_INTEGRATOR_IMPLICIT);
    return test_report("test_failed_step");
}
