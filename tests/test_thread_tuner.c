/* The thread tuner (libwetcloth/thread_tuner.h), fed with made-up step
 * times: it keeps the count that is faster, finds it again when the
 * machine changes, and probes rarely once a count keeps winning. And a
 * world whose thread count changes from step to step ends bitwise where a
 * one-thread world ends (which is why the tuner may change it at all). */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "test_util.h"
#include "clock.h"
#include "idle_cores.h"
#include "thread_tuner.h"
#include "wetcloth.h"
#include "world.h"

/* Step time on `threads` threads for a machine where `free_cores` cores
 * are free: the work splits over the threads that find a core, and every
 * thread beyond the free cores costs a scheduler tick at each barrier. */
static double step_time(int32_t threads, int32_t free_cores, double work, double tick)
{
    int32_t running = threads < free_cores ? threads : free_cores;
    return work / running + (threads > free_cores ? tick : 0.0);
}

typedef struct {
    int32_t steps_at[17]; /* steps run on each count, 1 .. 16 */
    int32_t last;         /* the count of the last step */
} run_log;

static run_log drive(wc_thread_tuner *t, int32_t steps, int32_t free_cores, double work,
                     double tick)
{
    run_log log;
    memset(&log, 0, sizeof log);
    for (int32_t s = 0; s < steps; ++s) {
        int32_t n = wci_thread_tuner_threads(t);
        CHECK(n >= 1 && n <= t->most, "step %d: %d threads of at most %d", s, n, t->most);
        ++log.steps_at[n];
        log.last = n;
        wci_thread_tuner_record(t, step_time(n, free_cores, work, tick));
    }
    return log;
}

/* An idle 2-core machine: the world starts on 1 thread, finds 2 faster
 * and stays there; the probes of 1 thread grow rare. */
static void idle_machine_keeps_two(void)
{
    wc_thread_tuner t;
    wci_thread_tuner_create(&t, 2, 1);
    run_log log = drive(&t, 5000, 2, 0.020, 0.004);
    printf("idle 2 cores: %d steps on 2 threads, %d on 1\n", log.steps_at[2], log.steps_at[1]);
    CHECK(log.last == 2, "ended on %d threads", log.last);
    /* the first 12 steps (2 of warm-up, 2 more to fill the samples, 8
     * before the first probe) and that probe's 4 on one thread, then
     * probes of 4 steps on 1, the period doubling from 32 to 1024: 8 of
     * them in 5000 steps */
    CHECK(log.steps_at[1] <= 12 + 4 + 4 * 8, "%d steps on 1 thread", log.steps_at[1]);
    CHECK(t.period == 1024, "period %d", (int)t.period);
}

/* One core busy with another program: 2 threads pay a tick per step and are
 * slower than 1; the tuner moves to 1 within its first probe, and back to 2
 * when the other program ends. */
static void busy_core_moves_to_one_and_back(void)
{
    wc_thread_tuner t;
    wci_thread_tuner_create(&t, 2, 1);
    run_log busy = drive(&t, 2000, 1, 0.020, 0.030);
    printf("one core busy: %d steps on 2 threads, %d on 1\n", busy.steps_at[2], busy.steps_at[1]);
    CHECK(busy.last == 1, "busy: ended on %d threads", busy.last);
    CHECK(busy.steps_at[2] < 60, "busy: %d steps on the slower 2 threads", busy.steps_at[2]);
    run_log idle = drive(&t, 4000, 2, 0.020, 0.030);
    printf("then idle: %d steps on 2 threads, %d on 1\n", idle.steps_at[2], idle.steps_at[1]);
    CHECK(idle.last == 2, "idle again: ended on %d threads", idle.last);
    /* the probe period had grown to 1024 while 2 threads kept losing */
    CHECK(idle.steps_at[2] > 2500, "idle again: only %d steps on 2 threads", idle.steps_at[2]);
}

/* A probe whose first step on the probed count takes more than twice the
 * chosen count's ends there, lost: one step on the slow count, not four,
 * and the next probe waits until that step's extra cost is 5 % of the
 * steps between (here 100 ms extra = 5 chosen steps, so 100 steps, more
 * than the doubled period of 64). A probe that is merely slower runs all
 * its steps. */
static void clearly_lost_probe_ends_at_once(void)
{
    wc_thread_tuner t;
    wci_thread_tuner_create(&t, 2, 1);
    int32_t on_two = 0, steps = 0;
    while (!t.probed) {
        wci_thread_tuner_record(&t, 0.020);
        ++steps;
    }
    /* 2 of warm-up, 2 more to fill the samples, then FIRST_PROBE */
    CHECK(steps == 12, "probe after %d steps", (int)steps);
    for (int k = 0; k < 8 && (t.probed || k == 0); ++k) {
        int32_t n = wci_thread_tuner_threads(&t);
        on_two += n == 2;
        wci_thread_tuner_record(&t, n == 2 ? 0.120 : 0.020);
    }
    CHECK(on_two == 1 && t.probed == 0 && t.chosen == 1 && wci_thread_tuner_threads(&t) == 1,
          "%d steps on 2 threads, probing %d, chosen %d", (int)on_two, (int)t.probed, (int)t.chosen);
    CHECK(t.until_probe == 100 && t.period == 100, "next probe in %d, period %d",
          (int)t.until_probe, (int)t.period);
    /* 1.5 times slower: not clearly lost, the probe runs its 4 steps */
    wci_thread_tuner_create(&t, 2, 1);
    while (!t.probed) wci_thread_tuner_record(&t, 0.020);
    on_two = 0;
    while (t.probed) {
        int32_t n = wci_thread_tuner_threads(&t);
        on_two += n == 2;
        wci_thread_tuner_record(&t, n == 2 ? 0.030 : 0.020);
    }
    CHECK(on_two == 4 && t.chosen == 1, "%d steps on 2 threads, chosen %d", (int)on_two,
          (int)t.chosen);
}

/* A tuner settled on 2 threads of 2 (first stages of 0.6 ms and steps of
 * 12 ms on 2 threads, 1 ms and 20 ms on 1), at the start of a probe of 1. */
static void settled_on_two(wc_thread_tuner *t, double two_stage)
{
    wci_thread_tuner_create(t, 2, 1);
    for (int32_t s = 0; s < 100000 && !(t->chosen == 2 && t->probed == 1); ++s) {
        int32_t n = wci_thread_tuner_threads(t);
        n = wci_thread_tuner_first_stage(t, n == 2 ? two_stage : 0.001);
        wci_thread_tuner_record(t, n == 2 ? 0.012 : 0.020);
    }
    CHECK(t->chosen == 2 && t->probed == 1, "not settled on 2 threads: chosen %d, probing %d",
          (int)t->chosen, (int)t->probed);
}

/* A probe of fewer threads whose first stage (the forces) takes more than
 * 1.25 times the chosen count's ends after that stage: the rest of the
 * step runs on the chosen count, that step's time is no sample, and the
 * next probe comes after the doubled period. A first stage that is not
 * that much slower, or too short to tell (under 0.5 ms on the chosen
 * count), lets the probe go on; and a probe of more threads is never ended
 * by its first stage (its new threads start with cold caches). */
static void lost_first_stage_ends_the_probe(void)
{
    wc_thread_tuner t;
    settled_on_two(&t, 0.0006);
    int32_t period = t.period;
    CHECK(wci_thread_tuner_threads(&t) == 2 && wci_thread_tuner_first_stage(&t, 0.0006) == 2,
          "the probe's first step is not on the chosen 2 threads");
    wci_thread_tuner_record(&t, 0.012);
    CHECK(wci_thread_tuner_threads(&t) == 1, "the probe's second step on %d threads",
          (int)wci_thread_tuner_threads(&t));
    CHECK(wci_thread_tuner_first_stage(&t, 0.001) == 2, "the rest of the step not on 2 threads");
    int32_t recent = t.recent_next;
    wci_thread_tuner_record(&t, 0.016);
    CHECK(!t.probed && t.chosen == 2 && t.recent_next == recent && !t.skip_record,
          "after the lost stage: probing %d, chosen %d, the mixed step a sample: %d", (int)t.probed,
          (int)t.chosen, t.recent_next != recent);
    CHECK(t.period == (2 * period < 1024 ? 2 * period : 1024) && t.until_probe == t.period,
          "period %d (was %d), next probe in %d", (int)t.period, (int)period, (int)t.until_probe);
    /* 1.2 times as long: the step goes on on 1 thread */
    settled_on_two(&t, 0.0006);
    wci_thread_tuner_first_stage(&t, 0.0006);
    wci_thread_tuner_record(&t, 0.012);
    CHECK(wci_thread_tuner_first_stage(&t, 0.00072) == 1, "a first stage 1.2x as long ended it");
    /* too short to tell */
    settled_on_two(&t, 0.0002);
    wci_thread_tuner_first_stage(&t, 0.0002);
    wci_thread_tuner_record(&t, 0.012);
    CHECK(wci_thread_tuner_first_stage(&t, 0.0004) == 1, "a 0.2 ms first stage ended it");
    /* a probe of more threads, its first stage 3 times one thread's */
    wci_thread_tuner_create(&t, 2, 1);
    while (!t.probed) {
        wci_thread_tuner_first_stage(&t, 0.001);
        wci_thread_tuner_record(&t, 0.020);
    }
    wci_thread_tuner_first_stage(&t, 0.001);
    wci_thread_tuner_record(&t, 0.020);
    CHECK(wci_thread_tuner_threads(&t) == 2 && wci_thread_tuner_first_stage(&t, 0.003) == 2,
          "a probe of more threads ended by its first stage");
}

/* The machine's idle cores, made up: a probe of more threads runs only
 * when at least half a core per added thread sat idle. */
static double made_up_spare;
static double spare_of(void *context)
{
    (void)context;
    return made_up_spare;
}

/* One core busy and the system saying so: no step ever runs on 2 threads
 * (the probes are skipped at no cost), and once the count shows an idle
 * core the next probe runs and wins. Where the count comes too soon the
 * probe waits; where it is unknown the probe runs as without it. */
static void busy_cores_skip_the_probe(void)
{
    wc_thread_tuner t;
    wci_thread_tuner_create(&t, 2, 1);
    t.spare_cores = spare_of;
    made_up_spare = 0.05;
    run_log busy = drive(&t, 2000, 1, 0.020, 0.030);
    printf("one core busy, counted: %d steps on 2 threads, period %d\n", busy.steps_at[2],
           (int)t.period);
    CHECK(busy.steps_at[2] == 0, "busy: %d steps on 2 threads", busy.steps_at[2]);
    CHECK(t.period == 1024, "busy: period %d", (int)t.period);
    made_up_spare = 0.95;
    run_log idle = drive(&t, 2000, 2, 0.020, 0.030);
    /* the next probe comes within the period, 1,024 steps, and takes 8 */
    CHECK(idle.last == 2 && idle.steps_at[2] >= 2000 - 1024 - 8 - WC_TUNER_SAMPLES - 8,
          "idle again: %d steps on 2, last %d", idle.steps_at[2], idle.last);
    /* too soon to tell: the first probe waits 8 steps more, then runs */
    wci_thread_tuner_create(&t, 2, 1);
    t.spare_cores = spare_of;
    made_up_spare = WC_IDLE_TOO_SOON;
    int32_t steps = 0;
    for (; steps < 12; ++steps) wci_thread_tuner_record(&t, 0.020);
    CHECK(!t.probed && t.until_probe == 8, "too soon: probing %d, next in %d", (int)t.probed,
          (int)t.until_probe);
    made_up_spare = WC_IDLE_UNKNOWN;
    for (; steps < 20; ++steps) wci_thread_tuner_record(&t, 0.020);
    CHECK(t.probed == 2, "unknown: no probe after %d steps", (int)steps);
}

/* The system's count over a tenth of a second in which this thread kept a
 * core busy: at least one core fewer than the machine has were idle. Too
 * soon after, it says so. */
static void idle_meter_counts_a_busy_core(void)
{
    wc_idle_meter m;
    wci_idle_meter_start(&m);
    double start = wci_clock_seconds(), spin = 0.0;
    double at_once = wci_idle_meter_read(&m);
    CHECK(at_once == WC_IDLE_TOO_SOON || (at_once == WC_IDLE_UNKNOWN && !m.known),
          "a read at once gave %g, not too soon", at_once);
    while (wci_clock_seconds() - start < 1.5 * WC_IDLE_MIN_WINDOW) spin += 1.0;
    double spare = wci_idle_meter_read(&m);
    int processors = 0;
#ifdef __linux__
    FILE *f = fopen("/proc/stat", "r");
    char line[4096];
    while (f && fgets(line, sizeof line, f))
        if (!strncmp(line, "cpu", 3) && line[3] >= '0' && line[3] <= '9') ++processors;
    if (f) fclose(f);
    CHECK(spare != WC_IDLE_UNKNOWN, "no count on Linux");
#endif
    printf("idle cores while one spun (%.0f turns): %g of %d\n", spin, spare, processors);
    if (spare == WC_IDLE_UNKNOWN) return;
    CHECK(spare >= 0.0, "%g idle cores", spare);
    /* a 10 ms tick per processor over 0.15 s: within 0.07 cores each */
    if (processors > 0)
        CHECK(spare <= processors - 1 + 0.07 * processors, "%g idle cores of %d while one spun",
              spare, processors);
}

/* The machine gets busy after the tuner had settled on 2 threads with a
 * long probe period: the slowdown brings the probe forward. */
static void slowdown_brings_the_probe_forward(void)
{
    wc_thread_tuner t;
    wci_thread_tuner_create(&t, 2, 1);
    drive(&t, 20000, 2, 0.020, 0.030);
    CHECK(t.period == 1024 && wci_thread_tuner_threads(&t) == 2, "settled: period %d, %d threads",
          (int)t.period, (int)wci_thread_tuner_threads(&t));
    run_log busy = drive(&t, 100, 1, 0.020, 0.030);
    printf("busy after settling: %d of 100 steps on 2 threads\n", busy.steps_at[2]);
    /* 3 steps to see the slowdown, a probe's 4 on the chosen count, and at
     * most 3 more before the slowdown shows in the median */
    CHECK(busy.last == 1 && busy.steps_at[2] <= 12, "%d steps on 2 threads, last %d",
          busy.steps_at[2], busy.last);
}

/* 16 threads on a machine with 5 free cores: the ladder 16, 8, 4 finds 4
 * (of the powers of two, the fastest: 8 threads would pay the tick). */
static void sixteen_threads_find_the_free_cores(void)
{
    wc_thread_tuner t;
    wci_thread_tuner_create(&t, 16, 1);
    run_log log = drive(&t, 3000, 5, 0.080, 0.030);
    printf("16 threads, 5 free cores: last %d; steps on 16/8/4/2/1: %d/%d/%d/%d/%d\n", log.last,
           log.steps_at[16], log.steps_at[8], log.steps_at[4], log.steps_at[2], log.steps_at[1]);
    CHECK(log.last == 4, "ended on %d threads", log.last);
    CHECK(log.steps_at[4] > 2500, "only %d steps on 4 threads", log.steps_at[4]);
}

/* More threads are taken only when clearly faster, fewer when no slower. */
static void ties_go_to_fewer_threads(void)
{
    wc_thread_tuner t;
    wci_thread_tuner_create(&t, 2, 1);
    for (int32_t s = 0; s < 500; ++s) wci_thread_tuner_record(&t, 0.01);
    CHECK(t.chosen == 1, "equal times: %d threads chosen", (int)t.chosen);
}

static void off_or_one_thread_never_changes(void)
{
    wc_thread_tuner t;
    wci_thread_tuner_create(&t, 4, 0);
    run_log log = drive(&t, 500, 1, 0.02, 0.03);
    CHECK(log.steps_at[4] == 500, "adapt off: %d of 500 steps on 4 threads", log.steps_at[4]);
    wci_thread_tuner_create(&t, 1, 1);
    log = drive(&t, 500, 4, 0.02, 0.03);
    CHECK(log.steps_at[1] == 500, "one thread: %d of 500 steps on it", log.steps_at[1]);
}

/* A world whose steps run on 1, 2, 4, 3, ... threads in turn ends where a
 * one-thread world ends, bit for bit (with self-collision and a collider). */
static uint64_t run_world(int32_t switching)
{
    wc_world_def wd = wc_world_def_default();
    wd.thread_count = 4;
    wd.adapt_threads = 0;
    wd.integrator = WC_INTEGRATOR_IMPLICIT;
    wc_world *w = NULL;
    wc_message msg;
    if (wc_world_create(&wd, &w, &msg) != WC_OK) {
        CHECK(0, "world: %s", msg.text);
        return 0;
    }
    wc_grid_cloth_def def = wc_grid_cloth_def_default();
    def.count_u = def.count_v = 72; /* above the threshold of the threaded loops */
    def.center[2] = 0.4;
    def.self_collision = 1;
    int32_t id = -1;
    CHECK(wc_world_add_grid_cloth(w, &def, &id) == WC_OK, "grid: %s", wc_world_last_error(w));
    wc_convex_collider_def sphere = wc_convex_collider_def_default();
    sphere.radius = 0.3;
    int32_t collider = -1;
    CHECK(wc_world_add_convex_collider(w, &sphere, &collider) == WC_OK, "sphere: %s",
          wc_world_last_error(w));
    static const int32_t counts[4] = {1, 2, 4, 3};
    for (int32_t s = 0; s < 24; ++s) {
        w->tuner.current = switching ? counts[s % 4] : 1;
        CHECK(wc_world_advance(w, 1.0 / 240.0, 1) == WC_OK, "step %d: %s", s,
              wc_world_last_error(w));
        CHECK(wc_world_get_stats(w).threads == w->tuner.current, "step %d ran on %d threads", s,
              wc_world_get_stats(w).threads);
    }
    int32_t n = wc_cloth_particle_count(w, id);
    double *x = malloc(3 * (size_t)n * sizeof *x);
    wc_cloth_get_positions(w, id, x, n);
    uint64_t h = 14695981039346656037ULL;
    const unsigned char *b = (const unsigned char *)x;
    for (size_t k = 0; k < 3 * (size_t)n * sizeof *x; ++k) h = (h ^ b[k]) * 1099511628211ULL;
    free(x);
    wc_world_destroy(w);
    return h;
}

static void changing_counts_give_the_same_bits(void)
{
    uint64_t one = run_world(0), switching = run_world(1);
    printf("24 steps on 1 thread: %016llx; on 1, 2, 4, 3 in turn: %016llx\n",
           (unsigned long long)one, (unsigned long long)switching);
    CHECK(one == switching && one != 0, "the thread count changed the result");
}

int main(void)
{
    idle_machine_keeps_two();
    busy_core_moves_to_one_and_back();
    clearly_lost_probe_ends_at_once();
    lost_first_stage_ends_the_probe();
    busy_cores_skip_the_probe();
    idle_meter_counts_a_busy_core();
    slowdown_brings_the_probe_forward();
    sixteen_threads_find_the_free_cores();
    ties_go_to_fewer_threads();
    off_or_one_thread_never_changes();
    changing_counts_give_the_same_bits();
    return test_report("test_thread_tuner");
}
